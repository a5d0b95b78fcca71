//! The error type of the finite-element module: every failure is a value naming what went wrong.

use std::fmt;

/// A finite-element failure. The message names the element, node, field or value concerned.
#[derive(Debug, Clone, PartialEq)]
pub enum FeError {
    /// An input value (section, material, parameter) is out of range or not finite.
    InvalidInput(String),
    /// The mesh is inconsistent: degenerate element, dangling node, DOF without mass or stiffness.
    Mesh(String),
    /// A numerical method failed (factorisation, eigen solve did not converge).
    Numerical(String),
    /// Reading or writing a file failed.
    Io(String),
}

impl fmt::Display for FeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            FeError::InvalidInput(m) => write!(f, "invalid FE input: {m}"),
            FeError::Mesh(m) => write!(f, "mesh error: {m}"),
            FeError::Numerical(m) => write!(f, "numerical failure: {m}"),
            FeError::Io(m) => write!(f, "I/O error: {m}"),
        }
    }
}

impl std::error::Error for FeError {}

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
