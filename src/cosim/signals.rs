//! Inputs as continuous signals between communication points.

/// A real input that changes linearly from its reference time on: the value set at a
/// communication point plus the first derivative from `fmi2SetRealInputDerivatives`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Signal {
    /// Value at `reference_time`, in the input's SI unit.
    pub value: f64,
    /// Rate of change from `reference_time` on, in the input's unit per s.
    pub derivative: f64,
    /// Time in s at which the signal has `value`.
    pub reference_time: f64,
}

impl Signal {
    /// A signal that stays at `value` for all times.
    pub fn constant(value: f64) -> Signal {
        Signal {
            value,
            derivative: 0.0,
            reference_time: 0.0,
        }
    }

    /// The value at time `t` (s); also before `reference_time`, on the same line.
    pub fn at(&self, t: f64) -> f64 {
        self.value + self.derivative * (t - self.reference_time)
    }

    /// Whether `next`, valid from `t` on, continues this signal without a jump at `t`.
    pub fn continues_into(&self, next: &Signal, t: f64) -> bool {
        let before = self.at(t);
        let after = next.at(t);
        (before - after).abs() <= 1e-12 * before.abs().max(after.abs()).max(1.0)
    }
}

/// All inputs of the model, in SI units.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Inputs {
    /// Crank speed in rad/s.
    pub crank_speed: Signal,
    /// Drivetrain reaction torque on the housing about the crank axis, N m.
    pub load_torque: Signal,
    /// Scale on each mount's force-deflection curve (>= 0).
    pub stiffness_scale: [Signal; 4],
    /// Scale on each mount's damping (>= 0).
    pub damping_scale: [Signal; 4],
    /// Scene 3: displacement of each mount's attachment point on the external body, m, per
    /// vehicle axis.
    pub body_displacement: [[Signal; 3]; 4],
    /// Scene 3: velocity of each mount's attachment point on the external body, m/s.
    pub body_velocity: [[Signal; 3]; 4],
    /// The body alone: the force on the body at each mount point, N, per vehicle axis.
    pub body_force: [[Signal; 3]; 4],
}

impl Inputs {
    /// Constant engine speed `rpm`, no load torque, every mount at its nominal stiffness and
    /// damping.
    pub fn steady(rpm: f64) -> Inputs {
        Inputs {
            crank_speed: Signal::constant(rpm * super::RPM_TO_RAD_PER_S),
            load_torque: Signal::constant(0.0),
            stiffness_scale: [Signal::constant(1.0); 4],
            damping_scale: [Signal::constant(1.0); 4],
            body_displacement: [[Signal::constant(0.0); 3]; 4],
            body_velocity: [[Signal::constant(0.0); 3]; 4],
            body_force: [[Signal::constant(0.0); 3]; 4],
        }
    }

    /// The signals of the external body's interface: attachment displacements and velocities
    /// and the forces on the body, mount by mount.
    pub fn interface(&self) -> impl Iterator<Item = &Signal> + '_ {
        [
            &self.body_displacement,
            &self.body_velocity,
            &self.body_force,
        ]
        .into_iter()
        .flatten()
        .flatten()
    }

    /// Physical admissibility of the input values (finite values are checked by the caller).
    pub fn validate(&self) -> Result<(), super::Error> {
        use super::error::Input;
        let bad = |input, value, rule| Err(super::Error::Input { input, value, rule });
        if self.crank_speed.value.is_nan() || self.crank_speed.value < 0.0 {
            return bad(Input::CrankSpeed, self.crank_speed.value, "is negative");
        }
        for (i, s) in self.stiffness_scale.iter().enumerate() {
            if s.value.is_nan() || s.value < 0.0 {
                let rule = "must be >= 0 (0: no stiffness; the mount keeps its preload)";
                return bad(Input::StiffnessScale(i), s.value, rule);
            }
        }
        for (i, s) in self.damping_scale.iter().enumerate() {
            if s.value.is_nan() || s.value < 0.0 {
                return bad(Input::DampingScale(i), s.value, "must be >= 0");
            }
        }
        Ok(())
    }

    /// Whether `next` continues every signal without a jump at time `t`. The interface signals
    /// of an external body are not compared: a coupling master sets them every communication
    /// step from the other model's outputs, where they never exactly continue the ramp before;
    /// their small jumps bend the trajectory less than an integrator restart at each step would
    /// cost, and the error control sees them.
    pub fn continue_into(&self, next: &Inputs, t: f64) -> bool {
        let pairs = [
            (&self.crank_speed, &next.crank_speed),
            (&self.load_torque, &next.load_torque),
        ];
        pairs.iter().all(|(a, b)| a.continues_into(b, t))
            && self
                .stiffness_scale
                .iter()
                .zip(&next.stiffness_scale)
                .all(|(a, b)| a.continues_into(b, t))
            && self
                .damping_scale
                .iter()
                .zip(&next.damping_scale)
                .all(|(a, b)| a.continues_into(b, t))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn inputs() -> Inputs {
        Inputs {
            crank_speed: Signal {
                value: 100.0,
                derivative: 10.0,
                reference_time: 1.0,
            },
            load_torque: Signal::constant(0.0),
            stiffness_scale: [Signal::constant(1.0); 4],
            damping_scale: [Signal::constant(1.0); 4],
            ..Inputs::steady(0.0)
        }
    }

    #[test]
    fn a_ramp_continued_at_its_end_is_not_a_jump() {
        let a = inputs();
        let mut b = a;
        b.crank_speed = Signal {
            value: 110.0,
            derivative: 10.0,
            reference_time: 2.0,
        };
        assert!(a.continue_into(&b, 2.0));
        b.crank_speed.value = 120.0;
        assert!(!a.continue_into(&b, 2.0));
    }

    #[test]
    fn validation_names_the_bad_input() {
        let a = inputs();
        assert!(a.validate().is_ok());
        let mut bad = a;
        bad.stiffness_scale[2].value = -1.0;
        assert!(matches!(
            bad.validate(),
            Err(crate::cosim::Error::Input {
                input: crate::cosim::error::Input::StiffnessScale(2),
                ..
            })
        ));
        bad = a;
        bad.damping_scale[0].value = -0.5;
        assert!(bad.validate().is_err());
    }
}
