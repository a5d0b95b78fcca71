//! The runtime's inputs: the coupled model's ([`ModelInputs`]) and the body alone's mount
//! forces, each a [`RampInput`] (a value at a reference time and its first derivative, as a
//! master sets them at a communication point). The model checks them, once
//! ([`ModelInputs::validate`], [`crate::model::inputs::validate_body_forces`]).

use crate::model::inputs::AttachmentMotion;
use crate::model::{Input, ModelInputs, RampInput};

/// All inputs of the runtime, in SI units. Per mount, in configuration order: a list shorter
/// than the configuration's mounts leaves the others at their nominal value (scale 1, body at
/// rest, no force); the runtime sizes the lists to the configuration ([`Inputs::sized`]).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Inputs {
    /// The engine's inputs: crank speed (rad/s), load torque (N m), per mount the stiffness and
    /// damping scales and (scene 3) the external body's motion at the mount.
    pub model: ModelInputs,
    /// The body alone: the force on the body at each mount, N, per vehicle axis.
    pub body_force: Vec<[RampInput; 3]>,
}

impl Inputs {
    /// Constant engine speed `rpm`, no load torque, every mount at its nominal stiffness and
    /// damping, the body at rest and without forces.
    pub fn steady(rpm: f64) -> Inputs {
        let mut model = ModelInputs::new(0);
        model.crank_speed = RampInput::constant(rpm * super::RPM_TO_RAD_PER_S);
        Inputs {
            model,
            body_force: Vec::new(),
        }
    }

    /// Every input at its nominal value for `mounts` mounts: speed and load torque zero, every
    /// scale 1, the body at rest and without forces.
    pub fn nominal(mounts: usize) -> Inputs {
        Inputs {
            model: ModelInputs::new(mounts),
            body_force: vec![[RampInput::ZERO; 3]; mounts],
        }
    }

    /// The ramp of `input`, to change (`None` for a mount these inputs do not have).
    pub fn ramp_mut(&mut self, input: Input) -> Option<&mut RampInput> {
        match input {
            Input::BodyForce(i, j) => self.body_force.get_mut(i).and_then(|f| f.get_mut(j)),
            _ => self.model.ramp_mut(input),
        }
    }

    /// These inputs for `mounts` configured mounts: per-mount lists padded with nominal values
    /// or cut to length.
    pub fn sized(&self, mounts: usize) -> Inputs {
        let mut sized = self.clone();
        let m = &mut sized.model;
        m.stiffness_scale.resize(mounts, RampInput::constant(1.0));
        m.damping_scale.resize(mounts, RampInput::constant(1.0));
        m.body_motion.resize(mounts, AttachmentMotion::AT_REST);
        sized.body_force.resize(mounts, [RampInput::ZERO; 3]);
        sized
    }

    /// These inputs with the interface signals (the external body's motion, the forces on the
    /// body) of `interface`.
    pub fn with_interface(&self, interface: &Inputs) -> Inputs {
        let mut with = self.clone();
        with.model.body_motion = interface.model.body_motion.clone();
        with.body_force = interface.body_force.clone();
        with
    }

    /// Whether the interface signals of `next` continue these at `t`.
    pub fn interface_continues_into(&self, next: &Inputs, t: f64) -> bool {
        let forces =
            |i: &Inputs| -> Vec<RampInput> { i.body_force.iter().flatten().copied().collect() };
        let (a, b) = (forces(self), forces(next));
        self.model.body_motion_continues_into(&next.model, t)
            && a.len() == b.len()
            && a.iter().zip(&b).all(|(a, b)| a.continues_into(b, t))
    }
}
