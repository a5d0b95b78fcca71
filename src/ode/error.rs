//! Errors reported by the integrator. After any error the integrator still holds the state of
//! the last successful step.

/// Why an integrator call failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BdfError {
    /// An option is out of range.
    #[error("invalid option `{field}`: {message}")]
    InvalidOption {
        /// The option's field name in `BdfOptions`.
        field: &'static str,
        /// What is wrong with its value.
        message: String,
    },
    /// An argument of a call is invalid (wrong length, non-finite, out of range).
    #[error("invalid argument `{field}`: {message}")]
    InvalidInput {
        /// The argument's name.
        field: &'static str,
        /// What is wrong with it.
        message: String,
    },
    /// The step size became too small to change `t` (or fell below `h_min`).
    #[error("step size underflow at t = {t} (h = {h})")]
    StepSizeUnderflow {
        /// Time of the last successful step.
        t: f64,
        /// The step size that no longer changes `t`.
        h: f64,
    },
    /// The local error test failed too often on one step.
    #[error("{failures} error-test failures in one step at t = {t} (h = {h})")]
    TooManyErrorTestFailures {
        /// Time of the last successful step.
        t: f64,
        /// The last step size tried.
        h: f64,
        /// Error-test failures on this step.
        failures: usize,
    },
    /// The Newton iteration failed to converge too often on one step.
    #[error("{failures} Newton convergence failures in one step at t = {t} (h = {h})")]
    TooManyConvergenceFailures {
        /// Time of the last successful step.
        t: f64,
        /// The last step size tried.
        h: f64,
        /// Newton convergence failures on this step.
        failures: usize,
    },
    /// The right-hand side (or mass matrix) kept returning NaN/inf although the step was reduced.
    #[error("right-hand side is not finite near t = {t}")]
    NonFiniteRhs {
        /// Time of the last successful step.
        t: f64,
    },
    /// The problem reported a recoverable error at every reduced step.
    #[error("problem evaluation failed repeatedly near t = {t}: {message}")]
    RepeatedProblemError {
        /// Time of the last successful step.
        t: f64,
        /// The problem's last message.
        message: String,
    },
    /// The problem reported an unrecoverable error.
    #[error("problem failed at t = {t}: {message}")]
    ProblemFailed {
        /// Time at which the problem failed.
        t: f64,
        /// The problem's message.
        message: String,
    },
    /// `max_steps_per_call` internal steps did not reach the stop time.
    #[error("{steps} steps taken before reaching the stop time (at t = {t})")]
    TooManySteps {
        /// Time reached.
        t: f64,
        /// Steps taken in this call.
        steps: usize,
    },
    /// The requested accuracy is below what double precision can deliver at this state.
    #[error("tolerances too small at t = {t}; increase them by a factor of at least {factor}")]
    TooMuchAccuracy {
        /// Time of the last successful step.
        t: f64,
        /// Factor by which the tolerances must at least grow.
        factor: f64,
    },
    /// A state component made a WRMS weight non-positive or non-finite.
    #[error("error weight of component {index} is not positive/finite at t = {t}")]
    BadErrorWeight {
        /// Time of the last successful step.
        t: f64,
        /// Index of the state component.
        index: usize,
    },
    /// Interpolation was requested outside the last step.
    #[error("interpolation time {t} is outside the last step [{t_lo}, {t_hi}]")]
    BadInterpolationTime {
        /// The requested time.
        t: f64,
        /// Start of the last step.
        t_lo: f64,
        /// End of the last step.
        t_hi: f64,
    },
    /// A snapshot does not fit this integrator (dimension, version, length).
    #[error("snapshot rejected: {0}")]
    BadSnapshot(String),
}
