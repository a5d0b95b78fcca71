//! Stiff structural problem: 20-DOF spring–mass chain, 1 % modal damping, modes 4–100 Hz plus
//! one 2 kHz mode, 25 Hz forcing, 1 s. Truth: modal superposition (closed-form SDOF responses).

use engine_mount_chassis::ode::test_problems::SpringChain;
use engine_mount_chassis::ode::{Bdf, BdfOptions, BdfStats, Tolerance};

struct Run {
    rel_error: f64,
    stats: BdfStats,
}

fn run(rtol: f64, stability: bool, mass_matrix: bool) -> Run {
    let mut p = SpringChain::standard(mass_matrix).expect("standard chain");
    let y0 = vec![0.0; p.dofs() * 2];
    let opts = BdfOptions {
        rtol,
        atol: Tolerance::Scalar(rtol * 1e-3),
        stability_limit_detection: stability,
        ..Default::default()
    };
    let mut bdf = Bdf::new(&mut p, 0.0, &y0, opts).expect("valid setup");
    bdf.advance_to(&mut p, 1.0).expect("chain integrates");
    assert_eq!(bdf.t(), 1.0);
    let exact = p.exact(&y0, 1.0);
    let scale = exact.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let err = bdf
        .y()
        .iter()
        .zip(&exact)
        .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
    Run {
        rel_error: err / scale,
        stats: bdf.stats().clone(),
    }
}

#[test]
fn chain_has_the_specified_modes() {
    let p = SpringChain::standard(false).expect("standard chain");
    let f = p.frequencies_hz();
    assert_eq!(f.len(), 20);
    assert!(f[0] > 3.5 && f[0] < 4.5, "lowest mode {}", f[0]);
    assert!(
        f[18] > 95.0 && f[18] < 101.0,
        "highest chain mode {}",
        f[18]
    );
    assert!(f[19] > 1900.0 && f[19] < 2100.0, "stiff mode {}", f[19]);
}

#[test]
fn chain_error_is_at_the_tolerance_scale() {
    for stability in [false, true] {
        let loose = run(1e-4, stability, false);
        let tight = run(1e-7, stability, false);
        eprintln!(
            "stability {stability}: rel err {:.2e} @1e-4, {:.2e} @1e-7",
            loose.rel_error, tight.rel_error
        );
        // Global error of a lightly damped oscillator accumulates over ~1e3..2e4 steps, so the
        // bound is a modest multiple of rtol.
        assert!(
            loose.rel_error < 2e-2,
            "rtol 1e-4: relative error {}",
            loose.rel_error
        );
        assert!(
            tight.rel_error < 1e-4,
            "rtol 1e-7: relative error {}",
            tight.rel_error
        );
        assert!(tight.rel_error < loose.rel_error);
    }
}

#[test]
fn mass_matrix_form_gives_the_same_solution() {
    let plain = run(1e-6, false, false);
    let with_mass = run(1e-6, false, true);
    eprintln!(
        "plain {:.2e}, with mass matrix {:.2e}",
        plain.rel_error, with_mass.rel_error
    );
    assert!(with_mass.rel_error < 1e-3);
}

#[test]
fn stability_limit_detection_saves_steps_at_rtol_1e_4() {
    let off = run(1e-4, false, false);
    let on = run(1e-4, true, false);
    eprintln!("steps off {} on {}", off.stats.steps, on.stats.steps);
    assert!(on.stats.stability_order_reductions > 0);
    assert!(
        on.stats.steps * 2 < off.stats.steps,
        "with detection {} steps, without {}",
        on.stats.steps,
        off.stats.steps
    );
}
