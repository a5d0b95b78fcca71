//! The powertrain as one rigid body on its mounts, at its centre of mass: the quantities of the
//! mount-system design (Jeong & Singh, J. Sound Vib. 231 (2000)) — the 6×6 mass matrix, the
//! mounts' tangent stiffness at their operating points, the torque-roll axis and the mounts'
//! elastic axis for a torque about the crank.
//!
//! The decoupling table itself (kinetic energy of each mode over the six directions) comes from
//! the modes of the whole linearised model ([`super::Mode::centre_of_mass_directions`]); what is
//! here is what an independent 6×6 computation needs to check it.

use nalgebra::{Matrix3, Matrix6, Vector3, Vector6};

use super::evaluate::Mode;
use super::{CoupledModel, MountTarget};

/// `T` with `v_ref = T v_at` for the twist `[velocity, ω]` of a rigid body taken at two points
/// `r = ref − at` apart: `v_ref = v_at + ω × r`.
pub(super) fn shift(r: &Vector3<f64>) -> Matrix6<f64> {
    let mut t = Matrix6::identity();
    t.fixed_view_mut::<3, 3>(0, 3)
        .copy_from(&(-r.cross_matrix()));
    t
}

/// A line in space.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Axis {
    /// A point of the line (vehicle frame, m).
    pub point: Vector3<f64>,
    /// Unit direction.
    pub direction: Vector3<f64>,
}

/// One mount's tangent stiffness and damping at the operating point.
#[derive(Debug, Clone, PartialEq)]
pub struct MountStiffness {
    /// Configuration index (0-based; the FMU's `mount[index + 1]`).
    pub index: usize,
    /// The mount's name.
    pub name: String,
    /// Bracket position at the static equilibrium (vehicle frame, m).
    pub bracket: Vector3<f64>,
    /// What the far end is attached to: `None` ground (or an external body), else the body
    /// point's name.
    pub body_point: Option<String>,
    /// `∂F/∂(bracket − attachment)` of the force on the body, positive definite (N/m, vehicle
    /// axes), with the mount's stiffness scale.
    pub stiffness: Matrix3<f64>,
    /// The same for the relative velocity (N s/m), with the damping scale.
    pub damping: Matrix3<f64>,
    /// The static force on the body at the equilibrium (N, vehicle axes): turning with the
    /// powertrain, it adds the geometric stiffness `−[−F]× [x − c]×` that a 6×6 problem from
    /// the tangent stiffness alone leaves out.
    pub force: Vector3<f64>,
}

/// The powertrain as one rigid body on its mounts at the static equilibrium.
#[derive(Debug, Clone, PartialEq)]
pub struct RigidPowertrain {
    /// Centre of mass of all powertrain bodies (vehicle frame, m).
    pub centre_of_mass: Vector3<f64>,
    /// Mass matrix at the centre of mass for the twist `[velocity, ω]` (vehicle axes; kg, kg m²).
    pub mass: Matrix6<f64>,
    /// Every active mount.
    pub mounts: Vec<MountStiffness>,
    /// The mounts' stiffness at the centre of mass as if their far ends were held (N/m, N/rad,
    /// N m/rad).
    pub stiffness: Matrix6<f64>,
    /// The crank axis at the equilibrium (unit).
    pub crank_axis: Vector3<f64>,
    /// The axis the free body turns about under a torque about the crank axis: through the
    /// centre of mass along `J⁻¹ e_crank`.
    pub torque_roll_axis: Axis,
    /// The axis the body on its mounts turns about statically under a torque about the crank
    /// axis: the screw axis of `K⁻¹ [0, e_crank]`.
    pub elastic_axis: Axis,
}

impl RigidPowertrain {
    /// Angle between the torque-roll axis and the elastic axis (rad, 0..π/2).
    pub fn axis_angle(&self) -> f64 {
        self.torque_roll_axis
            .direction
            .dot(&self.elastic_axis.direction)
            .abs()
            .min(1.0)
            .acos()
    }

    /// Distance of the elastic axis from the centre of mass (m), which the torque-roll axis
    /// passes through.
    pub fn axis_offset(&self) -> f64 {
        let d = self.centre_of_mass - self.elastic_axis.point;
        (d - self.elastic_axis.direction * d.dot(&self.elastic_axis.direction)).norm()
    }
}

/// The centre of mass `c` of a body whose 6×6 mass matrix at point `at` is `m`: its
/// translation-rotation block is `−m [c − at]×`.
fn centre_of_mass(m: &Matrix6<f64>, at: &Vector3<f64>) -> Vector3<f64> {
    let mass = m[(0, 0)];
    let s = -m.fixed_view::<3, 3>(0, 3).into_owned() / mass;
    let s = 0.5 * (s - s.transpose());
    at + Vector3::new(s[(2, 1)], s[(0, 2)], s[(1, 0)])
}

impl CoupledModel {
    /// Each powertrain body's mass matrix at its reference point and that point's position, at
    /// `y` with the engine at rest.
    pub(super) fn body_masses(&self, y: &[f64]) -> Vec<(Matrix6<f64>, Vector3<f64>)> {
        let ev = self.evaluate_mode(self.fade_start, y, Mode::AT_REST);
        ev.dynamics
            .iter()
            .zip(&ev.kinematics)
            .map(|(d, k)| (d.mass, k.position))
            .collect()
    }

