//! Inputs of the coupled model and of the body alone, settable at any time (FMI: at
//! communication points, with derivatives for `canInterpolateInputs`). Every input is a ramp,
//! `value + rate · (t − since)`, the one signal type from the FMU's input tracks down to the
//! equations of motion.
//!
//! The model checks its inputs here, once: what is outside an input's domain is refused with a
//! typed [`InputError`] naming the [`Input`], which the FMU turns into its variable's name. Mounts
//! and axes are counted from 1 in every message, as the FMU's variables count them.

use serde::{Deserialize, Serialize};

/// The fastest an external body's point at a mount may move, m/s: a car body's points vibrate
/// at mm/s to a few m/s; a displacement ramp or a velocity beyond this is a master's error
/// (a wrong unit, a lost connection), refused naming the input rather than integrated.
pub const ATTACHMENT_SPEED_LIMIT: f64 = 100.0;

/// The largest acceleration of an external body's point at a mount, m/s² (about 1000 g): the
/// bound on a velocity ramp's rate, for the same reason as [`ATTACHMENT_SPEED_LIMIT`].
pub const ATTACHMENT_ACCELERATION_LIMIT: f64 = 1e4;

/// The body alone refuses a force at a mount larger than this many times the powertrain's
/// weight (so at least that many times the largest static mount force): 100 × m g is about
/// 190 kN for the built-in engine, far beyond a mount's bump stop.
pub const BODY_FORCE_LIMIT_WEIGHTS: f64 = 100.0;

/// A body force may change by at most its bound within this time (s): its rate is refused
/// beyond `bound / BODY_FORCE_RISE_TIME`.
pub const BODY_FORCE_RISE_TIME: f64 = 1e-3;

/// A real input that varies linearly between settings: `value + rate · (t − since)`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RampInput {
    /// Value at `since`, in the input's SI unit.
    pub value: f64,
    /// Slope (the input's unit per second).
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

    /// The ramp's value at time `t`; also before `since`, on the same line.
    pub fn at(&self, t: f64) -> f64 {
        self.value + self.rate * (t - self.since)
    }

    /// Whether value, rate and reference time are finite.
    pub fn is_finite(&self) -> bool {
        self.value.is_finite() && self.rate.is_finite() && self.since.is_finite()
    }

    /// Whether `next`, valid from `t` on, continues this ramp without a jump at `t`.
    pub fn continues_into(&self, next: &RampInput, t: f64) -> bool {
        let before = self.at(t);
        let after = next.at(t);
        (before - after).abs() <= 1e-12 * before.abs().max(after.abs()).max(1.0)
    }
}

/// One input of the model, mounts and axes indexed from 0 (displayed from 1).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Input {
    /// Crank speed set-point, rad/s.
    CrankSpeed,
    /// Load torque, N m.
    LoadTorque,
    /// Stiffness scale of a mount.
    StiffnessScale(usize),
    /// Damping scale of a mount.
    DampingScale(usize),
    /// Displacement of an external body's point at a mount along a vehicle axis, m.
    BodyDisplacement(usize, usize),
    /// Velocity of an external body's point at a mount along a vehicle axis, m/s.
    BodyVelocity(usize, usize),
    /// The body alone: the force on the body at a mount along a vehicle axis, N.
    BodyForce(usize, usize),
}

const AXES: [&str; 3] = ["x", "y", "z"];

impl std::fmt::Display for Input {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            Input::CrankSpeed => write!(f, "crank speed [rad/s]"),
            Input::LoadTorque => write!(f, "load torque [N m]"),
            Input::StiffnessScale(i) => write!(f, "stiffness scale of mount {}", i + 1),
            Input::DampingScale(i) => write!(f, "damping scale of mount {}", i + 1),
            Input::BodyDisplacement(i, j) => {
                write!(
                    f,
                    "body displacement at mount {} along {} [m]",
                    i + 1,
                    AXES[j]
                )
            }
            Input::BodyVelocity(i, j) => {
                write!(
                    f,
                    "body velocity at mount {} along {} [m/s]",
                    i + 1,
                    AXES[j]
                )
            }
            Input::BodyForce(i, j) => {
                write!(
                    f,
                    "force on the body at mount {} along {} [N]",
                    i + 1,
                    AXES[j]
                )
            }
        }
    }
}

