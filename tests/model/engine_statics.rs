//! Static equilibrium (fact 6) and configuration handling of the engine model.

use engine_mount_chassis::model::{CoupledModel, VehicleConfig, POWERTRAIN_MASS};

fn vertical_sum(scene: &CoupledModel, y: &[f64]) -> f64 {
    let out = scene.outputs(0.0, y).expect("outputs");
    out.mount_forces.iter().map(|f| f[2]).sum()
}

#[test]
fn default_config_is_valid_and_statics_carry_the_weight() {
    let cfg = VehicleConfig::default();
    cfg.validate().expect("default config valid");
    let mut scene = CoupledModel::on_ground(&cfg).expect("scene");
    let y = scene.static_equilibrium(0.0).expect("equilibrium");
    let weight = POWERTRAIN_MASS * cfg.gravity;
    // Force on the ground side: the powertrain pushes the ground down.
    let sum = -vertical_sum(&scene, &y);
    assert!(
        (sum / weight - 1.0).abs() < 1e-3,
        "sum {sum} vs weight {weight}"
    );
}

#[test]
fn weight_is_carried_without_preload_and_with_load_torque_and_three_mounts() {
    // Fact 6 where the answer is not built into the preloads: no preload at all (the weight
    // deflects the progressive mounts by several mm), a 150 N m load torque, one mount removed.
    let mut cfg = VehicleConfig::default();
    for m in &mut cfg.mounts {
        m.preload = [0.0; 3];
    }
    cfg.mounts[1].active = false;
    let weight = POWERTRAIN_MASS * cfg.gravity;
    let mut scene = CoupledModel::on_ground(&cfg).expect("scene");
    scene.set_load_torque(0.0, 150.0, 0.0).expect("torque");
    let y = scene.static_equilibrium(0.0).expect("equilibrium");
    let out = scene.outputs(0.0, &y).expect("outputs");
    let sum: f64 = -out.mount_forces.iter().map(|f| f[2]).sum::<f64>();
    assert!(
        (sum / weight - 1.0).abs() < 1e-3,
        "sum {sum} vs weight {weight}"
    );
    // The moment about y of the mount forces (ground side) balances the load torque.
    let cg = engine_mount_chassis::model::POWERTRAIN_CG;
    let my: f64 = cfg
        .mounts
        .iter()
        .zip(&out.mount_forces)
        .map(|(m, f)| {
            let r = [m.bracket[0] - cg[0], m.bracket[2] - cg[2]];
            r[1] * f[0] - r[0] * f[2]
        })
        .sum();
    assert!((my - 150.0).abs() < 0.5, "mount moment about y {my}");
    assert_eq!(out.mount_forces[1], [0.0; 3]);
    // The static accelerations vanish.
    for a in out
        .housing
        .acceleration
        .iter()
        .chain(&out.monoblock.acceleration)
    {
        assert!(a.abs() < 1e-6, "{a}");
    }
}

#[test]
fn too_soft_mounts_give_a_clear_error() {
    let mut scene = CoupledModel::on_ground(&VehicleConfig::default()).expect("scene");
    for i in 0..4 {
        scene.set_mount_scales(i, 0.02, 1.0).expect("scale");
    }
    let mut cfg = VehicleConfig::default();
    for m in &mut cfg.mounts {
        m.preload = [0.0; 3];
    }
    let mut soft = CoupledModel::on_ground(&cfg).expect("scene");
    for i in 0..4 {
        soft.set_mount_scales(i, 0.02, 1.0).expect("scale");
    }
    let e = soft.static_equilibrium(0.0).expect_err("too soft");
    assert!(e.to_string().contains("too soft"), "{e}");
}

