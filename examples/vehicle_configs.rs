//! Writes the vehicle configurations shipped in the FMU's `resources/`:
//! - `vehicle.json`: the default (the M13 inline-3 on four mounts in the procedural body),
//! - `vehicle_three_mounts.json`: the paper's improved vehicle (§7.1), the rear right mount removed
//!   (it carried little static load but had a low vibration impedance). The three remaining
//!   mounts get the vertical preloads that carry the weight at the design position (three
//!   equations: vertical force and the two tilting moments about the CG), so the operating
//!   points stay in the linear range of the curves.
//!
//! `cargo run --release --example vehicle_configs`

use engine_mount_chassis::model::{VehicleConfig, POWERTRAIN_CG, POWERTRAIN_MASS};
use nalgebra::{Matrix3, Vector3};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/resources");
    std::fs::create_dir_all(dir)?;
    let default = VehicleConfig::default();
    let mut three = default.clone();
    for mount in three.mounts.iter_mut().filter(|m| m.name == "rear_right") {
        mount.active = false;
    }
    let active: Vec<usize> = (0..three.mounts.len())
        .filter(|i| three.mounts[*i].active)
        .collect();
    if active.len() != 3 {
        return Err("the three-mount vehicle needs exactly three active mounts".into());
    }
    let mut a = Matrix3::zeros();
    for (col, i) in active.iter().enumerate() {
        let b = three.mounts[*i].bracket;
        a[(0, col)] = 1.0;
        a[(1, col)] = b[1] - POWERTRAIN_CG[1];
        a[(2, col)] = b[0] - POWERTRAIN_CG[0];
    }
    let weight = POWERTRAIN_MASS * default.gravity;
    let loads = a
        .lu()
        .solve(&Vector3::new(weight, 0.0, 0.0))
        .ok_or("the three mounts cannot carry the weight (collinear)")?;
    for (col, i) in active.iter().enumerate() {
        three.mounts[*i].preload = [0.0, 0.0, loads[col]];
    }
    for (name, config) in [
        ("vehicle.json", &default),
        ("vehicle_three_mounts.json", &three),
    ] {
        let path = format!("{dir}/{name}");
        std::fs::write(&path, config.to_json() + "\n")?;
        println!("wrote {path}");
    }
    Ok(())
}