impl Input {
    /// The model's one rule for this input, on its ramp in SI units: finite; a crank speed and
    /// mount scales >= 0; an external body's point within [`ATTACHMENT_SPEED_LIMIT`] and
    /// [`ATTACHMENT_ACCELERATION_LIMIT`]; a force on the body within `force_limit` (N, the body
    /// alone's bound) and changing at most by it within [`BODY_FORCE_RISE_TIME`].
    pub fn check(self, ramp: &RampInput, force_limit: f64) -> Result<(), InputError> {
        let refuse = |rule: String| Err(InputError::value(self, ramp, rule));
        let (value, rate) = (ramp.value, ramp.rate);
        match self {
            Input::CrankSpeed
            | Input::LoadTorque
            | Input::StiffnessScale(_)
            | Input::DampingScale(_)
                if !ramp.is_finite() =>
            {
                refuse(format!("(rate {rate}) must be finite"))
            }
            _ if !ramp.is_finite() => refuse(format!("(rate {rate}) is not finite")),
            Input::CrankSpeed if value < 0.0 => refuse("is negative".into()),
            Input::StiffnessScale(_) if value < 0.0 => {
                refuse("must be >= 0 (0: no stiffness; the mount keeps its preload)".into())
            }
            Input::DampingScale(_) if value < 0.0 => refuse("must be >= 0".into()),
            Input::BodyDisplacement(..) if rate.abs() > ATTACHMENT_SPEED_LIMIT => refuse(format!(
                "changes at {rate} m/s, beyond the {ATTACHMENT_SPEED_LIMIT} m/s a point of a car \
                 body can move"
            )),
            Input::BodyVelocity(..) if value.abs() > ATTACHMENT_SPEED_LIMIT => refuse(format!(
                "is beyond the {ATTACHMENT_SPEED_LIMIT} m/s a point of a car body can move"
            )),
            Input::BodyVelocity(..) if rate.abs() > ATTACHMENT_ACCELERATION_LIMIT => {
                refuse(format!(
                    "changes at {rate} m/s², beyond the {ATTACHMENT_ACCELERATION_LIMIT} m/s² a \
                     point of a car body can accelerate"
                ))
            }
            Input::BodyForce(..) => {
                let bound = format!(
                    "{force_limit:.4e} N ({BODY_FORCE_LIMIT_WEIGHTS} times the powertrain's weight)"
                );
                if value.abs() > force_limit {
                    refuse(format!("is beyond the plausible bound {bound}"))
                } else if rate.abs() > force_limit / BODY_FORCE_RISE_TIME {
                    refuse(format!(
                        "changes at {rate} N/s: beyond the plausible bound {bound} within \
                         {BODY_FORCE_RISE_TIME} s"
                    ))
                } else {
                    Ok(())
                }
            }
            _ => Ok(()),
        }
    }

    /// Whether this is the motion of an external body's point at a mount, which only a scene
    /// with an external body uses.
    pub fn is_external_body_motion(self) -> bool {
        matches!(self, Input::BodyDisplacement(..) | Input::BodyVelocity(..))
    }
}

/// An input the model refuses.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum InputError {
    /// An input outside its domain.
    #[error("{input} = {value} {rule}")]
    Value {
        /// The input at fault.
        input: Input,
        /// Its value at its reference time, in SI units.
        value: f64,
        /// The rule it breaks, as a sentence ending ("must be >= 0", …).
        rule: String,
    },
    /// Anything else, in the model's terms.
    #[error("{0}")]
    Other(String),
}

impl InputError {
    fn value(input: Input, ramp: &RampInput, rule: impl Into<String>) -> Self {
        InputError::Value {
            input,
            value: ramp.value,
            rule: rule.into(),
        }
    }
}

