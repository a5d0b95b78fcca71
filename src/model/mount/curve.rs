//! Monotone C¹ force–deflection characteristic of one mount direction.
//!
//! The curve is given by its tangent stiffness as a piecewise-linear function of the deflection
//! (knots sorted by deflection, constant beyond the outer knots). The elastic force is the exact
//! integral `g(δ) = ∫₀^δ k(s) ds`: a quadratic spline that is C¹ everywhere (no kinks) and strictly
//! monotone whenever every knot stiffness is positive. Bump stops are simply steep, smooth
//! progressive branches of the stiffness profile.

use serde::{Deserialize, Serialize};

/// One knot of the tangent stiffness profile.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct StiffnessKnot {
    /// Deflection (m).
    pub deflection: f64,
    /// Tangent stiffness at that deflection (N/m).
    pub stiffness: f64,
}

/// Force–deflection characteristic of one mount direction.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MountCurve {
    /// Tangent stiffness knots, strictly increasing in deflection, bracketing zero deflection.
    pub knots: Vec<StiffnessKnot>,
}

impl MountCurve {
    /// Symmetric progressive elastomer mount (DESIGN §8): linear stiffness `k` within ±3 mm,
    /// 3 k at ±8 mm, bump stop at 10 k from ±11 mm on.
    pub fn progressive(k: f64) -> Self {
        let half = [
            (0.0, 1.0),
            (0.003, 1.0),
            (0.008, 3.0),
            (0.011, 10.0),
            (0.030, 10.0),
        ];
        let mut knots: Vec<StiffnessKnot> = half
            .iter()
            .rev()
            .filter(|(d, _)| *d > 0.0)
            .map(|&(d, f)| StiffnessKnot {
                deflection: -d,
                stiffness: f * k,
            })
            .collect();
        knots.extend(half.iter().map(|&(d, f)| StiffnessKnot {
            deflection: d,
            stiffness: f * k,
        }));
        Self { knots }
    }

    /// Linear characteristic of stiffness `k`.
    pub fn linear(k: f64) -> Self {
        Self {
            knots: vec![
                StiffnessKnot {
                    deflection: -0.01,
                    stiffness: k,
                },
                StiffnessKnot {
                    deflection: 0.01,
                    stiffness: k,
                },
            ],
        }
    }

    /// Checks the knots; `field` names the curve in the message.
    pub fn validate(&self, field: &str) -> Result<(), String> {
        if self.knots.len() < 2 {
            return Err(format!(
                "{field}.knots: need at least 2 knots, got {}",
                self.knots.len()
            ));
        }
        for (i, k) in self.knots.iter().enumerate() {
            if !k.deflection.is_finite() {
                return Err(format!(
                    "{field}.knots[{i}].deflection = {} is not finite",
                    k.deflection
                ));
            }
            if !(k.stiffness.is_finite() && k.stiffness > 0.0) {
                return Err(format!(
                    "{field}.knots[{i}].stiffness = {} must be positive (the curve must be monotone)",
                    k.stiffness
                ));
            }
            if i > 0 && k.deflection <= self.knots[i - 1].deflection {
                return Err(format!(
                    "{field}.knots[{i}].deflection = {} must exceed the previous knot {}",
                    k.deflection,
                    self.knots[i - 1].deflection
                ));
            }
        }
        let first = self.knots[0].deflection;
        let last = self.knots[self.knots.len() - 1].deflection;
        if first > 0.0 || last < 0.0 {
            return Err(format!(
                "{field}.knots must bracket zero deflection, span [{first}, {last}]"
            ));
        }
        Ok(())
    }

    /// Deflection range covered by the knots (beyond it the last stiffness is extrapolated).
    pub fn range(&self) -> (f64, f64) {
        match (self.knots.first(), self.knots.last()) {
            (Some(a), Some(b)) => (a.deflection, b.deflection),
            _ => (0.0, 0.0),
        }
    }

    /// Tangent stiffness `k(δ)`.
    pub fn stiffness(&self, d: f64) -> f64 {
        let k = &self.knots;
        if k.is_empty() {
            return 0.0;
        }
        if d <= k[0].deflection {
            return k[0].stiffness;
        }
        for w in k.windows(2) {
            if d <= w[1].deflection {
                let t = (d - w[0].deflection) / (w[1].deflection - w[0].deflection);
                return w[0].stiffness + t * (w[1].stiffness - w[0].stiffness);
            }
        }
        k[k.len() - 1].stiffness
    }

    /// Elastic force `g(δ) = ∫₀^δ k`, with `g(0) = 0`.
    pub fn force(&self, d: f64) -> f64 {
        self.primitive(d) - self.primitive(0.0)
    }

    /// Stored energy `∫₀^δ g`.
    pub fn energy(&self, d: f64) -> f64 {
        let g0 = self.primitive(0.0);
        self.second_primitive(d) - self.second_primitive(0.0) - g0 * d
    }

    /// `P(δ) = ∫_{δ₀}^δ k` from the first knot, exact for the piecewise-linear profile.
    fn primitive(&self, d: f64) -> f64 {
        self.integrate(d, false)
    }

