//! Outputs at a communication point: mount forces, body motions, crank angle and accelerations
//! from one evaluation of the equations of motion (no finite differences of velocities).

use nalgebra::Vector3;

use super::ground_scene::{Evaluation, GroundScene};
use crate::ode::ProblemError;

/// Motion of one body's reference point (its centre of mass in the reference configuration).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BodyMotion {
    /// Displacement (m, vehicle frame).
    pub displacement: [f64; 3],
    /// Cardan angles `R = Rx Ry Rz` (rad).
    pub rotation: [f64; 3],
    /// Velocity (m/s) and angular velocity (rad/s), vehicle frame.
    pub velocity: [f64; 3],
    pub angular_velocity: [f64; 3],
    /// Acceleration (m/s²) and angular acceleration (rad/s²), vehicle frame.
    pub acceleration: [f64; 3],
    pub angular_acceleration: [f64; 3],
}

/// All outputs of the engine model at one time.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct EngineOutputs {
    pub time: f64,
    /// Per configured mount: force on the ground/chassis side (N, vehicle frame); zero if removed.
    pub mount_forces: Vec<[f64; 3]>,
    /// Per configured mount: deflection in mount axes (m); zero if removed.
    pub mount_deflections: Vec<[f64; 3]>,
    /// Housing (or rigid powertrain) motion.
    pub housing: BodyMotion,
    /// Monoblock motion (equal to the housing's when the ring carriers are rigid).
    pub monoblock: BodyMotion,
    /// Crank angle relative to the monoblock (rad, unwrapped).
    pub crank_angle: f64,
    /// Crank spin input (rad/s).
    pub crank_speed: f64,
    /// Excitation fade-in factor.
    pub excitation: f64,
}

fn arr(v: &Vector3<f64>) -> [f64; 3] {
    [v.x, v.y, v.z]
}

impl GroundScene {
    /// Outputs at `(t, y)`.
    pub fn outputs(&self, t: f64, y: &[f64]) -> Result<EngineOutputs, ProblemError> {
        self.check_state(y)?;
        let ev = self.evaluate(t, y);
        self.outputs_from(t, y, &ev)
    }

    /// Outputs from an evaluation `ev` of the engine at `(t, y)`, `y` the engine states (the
    /// hybrid scene passes one whose mount forces act against the moving chassis).
    pub(crate) fn outputs_from(
        &self,
        t: f64,
        y: &[f64],
        ev: &Evaluation,
    ) -> Result<EngineOutputs, ProblemError> {
        let acc = self.accelerations(ev)?;
        let nb = self.body_count();
        let motion = |b: usize| {
            let q = &y[6 * b..6 * b + 6];
            let k = &ev.kinematics[b];
            BodyMotion {
                displacement: [q[0], q[1], q[2]],
                rotation: [q[3], q[4], q[5]],
                velocity: arr(&k.velocity),
                angular_velocity: arr(&k.omega),
                acceleration: [acc[b][0], acc[b][1], acc[b][2]],
                angular_acceleration: [acc[b][3], acc[b][4], acc[b][5]],
            }
        };
        let mut mount_forces = Vec::with_capacity(ev.mounts.len());
        let mut mount_deflections = Vec::with_capacity(ev.mounts.len());
        for m in &ev.mounts {
            match m {
                Some(r) => {
                    mount_forces.push(arr(&(-r.force)));
                    mount_deflections.push(arr(&r.deflection));
                }
                None => {
                    mount_forces.push([0.0; 3]);
                    mount_deflections.push([0.0; 3]);
                }
            }
        }
        Ok(EngineOutputs {
            time: t,
            mount_forces,
            mount_deflections,
            housing: motion(nb - 1),
            monoblock: motion(0),
            crank_angle: y[self.crank_index()],
            crank_speed: self.inputs().crank_speed.at(t),
            excitation: self.excitation(t),
        })
    }
}