/// All inputs of the coupled model, one per configured mount where per mount.
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

    /// The model's inputs with their names, in the order they are checked: crank speed, load
    /// torque, per mount the stiffness and damping scales, per mount and axis the external
    /// body's displacement and velocity.
    pub fn ramps(&self) -> Vec<(Input, &RampInput)> {
        let mut all = vec![
            (Input::CrankSpeed, &self.crank_speed),
            (Input::LoadTorque, &self.load_torque),
        ];
        for (i, (k, c)) in self
            .stiffness_scale
            .iter()
            .zip(&self.damping_scale)
            .enumerate()
        {
            all.extend([(Input::StiffnessScale(i), k), (Input::DampingScale(i), c)]);
        }
        for (i, m) in self.body_motion.iter().enumerate() {
            for j in 0..3 {
                all.extend([
                    (Input::BodyDisplacement(i, j), &m.displacement[j]),
                    (Input::BodyVelocity(i, j), &m.velocity[j]),
                ]);
            }
        }
        all
    }

    /// The ramp of `input`, to change (`None` for a mount these inputs do not have, and for the
    /// body alone's forces, which are not the coupled model's).
    pub fn ramp_mut(&mut self, input: Input) -> Option<&mut RampInput> {
        match input {
            Input::CrankSpeed => Some(&mut self.crank_speed),
            Input::LoadTorque => Some(&mut self.load_torque),
            Input::StiffnessScale(i) => self.stiffness_scale.get_mut(i),
            Input::DampingScale(i) => self.damping_scale.get_mut(i),
            Input::BodyDisplacement(i, j) => self
                .body_motion
                .get_mut(i)
                .and_then(|m| m.displacement.get_mut(j)),
            Input::BodyVelocity(i, j) => self
                .body_motion
                .get_mut(i)
                .and_then(|m| m.velocity.get_mut(j)),
            Input::BodyForce(..) => None,
        }
    }

    /// Whether these are inputs for `mounts` configured mounts and each passes its rule
    /// ([`Input::check`]).
    pub fn validate(&self, mounts: usize) -> Result<(), InputError> {
        self.check_lengths(mounts)?;
        self.ramps()
            .into_iter()
            .try_for_each(|(input, ramp)| input.check(ramp, f64::INFINITY))
    }

    /// Whether these are inputs for `mounts` configured mounts: one entry per mount.
    pub fn check_lengths(&self, mounts: usize) -> Result<(), InputError> {
        let lengths = [
            self.stiffness_scale.len(),
            self.damping_scale.len(),
            self.body_motion.len(),
        ];
        if lengths.iter().any(|&n| n != mounts) {
            return Err(InputError::Other(format!(
                "{} stiffness scales, {} damping scales and {} attachment motions for {mounts} \
                 mounts",
                lengths[0], lengths[1], lengths[2]
            )));
        }
        Ok(())
    }

    /// Whether `next` continues the engine's inputs (speed, load torque, mount scales) without a
    /// jump at time `t`. The external body's motion is not compared: a coupling master sets it
    /// every communication step from the other model's outputs, where it never exactly continues
    /// the ramp before; its small jumps bend the trajectory less than an integrator restart at
    /// each step would cost, and the error control sees them.
    pub fn continue_into(&self, next: &ModelInputs, t: f64) -> bool {
        let ramps = |m: &ModelInputs| -> Vec<RampInput> {
            [m.crank_speed, m.load_torque]
                .into_iter()
                .chain(m.stiffness_scale.iter().copied())
                .chain(m.damping_scale.iter().copied())
                .collect()
        };
        let (a, b) = (ramps(self), ramps(next));
        a.len() == b.len() && a.iter().zip(&b).all(|(a, b)| a.continues_into(b, t))
    }

    /// Whether the external body's motion in `next` continues this one's at `t`.
    pub fn body_motion_continues_into(&self, next: &ModelInputs, t: f64) -> bool {
        let ramps = |m: &ModelInputs| -> Vec<RampInput> {
            m.body_motion
                .iter()
                .flat_map(|a| a.displacement.iter().chain(&a.velocity).copied())
                .collect()
        };
        let (a, b) = (ramps(self), ramps(next));
        a.len() == b.len() && a.iter().zip(&b).all(|(a, b)| a.continues_into(b, t))
    }
}

