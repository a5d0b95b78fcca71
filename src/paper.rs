//! Reference values from the paper (Fischer, Witteveen, Premstaller, "Nonlinear Vibration
//! Analysis of FIAT Brava Chassis with 3-Cylinder DI Diesel Engine by Elastic Multibody
//! Simulation", `shared/reference`), for verification and for deriving the default
//! configuration. Nothing in the model reads them at run time.

/// Table 1, engine on rigid ground: rigid-body modes (Hz) with the paper's names.
pub const TABLE1_RIGID: [(f64, &str); 6] = [
    (4.54, "axial translation"),
    (5.21, "vertical translation"),
    (5.38, "lateral translation"),
    (10.74, "pitching"),
    (11.80, "rolling"),
    (12.99, "yawing"),
];

/// Table 1, engine on rigid ground: ring-carrier modes (Hz).
pub const TABLE1_RING_CARRIER: [(f64, &str); 6] = [
    (42.89, "axial deformation of ring carriers"),
    (66.63, "torsion deformation ring carriers"),
    (97.77, "front ring carrier, ajar vertical"),
    (101.42, "front ring carrier, ajar lateral"),
    (128.15, "rear ring carrier, ajar vertical"),
    (149.09, "rear ring carrier, ajar lateral"),
];

/// Table 1, engine in the elastic chassis (middle column), Hz.
pub const TABLE1_HYBRID: [f64; 17] = [
    3.13, 3.49, 4.53, 7.38, 10.38, 10.76, 12.00, 31.50, 32.07, 42.95, 46.20, 52.00, 66.53, 95.07,
    101.42, 128.17, 142.33,
];