    /// The common centre of mass of bodies given as [`Self::body_masses`].
    pub(super) fn common_centre_of_mass(masses: &[(Matrix6<f64>, Vector3<f64>)]) -> Vector3<f64> {
        let total: f64 = masses.iter().map(|(m, _)| m[(0, 0)]).sum();
        masses
            .iter()
            .map(|(m, at)| centre_of_mass(m, at) * m[(0, 0)])
            .sum::<Vector3<f64>>()
            / total
    }

    /// The powertrain as one rigid body on its mounts at the static equilibrium `y_eq`.
    pub fn rigid_powertrain(&self, y_eq: &[f64]) -> Result<RigidPowertrain, String> {
        self.check_state(y_eq).map_err(|e| format!("{e:?}"))?;
        let masses = self.body_masses(y_eq);
        let cg = Self::common_centre_of_mass(&masses);
        let mass = masses.iter().fold(Matrix6::zeros(), |sum, (m, at)| {
            let t = shift(&(at - cg));
            sum + t.transpose() * m * t
        });
        let ev = self.evaluate_mode(self.fade_start, y_eq, Mode::AT_REST);
        let hb = self.powertrain.housing_index();
        let housing = &ev.kinematics[hb];
        let reference = self.powertrain.bodies()[hb].reference;
        let mut mounts = Vec::new();
        let mut stiffness = Matrix6::zeros();
        for (i, (m, r)) in self.mounts.iter().zip(&ev.mounts).enumerate() {
            let (Some(m), Some(r)) = (m, r) else { continue };
            let bracket = housing.point(&(m.mount.bracket - reference));
            let k = -r.stiffness();
            // Bracket displacement of the body's twist at the centre of mass: u − [x − c]× θ.
            let mut g = nalgebra::Matrix3x6::zeros();
            g.fixed_view_mut::<3, 3>(0, 0)
                .copy_from(&Matrix3::identity());
            g.fixed_view_mut::<3, 3>(0, 3)
                .copy_from(&(-(bracket - cg).cross_matrix()));
            stiffness += g.transpose() * k * g;
            mounts.push(MountStiffness {
                index: i,
                name: m.mount.name.clone(),
                bracket,
                body_point: match m.target {
                    MountTarget::BodyPoint(p) => Some(self.body.points[p].name.clone()),
                    MountTarget::Ground | MountTarget::External => None,
                },
                stiffness: k,
                damping: -r.damping(),
                force: -r.force,
            });
        }
        let crank_axis = ev.kinematics[0].rotation * Vector3::y();
        let inertia = mass.fixed_view::<3, 3>(3, 3).into_owned();
        let roll = inertia
            .try_inverse()
            .ok_or("the powertrain's inertia tensor is singular")?
            * crank_axis;
        let torque = Vector6::new(0.0, 0.0, 0.0, crank_axis.x, crank_axis.y, crank_axis.z);
        let x = stiffness
            .cholesky()
            .ok_or("the mounts do not hold the powertrain in every direction (K is singular)")?
            .solve(&torque);
        let (u, theta) = (x.fixed_rows::<3>(0), x.fixed_rows::<3>(3));
        let (u, theta) = (Vector3::from(u), Vector3::from(theta));
        Ok(RigidPowertrain {
            centre_of_mass: cg,
            mass,
            mounts,
            stiffness,
            crank_axis,
            torque_roll_axis: Axis {
                point: cg,
                direction: roll.normalize(),
            },
            elastic_axis: Axis {
                point: cg + theta.cross(&u) / theta.norm_squared(),
                direction: theta.normalize(),
            },
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_centre_of_mass_of_a_shifted_point_mass_is_found_again() {
        // A 3 kg point at c: its mass matrix at `at` is Tᵀ diag(m, m, m, 0, 0, 0) T with
        // T = shift(c − at).
        let c = Vector3::new(0.3, -0.2, 0.5);
        let at = Vector3::new(-0.1, 0.4, 0.2);
        let mut m0 = Matrix6::zeros();
        for i in 0..3 {
            m0[(i, i)] = 3.0;
        }
        let t = shift(&(c - at));
        let m_at = t.transpose() * m0 * t;
        assert!((centre_of_mass(&m_at, &at) - c).norm() < 1e-14);
    }

    #[test]
    fn a_shifted_twist_moves_points_alike() {
        // The velocity of a point p from the twist at a and from the twist shifted to b agree.
        let (a, b, p) = (
            Vector3::new(0.1, 0.2, 0.3),
            Vector3::new(-0.4, 0.0, 0.9),
            Vector3::new(1.0, -1.0, 0.5),
        );
        let twist_b = Vector6::new(0.3, -0.1, 0.2, 0.5, 0.7, -0.2);
        let twist_a = shift(&(a - b)) * twist_b;
        let at = |t: &Vector6<f64>, o: &Vector3<f64>| {
            Vector3::new(t[0], t[1], t[2]) + Vector3::new(t[3], t[4], t[5]).cross(&(p - o))
        };
        assert!((at(&twist_a, &a) - at(&twist_b, &b)).norm() < 1e-15);
    }
}