/// The one check of the body alone's mount forces: each passes its rule ([`Input::check`]) with
/// the bound `limit` (N).
pub fn validate_body_forces(forces: &[[RampInput; 3]], limit: f64) -> Result<(), InputError> {
    for (i, f) in forces.iter().enumerate() {
        for (j, r) in f.iter().enumerate() {
            Input::BodyForce(i, j).check(r, limit)?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_ramp_continued_at_its_end_is_not_a_jump() {
        let a = RampInput {
            value: 100.0,
            rate: 10.0,
            since: 1.0,
        };
        let mut b = RampInput {
            value: 110.0,
            rate: 10.0,
            since: 2.0,
        };
        assert!(a.continues_into(&b, 2.0));
        b.value = 120.0;
        assert!(!a.continues_into(&b, 2.0));
    }

    #[test]
    fn refusals_name_the_input_counting_mounts_and_axes_from_1() {
        let good = ModelInputs::new(3);
        assert!(good.validate(3).is_ok());
        let mut bad = good.clone();
        bad.stiffness_scale[2].value = -1.0;
        let e = bad.validate(3).unwrap_err();
        assert!(matches!(
            e,
            InputError::Value {
                input: Input::StiffnessScale(2),
                ..
            }
        ));
        assert!(
            e.to_string().starts_with("stiffness scale of mount 3 = -1"),
            "{e}"
        );
        let mut bad = good.clone();
        bad.body_motion[1].displacement[2].rate = 1e300;
        let e = bad.validate(3).unwrap_err();
        assert!(
            matches!(
                e,
                InputError::Value {
                    input: Input::BodyDisplacement(1, 2),
                    ..
                }
            ),
            "{e}"
        );
        assert!(e.to_string().contains("mount 2 along z"), "{e}");
        let mut bad = good;
        bad.body_motion[0].velocity[0].rate = 2.0 * ATTACHMENT_ACCELERATION_LIMIT;
        assert!(bad.validate(3).is_err());
    }

    /// Each rule is on its own input's ramp: an external body's point may be anywhere but not
    /// move faster than 100 m/s; its velocity up to 100 m/s, changing by up to 1e4 m/s².
    #[test]
    fn each_input_has_its_own_rule() {
        let ramp = |value, rate| RampInput {
            value,
            rate,
            since: 0.0,
        };
        let r = Input::BodyDisplacement(0, 0);
        assert!(r.check(&ramp(1e3, 99.0), f64::INFINITY).is_ok());
        assert!(r.check(&ramp(0.0, 101.0), f64::INFINITY).is_err());
        let v = Input::BodyVelocity(3, 2);
        assert!(v.check(&ramp(-99.0, 9e3), f64::INFINITY).is_ok());
        assert!(v.check(&ramp(-101.0, 0.0), f64::INFINITY).is_err());
        assert!(v.check(&ramp(0.0, -1.1e4), f64::INFINITY).is_err());
        // A speed set-point must be >= 0; a load torque may have either sign.
        assert!(Input::CrankSpeed.check(&ramp(-1.0, 0.0), 0.0).is_err());
        assert!(Input::LoadTorque.check(&ramp(-1e3, -1e3), 0.0).is_ok());
        // Forces are bounded by the limit given, their rate by the limit per rise time.
        let f = Input::BodyForce(0, 2);
        assert!(f.check(&ramp(-999.0, 0.0), 1e3).is_ok());
        assert!(f.check(&ramp(1001.0, 0.0), 1e3).is_err());
        assert!(f
            .check(&ramp(0.0, 1.01e3 / BODY_FORCE_RISE_TIME), 1e3)
            .is_err());
    }

    #[test]
    fn body_forces_beyond_the_bound_are_refused() {
        let limit = 1e5;
        let mut f = vec![[RampInput::ZERO; 3]; 2];
        f[1][2] = RampInput::constant(0.99 * limit);
        assert!(validate_body_forces(&f, limit).is_ok());
        f[1][2] = RampInput::constant(1e300);
        let e = validate_body_forces(&f, limit).unwrap_err();
        assert!(
            matches!(
                e,
                InputError::Value {
                    input: Input::BodyForce(1, 2),
                    ..
                }
            ),
            "{e}"
        );
        f[1][2] = RampInput {
            value: 0.0,
            rate: 2.0 * limit / BODY_FORCE_RISE_TIME,
            since: 0.0,
        };
        assert!(validate_body_forces(&f, limit).is_err());
    }
}
