//! The Nordsieck history array `zn[j] = h^j y^(j) / j!` (j = 0..=max_order) and its
//! operations: prediction, its exact inverse pattern on failure, rescaling to a new step size,
//! order changes and interpolation.

use super::coefficients::{decrease_order_coefficients, increase_order_coefficients, L_MAX};

/// History array of `max_order + 1` vectors of length `n`. `zn[max_order]` doubles as storage
/// of the saved correction for a later order increase (as in CVODE) while `q < max_order`.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Nordsieck {
    pub zn: Vec<Vec<f64>>,
}

impl Nordsieck {
    pub fn new(n: usize, max_order: usize) -> Self {
        Self {
            zn: vec![vec![0.0; n]; max_order + 1],
        }
    }

    /// Predictor: multiplies the history by the Pascal matrix (Taylor expansion to t + h).
    pub fn predict(&mut self, q: usize) {
        for k in 1..=q {
            for j in (k..=q).rev() {
                let (lo, hi) = self.zn.split_at_mut(j);
                for (a, b) in lo[j - 1].iter_mut().zip(hi[0].iter()) {
                    *a += *b;
                }
            }
        }
    }

    /// Undoes [`Self::predict`] after a failed step.
    pub fn restore(&mut self, q: usize) {
        for k in 1..=q {
            for j in (k..=q).rev() {
                let (lo, hi) = self.zn.split_at_mut(j);
                for (a, b) in lo[j - 1].iter_mut().zip(hi[0].iter()) {
                    *a -= *b;
                }
            }
        }
    }

    /// Rescales to a step `eta` times the current one: `zn[j] *= eta^j`.
    pub fn rescale(&mut self, q: usize, eta: f64) {
        let mut factor = eta;
        for j in 1..=q {
            for v in self.zn[j].iter_mut() {
                *v *= factor;
            }
            factor *= eta;
        }
    }

    /// Applies the corrector: `zn[j] += l[j] * acor` for j = 0..=q.
    pub fn correct(&mut self, q: usize, l: &[f64; L_MAX + 1], acor: &[f64]) {
        for j in 0..=q {
            let lj = l[j];
            for (z, a) in self.zn[j].iter_mut().zip(acor) {
                *z += lj * *a;
            }
        }
    }

    /// Raises the order from `q` to `q + 1` using the correction saved in `zn[saved_index]`.
    pub fn increase_order(
        &mut self,
        q: usize,
        hscale: f64,
        tau: &[f64; L_MAX + 1],
        saved_index: usize,
    ) {
        let (l, a1) = increase_order_coefficients(q, hscale, tau);
        let new_col = q + 1;
        if saved_index != new_col {
            let saved = self.zn[saved_index].clone();
            for (z, s) in self.zn[new_col].iter_mut().zip(&saved) {
                *z = a1 * *s;
            }
        } else {
            for z in self.zn[new_col].iter_mut() {
                *z *= a1;
            }
        }
        for j in 2..=q {
            let (lo, hi) = self.zn.split_at_mut(new_col);
            for (z, s) in lo[j].iter_mut().zip(hi[0].iter()) {
                *z += l[j] * *s;
            }
        }
    }

    /// Lowers the order from `q` to `q - 1`.
    pub fn decrease_order(&mut self, q: usize, hscale: f64, tau: &[f64; L_MAX + 1]) {
        let l = decrease_order_coefficients(q, hscale, tau);
        for j in 2..q {
            let (lo, hi) = self.zn.split_at_mut(q);
            for (z, s) in lo[j].iter_mut().zip(hi[0].iter()) {
                *z -= l[j] * *s;
            }
        }
    }