    /// `∫_{δ₀}^δ P`.
    fn second_primitive(&self, d: f64) -> f64 {
        self.integrate(d, true)
    }

    fn integrate(&self, d: f64, twice: bool) -> f64 {
        let k = &self.knots;
        if k.is_empty() {
            return 0.0;
        }
        // Segments: (-inf, x0] constant k0, [xi, xi+1] linear, [xn, inf) constant kn. Origin at x0.
        let x0 = k[0].deflection;
        let mut p = 0.0; // P at the segment start
        let mut q = 0.0; // ∫P at the segment start
        if d <= x0 {
            let h = d - x0;
            return if twice {
                0.5 * k[0].stiffness * h * h
            } else {
                k[0].stiffness * h
            };
        }
        for w in k.windows(2) {
            let (xa, ka, xb, kb) = (
                w[0].deflection,
                w[0].stiffness,
                w[1].deflection,
                w[1].stiffness,
            );
            let len = xb - xa;
            let slope = (kb - ka) / len;
            let h = d.min(xb) - xa;
            let p_h = p + ka * h + 0.5 * slope * h * h;
            let q_h = q + p * h + 0.5 * ka * h * h + slope * h * h * h / 6.0;
            if d <= xb {
                return if twice { q_h } else { p_h };
            }
            p = p_h;
            q = q_h;
        }
        let last = k[k.len() - 1];
        let h = d - last.deflection;
        if twice {
            q + p * h + 0.5 * last.stiffness * h * h
        } else {
            p + last.stiffness * h
        }
    }
}

/// A [`MountCurve`] prepared for evaluation: the force at every knot integrated once, so force
/// and tangent stiffness come from one scan of the knots.
#[derive(Debug, Clone, PartialEq)]
pub struct CurveTable {
    /// (deflection, stiffness, force `g` at the knot).
    knots: Vec<(f64, f64, f64)>,
}

impl CurveTable {
    /// The curve tabulated with the force at every knot.
    pub fn new(curve: &MountCurve) -> Self {
        Self {
            knots: curve
                .knots
                .iter()
                .map(|k| (k.deflection, k.stiffness, curve.force(k.deflection)))
                .collect(),
        }
    }

    /// Force `g(δ)` and tangent stiffness `k(δ)`: the same values as [`MountCurve::force`] and
    /// [`MountCurve::stiffness`].
    pub fn force_and_stiffness(&self, d: f64) -> (f64, f64) {
        let k = &self.knots;
        let Some(&(x0, k0, g0)) = k.first() else {
            return (0.0, 0.0);
        };
        if d <= x0 {
            return (g0 + k0 * (d - x0), k0);
        }
        for w in k.windows(2) {
            let ((xa, ka, ga), (xb, kb, _)) = (w[0], w[1]);
            if d <= xb {
                let h = d - xa;
                let slope = (kb - ka) / (xb - xa);
                return (ga + h * (ka + 0.5 * slope * h), ka + slope * h);
            }
        }
        let (xn, kn, gn) = k[k.len() - 1];
        (gn + kn * (d - xn), kn)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn force_is_integral_of_stiffness_and_energy_integral_of_force() {
        let c = MountCurve::progressive(48_300.0);
        c.validate("curve").expect("valid");
        let h = 1e-7;
        for i in -300..=300 {
            let d = i as f64 * 1e-4;
            let dk = (c.force(d + h) - c.force(d - h)) / (2.0 * h);
            assert!((dk - c.stiffness(d)).abs() < 1e-4 * c.stiffness(d), "d={d}");
            let de = (c.energy(d + h) - c.energy(d - h)) / (2.0 * h);
            assert!(
                (de - c.force(d)).abs() < 1e-6 * (1.0 + c.force(d).abs()),
                "d={d}"
            );
        }
        assert_eq!(c.force(0.0), 0.0);
        // Linear range: 48.3 N/mm × 2 mm, exactly.
        assert!((c.force(0.002) - 96.6).abs() < 1e-9);
        assert!((c.force(-0.002) + 96.6).abs() < 1e-9);
    }

    #[test]
    fn table_gives_the_curve_everywhere() {
        let c = MountCurve::progressive(48_300.0);
        let table = CurveTable::new(&c);
        for i in -400..=400 {
            let d = i as f64 * 1e-4 + 3e-6;
            let (g, k) = table.force_and_stiffness(d);
            assert!((g - c.force(d)).abs() < 1e-9 * (1.0 + g.abs()), "d={d}");
            assert!((k - c.stiffness(d)).abs() < 1e-9 * k, "d={d}");
        }
    }

    #[test]
    fn non_monotone_curve_is_rejected_naming_the_knot() {
        let mut c = MountCurve::progressive(1.0);
        c.knots[2].stiffness = -5.0;
        let e = c
            .validate("mounts[0].curves[2]")
            .expect_err("negative stiffness");
        assert!(
            e.contains("mounts[0].curves[2].knots[2].stiffness = -5"),
            "{e}"
        );
    }
}
