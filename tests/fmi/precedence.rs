//! Which value wins where two sources give one: `fmi2SetupExperiment`'s tolerance is the
//! integrator's relative tolerance unless the master set `solver.relTol` itself; a configuration
//! file's vehicle values hold unless the master set the matching FMU parameter, and the
//! parameters read back what the model uses.

use crate::common::*;
use engine_mount_chassis::fmi2::variables::{boolean, integer, real, string};

/// Integrator steps for 50 ms at 2000 rpm after setting up with `tolerance` (and `rel_tol`).
fn steps(
    fmu: &Fmu,
    name: &str,
    tolerance: Option<f64>,
    rel_tol: Option<f64>,
) -> (i32, Vec<String>) {
    let s = fmu.instantiate(name);
    s.log_everything();
    assert_eq!(s.set_real(&[real::RPM], &[2000.0]), OK);
    if let Some(r) = rel_tol {
        assert_eq!(s.set_real(&[real::SOLVER_REL_TOL], &[r]), OK);
    }
    let status = match tolerance {
        Some(t) => s.setup_with_tolerance(t),
        None => s.setup(0.0, None),
    };
    assert_eq!(status, OK);
    assert_eq!(s.enter_init(), OK);
    assert_eq!(s.exit_init(), OK, "{:?}", s.logs());
    for k in 0..50 {
        assert_eq!(s.do_step(k as f64 * 1e-3, 1e-3), OK);
    }
    let (_, n) = s.get_integer(&[integer::SOLVER_STEPS]);
    (n[0], s.logs())
}

#[test]
fn the_experiment_tolerance_is_used_unless_rel_tol_was_set() {
    let fmu = Fmu::load();
    let (default, log) = steps(&fmu, "tol-default", None, None);
    assert!(
        log.iter()
            .any(|l| l.contains("relative tolerance 0.00001 (solver.relTol)")
                || l.contains("relative tolerance 1e-5 (solver.relTol)")),
        "{log:?}"
    );
    let (loose, log) = steps(&fmu, "tol-experiment", Some(1e-3), None);
    assert!(
        log.iter()
            .any(|l| l.contains("relative tolerance 0.001 from fmi2SetupExperiment")),
        "{log:?}"
    );
    assert!(
        loose < default,
        "{loose} steps at 1e-3 vs {default} at 1e-5"
    );
    // exactly what solver.relTol = 1e-3 gives
    let (same, _) = steps(&fmu, "tol-as-parameter", None, Some(1e-3));
    assert_eq!(loose, same);
    let (explicit, log) = steps(&fmu, "tol-explicit", Some(1e-3), Some(1e-5));
    assert!(
        log.iter()
            .any(|l| l.contains("from solver.relTol (set explicitly")),
        "{log:?}"
    );
    assert_eq!(explicit, default);
}

#[test]
fn a_tolerance_outside_the_range_is_an_error() {
    let fmu = Fmu::load();
    let s = fmu.instantiate("tol-bad");
    assert_eq!(s.setup_with_tolerance(f64::NAN), ERROR);
    assert_eq!(s.setup_with_tolerance(2.0), ERROR);
    assert!(
        s.logs()
            .iter()
            .any(|l| l.contains("tolerance 2 is outside")),
        "{:?}",
        s.logs()
    );
    assert_eq!(s.setup_with_tolerance(1e-4), OK);
}

#[test]
fn a_configuration_file_keeps_its_values_unless_the_master_sets_the_parameter() {
    let fmu = Fmu::load();
    let dir = std::env::temp_dir().join(format!("emc-precedence-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let config = dir.join("loaded.json");
    std::fs::write(
        &config,
        r#"{"extends": "default", "engine": {"gas": {"load": 0.7}}, "effects": {"balance_shaft": false}}"#,
    )
    .unwrap();
    let path = config.display().to_string();

    // Not set by the master: the file's values are used, and the parameters say so.
    let s = fmu.instantiate("file-values");
    assert_eq!(s.set_string(&[string::CONFIG_FILE], &[&path]), OK);
    s.initialize();
    assert_eq!(s.reals(&[real::ENGINE_LOAD]), vec![0.7]);
    let (_, b) = s.get_boolean(&[boolean::EFFECT_BALANCE_SHAFT]);
    assert_eq!(b, vec![false]);

    // Set by the master: the parameter wins, with a log line naming both values.
    let s = fmu.instantiate("parameter-wins");
    s.log_everything();
    assert_eq!(s.set_string(&[string::CONFIG_FILE], &[&path]), OK);
    assert_eq!(s.set_real(&[real::ENGINE_LOAD], &[0.2]), OK);
    s.initialize();
    assert_eq!(s.reals(&[real::ENGINE_LOAD]), vec![0.2]);
    assert!(
        s.logs()
            .iter()
            .any(|l| l
                .contains("engine.load = 0.2 (FMU parameter) replaces the configuration's 0.7")),
        "{:?}",
        s.logs()
    );
    let (_, b) = s.get_boolean(&[boolean::EFFECT_BALANCE_SHAFT]);
    assert_eq!(b, vec![false], "not set: still the file's");
    let _ = std::fs::remove_dir_all(&dir);
}
