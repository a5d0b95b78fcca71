//! Composite-body dynamics (virtual power / Kane) of a rigid body carrying internal parts with
//! prescribed relative motion.
//!
//! Body coordinates: position `p` of the body reference point and its rotation `R` (both in the
//! vehicle frame); velocities `v = [ṗ, ω]` with `ω` the angular velocity in the vehicle frame.
//!
//! Crank drive semantics: the engine-speed input `ω_c` is the crankshaft's spin about its own axis
//! `e = R e_y` in inertial space, as a flywheel held by a stiff drivetrain keeps it. The crank
//! angle relative to the block therefore moves at `φ' = ω_c − e·ω`. Projecting every part's
//! Newton–Euler equations onto the body velocities with these partial velocities yields, without
//! any hand-written order formula, the shaking forces and rocking moments, the mass torque (the
//! reaction of the drive torque the parts need, paper §4.2), the gyroscopic coupling of the
//! spinning shafts and an effective mass matrix that is symmetric — so free vibration with the
//! crank at rest conserves energy.

use nalgebra::{Matrix3, Matrix6, Vector3, Vector6};

#[cfg(test)]
use super::parts::Part;

/// Pose and velocity of one body.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyKinematics {
    /// World position of the reference point (m, vehicle frame).
    pub position: Vector3<f64>,
    /// Rotation from body axes to the vehicle frame.
    pub rotation: Matrix3<f64>,
    /// Velocity of the reference point (m/s, vehicle frame).
    pub velocity: Vector3<f64>,
    /// Angular velocity (rad/s, vehicle frame).
    pub omega: Vector3<f64>,
}

impl BodyKinematics {
    /// Body at its reference pose, at rest.
    pub fn at_rest(position: Vector3<f64>) -> Self {
        Self {
            position,
            rotation: Matrix3::identity(),
            velocity: Vector3::zeros(),
            omega: Vector3::zeros(),
        }
    }

    /// World position of a body-fixed point given relative to the reference point in body axes.
    pub fn point(&self, local: &Vector3<f64>) -> Vector3<f64> {
        self.position + self.rotation * local
    }

    /// World velocity of a body-fixed point.
    pub fn point_velocity(&self, local: &Vector3<f64>) -> Vector3<f64> {
        self.velocity + self.omega.cross(&(self.rotation * local))
    }
}

/// State of the crank drive as seen by the parts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CrankDriveState {
    /// Crank angle relative to the body (rad).
    pub angle: f64,
    /// Crank spin about its axis in inertial space (rad/s).
    pub speed: f64,
    /// Time derivative of `speed` (rad/s²).
    pub acceleration: f64,
    /// Scale of the parts' relative motion (excitation): 1 in operation, 0 with mass forces off,
    /// in between during the excitation fade-in.
    pub excitation: f64,
    /// Crank spin (rad/s) that enters the shafts' angular momentum (gyroscopic terms); 0 when the
    /// gyroscopic effect is switched off.
    pub spin: f64,
}

impl CrankDriveState {
    /// Crank standing still at `angle`.
    pub fn at_rest(angle: f64) -> Self {
        Self {
            angle,
            speed: 0.0,
            acceleration: 0.0,
            excitation: 1.0,
            spin: 0.0,
        }
    }
}

/// Mass matrix and generalised forces of one composite body, `M v' = f`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyDynamics {
    /// Composite 6×6 mass matrix for `v = [u', ω]`.
    pub mass: Matrix6<f64>,
    /// Generalised forces (force and moment about the reference point, vehicle frame).
    pub force: Vector6<f64>,
}

impl BodyDynamics {
    /// No mass and no force (the start of a sum).
    pub fn zero() -> Self {
        Self {
            mass: Matrix6::zeros(),
            force: Vector6::zeros(),
        }
    }

    /// Adds a force `f` (vehicle frame) acting at world point `x`.
    pub fn add_point_force(&mut self, body: &BodyKinematics, x: &Vector3<f64>, f: &Vector3<f64>) {
        let m = (x - body.position).cross(f);
        self.add_wrench(f, &m);
    }

    /// Adds a force through the reference point and a moment.
    pub fn add_wrench(&mut self, f: &Vector3<f64>, m: &Vector3<f64>) {
        for i in 0..3 {
            self.force[i] += f[i];
            self.force[3 + i] += m[i];
        }
    }
}

