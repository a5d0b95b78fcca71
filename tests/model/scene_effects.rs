//! Scene-level effect switches: the automatic chassis cut-off and the rigid chassis.

use engine_mount_chassis::cosim::{
    BodyOptions, EffectSwitch, Inputs, SceneKind, Settings, Simulation, VehicleOverrides,
    RPM_TO_RAD_PER_S,
};

/// RMS of the vertical steering-wheel acceleration over 0.3–0.5 s, and the number of states.
fn steering_wheel_rms(settings: &Settings) -> (f64, usize, Vec<String>) {
    let mut sim = Simulation::new(settings, 0.0, &Inputs::steady(1900.0)).unwrap();
    let describe = sim.describe();
    let mut sum = 0.0;
    let mut n = 0;
    for k in 1..=500 {
        let t = k as f64 * 1e-3;
        sim.advance_to(t).unwrap();
        if t > 0.3 {
            let a = sim.outputs().unwrap().steering_wheel_acceleration[2];
            sum += a * a;
            n += 1;
        }
    }
    ((sum / n as f64).sqrt(), sim.state_count(), describe)
}

#[test]
fn automatic_cutoff_follows_the_scene() {
    let c = BodyOptions::default();
    assert_eq!(c.mode_cutoff_hz, 0.0);
    assert!((c.cutoff_hz() - 2500.0 / 60.0 * 4.5 * 1.2).abs() < 1e-9);
    let low = BodyOptions {
        max_rpm: 1200.0,
        max_engine_order: 2.0,
        ..c.clone()
    };
    assert!((low.cutoff_hz() - 48.0).abs() < 1e-9);
    let explicit = BodyOptions {
        mode_cutoff_hz: 80.0,
        ..c
    };
    assert_eq!(explicit.cutoff_hz(), 80.0);

    let settings = Settings {
        scene: SceneKind::Body,
        chassis: BodyOptions {
            max_rpm: 1200.0,
            max_engine_order: 2.0,
            ..BodyOptions::default()
        },
        ..Settings::default()
    };
    let sim = Simulation::new(&settings, 0.0, &Inputs::steady(1000.0)).unwrap();
    let text = sim.describe().join("\n");
    assert!(text.contains("automatic cut-off 48 Hz"), "{text}");
}

#[test]
fn a_rigid_chassis_removes_the_body_resonances_and_costs_less() {
    // 1900 rpm: the 1st order (31.7 Hz) sits on the steering-wheel modes of the elastic body.
    let elastic = Settings {
        scene: SceneKind::Body,
        vehicle: VehicleOverrides::default().with_effect(EffectSwitch::BalanceShaft, false),
        chassis: BodyOptions {
            mode_cutoff_hz: 100.0,
            ..BodyOptions::default()
        },
        ..Settings::default()
    };
    let rigid = Settings {
        vehicle: elastic
            .vehicle
            .with_effect(EffectSwitch::ChassisFlexibility, false),
        ..elastic.clone()
    };
    let (a_elastic, states_elastic, _) = steering_wheel_rms(&elastic);
    let (a_rigid, states_rigid, text) = steering_wheel_rms(&rigid);
    assert!(text.join(" ").contains("rigid chassis"), "{text:?}");
    assert!(
        a_rigid < 0.2 * a_elastic,
        "rigid {a_rigid} vs elastic {a_elastic} m/s2"
    );
    assert!(
        states_rigid + 40 < states_elastic,
        "{states_rigid} vs {states_elastic} states"
    );
    eprintln!("steering wheel z RMS: elastic {a_elastic:.3}, rigid {a_rigid:.4} m/s2; states {states_elastic} -> {states_rigid}");
}

/// Amplitude of the 1.5 order of mount 1's vertical force over 8 revolutions at 2000 rpm.
fn one_and_a_half_order(settings: &Settings) -> f64 {
    let rpm = 2000.0;
    let mut sim = Simulation::new(settings, 0.0, &Inputs::steady(rpm)).unwrap();
    let t_rev = 60.0 / rpm;
    let steps = 72;
    let h = t_rev / steps as f64;
    let (mut c, mut s) = (0.0, 0.0);
    let w = 1.5 * rpm * RPM_TO_RAD_PER_S;
    let (settle, window) = (12 * steps, 8 * steps);
    for k in 1..=(settle + window) {
        let t = k as f64 * h;
        sim.advance_to(t).unwrap();
        if k > settle {
            let f = sim.outputs().unwrap().mount_force[0][2];
            c += f * (w * t).cos();
            s += f * (w * t).sin();
        }
    }
    2.0 * (c * c + s * s).sqrt() / window as f64
}

#[test]
fn full_load_combustion_raises_the_gas_order() {
    let idle = one_and_a_half_order(&Settings::default());
    let full = one_and_a_half_order(&Settings {
        vehicle: VehicleOverrides {
            gas_load: Some(1.0),
            ..Default::default()
        },
        ..Settings::default()
    });
    // Peak pressures 51 → 139 bar: the gas torque's 1.5 order grows by about that much.
    assert!(
        full > 1.8 * idle,
        "1.5 order: full load {full} N vs idle {idle} N"
    );
    let bad = Settings {
        vehicle: VehicleOverrides {
            gas_load: Some(1.5),
            ..Default::default()
        },
        ..Settings::default()
    };
    let Err(err) = Simulation::new(&bad, 0.0, &Inputs::steady(2000.0)) else {
        panic!("a load above 1 was accepted");
    };
    assert!(err.to_string().contains("load"), "{err}");
}
