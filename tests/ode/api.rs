//! Driver behaviour: errors as values with the last good state kept, interpolation inside the
//! last step, restart at order 1 after a jump.

#![allow(clippy::needless_range_loop)]

use engine_mount_chassis::ode::test_problems::LinearOscillator;
use engine_mount_chassis::ode::{Bdf, BdfError, BdfOptions, OdeProblem, ProblemError, Tolerance};

/// y' = -y until t = 0.5, then the right-hand side returns NaN.
struct PoisonedAfterHalf;
impl OdeProblem for PoisonedAfterHalf {
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&mut self, t: f64, y: &[f64], f: &mut [f64]) -> Result<(), ProblemError> {
        f[0] = if t > 0.5 { f64::NAN } else { -y[0] };
        Ok(())
    }
}

#[test]
fn non_finite_rhs_is_an_error_and_keeps_the_last_good_step() {
    let mut p = PoisonedAfterHalf;
    let mut bdf = Bdf::new(&mut p, 0.0, &[1.0], BdfOptions::default()).unwrap();
    let err = bdf.advance_to(&mut p, 1.0).unwrap_err();
    assert!(matches!(err, BdfError::NonFiniteRhs { .. }), "{err}");
    assert!(bdf.t() <= 0.5 && bdf.t() > 0.4, "t = {}", bdf.t());
    let y = bdf.y()[0];
    assert!(
        (y - (-bdf.t()).exp()).abs() < 1e-4,
        "y = {y} at t = {}",
        bdf.t()
    );
}

#[test]
fn bad_arguments_are_reported_by_name() {
    let mut p = LinearOscillator::default();
    let e = Bdf::new(&mut p, 0.0, &[1.0, 2.0], BdfOptions::default()).unwrap_err();
    assert!(format!("{e}").contains("y0"));
    let e = Bdf::new(&mut p, 0.0, &[1.0, 2.0, f64::NAN], BdfOptions::default()).unwrap_err();
    assert!(format!("{e}").contains("entry 2"));
    let e = Bdf::new(
        &mut p,
        0.0,
        &[1.0; 3],
        BdfOptions {
            rtol: -1.0,
            ..Default::default()
        },
    )
    .unwrap_err();
    assert!(format!("{e}").contains("rtol"));
    let e = Bdf::new(
        &mut p,
        0.0,
        &[1.0; 3],
        BdfOptions {
            max_order: 6,
            ..Default::default()
        },
    )
    .unwrap_err();
    assert!(format!("{e}").contains("max_order"));
    let e = Bdf::new(
        &mut p,
        0.0,
        &[1.0; 3],
        BdfOptions {
            atol: Tolerance::Vector(vec![1e-6; 2]),
            ..Default::default()
        },
    )
    .unwrap_err();
    assert!(format!("{e}").contains("atol"));
    let mut bdf = Bdf::new(&mut p, 0.0, &[1.0; 3], BdfOptions::default()).unwrap();
    bdf.advance_to(&mut p, 1.0).unwrap();
    assert!(matches!(
        bdf.advance_to(&mut p, 0.5),
        Err(BdfError::InvalidInput {
            field: "t_stop",
            ..
        })
    ));
    assert!(matches!(
        bdf.advance_to(&mut p, f64::NAN),
        Err(BdfError::InvalidInput {
            field: "t_stop",
            ..
        })
    ));
    let mut out = [0.0; 3];
    assert!(matches!(
        bdf.interpolate(2.0, 0, &mut out),
        Err(BdfError::BadInterpolationTime { .. })
    ));
    assert!(bdf.interpolate(1.0, 0, &mut [0.0; 2]).is_err());
}

#[test]
fn too_many_steps_is_reported() {
    let mut p = LinearOscillator::default();
    let opts = BdfOptions {
        max_steps_per_call: 5,
        rtol: 1e-10,
        atol: Tolerance::Scalar(1e-12),
        ..Default::default()
    };
    let mut bdf = Bdf::new(&mut p, 0.0, &[1.0; 3], opts).unwrap();
    let e = bdf.advance_to(&mut p, 10.0).unwrap_err();
    assert!(matches!(e, BdfError::TooManySteps { steps: 5, .. }));
    assert!(bdf.t() > 0.0 && bdf.y().iter().all(|v| v.is_finite()));
}

#[test]
fn interpolation_inside_the_last_step_is_accurate() {
    let mut p = LinearOscillator::default();
    let y0 = p.y0;
    let opts = BdfOptions {
        rtol: 1e-9,
        atol: Tolerance::Scalar(1e-11),
        ..Default::default()
    };
    let mut bdf = Bdf::new(&mut p, 0.0, &y0, opts).unwrap();
    bdf.advance_to(&mut p, 1.0).unwrap();
    let h = bdf.stats().h;
    let mut out = [0.0; 3];
    for frac in [0.0, 0.3, 0.7, 1.0] {
        let t = 1.0 - frac * h;
        bdf.interpolate(t, 0, &mut out).unwrap();
        let exact = p.exact_derivative(t, 0);
        for i in 0..3 {
            assert!((out[i] - exact[i]).abs() < 1e-7, "t {t} comp {i}");
        }
        bdf.interpolate(t, 1, &mut out).unwrap();
        let exact = p.exact_derivative(t, 1);
        for i in 0..3 {
            assert!(
                (out[i] - exact[i]).abs() < 1e-5,
                "derivative at t {t} comp {i}"
            );
        }
    }
}

