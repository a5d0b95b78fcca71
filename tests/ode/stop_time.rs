//! Co-simulation stepping: advancing in 1 ms and 0.1 ms chunks keeps the history, matches one
//! free run within tolerance and costs at most 1.3x its steps. The problem is the 19-mass chain
//! (4–100 Hz, smooth 25 Hz forcing) at a tolerance where the free step (~70 us) is below the
//! 0.1 ms communication step; the exact modal solution checks both runs. Stepping past output
//! times and interpolating (what the FMU does) costs exactly the free run's steps.

use engine_mount_chassis::ode::test_problems::SpringChain;
use engine_mount_chassis::ode::{Bdf, BdfOptions, Tolerance};

const T_END: f64 = 0.05;
const RTOL: f64 = 1e-9;

fn opts() -> BdfOptions {
    BdfOptions {
        rtol: RTOL,
        atol: Tolerance::Scalar(1e-12),
        ..Default::default()
    }
}

#[test]
fn chunked_runs_match_the_free_run() {
    let mut p = SpringChain::without_stiff_mode().expect("smooth chain");
    let y0 = vec![0.0; p.dim2()];
    let mut free = Bdf::new(&mut p, 0.0, &y0, opts()).unwrap();
    free.advance_to(&mut p, T_END).unwrap();
    let exact = p.exact(&y0, T_END);
    let scale = exact.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let free_err = free
        .y()
        .iter()
        .zip(&exact)
        .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
    for chunk in [1e-3, 1e-4] {
        let mut b = Bdf::new(&mut p, 0.0, &y0, opts()).unwrap();
        let n = (T_END / chunk).round() as usize;
        for k in 1..=n {
            // Points computed as start + k h, as FMI masters do.
            let t = k as f64 * chunk;
            b.advance_to(&mut p, t).unwrap();
            assert_eq!(b.t(), t, "lands exactly on the communication point");
        }
        let diff = b
            .y()
            .iter()
            .zip(free.y())
            .fold(0.0_f64, |m, (a, c)| m.max((a - c).abs()));
        let err = b
            .y()
            .iter()
            .zip(&exact)
            .fold(0.0_f64, |m, (a, c)| m.max((a - c).abs()));
        let ratio = b.stats().steps as f64 / free.stats().steps as f64;
        eprintln!(
            "chunk {chunk:e}: steps {} vs free {} (x{ratio:.3}), diff {:.2e}, err {:.2e} vs free err {:.2e} (scale {scale:.2e})",
            b.stats().steps,
            free.stats().steps,
            diff,
            err,
            free_err
        );
        assert!(
            ratio <= 1.3,
            "chunk {chunk}: {ratio} times the free run's steps"
        );
        assert!(
            diff <= 100.0 * RTOL * scale,
            "chunk {chunk}: differs from the free run by {diff}"
        );
        assert!(
            err <= 3.0 * free_err + 10.0 * RTOL * scale,
            "chunk {chunk}: error {err}"
        );
    }
}

#[test]
fn jitter_in_the_stop_time_is_tolerated() {
    let mut p = SpringChain::standard(false).expect("standard chain");
    let y0 = vec![0.0; 40];
    let mut b = Bdf::new(&mut p, 0.0, &y0, opts()).unwrap();
    b.advance_to(&mut p, 0.1 + 0.2).unwrap();
    let steps = b.stats().steps;
    // 0.30000000000000004 vs 0.3: no step, no error.
    b.advance_to(&mut p, 0.3).unwrap();
    assert_eq!(b.stats().steps, steps);
}

#[test]
fn stepping_past_output_times_interpolates_within_tolerance_at_no_extra_cost() {
    let mut p = SpringChain::without_stiff_mode().expect("smooth chain");
    let y0 = vec![0.0; p.dim2()];
    let mut free = Bdf::new(&mut p, 0.0, &y0, opts()).unwrap();
    free.advance_to(&mut p, T_END).unwrap();
    for chunk in [1e-3, 1e-4, 1e-6] {
        let mut b = Bdf::new(&mut p, 0.0, &y0, opts()).unwrap();
        let mut y = vec![0.0; p.dim2()];
        let n = (T_END / chunk).round() as usize;
        let mut worst: f64 = 0.0;
        let mut scale: f64 = 0.0;
        for k in 1..=n {
            let t = k as f64 * chunk;
            b.advance_past(&mut p, t, &mut y).unwrap();
            assert!(b.t() >= t, "the integrator is at or past the output time");
            // Check a sample of the output times against the exact modal solution.
            if k % (n / 10).max(1) == 0 {
                let exact = p.exact(&y0, t);
                scale = exact.iter().fold(scale, |m, v| m.max(v.abs()));
                worst = y
                    .iter()
                    .zip(&exact)
                    .fold(worst, |m, (a, e)| m.max((a - e).abs()));
            }
        }
        let ratio = b.stats().steps as f64 / free.stats().steps as f64;
        eprintln!("chunk {chunk:e}: steps x{ratio:.3}, error {worst:.2e} (scale {scale:.2e})");
        assert!(
            ratio <= 1.02,
            "chunk {chunk}: {ratio} times the free run's steps"
        );
        assert!(
            worst <= 100.0 * RTOL * scale,
            "chunk {chunk}: error {worst}"
        );
    }
    // An output time behind the last step cannot be served.
    let mut b = Bdf::new(&mut p, 0.0, &y0, opts()).unwrap();
    let mut y = vec![0.0; p.dim2()];
    b.advance_past(&mut p, 0.01, &mut y).unwrap();
    assert!(b.advance_past(&mut p, 0.001, &mut y).is_err());
}
