//! The error type of the reduction: every failure is a value naming the field, node or value.

use crate::fe::FeError;

/// A failure of the chassis reduction or of a query on a reduced chassis.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CmsError {
    /// A specification field or query argument is out of range; the message names it.
    #[error("invalid reduction input: {0}")]
    InvalidInput(String),
    /// Building, assembling or solving the FE model failed.
    #[error("chassis FE model: {0}")]
    Fe(FeError),
    /// A factorisation or eigen solve of the reduction failed.
    #[error("reduction failed numerically: {0}")]
    Numerical(String),
}

impl From<FeError> for CmsError {
    fn from(e: FeError) -> Self {
        CmsError::Fe(e)
    }
}