#[test]
fn restart_after_a_jump_follows_the_new_solution() {
    let mut p = LinearOscillator::default();
    let y0 = p.y0;
    let opts = BdfOptions {
        rtol: 1e-8,
        atol: Tolerance::Scalar(1e-10),
        ..Default::default()
    };
    let mut bdf = Bdf::new(&mut p, 0.0, &y0, opts).unwrap();
    bdf.advance_to(&mut p, 0.5).unwrap();
    // Jump to a new state; the exact solution restarts from it at t = 0.5.
    let jumped = [-1.0, 2.0, 0.25];
    bdf.restart(&mut p, Some(&jumped)).unwrap();
    assert_eq!(bdf.stats().order_next, 1);
    bdf.advance_to(&mut p, 1.5).unwrap();
    let shifted = LinearOscillator {
        y0: jumped,
        ..LinearOscillator::default()
    };
    let exact = shifted.exact_derivative(1.0, 0);
    for i in 0..3 {
        assert!(
            (bdf.y()[i] - exact[i]).abs() < 1e-6,
            "comp {i}: {} vs {}",
            bdf.y()[i],
            exact[i]
        );
    }
}

#[test]
fn lowering_max_order_mid_run_stays_accurate() {
    let mut p = LinearOscillator::default();
    let y0 = p.y0;
    let opts = BdfOptions {
        rtol: 1e-8,
        atol: Tolerance::Scalar(1e-10),
        ..Default::default()
    };
    let mut bdf = Bdf::new(&mut p, 0.0, &y0, opts.clone()).unwrap();
    bdf.advance_to(&mut p, 1.0).unwrap();
    assert!(bdf.stats().order >= 3);
    bdf.set_options(BdfOptions {
        max_order: 2,
        ..opts
    })
    .unwrap();
    bdf.advance_to(&mut p, 2.0).unwrap();
    assert!(bdf.stats().order <= 2);
    let exact = p.exact_derivative(2.0, 0);
    for i in 0..3 {
        assert!((bdf.y()[i] - exact[i]).abs() < 1e-6, "comp {i}");
    }
}

#[test]
fn an_earlier_stop_time_after_a_failed_first_call_is_honoured() {
    // The first call fails at once (too few steps allowed); a later call with a stop time
    // shorter than the prepared first step must still land exactly and accurately.
    let mut p = LinearOscillator::default();
    let y0 = p.y0;
    let opts = BdfOptions {
        rtol: 1e-8,
        atol: Tolerance::Scalar(1e-10),
        max_steps_per_call: 1,
        h_init: Some(0.05),
        ..Default::default()
    };
    let mut bdf = Bdf::new(&mut p, 0.0, &y0, opts.clone()).unwrap();
    assert!(bdf.advance_to(&mut p, 10.0).is_err());
    let t1 = bdf.t();
    bdf.set_options(BdfOptions {
        max_steps_per_call: 100_000,
        ..opts
    })
    .unwrap();
    let target = t1 + 1e-3;
    bdf.advance_to(&mut p, target).unwrap();
    assert_eq!(bdf.t(), target);
    let exact = p.exact_derivative(target, 0);
    for i in 0..3 {
        assert!((bdf.y()[i] - exact[i]).abs() < 1e-6, "comp {i}");
    }
}

/// y' = 1 / (0.5 - t)^2: the solution blows up at t = 0.5.
struct BlowUp;
impl OdeProblem for BlowUp {
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&mut self, t: f64, _y: &[f64], f: &mut [f64]) -> Result<(), ProblemError> {
        f[0] = 1.0 / ((0.5 - t) * (0.5 - t));
        Ok(())
    }
}

#[test]
fn a_singularity_ends_in_an_error_value_with_the_last_good_state() {
    let mut p = BlowUp;
    let mut bdf = Bdf::new(&mut p, 0.0, &[0.0], BdfOptions::default()).unwrap();
    let err = bdf.advance_to(&mut p, 1.0).unwrap_err();
    assert!(
        matches!(
            err,
            BdfError::StepSizeUnderflow { .. }
                | BdfError::TooManyErrorTestFailures { .. }
                | BdfError::TooManyConvergenceFailures { .. }
                | BdfError::TooMuchAccuracy { .. }
                | BdfError::NonFiniteRhs { .. }
                | BdfError::TooManySteps { .. }
        ),
        "{err}"
    );
    let t = bdf.t();
    assert!(t < 0.5 && t > 0.4, "stopped at t = {t}");
    // Exact solution 1/(0.5 - t) - 2 at the last good step.
    let exact = 1.0 / (0.5 - t) - 2.0;
    assert!(bdf.y()[0].is_finite());
    // Close to the pole the problem is ill-conditioned; the state is still the right magnitude.
    assert!(
        (bdf.y()[0] - exact).abs() <= 0.1 * exact.abs().max(1.0),
        "{} vs {exact}",
        bdf.y()[0]
    );
    eprintln!("{err}");
}
