//! Why a simulation could not be built or continued, typed so that the FMI layer can name the
//! parameter or input behind it in its own terms.

use crate::model::scene::{BodyOption, SceneError};

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
        rule: &'static str,
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

/// One of the runtime's inputs ([`super::Inputs`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Input {
    /// Crank speed set-point, rad/s.
    CrankSpeed,
    /// Load torque, N m.
    LoadTorque,
    /// Stiffness scale of mount `i` (0-based).
    StiffnessScale(usize),
    /// Damping scale of mount `i` (0-based).
    DampingScale(usize),
}

impl std::fmt::Display for Input {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Input::CrankSpeed => write!(f, "crank speed [rad/s]"),
            Input::LoadTorque => write!(f, "load torque [N m]"),
            Input::StiffnessScale(i) => write!(f, "stiffness scale of mount {i}"),
            Input::DampingScale(i) => write!(f, "damping scale of mount {i}"),
        }
    }
}
