use engine_mount_chassis::ode::test_problems::{Robertson, SpringChain};
use engine_mount_chassis::ode::{Bdf, BdfOptions, Tolerance};
use std::time::Instant;
fn main() {
    let chain = SpringChain::standard(false);
    println!("freqs {:?}", chain.frequencies_hz());
    for mm in [false] {
        for stab in [false, true] {
            for fd in [9usize, 18] {
                for rtol in [1e-3, 1e-4, 1e-5, 1e-6, 1e-8] {
                    let mut p = SpringChain::standard(mm);
                    p.force_dof = fd;
                    let y0 = vec![0.0; 40];
                    let opts = BdfOptions {
                        rtol,
                        atol: Tolerance::Scalar(rtol * 1e-3),
                        stability_limit_detection: stab,
                        ..Default::default()
                    };
                    let t0 = Instant::now();
                    let mut b = Bdf::new(&mut p, 0.0, &y0, opts).unwrap();
                    let r = b.advance_to(&mut p, 1.0);
                    let ex = p.exact(&y0, 1.0);
                    let err = b
                        .y()
                        .iter()
                        .zip(&ex)
                        .map(|(a, e)| (a - e).abs())
                        .fold(0.0, f64::max);
                    let scale = ex.iter().map(|v| v.abs()).fold(0.0, f64::max);
                    println!("fd {fd} stab {stab} rtol {rtol:e}: {:?} err {err:.3e} (scale {scale:.3e}) {:?} {:?}", r.err(), b.stats(), t0.elapsed());
                }
            }
        }
    }
    for rtol in [1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-10, 1e-12] {
        let mut p = Robertson {
            analytic_jacobian: true,
        };
        let opts = BdfOptions {
            rtol,
            atol: Tolerance::Vector(vec![rtol * 1e-4, rtol * 1e-10, rtol * 1e-4]),
            ..Default::default()
        };
        let mut b = Bdf::new(&mut p, 0.0, &Robertson::Y0, opts).unwrap();
        let r = b.advance_to(&mut p, 40.0);
        let e: Vec<f64> = b
            .y()
            .iter()
            .zip(Robertson::Y_AT_40)
            .map(|(a, e)| ((a - e) / e).abs())
            .collect();
        println!(
            "rober rtol {rtol:e}: {:?} relerr {e:?} steps {}",
            r.err(),
            b.stats().steps
        );
    }
}
