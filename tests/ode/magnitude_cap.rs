//! The magnitude cap on the relative tolerance keeps a growing angle's phase accurate.

use engine_mount_chassis::ode::{Bdf, BdfOptions, OdeProblem, ProblemError, Tolerance};

/// φ' = Ω (1 + ½ sin 2t): an angle that grows without bound, exactly φ = Ω (t + (1 − cos 2t)/4).
struct Angle;

const OMEGA: f64 = 200.0;

impl OdeProblem for Angle {
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&mut self, t: f64, _y: &[f64], f: &mut [f64]) -> Result<(), ProblemError> {
        f[0] = OMEGA * (1.0 + 0.5 * (2.0 * t).sin());
        Ok(())
    }
}

fn phase_error(cap: Option<Vec<f64>>) -> (f64, u64) {
    let opts = BdfOptions {
        rtol: 1e-6,
        atol: Tolerance::Scalar(1e-9),
        magnitude_cap: cap,
        ..BdfOptions::default()
    };
    let mut bdf = Bdf::new(&mut Angle, 0.0, &[0.0], opts).unwrap();
    let t_end = 100.0;
    bdf.advance_to(&mut Angle, t_end).unwrap();
    let exact = OMEGA * (t_end + (1.0 - (2.0 * t_end).cos()) / 4.0);
    ((bdf.y()[0] - exact).abs(), bdf.stats().steps)
}

#[test]
fn capped_relative_tolerance_bounds_the_phase_error() {
    let (uncapped, _) = phase_error(None);
    let (capped, _) = phase_error(Some(vec![2.0 * std::f64::consts::PI]));
    // 20 000 rad at the end: uncapped, rtol |φ| allows errors of order 1e-2 rad per step.
    assert!(capped < 1e-3, "capped phase error {capped}");
    assert!(
        capped * 20.0 < uncapped,
        "capped {capped} vs uncapped {uncapped}"
    );
    eprintln!("phase error after 100 s: capped {capped:.2e} rad, uncapped {uncapped:.2e} rad");
}

#[test]
fn bad_caps_are_rejected_by_name() {
    for cap in [vec![0.0], vec![f64::NAN], vec![1.0, 1.0]] {
        let opts = BdfOptions {
            magnitude_cap: Some(cap),
            ..BdfOptions::default()
        };
        let Err(err) = Bdf::new(&mut Angle, 0.0, &[0.0], opts) else {
            panic!("a bad cap was accepted");
        };
        assert!(err.to_string().contains("magnitude_cap"), "{err}");
    }
}
