//! The error type of the reduction: every failure is a value naming the field, node or value.

use std::fmt;

use crate::fe::FeError;

/// A failure of the chassis reduction or of a query on a reduced chassis.
#[derive(Debug, Clone, PartialEq)]
pub enum CmsError {
    /// A specification field or query argument is out of range; the message names it.
    InvalidInput(String),
    /// Building, assembling or solving the FE model failed.
    Fe(FeError),
    /// A factorisation or eigen solve of the reduction failed.
    Numerical(String),
}

impl fmt::Display for CmsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CmsError::InvalidInput(m) => write!(f, "invalid reduction input: {m}"),
            CmsError::Fe(e) => write!(f, "chassis FE model: {e}"),
            CmsError::Numerical(m) => write!(f, "reduction failed numerically: {m}"),
        }
    }
}

impl std::error::Error for CmsError {}

impl From<FeError> for CmsError {
    fn from(e: FeError) -> Self {
        CmsError::Fe(e)
    }
}
