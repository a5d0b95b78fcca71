//! Jacobian `∂f/∂y` of the hybrid scene.
//!
//! The chassis columns (η, η̇) are exact: the right-hand side depends on them only through the
//! modal terms and the mount forces, whose derivatives the mount law returns (the housing rows
//! are accelerations, so they carry the housing's inverse mass matrix, which η does not change). The engine columns
//! (a few dozen) are central differences of the whole right-hand side, so every coupling of the
//! engine motion into the mounts and the chassis is included.

use faer::MatMut;
use nalgebra::Vector3;

use super::composite::BodyDynamics;
use super::hybrid_scene::HybridScene;
use crate::ode::{OdeProblem, ProblemError};

impl HybridScene {
    pub(crate) fn coupled_jacobian(
        &self,
        t: f64,
        y: &[f64],
        mut j: MatMut<'_, f64>,
    ) -> Result<(), ProblemError> {
        self.check_state(y)?;
        let n = self.dim();
        let ne = self.engine_dim();
        let m = self.modes_count();
        for r in 0..n {
            for c in 0..n {
                j[(r, c)] = 0.0;
            }
        }
        // Engine columns: central differences.
        let mut yp = y.to_vec();
        let mut fp = vec![0.0; n];
        let mut fm = vec![0.0; n];
        for c in 0..ne {
            let h = 1e-7 * y[c].abs().max(1.0);
            yp[c] = y[c] + h;
            let ev = self.evaluate(t, &yp);
            self.write_rhs(&yp, &ev, &mut fp)?;
            yp[c] = y[c] - h;
            let ev = self.evaluate(t, &yp);
            self.write_rhs(&yp, &ev, &mut fm)?;
            yp[c] = y[c];
            for r in 0..n {
                j[(r, c)] = (fp[r] - fm[r]) / (2.0 * h);
            }
        }
        // Chassis columns: exact.
        let ev = self.evaluate(t, y);
        let hb = self.engine().housing_index();
        let nb = self.engine().body_count();
        let housing_row = 6 * nb + 6 * hb;
        let h = &ev.engine.kinematics[hb];
        // The housing rows are accelerations: generalised forces premultiplied by M_h⁻¹.
        let housing_mass = ev.engine.dynamics[hb].mass.lu();
        let reference = self.engine().bodies()[hb].reference;
        let chassis = self.chassis();
        let (eta_row, rate_row) = (self.eta_index(), self.eta_rate_index());
        for k in 0..m {
            j[(eta_row + k, rate_row + k)] = 1.0;
            let w = chassis.omega[k];
            j[(rate_row + k, eta_row + k)] -= w * w;
            j[(rate_row + k, rate_row + k)] -= 2.0 * chassis.zeta[k] * w;
        }
        for (i, (mount, link)) in self.engine().mounts().iter().zip(self.links()).enumerate() {
            let (Some(mount), Some(p)) = (mount, link) else {
                continue;
            };
            let Some(r) = ev.engine.mounts[i] else {
                continue;
            };
            let x = h.point(&(mount.bracket - reference));
            let shape = &chassis.points[*p].shape;
            for k in 0..m {
                let phi_k = Vector3::new(shape[k][0], shape[k][1], shape[k][2]);
                // ∂F/∂η_k = −S φ_k and ∂F/∂η̇_k = −D φ_k (the attachment moves with η).
                for (col, df) in [
                    (eta_row + k, -(r.stiffness * phi_k)),
                    (rate_row + k, -(r.damping * phi_k)),
                ] {
                    let mut q = BodyDynamics::zero();
                    q.add_point_force(h, &x, &df);
                    let acc = housing_mass.solve(&q.force).ok_or_else(|| {
                        ProblemError::Fatal("singular housing mass matrix".into())
                    })?;
                    for a in 0..6 {
                        j[(housing_row + a, col)] += acc[a];
                    }
                    // The chassis receives −F at the node.
                    for (l, s) in shape.iter().enumerate() {
                        j[(rate_row + l, col)] -= s[0] * df.x + s[1] * df.y + s[2] * df.z;
                    }
                }
            }
        }
        Ok(())
    }
}
