//! How the outputs respond at once to the motion of an external body at the mounts (scene 3):
//! the partial derivatives a co-simulation master needs to couple the engine to a body stably
//! (`fmi2GetDirectionalDerivative`).
//!
//! With the state held, a mount's force depends on its attachment's displacement and velocity
//! through the tangent stiffness and damping of its characteristic at the current deflection,
//! and the housing's acceleration on the mount forces through the housing's mass matrix. Both
//! are exact derivatives of what [`CoupledModel::outputs`] computes.

use nalgebra::{Matrix3, Vector3};

use super::evaluate::Mode;
use super::{CoupledModel, MountTarget};
use crate::ode::ProblemError;

/// The instantaneous response to one mount's attachment motion.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MountSensitivity {
    /// `∂F/∂u`: force of the mount on the body per attachment displacement (N/m, vehicle axes).
    pub force_per_displacement: Matrix3<f64>,
    /// `∂F/∂v`: force on the body per attachment velocity (N s/m).
    pub force_per_velocity: Matrix3<f64>,
    /// Acceleration of the housing's reference point (the `powertrain.a` output) per unit
    /// force of this mount on the body (1/kg).
    pub housing_acceleration_per_force: Matrix3<f64>,
}

impl CoupledModel {
    /// Per configured mount on an external body, its [`MountSensitivity`] at `(t, y)`;
    /// `None` for a removed mount or one on ground or the model's own body.
    pub fn interface_sensitivities(
        &self,
        t: f64,
        y: &[f64],
    ) -> Result<Vec<Option<MountSensitivity>>, ProblemError> {
        self.check_state(y)?;
        let ev = self.evaluate_mode(t, y, Mode::RUNNING);
        let hb = self.powertrain.housing_index();
        let housing = &ev.kinematics[hb];
        let mass = &ev.dynamics[hb].mass;
        let solve = |q: nalgebra::Vector6<f64>| {
            mass.cholesky()
                .map(|c| c.solve(&q))
                .or_else(|| mass.lu().solve(&q))
                .ok_or_else(|| ProblemError::Fatal("singular housing mass matrix".into()))
        };
        let reference = self.powertrain.bodies()[hb].reference;
        let point = self.powertrain.housing_reference();
        let arm = housing.rotation * (point - reference);
        let mut out = Vec::with_capacity(self.mounts.len());
        for (m, r) in self.mounts.iter().zip(&ev.mounts) {
            let (Some(m), Some(r)) = (m, r) else {
                out.push(None);
                continue;
            };
            if m.target != MountTarget::External {
                out.push(None);
                continue;
            }
            let x = housing.point(&(m.mount.bracket - reference));
            // The force on the bracket is −F (F: on the body): a unit F along axis c acts on the
            // housing as −e_c at x.
            let mut per_force = Matrix3::zeros();
            for c in 0..3 {
                let f = -Vector3::ith(c, 1.0);
                let moment = (x - housing.position).cross(&f);
                let q = nalgebra::Vector6::new(f.x, f.y, f.z, moment.x, moment.y, moment.z);
                let acc = solve(q)?;
                let a0 = Vector3::new(acc[0], acc[1], acc[2]);
                let alpha = Vector3::new(acc[3], acc[4], acc[5]);
                per_force.set_column(c, &(a0 + alpha.cross(&arm)));
            }
            // F = −force(rel), rel = x − attachment − u: ∂F/∂u = ∂force/∂rel.
            out.push(Some(MountSensitivity {
                force_per_displacement: r.stiffness(),
                force_per_velocity: r.damping(),
                housing_acceleration_per_force: per_force,
            }));
        }
        Ok(out)
    }
}