#[test]
fn invalid_values_are_rejected_naming_field_and_value() {
    type Mutation = Box<dyn Fn(&mut VehicleConfig)>;
    let cases: Vec<(Mutation, &str)> = vec![
        (
            Box::new(|c| c.engine.monoblock.mass = -3.0),
            "monoblock.mass = -3",
        ),
        (
            Box::new(|c| c.engine.housing.inertia[0][0] = -1.0),
            "housing.inertia",
        ),
        (
            Box::new(|c| c.engine.crank_drive.conrod_length = 0.04),
            "lambda",
        ),
        (
            Box::new(|c| c.mounts[2].curves[1].knots[3].stiffness = 0.0),
            "mounts[2].curves[1].knots[3].stiffness = 0",
        ),
        (Box::new(|c| c.engine.gas.load = 1.5), "gas.load = 1.5"),
        (
            Box::new(|c| c.engine.crank_drive.cylinders[1].firing_tdc_deg = 100.0),
            "crank_drive.cylinders[1].firing_tdc_deg = 100",
        ),
        (Box::new(|c| c.mounts.truncate(2)), "2 active mounts"),
        (
            Box::new(|c| c.engine.crank_drive.oscillating_mass = f64::NAN),
            "crank_drive.oscillating_mass = NaN",
        ),
    ];
    for (mutate, expect) in cases {
        let mut c = VehicleConfig::default();
        mutate(&mut c);
        let e = c.validate().expect_err(expect).to_string();
        assert!(
            e.contains(expect),
            "message {e:?} should contain {expect:?}"
        );
        assert!(CoupledModel::on_ground(&c).is_err());
    }
}

#[test]
fn json_round_trip_and_partial_json_only_by_extending_the_default() {
    let d = VehicleConfig::default();
    let back = VehicleConfig::from_json(&d.to_json()).expect("round trip");
    assert_eq!(back, d);
    let partial = VehicleConfig::from_json(
        r#"{"extends": "default", "gravity": 9.80665, "effects": {"gas_forces": false}}"#,
    )
    .expect("partial");
    assert_eq!(partial.gravity, 9.80665);
    assert!(!partial.effects.gas_forces);
    assert!(partial.effects.mass_forces);
    assert_eq!(partial.mounts, d.mounts);
    // Without `extends` a partial file is an error naming what is missing.
    let e = VehicleConfig::from_json(r#"{"gravity": 9.80665}"#).expect_err("missing fields");
    assert!(e.to_string().contains("missing field"), "{e}");
    let e = VehicleConfig::from_json(r#"{"gravity": "x"}"#).expect_err("bad json");
    assert!(e.to_string().contains("gravity"), "{e}");
}

#[test]
fn resource_file_equals_the_defaults() {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/resources/vehicle.json"
    ))
    .expect("resources/vehicle.json");
    let cfg = VehicleConfig::from_json(&text).expect("resource parses");
    assert_eq!(
        cfg,
        VehicleConfig::default(),
        "regenerate with `cargo run --release --example vehicle_configs`"
    );
}

#[test]
fn three_mount_resource_carries_the_weight_at_the_design_position() {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/resources/vehicle_three_mounts.json"
    ))
    .expect("resources/vehicle_three_mounts.json");
    let cfg = VehicleConfig::from_json(&text).expect("resource parses");
    let names: Vec<&str> = cfg
        .mounts
        .iter()
        .filter(|m| m.active)
        .map(|m| m.name.as_str())
        .collect();
    assert_eq!(names, ["front_left", "front_right", "rear_left"]);
    let rest = VehicleConfig {
        mounts: cfg.mounts.clone(),
        ..VehicleConfig::default()
    };
    assert_eq!(rest, cfg, "only the mounts differ from the default");
    let mut scene = CoupledModel::on_ground(&cfg).expect("valid");
    let y = scene.static_equilibrium(0.0).expect("equilibrium");
    let out = scene.outputs(0.0, &y).expect("outputs");
    let vertical: f64 = out.mount_forces.iter().map(|f| f[2]).sum();
    let weight = 180.0 * cfg.gravity;
    assert!((vertical + weight).abs() < 1e-3 * weight, "{vertical}");
    // the preloads balance the weight at the design position: the operating points stay linear
    for d in out.housing.displacement {
        assert!(d.abs() < 1e-5, "static displacement {d} m");
    }
}
