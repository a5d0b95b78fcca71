//! Inputs of the engine model, settable at any time (FMI: at communication points, with
//! derivatives for `canInterpolateInputs`).

/// A real input that varies linearly between settings: `value + rate · (t − since)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RampInput {
    pub value: f64,
    pub rate: f64,
    pub since: f64,
}

impl RampInput {
    pub fn constant(value: f64) -> Self {
        Self {
            value,
            rate: 0.0,
            since: 0.0,
        }
    }

    pub fn at(&self, t: f64) -> f64 {
        self.value + self.rate * (t - self.since)
    }
}

/// All inputs of the engine model.
#[derive(Debug, Clone, PartialEq)]
pub struct EngineInputs {
    /// Crank spin about its axis (rad/s) and its time derivative.
    pub crank_speed: RampInput,
    /// Load torque on the housing about the crank axis +y (N m): the drivetrain reaction.
    pub load_torque: RampInput,
    /// Per configured mount (index as in the configuration): stiffness and damping scale factors.
    pub stiffness_scale: Vec<f64>,
    pub damping_scale: Vec<f64>,
}

impl EngineInputs {
    pub fn new(mounts: usize) -> Self {
        Self {
            crank_speed: RampInput::constant(0.0),
            load_torque: RampInput::constant(0.0),
            stiffness_scale: vec![1.0; mounts],
            damping_scale: vec![1.0; mounts],
        }
    }
}

/// An input value the model rejects.
#[derive(Debug, Clone, PartialEq)]
pub struct InputError(pub String);

impl std::fmt::Display for InputError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for InputError {}
