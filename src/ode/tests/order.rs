//! Order of convergence at fixed order and fixed step: the global error of BDF-k must fall as
//! h^k on a smooth linear problem with a closed-form solution. The Nordsieck history is loaded
//! with exact derivatives so that starting errors do not mask the order.

use crate::ode::test_problems::LinearOscillator;
use crate::ode::{Bdf, BdfOptions, Tolerance};

fn global_error(order: usize, steps: usize) -> f64 {
    let mut p = LinearOscillator::default();
    let t_end = 2.0;
    let h = t_end / steps as f64;
    let opts = BdfOptions {
        rtol: 1e-13,
        atol: Tolerance::Scalar(1e-13),
        max_order: 5,
        ..Default::default()
    };
    let y0 = p.y0;
    let mut bdf = Bdf::new(&mut p, 0.0, &y0, opts).expect("valid setup");
    {
        let s = &mut bdf.s;
        let mut factorial = 1.0;
        for j in 0..=order {
            if j > 0 {
                factorial *= j as f64;
            }
            let d = p.exact_derivative(0.0, j);
            for i in 0..3 {
                s.zn.zn[j][i] = h.powi(j as i32) * d[i] / factorial;
            }
        }
        s.fixed = true;
        s.pending_h0 = false;
        s.q = order;
        s.qprime = order;
        s.qwait = order + 1;
        s.h = h;
        s.hprime = h;
        s.hscale = h;
        s.tau = [h; 7];
    }
    bdf.advance_to(&mut p, t_end)
        .expect("fixed-step run succeeds");
    assert_eq!(bdf.t(), t_end);
    let exact = p.exact_derivative(t_end, 0);
    bdf.y()
        .iter()
        .zip(exact)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max)
}

#[test]
fn fixed_order_fixed_step_converges_at_rate_k() {
    let steps = [20usize, 40, 80, 160];
    for order in 1..=5 {
        let errors: Vec<f64> = steps.iter().map(|&n| global_error(order, n)).collect();
        // Least-squares slope of log(error) against log(h).
        let xs: Vec<f64> = steps.iter().map(|&n| (2.0 / n as f64).ln()).collect();
        let ys: Vec<f64> = errors.iter().map(|e| e.ln()).collect();
        let mx = xs.iter().sum::<f64>() / xs.len() as f64;
        let my = ys.iter().sum::<f64>() / ys.len() as f64;
        let slope = xs
            .iter()
            .zip(&ys)
            .map(|(x, y)| (x - mx) * (y - my))
            .sum::<f64>()
            / xs.iter().map(|x| (x - mx) * (x - mx)).sum::<f64>();
        eprintln!("order {order}: errors {errors:?}, slope {slope:.3}");
        assert!(
            (slope - order as f64).abs() <= 0.3,
            "order {order}: slope {slope}, errors {errors:?}"
        );
    }
}
