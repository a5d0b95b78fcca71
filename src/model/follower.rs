//! The speed set-point follower: how the crank follows the engine-speed input.
//!
//! A master that computes the engine speed (a drivetrain model, a test-bench schedule) sends it
//! as a set-point `s(t)` with slope `s'(t)`. The crank speed `ω_c` follows it as a critically
//! damped second-order system with feed-forward of the slope,
//! `ω_c'' = (s − ω_c)/τ² + 2 (s' − ω_c')/τ`: a ramp is tracked exactly, a jump of the set-point
//! becomes a smooth run-up over a few `τ` (no torque impulse on the block, no restart of the
//! integrator), and at constant speed `ω_c = s`. `τ = 0` makes the crank speed the set-point
//! itself (no states; a set-point jump is then a speed jump).

use serde::{Deserialize, Serialize};

use super::validate::{non_negative, ConfigError};

/// The follower's one parameter.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpeedFollower {
    /// Time constant τ (s); 0: the crank speed equals the set-point.
    pub time_constant: f64,
}

impl SpeedFollower {
    /// The default time constant, 5 ms: a set-point step settles in about 30 ms, far faster than
    /// any engine speed change a drivetrain produces, far slower than the integrator's steps.
    pub const DEFAULT_TIME_CONSTANT: f64 = 0.005;
}

impl Default for SpeedFollower {
    fn default() -> Self {
        Self {
            time_constant: Self::DEFAULT_TIME_CONSTANT,
        }
    }
}

impl SpeedFollower {
    /// Refuses a negative or non-finite time constant, naming it `{field}.time_constant`.
    pub fn validate(&self, field: &str) -> Result<(), ConfigError> {
        non_negative(&format!("{field}.time_constant"), self.time_constant)
    }

    /// Whether the crank speed is a state.
    pub fn is_dynamic(&self) -> bool {
        self.time_constant > 0.0
    }

    /// `(ω_c', α_c')` for crank speed `omega`, acceleration `alpha`, set-point `set` and its
    /// slope `set_rate`.
    pub fn rates(&self, omega: f64, alpha: f64, set: f64, set_rate: f64) -> (f64, f64) {
        let w = 1.0 / self.time_constant;
        (alpha, w * w * (set - omega) + 2.0 * w * (set_rate - alpha))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Critically damped step response `1 − (1 + t/τ) e^{−t/τ}` (textbook).
    #[test]
    fn step_response_is_the_critically_damped_one_and_a_ramp_is_tracked_exactly() {
        let f = SpeedFollower {
            time_constant: 0.01,
        };
        let (mut w, mut a) = (0.0, 0.0);
        let h = 1e-6;
        let mut t = 0.0;
        while t < 0.05 - 0.5 * h {
            // RK4 on the linear system.
            let k1 = f.rates(w, a, 1.0, 0.0);
            let k2 = f.rates(w + 0.5 * h * k1.0, a + 0.5 * h * k1.1, 1.0, 0.0);
            let k3 = f.rates(w + 0.5 * h * k2.0, a + 0.5 * h * k2.1, 1.0, 0.0);
            let k4 = f.rates(w + h * k3.0, a + h * k3.1, 1.0, 0.0);
            w += h / 6.0 * (k1.0 + 2.0 * k2.0 + 2.0 * k3.0 + k4.0);
            a += h / 6.0 * (k1.1 + 2.0 * k2.1 + 2.0 * k3.1 + k4.1);
            t += h;
        }
        let x = t / 0.01;
        let exact = 1.0 - (1.0 + x) * (-x).exp();
        assert!((w - exact).abs() < 1e-9, "{w} vs {exact}");
        // On a ramp s = 3 + 2t with ω_c = s, ω_c' = s', the derivatives are exactly the ramp's.
        let (dw, da) = f.rates(3.0 + 2.0 * 0.4, 2.0, 3.0 + 2.0 * 0.4, 2.0);
        assert_eq!((dw, da), (2.0, 0.0));
    }
}
