//! Paper Table 1, column "engine supported by ground": modes of the linearised engine at its
//! static equilibrium, frequencies within 5 % and matching descriptions.

use engine_mount_chassis::model::{CoupledModel, Direction, Mode, ModeKind, VehicleConfig};
use engine_mount_chassis::paper::{TABLE1_RIGID, TABLE1_RING_CARRIER};

fn modes(cfg: VehicleConfig) -> Vec<Mode> {
    let mut scene = CoupledModel::on_ground(&cfg).expect("scene");
    let y = scene.static_equilibrium(0.0).expect("equilibrium");
    scene.modes(&y).expect("modes")
}

fn check(mode: &Mode, target: f64, what: &str) {
    assert!(
        (mode.frequency_hz / target - 1.0).abs() < 0.05,
        "{what}: model {:.2} Hz vs paper {target} Hz ({})",
        mode.frequency_hz,
        mode.description
    );
}

#[test]
fn table1_engine_on_ground() {
    let m = modes(VehicleConfig::default());
    assert_eq!(m.len(), 12, "{m:#?}");
    let rigid = [
        Direction::Axial,
        Direction::Vertical,
        Direction::Lateral,
        Direction::Pitch,
        Direction::Roll,
        Direction::Yaw,
    ];
    for (k, ((f, name), dir)) in TABLE1_RIGID.iter().zip(rigid).enumerate() {
        check(&m[k], *f, name);
        assert_eq!(
            m[k].kind,
            ModeKind::RigidBody(dir),
            "{name}: {}",
            m[k].description
        );
        assert!(m[k].mount_strain_fraction > 0.9);
    }
    let ring: [(&str, &[Direction]); 6] = [
        ("", &[Direction::Axial]),
        ("", &[Direction::Roll]),
        ("front", &[Direction::Vertical, Direction::Pitch]),
        ("front", &[Direction::Lateral, Direction::Yaw]),
        ("rear", &[Direction::Vertical, Direction::Pitch]),
        ("rear", &[Direction::Lateral, Direction::Yaw]),
    ];
    for (k, ((f, name), (carrier, dirs))) in TABLE1_RING_CARRIER.iter().zip(ring).enumerate() {
        let mode = &m[6 + k];
        check(mode, *f, name);
        match &mode.kind {
            ModeKind::RingCarrier { bushing, direction } => {
                assert!(dirs.contains(direction), "{name}: {}", mode.description);
                if !carrier.is_empty() {
                    assert_eq!(bushing, carrier, "{name}: {}", mode.description);
                }
            }
            other => panic!("{name}: expected a ring-carrier mode, got {other:?}"),
        }
        assert!(mode.mount_strain_fraction < 0.1);
    }
}

#[test]
fn rigid_powertrain_has_six_modes_near_the_rigid_targets() {
    let mut cfg = VehicleConfig::default();
    cfg.effects.ring_carrier_elasticity = false;
    let m = modes(cfg);
    assert_eq!(m.len(), 6);
    for (mode, (f, name)) in m.iter().zip(TABLE1_RIGID.iter()) {
        check(mode, *f, name);
    }
}

#[test]
fn rigid_modes_match_the_analytic_decoupled_formulas() {
    // Independent truth: with rigid ring carriers, the decoupled layout gives
    // f = √(k/m)/2π per direction with the summed mount rates and the effective inertias.
    let mut cfg = VehicleConfig::default();
    cfg.effects.ring_carrier_elasticity = false;
    let m = modes(cfg);
    let two_pi = 2.0 * std::f64::consts::PI;
    let (kx, ky, kz): (f64, f64, f64) = (4.0 * 51_500.0, 4.0 * 36_600.0, 4.0 * 48_300.0);
    let axial = (ky / 180.0).sqrt() / two_pi;
    let vertical = (kz / 180.0).sqrt() / two_pi;
    let lateral = (kx / 180.0).sqrt() / two_pi;
    let pitch = (kz * 0.16 / 6.8).sqrt() / two_pi;
    let roll = (kz * 0.09 / 3.1).sqrt() / two_pi;
    let yaw = ((kx * 0.16 + ky * 0.09) / 6.9).sqrt() / two_pi;
    for (mode, f) in m.iter().zip([axial, vertical, lateral, pitch, roll, yaw]) {
        assert!(
            (mode.frequency_hz / f - 1.0).abs() < 0.005,
            "{} vs analytic {f}",
            mode.frequency_hz
        );
    }
}
