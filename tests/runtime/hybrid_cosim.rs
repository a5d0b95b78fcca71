//! Scene 2 through the co-simulation runtime: the reduced chassis from the cache, statics,
//! stepping, outputs and exact restore.

use engine_mount_chassis::cosim::{CacheSetting, Inputs, SceneKind, Settings, Simulation};

fn settings(cache: &std::path::Path) -> Settings {
    let mut s = Settings {
        scene: SceneKind::Body,
        ..Settings::default()
    };
    s.chassis.cache = CacheSetting::Dir(cache.to_path_buf());
    s
}

fn temp_cache(tag: &str) -> std::path::PathBuf {
    std::env::temp_dir().join(format!("emc-hybrid-{tag}-{}", std::process::id()))
}

#[test]
fn scene_2_starts_at_the_coupled_equilibrium_and_runs() {
    let dir = temp_cache("run");
    let settings = settings(&dir);
    let mut sim = Simulation::new(&settings, 0.0, &Inputs::steady(1800.0)).unwrap();
    let log = sim.describe().join("\n");
    assert!(log.contains("reduced and cached at"), "{log}");
    let o = sim.outputs().unwrap();
    let fz: f64 = o.mount_force.iter().map(|f| f[2]).sum();
    // Fact 6 in the elastic chassis (ground/chassis-side forces point down).
    let w = 1765.8;
    assert!((fz + w).abs() < 0.5, "sum Fz {fz}");
    for k in 1..=40 {
        sim.advance_to(k as f64 * 2.5e-3).unwrap();
    }
    let o = sim.outputs().unwrap();
    let a = o.steering_wheel_acceleration;
    assert!(a.iter().chain(&o.seat_acceleration).all(|x| x.is_finite()));
    // The running engine shakes the body measurably but not absurdly (m/s²).
    let amp = a.iter().map(|x| x * x).sum::<f64>().sqrt();
    assert!(amp > 1e-4 && amp < 50.0, "steering wheel |a| = {amp}");

    // A second simulation reads the cache and gets the same model: same outputs bit for bit.
    let mut again = Simulation::new(&settings, 0.0, &Inputs::steady(1800.0)).unwrap();
    let log = again.describe().join("\n");
    assert!(log.contains("read from cache"), "{log}");
    for k in 1..=40 {
        again.advance_to(k as f64 * 2.5e-3).unwrap();
    }
    assert_eq!(again.outputs().unwrap(), o);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn restored_scene_2_state_continues_bit_for_bit() {
    let dir = temp_cache("restore");
    let settings = settings(&dir);
    let mut a = Simulation::new(&settings, 0.0, &Inputs::steady(1200.0)).unwrap();
    for k in 1..=20 {
        a.advance_to(k as f64 * 1e-3).unwrap();
    }
    let saved = a.dynamic_state();
    let mut b = Simulation::restore(&settings, &saved).unwrap();
    assert_eq!(b.dynamic_state(), saved);
    for k in 21..=40 {
        let t = k as f64 * 1e-3;
        a.advance_to(t).unwrap();
        b.advance_to(t).unwrap();
        assert_eq!(a.outputs().unwrap(), b.outputs().unwrap(), "t = {t}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_chassis_settings_are_errors_naming_the_value() {
    let dir = temp_cache("bad");
    let mut s = settings(&dir);
    s.chassis.mode_cutoff_hz = f64::NAN;
    let err = Simulation::new(&s, 0.0, &Inputs::steady(800.0))
        .err()
        .unwrap();
    assert!(
        matches!(
            &err,
            engine_mount_chassis::cosim::Error::BodyOption {
                option: engine_mount_chassis::cosim::BodyOption::ModeCutoff,
                value,
                ..
            } if value == "NaN Hz"
        ),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn improved_vehicle_three_mounts_and_stiffening_bar() {
    use engine_mount_chassis::model::VehicleConfig;
    let dir = temp_cache("improved");
    let mut engine = VehicleConfig::default();
    engine.mounts[3].active = false;
    let config = dir.join("engine_three_mounts.json");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(&config, serde_json::to_string(&engine).unwrap()).unwrap();
    let mut s = settings(&dir);
    s.config_file = Some(config);
    s.chassis.stiffening_bar = true;
    s.chassis.mode_cutoff_hz = 100.0;
    let mut sim = Simulation::new(&s, 0.0, &Inputs::steady(1500.0)).unwrap();
    let log = sim.describe().join("\n");
    assert!(
        log.contains("stiffening bar on") && log.contains("3 of 4 mounts active"),
        "{log}"
    );
    let o = sim.outputs().unwrap();
    assert_eq!(o.mount_force[3], [0.0; 3]);
    let fz: f64 = o.mount_force.iter().map(|f| f[2]).sum();
    assert!((fz + 1765.8).abs() < 0.5, "sum Fz {fz}");
    for k in 1..=20 {
        sim.advance_to(k as f64 * 2e-3).unwrap();
    }
    let o = sim.outputs().unwrap();
    assert_eq!(o.mount_force[3], [0.0; 3]);
    assert!(o.steering_wheel_acceleration.iter().all(|a| a.is_finite()));
    let _ = std::fs::remove_dir_all(&dir);
}
