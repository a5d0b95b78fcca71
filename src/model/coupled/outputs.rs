//! Outputs at a communication point, from the components present: mount forces, powertrain
//! motion, crank angle, and the motion of the body's output points — all from one evaluation of
//! the equations of motion (accelerations too: no finite differences of velocities).

use nalgebra::Vector3;

use super::evaluate::Mode;
use super::CoupledModel;
use crate::ode::ProblemError;

/// Motion of one powertrain point.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BodyMotion {
    /// Displacement (m, vehicle frame).
    pub displacement: [f64; 3],
    /// Cardan angles `R = Rx Ry Rz` (rad).
    pub rotation: [f64; 3],
    /// Velocity (m/s, vehicle frame).
    pub velocity: [f64; 3],
    /// Angular velocity (rad/s, vehicle frame).
    pub angular_velocity: [f64; 3],
    /// Acceleration (m/s², vehicle frame).
    pub acceleration: [f64; 3],
    /// Angular acceleration (rad/s², vehicle frame).
    pub angular_acceleration: [f64; 3],
}

/// Motion of a named body point (vehicle frame).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PointMotion {
    /// The point's name in the vehicle configuration.
    pub name: String,
    /// Displacement (m).
    pub displacement: [f64; 3],
    /// Velocity (m/s).
    pub velocity: [f64; 3],
    /// Acceleration (m/s²).
    pub acceleration: [f64; 3],
}

/// All outputs of the coupled model at one time.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Outputs {
    /// Time of the outputs (s).
    pub time: f64,
    /// Per configured mount: force on the ground/body side (N, vehicle frame); zero if removed.
    pub mount_forces: Vec<[f64; 3]>,
    /// Per configured mount: deflection in mount axes (m); zero if removed.
    pub mount_deflections: Vec<[f64; 3]>,
    /// Motion of the housing's reference point (its centre of mass in the reference
    /// configuration); with rigid ring carriers, of the same point of the rigid powertrain.
    pub housing: BodyMotion,
    /// Monoblock motion (its centre of mass); the same body as `housing` when the ring carriers
    /// are rigid.
    pub monoblock: BodyMotion,
    /// Crank angle relative to the monoblock (rad, unwrapped).
    pub crank_angle: f64,
    /// Crank speed (rad/s) — the follower's, or the set-point's.
    pub crank_speed: f64,
    /// Crank acceleration (rad/s²) — the follower's, or the set-point's.
    pub crank_acceleration: f64,
    /// Excitation fade-in factor.
    pub excitation: f64,
    /// The body's output points (none on rigid ground).
    pub points: Vec<PointMotion>,
}

impl Outputs {
    /// The output point called `name`, if the model has it.
    pub fn point(&self, name: &str) -> Option<&PointMotion> {
        self.points.iter().find(|p| p.name == name)
    }
}

fn arr(v: &Vector3<f64>) -> [f64; 3] {
    [v.x, v.y, v.z]
}

impl CoupledModel {
    /// Outputs at `(t, y)`.
    pub fn outputs(&self, t: f64, y: &[f64]) -> Result<Outputs, ProblemError> {
        self.check_state(y)?;
        let ev = self.evaluate(t, y);
        let mut f = vec![0.0; y.len()];
        self.write_rhs(t, y, &ev, Mode::RUNNING, &mut f)?;
        let l = &self.layout;
        let nb = l.bodies();
        // The rigid powertrain's body 0 has its reference at the monoblock's centre of mass; the
        // housing outputs are those of the housing's centre of mass, wherever the bodies are.
        let housing_point = self.powertrain.housing_reference();
        let motion = |b: usize, point: &Vector3<f64>| {
            let k = &ev.kinematics[b];
            let acc = &f[l.v(b)];
            let r = k.rotation * (point - self.powertrain.bodies()[b].reference);
            let alpha = Vector3::new(acc[3], acc[4], acc[5]);
            let a0 = Vector3::new(acc[0], acc[1], acc[2]);
            let q = &y[l.q(b)];
            let displacement = Vector3::new(q[0], q[1], q[2]) + r
                - (point - self.powertrain.bodies()[b].reference);
            BodyMotion {
                displacement: arr(&displacement),
                rotation: [q[3], q[4], q[5]],
                velocity: arr(&k.point_velocity(&(point - self.powertrain.bodies()[b].reference))),
                angular_velocity: arr(&k.omega),
                acceleration: arr(&(a0 + alpha.cross(&r) + k.omega.cross(&k.omega.cross(&r)))),
                angular_acceleration: [acc[3], acc[4], acc[5]],
            }
        };
        let monoblock_reference = self.powertrain.bodies()[0].reference;
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
        let (eta, rate) = (&y[l.eta()], &y[l.eta_rate()]);
        let eta_acc = &f[l.eta_rate()];
        let points = self
            .outputs
            .iter()
            .map(|o| PointMotion {
                name: o.name.clone(),
                displacement: arr(&self.point_translation(o.point, eta)),
                velocity: arr(&self.point_translation(o.point, rate)),
                acceleration: arr(&self.point_translation(o.point, eta_acc)),
            })
            .collect();
        Ok(Outputs {
            time: t,
            mount_forces,
            mount_deflections,
            housing: motion(nb - 1, &housing_point),
            monoblock: motion(0, &monoblock_reference),
            crank_angle: y[l.crank_angle()],
            crank_speed: ev.crank_speed,
            crank_acceleration: ev.crank_acceleration,
            excitation: self.excitation(t),
            points,
        })
    }
}