/// Adds the contributions of `parts` (including gravity `g`) to `out`, projecting each part's
/// Newton–Euler equations one by one. The model evaluates the same projection through the
/// parts' mass moments ([`super::part_moments`]); this direct form is their test reference.
#[cfg(test)]
pub(super) fn add_parts(
    parts: &[Part],
    body: &BodyKinematics,
    crank: &CrankDriveState,
    gravity: &Vector3<f64>,
    out: &mut BodyDynamics,
) {
    let e = body.rotation * Vector3::y();
    let w = body.omega;
    let e_dot_w = e.dot(&w);
    // Relative crank speed; its forced part (the engine running) is scaled by the excitation.
    let rel_speed = crank.excitation * crank.speed - e_dot_w;
    let rel_accel = crank.excitation * crank.acceleration;
    let spin_speed = crank.spin - e_dot_w;
    let e_outer = e * e.transpose();
    for part in parts {
        let path = part.path(crank.angle);
        let r = body.rotation * path.rho;
        let d = body.rotation * path.d_rho;
        let dd = body.rotation * path.dd_rho;
        // Partial velocities: linear Jp = [I, A] with A = −[r]× − d eᵀ, angular
        // Jw = [0, I − n e eᵀ]. Jpᵀ Jp = [[I, A], [Aᵀ, AᵀA]] is accumulated block by block.
        let a = -r.cross_matrix() - d * e.transpose();
        let n = part.spin_ratio;
        let jw_rot = Matrix3::identity() - e_outer * n;
        let a_bias = w.cross(&w.cross(&r))
            + 2.0 * rel_speed * w.cross(&d)
            + rel_speed * rel_speed * dd
            + rel_accel * d;
        let lin = gravity * part.mass - a_bias * part.mass;
        let m = part.mass;
        let a_m = a * m;
        let ata_m = a.transpose() * a_m;
        let a_t_lin = a.transpose() * lin;
        for i in 0..3 {
            out.mass[(i, i)] += m;
            out.force[i] += lin[i];
            out.force[3 + i] += a_t_lin[i];
            for j in 0..3 {
                out.mass[(i, 3 + j)] += a_m[(i, j)];
                out.mass[(3 + j, i)] += a_m[(i, j)];
                out.mass[(3 + i, 3 + j)] += ata_m[(i, j)];
            }
        }
        if part.inertia != Matrix3::zeros() {
            let j_world = body.rotation * part.inertia * body.rotation.transpose();
            let omega_part = w + e * (n * spin_speed);
            let alpha_bias = e * (n * rel_accel) + w.cross(&e) * (n * spin_speed);
            let moment = -(j_world * alpha_bias + omega_part.cross(&(j_world * omega_part)));
            let m_rot = jw_rot.transpose() * j_world * jw_rot;
            let mut block = out.mass.fixed_view_mut::<3, 3>(3, 3);
            block += m_rot;
            let proj = jw_rot.transpose() * moment;
            for i in 0..3 {
                out.force[3 + i] += proj[i];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::effects::Effects;
    use crate::model::powertrain::assembly::build_bodies;
    use crate::model::powertrain::part_moments::PartMoments;
    use crate::model::powertrain::parts::PartMotion;
    use crate::model::EngineConfig;

    #[test]
    fn spinning_rotor_exerts_the_classical_gyroscopic_moment() {
        // A rotor with spin inertia J turning at ω_c about the block's y axis, the block yawing
        // at Ω about z: the bearings must supply dH/dt = Ω × (J ω_c e_y); the rotor exerts the
        // opposite moment on the block (rigid-body textbook result, independent of Kane).
        let j = 0.15;
        let parts = vec![Part {
            name: "rotor".into(),
            mass: 0.0,
            inertia: Matrix3::new(0.0, 0.0, 0.0, 0.0, j, 0.0, 0.0, 0.0, 0.0),
            motion: PartMotion::Fixed {
                offset: Vector3::zeros(),
            },
            spin_ratio: 1.0,
        }];
        let omega = Vector3::new(0.0, 0.0, 2.0);
        let body = BodyKinematics {
            omega,
            ..BodyKinematics::at_rest(Vector3::zeros())
        };
        let crank = CrankDriveState {
            angle: 0.3,
            speed: 200.0,
            acceleration: 0.0,
            excitation: 1.0,
            spin: 200.0,
        };
        let mut d = BodyDynamics::zero();
        let moments = PartMoments::new(&parts);
        moments.add(&body, &crank, &Vector3::zeros(), &mut d);
        let expect = -omega.cross(&(Vector3::y() * (j * 200.0)));
        let got = Vector3::new(d.force[3], d.force[4], d.force[5]);
        assert!(
            (got - expect).norm() < 1e-9 * expect.norm(),
            "{got} vs {expect}"
        );
        // Without the gyroscopic effect the spin does not enter.
        let mut d0 = BodyDynamics::zero();
        moments.add(
            &body,
            &CrankDriveState { spin: 0.0, ..crank },
            &Vector3::zeros(),
            &mut d0,
        );
        assert!(Vector3::new(d0.force[3], d0.force[4], d0.force[5]).norm() < 1e-12);
    }

    #[test]
    fn composite_mass_matrix_is_symmetric_positive_definite_at_any_crank_angle() {
        let bodies = build_bodies(&EngineConfig::default(), &Effects::default());
        let rot = nalgebra::Rotation3::from_euler_angles(0.02, -0.03, 0.01).into_inner();
        for k in 0..12 {
            let crank = CrankDriveState::at_rest(0.5 * k as f64);
            let body = BodyKinematics {
                rotation: rot,
                ..BodyKinematics::at_rest(bodies[0].reference)
            };
            let mut d = BodyDynamics::zero();
            PartMoments::new(&bodies[0].parts).add(&body, &crank, &Vector3::zeros(), &mut d);
            assert!((d.mass - d.mass.transpose()).abs().max() < 1e-12);
            assert!(d.mass.cholesky().is_some());
        }
    }
}
