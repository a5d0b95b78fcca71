//! The body's damping from the vehicle configuration reaches the equations: a single-mode body's
//! free decay gives the configured ratio back (the logarithmic decrement of the sampled
//! response, independent of the code that applies it), and the hard damping cases (an undamped
//! body, 100 % everywhere, a single-point table, a step) stay stable in the engine's scene.

use engine_mount_chassis::cms::{RecoveryPoint, ReducedChassis};
use engine_mount_chassis::cosim::{
    BodyOptions, BodySimulation, Inputs, RampInput, SceneKind, Settings, Simulation,
};
use engine_mount_chassis::model::VehicleConfig;

const TWO_PI: f64 = 2.0 * std::f64::consts::PI;

fn temp_dir(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("emc-damping-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

/// One mode of `hz` seen at every mount point and output along z, with unit shape.
fn single_mode_body(hz: f64) -> ReducedChassis {
    let vehicle = VehicleConfig::default();
    let mut points: Vec<RecoveryPoint> = vehicle
        .mounts
        .iter()
        .map(|m| RecoveryPoint {
            name: m.body_node.clone().expect("body node"),
            node: 0,
            position: m.bracket,
            shape: vec![[0.0, 0.0, 1.0, 0.0, 0.0, 0.0]],
        })
        .collect();
    for name in &vehicle.outputs {
        points.push(RecoveryPoint {
            name: name.clone(),
            node: 0,
            position: [0.0; 3],
            shape: vec![[0.0, 0.0, 1.0, 0.0, 0.0, 0.0]],
        });
    }
    ReducedChassis {
        omega: vec![TWO_PI * hz],
        zeta: vec![0.0],
        points,
        cutoff_hz: None,
        own_damping: None,
    }
}

/// The damping ratio of a sampled free decay `a(t) = A e^{-σt} cos(ω_d t + φ)`: successive
/// maxima (located by a parabola through the three samples around each) shrink by
/// `e^{-σ T_d}`, the logarithmic decrement δ = 2πζ/√(1−ζ²).
fn ratio_from_decay(samples: &[f64]) -> f64 {
    let mut peaks = Vec::new();
    for k in 1..samples.len() - 1 {
        let (a, b, c) = (samples[k - 1], samples[k], samples[k + 1]);
        if b > a && b >= c && b > 0.0 {
            let curvature = a - 2.0 * b + c;
            let offset = 0.5 * (a - c) / curvature;
            peaks.push(b - 0.25 * (a - c) * offset);
        }
    }
    assert!(peaks.len() > 5, "{} peaks", peaks.len());
    let cycles = (peaks.len() - 1) as f64;
    let delta = (peaks[0] / peaks[peaks.len() - 1]).ln() / cycles;
    delta / (TWO_PI * TWO_PI + delta * delta).sqrt()
}

#[test]
fn a_single_mode_body_decays_with_the_configured_ratio() {
    let dir = temp_dir("decay");
    let hz = 20.0;
    std::fs::write(
        dir.join("one_mode.json"),
        serde_json::to_string(&single_mode_body(hz)).unwrap(),
    )
    .unwrap();
    // A G table interpolated at 20 Hz: g = 0.08, ζ = 0.04.
    std::fs::write(
        dir.join("vehicle.json"),
        r#"{"extends": "default", "body": {"kind": "reduced", "path": "one_mode.json",
            "damping": {"table": {"type": "g", "points": [[10, 0.04], [30, 0.12]]},
                        "above_cutoff": {"type": "crit", "points": [[0, 0.0]]}}}}"#,
    )
    .unwrap();
    let settings = Settings {
        scene: SceneKind::Body,
        config_file: Some(dir.join("vehicle.json")),
        ..Settings::default()
    };
    let rest = Inputs::steady(0.0);
    let mut body = BodySimulation::new(&settings, 0.0, &rest).expect("body alone");
    let mut step = rest.sized(4);
    step.body_force[0][2] = RampInput::constant(100.0);
    body.set_inputs(&step).unwrap();
    let h = 1.0 / (hz * 400.0);
    let samples: Vec<f64> = (1..=400 * 12)
        .map(|k| {
            body.advance_to(k as f64 * h).unwrap();
            body.outputs().steering_wheel_acceleration[2]
        })
        .collect();
    let zeta = ratio_from_decay(&samples);
    println!("configured 0.04, from the decay {zeta:.8}");
    assert!((zeta - 0.04).abs() < 1e-4, "ζ = {zeta}");
    let _ = std::fs::remove_dir_all(&dir);
}

