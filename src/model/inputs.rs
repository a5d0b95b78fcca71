//! Inputs of the coupled model, settable at any time (FMI: at communication points, with
//! derivatives for `canInterpolateInputs`). Every input is a ramp, `value + rate · (t − since)`.

use serde::{Deserialize, Serialize};

/// A real input that varies linearly between settings: `value + rate · (t − since)`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RampInput {
    /// Value at `since`.
    pub value: f64,
    /// Slope (per second).
    pub rate: f64,
    /// Time at which the ramp has `value` (s).
    pub since: f64,
}

impl RampInput {
    /// The constant zero.
    pub const ZERO: RampInput = RampInput {
        value: 0.0,
        rate: 0.0,
        since: 0.0,
    };

    /// A constant input.
    pub fn constant(value: f64) -> Self {
        Self {
            value,
            rate: 0.0,
            since: 0.0,
        }
    }

    /// The ramp's value at time `t`.
    pub fn at(&self, t: f64) -> f64 {
        self.value + self.rate * (t - self.since)
    }

    fn is_finite(&self) -> bool {
        self.value.is_finite() && self.rate.is_finite() && self.since.is_finite()
    }
}

/// All inputs of the coupled model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModelInputs {
    /// Crank speed set-point (rad/s, the crank's spin about its axis in inertial space) and its
    /// slope; the crank follows it directly or through the speed follower.
    pub crank_speed: RampInput,
    /// Load torque on the housing about the crank axis +y (N m): the drivetrain reaction.
    pub load_torque: RampInput,
    /// Per configured mount (index as in the configuration): stiffness scale factor. A ramp that
    /// reaches below zero is held at zero.
    pub stiffness_scale: Vec<RampInput>,
    /// Per configured mount: damping scale factor, held at zero like the stiffness scale.
    pub damping_scale: Vec<RampInput>,
    /// Per configured mount: motion of its attachment point on an external body (scene 3),
    /// vehicle frame; unused for mounts on ground or on the model's own body.
    pub body_motion: Vec<AttachmentMotion>,
}

/// Displacement from its reference position and velocity of a mount's attachment point on a
/// body outside the model, per vehicle axis, each a ramp like every continuous input.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AttachmentMotion {
    /// Displacement (m) along x, y, z.
    pub displacement: [RampInput; 3],
    /// Velocity (m/s) along x, y, z.
    pub velocity: [RampInput; 3],
}

impl AttachmentMotion {
    /// The attachment at rest in its reference position.
    pub const AT_REST: AttachmentMotion = AttachmentMotion {
        displacement: [RampInput::ZERO; 3],
        velocity: [RampInput::ZERO; 3],
    };

    /// Displacement and velocity at `t`.
    pub fn at(&self, t: f64) -> ([f64; 3], [f64; 3]) {
        (
            self.displacement.map(|r| r.at(t)),
            self.velocity.map(|r| r.at(t)),
        )
    }

    fn is_finite(&self) -> bool {
        self.displacement
            .iter()
            .chain(&self.velocity)
            .all(RampInput::is_finite)
    }
}

impl ModelInputs {
    /// Inputs for `mounts` configured mounts: speed and load torque zero, every scale 1.
    pub fn new(mounts: usize) -> Self {
        Self {
            crank_speed: RampInput::constant(0.0),
            load_torque: RampInput::constant(0.0),
            stiffness_scale: vec![RampInput::constant(1.0); mounts],
            damping_scale: vec![RampInput::constant(1.0); mounts],
            body_motion: vec![AttachmentMotion::AT_REST; mounts],
        }
    }

    /// Stiffness and damping scales of mount `i` at `t` (never negative).
    pub fn mount_scales(&self, i: usize, t: f64) -> (f64, f64) {
        (
            self.stiffness_scale[i].at(t).max(0.0),
            self.damping_scale[i].at(t).max(0.0),
        )
    }

    /// Finite values, non-negative mount scales, one scale pair per configured mount.
    pub fn validate(&self, mounts: usize) -> Result<(), InputError> {
        for (name, r) in [
            ("crank speed", &self.crank_speed),
            ("load torque", &self.load_torque),
        ] {
            if !r.is_finite() {
                return Err(InputError(format!(
                    "{name} {} (rate {}, since {}) must be finite",
                    r.value, r.rate, r.since
                )));
            }
        }
        if self.stiffness_scale.len() != mounts || self.damping_scale.len() != mounts {
            return Err(InputError(format!(
                "{} stiffness and {} damping scales for {mounts} mounts",
                self.stiffness_scale.len(),
                self.damping_scale.len()
            )));
        }
        if self.body_motion.len() != mounts {
            return Err(InputError(format!(
                "{} attachment motions for {mounts} mounts",
                self.body_motion.len()
            )));
        }
        if let Some(i) = self.body_motion.iter().position(|m| !m.is_finite()) {
            return Err(InputError(format!(
                "mounts[{i}] attachment displacement and velocity must be finite"
            )));
        }
        for (i, (k, c)) in self
            .stiffness_scale
            .iter()
            .zip(&self.damping_scale)
            .enumerate()
        {
            for (what, r) in [("stiffness", k), ("damping", c)] {
                if !(r.is_finite() && r.value >= 0.0) {
                    return Err(InputError(format!(
                        "mounts[{i}] {what} scale {} (rate {}) must be finite and >= 0",
                        r.value, r.rate
                    )));
                }
            }
        }
        Ok(())
    }
}

/// An input value the model rejects.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct InputError(pub String);
