//! Errors reported by the integrator. After any error the integrator still holds the state of
//! the last successful step.

use std::fmt;

/// Why an integrator call failed.
#[derive(Debug, Clone, PartialEq)]
pub enum BdfError {
    /// An option is out of range.
    InvalidOption {
        field: &'static str,
        message: String,
    },
    /// An argument of a call is invalid (wrong length, non-finite, out of range).
    InvalidInput {
        field: &'static str,
        message: String,
    },
    /// The step size became too small to change `t` (or fell below `h_min`).
    StepSizeUnderflow { t: f64, h: f64 },
    /// The local error test failed too often on one step.
    TooManyErrorTestFailures { t: f64, h: f64, failures: usize },
    /// The Newton iteration failed to converge too often on one step.
    TooManyConvergenceFailures { t: f64, h: f64, failures: usize },
    /// The right-hand side (or mass matrix) kept returning NaN/inf although the step was reduced.
    NonFiniteRhs { t: f64 },
    /// The problem reported a recoverable error at every reduced step.
    RepeatedProblemError { t: f64, message: String },
    /// The problem reported an unrecoverable error.
    ProblemFailed { t: f64, message: String },
    /// `max_steps_per_call` internal steps did not reach the stop time.
    TooManySteps { t: f64, steps: usize },
    /// The requested accuracy is below what double precision can deliver at this state.
    TooMuchAccuracy { t: f64, factor: f64 },
    /// A state component made a WRMS weight non-positive or non-finite.
    BadErrorWeight { t: f64, index: usize },
    /// Interpolation was requested outside the last step.
    BadInterpolationTime { t: f64, t_lo: f64, t_hi: f64 },
    /// A snapshot does not fit this integrator (dimension, version, length).
    BadSnapshot(String),
}

impl fmt::Display for BdfError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::InvalidOption { field, message } => {
                write!(f, "invalid option `{field}`: {message}")
            }
            Self::InvalidInput { field, message } => {
                write!(f, "invalid argument `{field}`: {message}")
            }
            Self::StepSizeUnderflow { t, h } => {
                write!(f, "step size underflow at t = {t} (h = {h})")
            }
            Self::TooManyErrorTestFailures { t, h, failures } => {
                write!(
                    f,
                    "{failures} error-test failures in one step at t = {t} (h = {h})"
                )
            }
            Self::TooManyConvergenceFailures { t, h, failures } => {
                write!(
                    f,
                    "{failures} Newton convergence failures in one step at t = {t} (h = {h})"
                )
            }
            Self::NonFiniteRhs { t } => write!(f, "right-hand side is not finite near t = {t}"),
            Self::RepeatedProblemError { t, message } => {
                write!(
                    f,
                    "problem evaluation failed repeatedly near t = {t}: {message}"
                )
            }
            Self::ProblemFailed { t, message } => write!(f, "problem failed at t = {t}: {message}"),
            Self::TooManySteps { t, steps } => write!(
                f,
                "{steps} steps taken before reaching the stop time (at t = {t})"
            ),
            Self::TooMuchAccuracy { t, factor } => {
                write!(f, "tolerances too small at t = {t}; increase them by a factor of at least {factor}")
            }
            Self::BadErrorWeight { t, index } => {
                write!(
                    f,
                    "error weight of component {index} is not positive/finite at t = {t}"
                )
            }
            Self::BadInterpolationTime { t, t_lo, t_hi } => {
                write!(
                    f,
                    "interpolation time {t} is outside the last step [{t_lo}, {t_hi}]"
                )
            }
            Self::BadSnapshot(m) => write!(f, "snapshot rejected: {m}"),
        }
    }
}

impl std::error::Error for BdfError {}