fn scene_with_damping(dir: &std::path::Path, name: &str, damping: &str) -> Settings {
    let file = dir.join(format!("{name}.json"));
    std::fs::write(
        &file,
        format!(r#"{{"extends": "default", "body": {{"damping": {damping}}}}}"#),
    )
    .unwrap();
    Settings {
        scene: SceneKind::Body,
        config_file: Some(file),
        chassis: BodyOptions {
            mode_cutoff_hz: 100.0,
            ..BodyOptions::default()
        },
        ..Settings::default()
    }
}

fn inputs(rpm: f64) -> Inputs {
    Inputs::steady(rpm)
}

/// The largest steering-wheel acceleration over 0.4 s at 1500 rpm; every output finite.
fn wheel_peak(settings: &Settings) -> f64 {
    let mut sim = Simulation::new(settings, 0.0, &inputs(1500.0)).expect("scene 2");
    crate::hard_cases::wheel_peak(&mut sim, 400)
}

#[test]
fn the_hard_damping_cases_stay_stable() {
    let dir = temp_dir("hard");
    let zero = r#"{"type": "crit", "points": [[0, 0.0]]}"#;
    let full = r#"{"type": "crit", "points": [[0, 1.0]]}"#;
    let cases = [
        (
            "undamped",
            format!(r#"{{"table": {zero}, "above_cutoff": {zero}}}"#),
        ),
        (
            "critical",
            format!(r#"{{"table": {full}, "above_cutoff": {full}}}"#),
        ),
        (
            "single point",
            r#"{"table": {"type": "q", "points": [[31.3, 16.6]]}}"#.to_string(),
        ),
        (
            "step",
            r#"{"table": {"type": "crit", "points": [[40, 0.01], [40, 0.07]]}}"#.to_string(),
        ),
    ];
    let mut peaks = Vec::new();
    for (name, damping) in &cases {
        let settings = scene_with_damping(&dir, &name.replace(' ', "_"), damping);
        let peak = wheel_peak(&settings);
        println!("{name}: steering-wheel peak {peak:.3} m/s²");
        assert!(peak < 100.0, "{name}: {peak} m/s²");
        peaks.push(peak);
    }
    // Critical damping everywhere calms the body below any lightly damped case.
    assert!(peaks[1] < peaks[0] && peaks[1] < peaks[2] && peaks[1] < peaks[3]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn an_override_of_a_mode_the_body_lacks_is_refused_naming_it() {
    let dir = temp_dir("override");
    let settings = scene_with_damping(
        &dir,
        "override",
        r#"{"table": {"type": "crit", "points": [[0, 0.05]]}, "modes": [[8, 0.02], [500, 0.02]]}"#,
    );
    let e = Simulation::new(&settings, 0.0, &inputs(1000.0))
        .err()
        .expect("refused")
        .to_string();
    assert!(
        e.contains("body.damping: modes[1]: mode 500, but the body has"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_adams_preset_is_the_old_table() {
    let file = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/resources/vehicle_adams_damping.json"
    );
    let vehicle = VehicleConfig::from_file(std::path::Path::new(file)).expect("preset");
    assert_eq!(
        vehicle.body.damping(),
        Some(&engine_mount_chassis::cms::BodyDamping::adams())
    );
}

#[test]
fn bad_tables_in_the_configuration_are_refused_naming_the_field_and_point() {
    for (damping, field, says) in [
        (
            r#"{"table": {"type": "crit", "points": [[10, 0.01], [5, 0.02]]}}"#,
            "body.damping.table",
            "point 1: frequency 5 Hz is below the one before it",
        ),
        (
            r#"{"table": {"type": "g", "points": [[10, -0.01]]}}"#,
            "body.damping.table",
            "point 0: G value -0.01",
        ),
        (
            r#"{"table": {"type": "crit", "points": [[10, 0.01]]}, "modes": [[0, 0.02]]}"#,
            "body.damping.modes[0]",
            "mode 0 does not exist",
        ),
        (
            r#"{"table": {"type": "kdamp", "points": [[10, 0.01]]}}"#,
            "body",
            "unknown variant `kdamp`",
        ),
    ] {
        let e = VehicleConfig::from_json(&format!(
            r#"{{"extends": "default", "body": {{"damping": {damping}}}}}"#
        ))
        .unwrap_err();
        assert!(
            e.field.starts_with(field) && e.message.contains(says),
            "{e}"
        );
    }
}

#[test]
fn damping_above_critical_is_accepted_with_a_warning_naming_mode_and_value() {
    let dir = temp_dir("overdamped");
    // Each a likely unit mistake: CRIT 1.5, G 10 (ζ = 5), Q 0.01 (ζ = 50), an override of 50.
    let cases = [
        (
            "crit",
            r#"{"table": {"type": "crit", "points": [[0, 1.5]]}}"#,
            "1.500",
        ),
        (
            "g",
            r#"{"table": {"type": "g", "points": [[0, 10.0]]}}"#,
            "5.000",
        ),
        (
            "q",
            r#"{"table": {"type": "q", "points": [[0, 0.01]]}}"#,
            "50.000",
        ),
        (
            "override",
            r#"{"table": {"type": "crit", "points": [[0, 0.05]]}, "modes": [[3, 50.0]]}"#,
            "50.000",
        ),
    ];
    for (name, damping, value) in cases {
        let settings = scene_with_damping(&dir, name, damping);
        let sim = Simulation::new(&settings, 0.0, &inputs(1500.0)).expect("accepted");
        let warnings: Vec<String> = sim
            .describe()
            .into_iter()
            .filter(|l| l.starts_with("warning: "))
            .collect();
        assert!(!warnings.is_empty(), "{name}: no warning");
        let first = &warnings[0];
        assert!(
            first.contains(&format!("is damped at {value} of critical, above critical"))
                && first.contains("body mode")
                && first.contains("the vehicle configuration's body.damping"),
            "{name}: {first}"
        );
        if name == "override" {
            assert!(first.contains("body mode 3 ("), "{first}");
            assert_eq!(warnings.len(), 1, "{warnings:?}");
        }
    }
    // The default 5 % warns of nothing.
    let settings = Settings {
        scene: SceneKind::Body,
        ..Settings::default()
    };
    let sim = Simulation::new(&settings, 0.0, &inputs(1500.0)).expect("scene 2");
    assert!(!sim.describe().iter().any(|l| l.starts_with("warning: ")));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_damping_type_error_in_the_json_names_its_path() {
    let e = VehicleConfig::from_json(
        r#"{"extends": "default", "body": {"kind": "procedural", "damping": {"table": {"type": "crit", "points": [[10.0, 0.05]]}, "modes": [[2.5, 0.02]]}}}"#,
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("body.damping.modes"), "{e}");
    assert!(e.contains("expected usize"), "{e}");
}
