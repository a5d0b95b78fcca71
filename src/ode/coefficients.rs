//! Coefficients of the fixed-leading-coefficient BDF method in Nordsieck form (CVODE's cvSetBDF,
//! cvSetTqBDF and the order-change polynomials of cvIncreaseBDF / cvDecreaseBDF).
//!
//! `tau[1..=q+1]` are the most recent step sizes (`tau[1]` the last successful one), `l[0..=q]`
//! the corrector polynomial, `tq[1..=5]` the error-test constants: `tq[1]`, `tq[2]`, `tq[3]` for
//! orders q-1, q, q+1, `tq[4]` the Newton tolerance and `tq[5]` the order-increase test constant.

/// Highest supported order.
pub const MAX_ORDER: usize = 5;
/// Length of the step-size history and polynomial arrays (index 0 unused where noted).
pub const L_MAX: usize = MAX_ORDER + 1;

/// Corrector and test coefficients for one step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepCoefficients {
    pub l: [f64; L_MAX + 1],
    pub tq: [f64; 6],
}

/// Computes `l` and `tq` for a step of size `h` at order `q` (CVODE cvSetBDF + cvSetTqBDF).
/// `need_order_change_constants` computes `tq[1]` and `tq[3]` (CVODE: when `qwait == 1`);
/// otherwise the values in `previous_tq` are kept.
pub fn bdf_coefficients(
    q: usize,
    h: f64,
    tau: &[f64; L_MAX + 1],
    nls_coef: f64,
    need_order_change_constants: bool,
    previous_tq: &[f64; 6],
) -> StepCoefficients {
    let mut l = [0.0; L_MAX + 1];
    l[0] = 1.0;
    l[1] = 1.0;
    let mut xi_inv = 1.0;
    let mut xistar_inv = 1.0;
    let mut alpha0 = -1.0;
    let mut alpha0_hat = -1.0;
    let mut hsum = h;
    if q > 1 {
        for j in 2..q {
            hsum += tau[j - 1];
            xi_inv = h / hsum;
            alpha0 -= 1.0 / j as f64;
            for i in (1..=j).rev() {
                l[i] += l[i - 1] * xi_inv;
            }
        }
        alpha0 -= 1.0 / q as f64;
        xistar_inv = -l[1] - alpha0;
        hsum += tau[q - 1];
        xi_inv = h / hsum;
        alpha0_hat = -l[1] - xi_inv;
        for i in (1..=q).rev() {
            l[i] += l[i - 1] * xistar_inv;
        }
    }

    let mut tq = *previous_tq;
    let qf = q as f64;
    let a1 = 1.0 - alpha0_hat + alpha0;
    let a2 = 1.0 + qf * a1;
    tq[2] = (a1 / (alpha0 * a2)).abs();
    tq[5] = (a2 * xistar_inv / (l[q] * xi_inv)).abs();
    if need_order_change_constants {
        if q > 1 {
            let c = xistar_inv / l[q];
            let a3 = alpha0 + 1.0 / qf;
            let a4 = alpha0_hat + xi_inv;
            let cpinv = (1.0 - a4 + a3) / a3;
            tq[1] = (c * cpinv).abs();
        } else {
            tq[1] = 1.0;
        }
        hsum += tau[q];
        xi_inv = h / hsum;
        let a5 = alpha0 - 1.0 / (qf + 1.0);
        let a6 = alpha0_hat - xi_inv;
        let cppinv = (1.0 - a6 + a5) / a2;
        tq[3] = (cppinv / (xi_inv * (qf + 2.0) * a5)).abs();
    }
    tq[4] = nls_coef / tq[2];
    StepCoefficients { l, tq }
}

/// Polynomial coefficients for raising the order from `q` to `q + 1` (cvIncreaseBDF) and the
/// factor `A1` applied to the saved correction.
pub fn increase_order_coefficients(
    q: usize,
    hscale: f64,
    tau: &[f64; L_MAX + 1],
) -> ([f64; L_MAX + 1], f64) {
    let mut l = [0.0; L_MAX + 1];
    l[2] = 1.0;
    let mut alpha1 = 1.0;
    let mut prod = 1.0;
    let mut xiold = 1.0;
    let mut alpha0 = -1.0;
    let mut hsum = hscale;
    if q > 1 {
        for j in 1..q {
            hsum += tau[j + 1];
            let xi = hsum / hscale;
            prod *= xi;
            alpha0 -= 1.0 / (j + 1) as f64;
            alpha1 += 1.0 / xi;
            for i in (2..=j + 2).rev() {
                l[i] = l[i] * xiold + l[i - 1];
            }
            xiold = xi;
        }
    }
    let a1 = (-alpha0 - alpha1) / prod;
    (l, a1)
}

/// Polynomial coefficients for lowering the order from `q` to `q - 1` (cvDecreaseBDF).
pub fn decrease_order_coefficients(
    q: usize,
    hscale: f64,
    tau: &[f64; L_MAX + 1],
) -> [f64; L_MAX + 1] {
    let mut l = [0.0; L_MAX + 1];
    l[2] = 1.0;
    let mut hsum = 0.0;
    for j in 1..=q.saturating_sub(2) {
        hsum += tau[j];
        let xi = hsum / hscale;
        for i in (2..=j + 2).rev() {
            l[i] = l[i] * xi + l[i - 1];
        }
    }
    l
}

#[cfg(test)]
mod tests {
    use super::*;

    /// With equal steps the corrector polynomial of fixed-leading-coefficient BDF is
    /// Lambda(x) = prod_{i=1..q} (1 + x / i), so l[1] = sum 1/i (the classical 1/beta0).
    #[test]
    fn equal_step_coefficients_match_classical_bdf() {
        let tau = [0.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0];
        for q in 1..=5 {
            let c = bdf_coefficients(q, 1.0, &tau, 0.1, true, &[0.0; 6]);
            let mut poly = [0.0; L_MAX + 1];
            poly[0] = 1.0;
            for i in 1..=q {
                for k in (1..=i).rev() {
                    poly[k] += poly[k - 1] / i as f64;
                }
            }
            for k in 0..=q {
                assert!(
                    (c.l[k] - poly[k]).abs() < 1e-13,
                    "q={q} k={k}: {} vs {}",
                    c.l[k],
                    poly[k]
                );
            }
            let harmonic: f64 = (1..=q).map(|j| 1.0 / j as f64).sum();
            assert!((c.l[1] - harmonic).abs() < 1e-14);
            assert!(c.tq[2] > 0.0 && c.tq[2].is_finite());
        }
    }
}
