//! Paper §6.2 / Table 1 middle column with the real chassis: the coupled modes of the engine in
//! the elastic body against the engine on rigid ground (left column).

use engine_mount_chassis::chassis::modal::{steering_wheel_pair, ModeKind as ChassisMode};
use engine_mount_chassis::cms::reduce_detailed;
use engine_mount_chassis::model::scene::{reduction_spec, BodyOptions};
use engine_mount_chassis::model::{CoupledModel, Direction, Mode, ModeKind, VehicleConfig};

const DIRECTIONS: [Direction; 6] = [
    Direction::Lateral,
    Direction::Axial,
    Direction::Vertical,
    Direction::Pitch,
    Direction::Roll,
    Direction::Yaw,
];

/// The coupled mode with the most powertrain kinetic energy in direction `d` (ring-carrier modes
/// excluded): the engine's rigid-body mode in that direction, wherever the chassis moved it.
fn engine_mode(modes: &[Mode], d: Direction) -> &Mode {
    let i = DIRECTIONS.iter().position(|x| *x == d).unwrap();
    modes
        .iter()
        .filter(|m| !matches!(m.kind, ModeKind::RingCarrier { .. }))
        .max_by(|a, b| {
            (a.powertrain_fraction * a.powertrain_directions[i])
                .total_cmp(&(b.powertrain_fraction * b.powertrain_directions[i]))
        })
        .unwrap()
}

#[test]
fn hybrid_modes_reproduce_paper_section_6_2() {
    // The FMU's default chassis: Craig-Bampton with the fixed-interface modes below 200 Hz.
    let cfg = VehicleConfig::default();
    let options = BodyOptions {
        mode_cutoff_hz: 200.0,
        ..BodyOptions::default()
    };
    let (spec, _) = reduction_spec(&cfg, &options).unwrap();
    let reduction = reduce_detailed(&spec).unwrap();
    let labels = reduction.describe_modes().unwrap();
    let chassis = reduction.reduced;
    let mut ground = CoupledModel::on_ground(&cfg).unwrap();
    let y_ground = ground.static_equilibrium(0.0).unwrap();
    let alone = ground.modes(&y_ground).unwrap();
    let mut hybrid = CoupledModel::with_body(&cfg, chassis).unwrap();
    let y = hybrid.static_equilibrium(0.0).unwrap();
    let modes = hybrid.modes(&y).unwrap();

    let ground_of = |d: Direction| {
        alone
            .iter()
            .find(|m| m.kind == ModeKind::RigidBody(d))
            .unwrap()
            .frequency_hz
    };
    let shift = |d: Direction| engine_mode(&modes, d).frequency_hz / ground_of(d) - 1.0;
    // Translational engine modes shift strongly (paper: up to ~40 %) ...
    let translations = [Direction::Axial, Direction::Vertical, Direction::Lateral].map(shift);
    assert!(
        translations.iter().all(|s| s.abs() > 0.08) && translations.iter().any(|s| s.abs() > 0.25),
        "translational shifts {translations:?}"
    );
    // ... while pitch, roll and yaw move less than 10 %.
    for d in [Direction::Pitch, Direction::Roll, Direction::Yaw] {
        assert!(shift(d).abs() < 0.10, "{d:?} shifts {}", shift(d));
    }
    // Ring-carrier modes shift little.
    for g in alone
        .iter()
        .filter(|m| matches!(m.kind, ModeKind::RingCarrier { .. }))
    {
        let nearest = modes
            .iter()
            .filter(|m| matches!(m.kind, ModeKind::RingCarrier { .. }))
            .map(|m| (m.frequency_hz / g.frequency_hz - 1.0).abs())
            .fold(f64::INFINITY, f64::min);
        assert!(
            nearest < 0.02,
            "ring carrier mode {} Hz moved {nearest}",
            g.frequency_hz
        );
    }
    // Steering-wheel modes at 31-33 Hz and the global torsion near the paper's, identified by the
    // FE description of the chassis mode that dominates them.
    let by_chassis_kind = |kind: ChassisMode| -> Vec<f64> {
        modes
            .iter()
            .filter(
                |m| matches!(&m.kind, ModeKind::Body { mode, .. } if labels[*mode].kind == kind),
            )
            .map(|m| m.frequency_hz)
            .collect()
    };
    let (vertical, lateral) = steering_wheel_pair(&labels).unwrap();
    let wheel: Vec<f64> = modes
        .iter()
        .filter(|m| matches!(&m.kind, ModeKind::Body { mode, .. } if *mode == vertical || *mode == lateral))
        .map(|m| m.frequency_hz)
        .collect();
    assert_eq!(wheel.len(), 2, "steering wheel modes {wheel:?}");
    assert!(wheel.iter().all(|f| (31.0..=33.0).contains(f)), "{wheel:?}");
    let torsion = by_chassis_kind(ChassisMode::GlobalTorsion);
    assert_eq!(torsion.len(), 1, "torsion modes {torsion:?}");
    // Paper: 46.2 Hz with the engine, 43 Hz without. The soft mounts barely move the torsion
    // mode in this model, so the body is tuned to 44.5 Hz, inside both bands (see fe_tune).
    assert!((44.0..=48.0).contains(&torsion[0]), "torsion {torsion:?}");
}
