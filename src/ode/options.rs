//! User-settable integrator options and their validation.

use super::error::BdfError;

/// Absolute tolerance: one value for all components or one per component.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Tolerance {
    /// The same absolute tolerance for every state.
    Scalar(f64),
    /// One absolute tolerance per state (length must equal the problem dimension).
    Vector(Vec<f64>),
}

impl Tolerance {
    /// Absolute tolerance of component `i` (the caller has validated the length).
    #[inline]
    pub fn get(&self, i: usize) -> f64 {
        match self {
            Tolerance::Scalar(a) => *a,
            Tolerance::Vector(v) => v[i],
        }
    }
}

/// Options of the BDF integrator. `Default` gives CVODE's defaults with rtol 1e-6, atol 1e-8.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BdfOptions {
    /// Relative tolerance (> 0, finite).
    pub rtol: f64,
    /// Absolute tolerance (>= 0, finite; the WRMS weight is 1/(rtol |y_i| + atol_i)).
    pub atol: Tolerance,
    /// Highest BDF order, 1..=5.
    pub max_order: usize,
    /// First step size; `None` lets the integrator estimate it (CVODE's cvHin).
    pub h_init: Option<f64>,
    /// Smallest step size allowed (>= 0).
    pub h_min: f64,
    /// Largest step size allowed (> 0, may be infinite).
    pub h_max: f64,
    /// Most internal steps taken by one call of `advance_to`.
    pub max_steps_per_call: usize,
    /// Most error-test failures on one step before giving up (CVODE maxnef = 7).
    pub max_err_test_fails: usize,
    /// Most nonlinear convergence failures on one step before giving up (CVODE maxncf = 10).
    pub max_conv_fails: usize,
    /// Hold the order below 3 for a while when lightly damped modes make BDF3–5 unstable.
    pub stability_limit_detection: bool,
    /// Per component, the largest magnitude the relative tolerance applies to: the WRMS weight
    /// is `1 / (rtol min(|y_i|, cap_i) + atol_i)`. For a state that grows without bound (a crank
    /// angle), a cap of one period keeps the *phase* accurate instead of allowing an error that
    /// grows with the number of revolutions. `None`: no cap (CVODE's weights).
    pub magnitude_cap: Option<Vec<f64>>,
    /// Steps after which the Jacobian is re-evaluated although Newton still converges with it
    /// (CVODE's msbj, 50 by default; convergence failures re-evaluate it earlier anyway).
    #[serde(default = "default_jacobian_max_age")]
    pub jacobian_max_age: u64,
}

fn default_jacobian_max_age() -> u64 {
    50
}

impl Default for BdfOptions {
    fn default() -> Self {
        Self {
            rtol: 1e-6,
            atol: Tolerance::Scalar(1e-8),
            max_order: 5,
            h_init: None,
            h_min: 0.0,
            h_max: f64::INFINITY,
            max_steps_per_call: 500_000,
            max_err_test_fails: 7,
            max_conv_fails: 10,
            stability_limit_detection: true,
            magnitude_cap: None,
            jacobian_max_age: default_jacobian_max_age(),
        }
    }
}

impl BdfOptions {
    /// Checks every field against the problem dimension `n`.
    ///
    /// Long on purpose: a flat list of independent checks, one per field.
    pub fn validate(&self, n: usize) -> Result<(), BdfError> {
        let bad =
            |field: &'static str, message: String| Err(BdfError::InvalidOption { field, message });
        if !(self.rtol.is_finite() && self.rtol > 0.0) {
            return bad("rtol", format!("must be finite and > 0, got {}", self.rtol));
        }
        if self.jacobian_max_age == 0 {
            return bad("jacobian_max_age", "must be at least 1 step".into());
        }
        match &self.atol {
            Tolerance::Scalar(a) => {
                if !(a.is_finite() && *a >= 0.0) {
                    return bad("atol", format!("must be finite and >= 0, got {a}"));
                }
            }
            Tolerance::Vector(v) => {
                if v.len() != n {
                    return bad(
                        "atol",
                        format!("has {} entries, the problem has {n} states", v.len()),
                    );
                }
                if let Some((i, a)) = v
                    .iter()
                    .enumerate()
                    .find(|(_, a)| !(a.is_finite() && **a >= 0.0))
                {
                    return bad(
                        "atol",
                        format!("entry {i} must be finite and >= 0, got {a}"),
                    );
                }
            }
        }
        if let Some(cap) = &self.magnitude_cap {
            if cap.len() != n {
                return bad(
                    "magnitude_cap",
                    format!("has {} entries, the problem has {n} states", cap.len()),
                );
            }
            if let Some((i, c)) = cap
                .iter()
                .enumerate()
                .find(|(_, c)| c.is_nan() || **c <= 0.0)
            {
                return bad("magnitude_cap", format!("entry {i} must be > 0, got {c}"));
            }
        }
        if !(1..=5).contains(&self.max_order) {
            return bad(
                "max_order",
                format!("must be in 1..=5, got {}", self.max_order),
            );
        }
        if let Some(h) = self.h_init {
            if !(h.is_finite() && h > 0.0) {
                return bad("h_init", format!("must be finite and > 0, got {h}"));
            }
        }
        if !(self.h_min.is_finite() && self.h_min >= 0.0) {
            return bad(
                "h_min",
                format!("must be finite and >= 0, got {}", self.h_min),
            );
        }
        if self.h_max.is_nan() || self.h_max <= 0.0 || self.h_max < self.h_min {
            return bad(
                "h_max",
                format!("must be > 0 and >= h_min, got {}", self.h_max),
            );
        }
        if self.max_steps_per_call == 0 {
            return bad("max_steps_per_call", "must be >= 1".to_string());
        }
        if self.max_err_test_fails == 0 {
            return bad("max_err_test_fails", "must be >= 1".to_string());
        }
        if self.max_conv_fails == 0 {
            return bad("max_conv_fails", "must be >= 1".to_string());
        }
        Ok(())
    }
}
