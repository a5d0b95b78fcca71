//! The block-diagonal plus low-rank Newton solve (Woodbury) against the dense one, on a modal
//! chain with a stiff two-mass absorber: same solution, same accuracy against a tight reference,
//! and snapshots that restore bit for bit through the flat serialisation.

use engine_mount_chassis::ode::test_problems::ModalChainWithAbsorber;
use engine_mount_chassis::ode::{Bdf, BdfError, BdfOptions, BdfSnapshot, OdeProblem, Tolerance};

fn options(rtol: f64) -> BdfOptions {
    BdfOptions {
        rtol,
        atol: Tolerance::Scalar(rtol * 1e-3),
        ..Default::default()
    }
}

fn run(structured: bool, rtol: f64, t_end: f64) -> (Vec<f64>, u64) {
    let mut p = ModalChainWithAbsorber::new(structured).unwrap();
    let y0 = vec![0.0; p.dim()];
    let mut bdf = Bdf::new(&mut p, 0.0, &y0, options(rtol)).unwrap();
    bdf.advance_to(&mut p, t_end).unwrap();
    (bdf.y().to_vec(), bdf.stats().steps)
}

fn relative_error(a: &[f64], reference: &[f64]) -> f64 {
    let num: f64 = a.iter().zip(reference).map(|(x, r)| (x - r).powi(2)).sum();
    let den: f64 = reference.iter().map(|r| r * r).sum();
    (num / den).sqrt()
}

#[test]
fn structured_and_dense_newton_reach_the_same_accuracy() {
    let t_end = 0.2;
    let (reference, _) = run(false, 1e-11, t_end);
    // The global error of one run scatters by a factor of about 3 with the rounding of the
    // linear solves (it changes the step sequence); over five tolerances the two solvers must
    // agree on average, and each run must follow its tolerance.
    let mut log_ratio = 0.0;
    let mut steps = (0u64, 0u64);
    let tolerances = [1e-4, 1e-5, 1e-6, 1e-7, 1e-8];
    for rtol in tolerances {
        let (dense, dense_steps) = run(false, rtol, t_end);
        let (structured, structured_steps) = run(true, rtol, t_end);
        let (e_dense, e_structured) = (
            relative_error(&dense, &reference),
            relative_error(&structured, &reference),
        );
        assert!(
            e_structured < 300.0 * rtol && e_dense < 300.0 * rtol,
            "rtol {rtol}: error {e_structured:e} (dense {e_dense:e})"
        );
        assert!(
            e_structured < 6.0 * e_dense && e_dense < 6.0 * e_structured,
            "rtol {rtol}: dense {e_dense:e}, structured {e_structured:e}"
        );
        log_ratio += (e_structured / e_dense).ln() / tolerances.len() as f64;
        steps.0 += dense_steps;
        steps.1 += structured_steps;
    }
    // The step count of one run scatters with rounding too (up to 30 % at rtol 1e-6 on this
    // stiff absorber); over all tolerances the two must take the same work.
    let ratio = steps.1 as f64 / steps.0 as f64;
    assert!(
        (0.85..1.18).contains(&ratio),
        "steps {} (structured) vs {} (dense)",
        steps.1,
        steps.0
    );
    assert!(
        log_ratio.abs() < 2f64.ln(),
        "structured/dense error ratio {:.2} on average",
        log_ratio.exp()
    );
}

#[test]
fn structured_snapshots_restore_bit_for_bit() {
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    let mut p = ModalChainWithAbsorber::new(true).unwrap();
    let y0 = vec![0.0; p.dim()];
    let mut bdf = Bdf::new(&mut p, 0.0, &y0, options(1e-6)).unwrap();
    bdf.advance_to(&mut p, 0.05).unwrap();
    let bytes = bdf.snapshot().to_bytes();
    bdf.advance_to(&mut p, 0.08).unwrap();
    let first = (bits(bdf.y()), bdf.stats().clone());

    let mut other = Bdf::new(&mut p, 0.0, &y0, BdfOptions::default()).unwrap();
    other
        .restore(&BdfSnapshot::from_bytes(&bytes).unwrap())
        .unwrap();
    other.advance_to(&mut p, 0.08).unwrap();
    assert_eq!(first.0, bits(other.y()));
    assert_eq!(first.1, *other.stats());

    // A dense integrator of the same problem refuses the structured snapshot, and vice versa.
    let mut dense_problem = ModalChainWithAbsorber::new(false).unwrap();
    let mut dense = Bdf::new(&mut dense_problem, 0.0, &y0, BdfOptions::default()).unwrap();
    let structured_snapshot = BdfSnapshot::from_bytes(&bytes).unwrap();
    assert!(matches!(
        dense.restore(&structured_snapshot),
        Err(BdfError::BadSnapshot(_))
    ));
    assert!(matches!(
        other.restore(&dense.snapshot()),
        Err(BdfError::BadSnapshot(_))
    ));
}

#[test]
fn the_test_problem_jacobian_is_its_derivative() {
    let mut p = ModalChainWithAbsorber::new(false).unwrap();
    let n = p.dim();
    let y: Vec<f64> = (0..n).map(|i| 1e-3 * (i as f64 * 0.9).sin()).collect();
    let mut j = faer::Mat::<f64>::zeros(n, n);
    assert!(p.jacobian(0.01, &y, j.as_mut()).unwrap());
    let (mut fp, mut fm) = (vec![0.0; n], vec![0.0; n]);
    for c in 0..n {
        let (mut yp, mut ym) = (y.clone(), y.clone());
        yp[c] += 1e-6;
        ym[c] -= 1e-6;
        p.rhs(0.01, &yp, &mut fp).unwrap();
        p.rhs(0.01, &ym, &mut fm).unwrap();
        let scale = (0..n).map(|r| j[(r, c)].abs()).fold(1.0, f64::max);
        for r in 0..n {
            let fd = (fp[r] - fm[r]) / 2e-6;
            assert!((fd - j[(r, c)]).abs() < 1e-6 * scale, "J[{r},{c}]");
        }
    }
}
