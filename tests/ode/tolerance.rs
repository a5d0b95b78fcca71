//! Tolerance proportionality on stiff nonlinear problems: Robertson (literature reference at
//! t = 40) with analytic and finite-difference Jacobians.

use engine_mount_chassis::ode::test_problems::Robertson;
use engine_mount_chassis::ode::{Bdf, BdfOptions, Tolerance};

fn robertson_error(rtol: f64, analytic_jacobian: bool) -> (f64, u64) {
    let mut p = Robertson { analytic_jacobian };
    let opts = BdfOptions {
        rtol,
        atol: Tolerance::Vector(vec![rtol * 1e-4, rtol * 1e-10, rtol * 1e-4]),
        ..Default::default()
    };
    let mut bdf = Bdf::new(&mut p, 0.0, &Robertson::Y0, opts).unwrap();
    bdf.advance_to(&mut p, 40.0).unwrap();
    let err = bdf
        .y()
        .iter()
        .zip(Robertson::Y_AT_40)
        .map(|(a, r)| ((a - r) / r).abs())
        .fold(0.0, f64::max);
    (err, bdf.stats().steps)
}

#[test]
fn robertson_error_falls_with_rtol() {
    for analytic in [true, false] {
        let rtols = [1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8];
        let runs: Vec<(f64, u64)> = rtols
            .iter()
            .map(|&r| robertson_error(r, analytic))
            .collect();
        eprintln!("analytic {analytic}: {runs:?}");
        for (r, (e, _)) in rtols.iter().zip(&runs) {
            assert!(*e < 100.0 * r, "rtol {r}: relative error {e}");
        }
        // Over five decades of rtol the error must fall by well over two decades, and the
        // work must grow.
        assert!(runs[5].0 < runs[0].0 * 1e-2, "errors {runs:?}");
        assert!(runs[3].0 < runs[0].0, "errors {runs:?}");
        assert!(runs[5].1 > runs[0].1 * 2);
    }
}

#[test]
fn tight_run_reproduces_the_literature_reference() {
    let (err, _) = robertson_error(1e-12, true);
    assert!(err < 1e-9, "relative error {err} at rtol 1e-12");
}
