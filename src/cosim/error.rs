//! Why a simulation could not be built or continued, typed so that the FMI layer can name the
//! parameter or input behind it in its own terms.

use crate::model::scene::{BodyOption, SceneError};
pub use crate::model::Input;
use crate::model::InputError;

/// An error of the co-simulation runtime.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Error {
    /// A body option is outside its domain or does not apply to the vehicle's body.
    #[error("{option} = {value} {rule}")]
    BodyOption {
        /// The body option at fault.
        option: BodyOption,
        /// Its value as given.
        value: String,
        /// The rule it breaks, as a sentence ending (e.g. "must be > 0").
        rule: String,
    },
    /// An input value is outside its domain (value in SI units).
    #[error("{input} = {value} {rule}")]
    Input {
        /// The input at fault.
        input: Input,
        /// Its value, in SI units.
        value: f64,
        /// The rule it breaks, as a sentence ending (e.g. "must be >= 0").
        rule: String,
    },
    /// The vehicle, the model or the integrator, in their own terms.
    #[error("{0}")]
    Model(String),
}

impl From<SceneError> for Error {
    fn from(e: SceneError) -> Self {
        match e {
            SceneError::Option {
                option,
                value,
                rule,
            } => Error::BodyOption {
                option,
                value,
                rule,
            },
            SceneError::Model(m) => Error::Model(m),
        }
    }
}

impl From<String> for Error {
    fn from(message: String) -> Self {
        Error::Model(message)
    }
}

impl From<Error> for String {
    fn from(e: Error) -> Self {
        e.to_string()
    }
}

impl From<InputError> for Error {
    fn from(e: InputError) -> Self {
        match e {
            InputError::Value { input, value, rule } => Error::Input { input, value, rule },
            InputError::Other(m) => Error::Model(m),
        }
    }
}