    /// The `k`-th derivative at `t = tn + s h` (CVODE's CVodeGetDky), `s` in [-1, 0] inside the
    /// last step.
    pub fn derivative(&self, q: usize, s: f64, h: f64, k: usize, out: &mut [f64]) {
        out.iter_mut().for_each(|v| *v = 0.0);
        if k > q {
            return;
        }
        for j in (k..=q).rev() {
            let mut c = 1.0;
            for i in (j + 1 - k..=j).rev() {
                c *= i as f64;
            }
            if j == q {
                for (o, z) in out.iter_mut().zip(&self.zn[j]) {
                    *o = c * *z;
                }
            } else {
                for (o, z) in out.iter_mut().zip(&self.zn[j]) {
                    *o = c * *z + s * *o;
                }
            }
        }
        if k > 0 {
            let r = h.powi(-(k as i32));
            out.iter_mut().for_each(|v| *v *= r);
        }
    }
}

/// Weighted root-mean-square norm `sqrt(mean((v_i w_i)^2))`.
pub fn wrms_norm(v: &[f64], w: &[f64]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    let s: f64 = v.iter().zip(w).map(|(a, b)| (a * b) * (a * b)).sum();
    (s / v.len() as f64).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// For a polynomial of degree <= q the Nordsieck array is exact, so prediction, rescaling
    /// and interpolation must reproduce the polynomial and its derivatives.
    #[test]
    fn polynomial_is_propagated_exactly() {
        // y(t) = 1 + 2t - 3t^2 + 0.5t^3, h = 0.1 at t = 0.
        let h = 0.1;
        let mut nd = Nordsieck::new(1, 5);
        nd.zn[0][0] = 1.0;
        nd.zn[1][0] = h * 2.0;
        nd.zn[2][0] = h * h * -3.0;
        nd.zn[3][0] = h * h * h * 0.5;
        let y = |t: f64| 1.0 + 2.0 * t - 3.0 * t * t + 0.5 * t * t * t;
        let dy = |t: f64| 2.0 - 6.0 * t + 1.5 * t * t;
        nd.predict(3);
        assert!((nd.zn[0][0] - y(0.1)).abs() < 1e-14);
        nd.rescale(3, 0.5);
        let mut out = [0.0];
        nd.derivative(3, -1.0, 0.05, 0, &mut out);
        assert!((out[0] - y(0.05)).abs() < 1e-14);
        nd.derivative(3, -0.5, 0.05, 1, &mut out);
        assert!((out[0] - dy(0.075)).abs() < 1e-13);
        // Undoing a prediction made with the rescaled step steps back by 0.05.
        nd.restore(3);
        nd.derivative(3, 0.0, 0.05, 0, &mut out);
        assert!((out[0] - y(0.05)).abs() < 1e-14);
    }

    /// Lowering the order from q to q-1 must keep value and slope at t_n and the values at the
    /// q-2 most recent past points (unequal steps), while dropping the degree-q term.
    #[test]
    fn order_decrease_keeps_the_interpolation_conditions() {
        let q = 5;
        let h = 0.1;
        let tau = [0.0, 0.1, 0.07, 0.13, 0.05, 0.11, 0.09];
        let coeffs = [0.3, -1.2, 0.8, 2.0, -0.7, 1.5];
        let mut nd = Nordsieck::new(1, 5);
        for (j, c) in coeffs.iter().enumerate() {
            nd.zn[j][0] = *c;
        }
        // Polynomial in s = (t - t_n) / h.
        let poly = |zn: &Nordsieck, order: usize, s: f64| {
            (0..=order).rev().fold(0.0, |acc, j| acc * s + zn.zn[j][0])
        };
        let before = nd.clone();
        nd.decrease_order(q, h, &tau);
        let mut past = 0.0;
        for j in 1..=q - 2 {
            past += tau[j];
            let s = -past / h;
            let (a, b) = (poly(&before, q, s), poly(&nd, q - 1, s));
            assert!((a - b).abs() < 1e-12, "past point {j}: {a} vs {b}");
        }
        assert_eq!(nd.zn[0][0], before.zn[0][0]);
        assert_eq!(nd.zn[1][0], before.zn[1][0]);
    }
}
