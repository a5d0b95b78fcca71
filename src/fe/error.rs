//! The error type of the finite-element module: every failure is a value naming what went wrong.

/// A finite-element failure. The message names the element, node, field or value concerned.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FeError {
    /// An input value (section, material, parameter) is out of range or not finite.
    #[error("invalid FE input: {0}")]
    InvalidInput(String),
    /// The mesh is inconsistent: degenerate element, dangling node, DOF without mass or stiffness.
    #[error("mesh error: {0}")]
    Mesh(String),
    /// A numerical method failed (factorisation, eigen solve did not converge).
    #[error("numerical failure: {0}")]
    Numerical(String),
    /// Reading or writing a file failed.
    #[error("I/O error: {0}")]
    Io(String),
}

/// Checks that `value` is finite and strictly positive; `what` names it in the error.
pub(crate) fn require_positive(what: &str, value: f64) -> Result<f64, FeError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(FeError::InvalidInput(format!(
            "{what} must be finite and > 0, got {value}"
        )))
    }
}

/// Checks that `value` is finite and not negative; `what` names it in the error.
pub(crate) fn require_non_negative(what: &str, value: f64) -> Result<f64, FeError> {
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err(FeError::InvalidInput(format!(
            "{what} must be finite and >= 0, got {value}"
        )))
    }
}
