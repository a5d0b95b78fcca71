//! Assembled Jacobian `∂f/∂y` of the ground scene.
//!
//! Assembled block by block, each block from what it depends on:
//! - kinematic rows (`u' = v`, `θ' = G(θ)⁻¹ ω`, `φ' = ω_c − e·ω`): analytic,
//! - mounts (the elements that later couple to the chassis): analytic, from the force law's
//!   stiffness and damping and the exact point kinematics,
//! - everything local to one body (parts with gravity and inertia terms, gas, load torque):
//!   central differences of that body's contribution in its own 12 coordinates and the crank angle,
//! - ring carriers: central differences of the element alone in the 24 coordinates it couples.
//!
//! So a full Jacobian costs about as much as one finite-difference Jacobian of the whole right-hand
//! side, but the stiff mount terms are exact and nothing is differentiated across elements.

use faer::MatMut;
use nalgebra::{Matrix3, SMatrix, Vector3, Vector6};

use super::composite::BodyDynamics;
use super::ground_scene::{GroundScene, Mode};
use super::rotation::{angular_velocity_map, skew};
use crate::ode::ProblemError;

const STEP: f64 = 1e-7;

/// `∂G/∂θ_k` of the Cardan angular-velocity map.
fn d_angular_velocity_map(theta: &Vector3<f64>, k: usize) -> Matrix3<f64> {
    let (sa, ca) = theta.x.sin_cos();
    let (sb, cb) = theta.y.sin_cos();
    match k {
        0 => Matrix3::new(0.0, 0.0, 0.0, 0.0, -sa, -ca * cb, 0.0, ca, -sa * cb),
        1 => Matrix3::new(0.0, 0.0, cb, 0.0, 0.0, sa * sb, 0.0, 0.0, -ca * sb),
        _ => Matrix3::zeros(),
    }
}

impl GroundScene {
    /// Writes `∂f/∂y` at `(t, y)` into `j` (dimension `dim × dim`).
    pub fn assembled_jacobian(
        &self,
        t: f64,
        y: &[f64],
        mut j: MatMut<'_, f64>,
    ) -> Result<(), ProblemError> {
        let nb = self.body_count();
        let n = 12 * nb + 1;
        let ic = self.crank_index();
        self.check_state(y)?;
        if j.nrows() != n || j.ncols() != n {
            return Err(ProblemError::Fatal(format!(
                "Jacobian is {}×{}, the engine model has {n} states",
                j.nrows(),
                j.ncols()
            )));
        }
        for r in 0..n {
            for c in 0..n {
                j[(r, c)] = 0.0;
            }
        }
        let kin: Vec<_> = (0..nb).map(|b| self.kinematics(y, b)).collect();
        // Kinematic rows.
        for (b, kb) in kin.iter().enumerate() {
            let (q, v) = (6 * b, 6 * nb + 6 * b);
            for i in 0..3 {
                j[(q + i, v + i)] = 1.0;
            }
            let theta = Vector3::new(y[q + 3], y[q + 4], y[q + 5]);
            let g_inv = angular_velocity_map(&theta)
                .try_inverse()
                .ok_or_else(|| ProblemError::Recoverable("Cardan singularity".into()))?;
            let rates = g_inv * kb.omega;
            for k in 0..3 {
                let col = -(g_inv * d_angular_velocity_map(&theta, k) * rates);
                for i in 0..3 {
                    j[(q + 3 + i, q + 3 + k)] = col[i];
                    j[(q + 3 + i, v + 3 + k)] = g_inv[(i, k)];
                }
            }
        }
        // Crank row: φ' = ω_c − e·ω with δe = −[e]× G δθ.
        {
            let e = kin[0].rotation * Vector3::y();
            let theta = Vector3::new(y[3], y[4], y[5]);
            let d_theta = kin[0].omega.transpose() * skew(&e) * angular_velocity_map(&theta);
            for k in 0..3 {
                j[(ic, 6 * nb + 3 + k)] = -e[k];
                j[(ic, 3 + k)] = d_theta[k];
            }
        }
        // Body-local contributions by central differences.
        for b in 0..nb {
            let rows = 6 * nb + 6 * b;
            let mut cols: Vec<usize> = (0..6)
                .map(|i| 6 * b + i)
                .chain((0..6).map(|i| 6 * nb + 6 * b + i))
                .collect();
            cols.push(ic);
            for &c in &cols {
                let local = |yy: &[f64]| {
                    self.local_dynamics(t, yy, &self.kinematics(yy, b), b, Mode::RUNNING)
                        .force
                };
                let d = self.central(y, c, local);
                for i in 0..6 {
                    j[(rows + i, c)] += d[i];
                }
            }
        }
        // Ring carriers by central differences of the element alone.
        if nb == 2 {
            for c in 0..24 {
                let col = c;
                let force = |yy: &[f64]| {
                    let k: Vec<_> = (0..2).map(|b| self.kinematics(yy, b)).collect();
                    let mut d = vec![BodyDynamics::zero(); 2];
                    self.add_ring_carriers(&k, &mut d);
                    let mut out = SMatrix::<f64, 12, 1>::zeros();
                    for i in 0..6 {
                        out[i] = d[0].force[i];
                        out[6 + i] = d[1].force[i];
                    }
                    out
                };
                let h = STEP;
                let mut yp = y.to_vec();
                yp[col] += h;
                let mut ym = y.to_vec();
                ym[col] -= h;
                let d = (force(&yp) - force(&ym)) / (2.0 * h);
                for i in 0..12 {
                    j[(6 * nb + i, col)] += d[i];
                }
            }
        }
        // Mounts: analytic.
        let hb = self.housing_index();
        let h = &kin[hb];
        let theta = Vector3::new(y[6 * hb + 3], y[6 * hb + 4], y[6 * hb + 5]);
        let g = angular_velocity_map(&theta);
        let ev_mounts = self.evaluate(t, y).mounts;
        for (m, resp) in self.mounts().iter().zip(&ev_mounts) {
            let (Some(m), Some(resp)) = (m, resp) else {
                continue;
            };
            let r = h.rotation * (m.bracket - self.bodies()[hb].reference);
            let rx = skew(&r);
            let dr_dtheta = -rx * g;
            // ∂F/∂q and ∂F/∂v (3×6 each).
            let mut df_dq = SMatrix::<f64, 3, 6>::zeros();
            df_dq
                .fixed_view_mut::<3, 3>(0, 0)
                .copy_from(&resp.stiffness);
            df_dq.fixed_view_mut::<3, 3>(0, 3).copy_from(
                &(resp.stiffness * dr_dtheta + resp.damping * skew(&h.omega) * dr_dtheta),
            );
            let mut df_dv = SMatrix::<f64, 3, 6>::zeros();
            df_dv.fixed_view_mut::<3, 3>(0, 0).copy_from(&resp.damping);
            df_dv
                .fixed_view_mut::<3, 3>(0, 3)
                .copy_from(&(-resp.damping * rx));
            // Generalised force [F; r × F].
            let fx = skew(&resp.force);
            let mut dq_dq = SMatrix::<f64, 6, 6>::zeros();
            dq_dq.fixed_view_mut::<3, 6>(0, 0).copy_from(&df_dq);
            let mut rot = rx * df_dq;
            let extra = -fx * dr_dtheta;
            for a in 0..3 {
                for c in 0..3 {
                    rot[(a, 3 + c)] += extra[(a, c)];
                }
            }
            dq_dq.fixed_view_mut::<3, 6>(3, 0).copy_from(&rot);
            let mut dq_dv = SMatrix::<f64, 6, 6>::zeros();
            dq_dv.fixed_view_mut::<3, 6>(0, 0).copy_from(&df_dv);
            dq_dv.fixed_view_mut::<3, 6>(3, 0).copy_from(&(rx * df_dv));
            let rows = 6 * nb + 6 * hb;
            for a in 0..6 {
                for c in 0..6 {
                    j[(rows + a, 6 * hb + c)] += dq_dq[(a, c)];
                    j[(rows + a, 6 * nb + 6 * hb + c)] += dq_dv[(a, c)];
                }
            }
        }
        if (0..n).any(|r| (0..n).any(|c| !j[(r, c)].is_finite())) {
            return Err(ProblemError::NonFinite);
        }
        Ok(())
    }

    fn central(&self, y: &[f64], c: usize, f: impl Fn(&[f64]) -> Vector6<f64>) -> Vector6<f64> {
        let mut yp = y.to_vec();
        yp[c] += STEP;
        let mut ym = y.to_vec();
        ym[c] -= STEP;
        (f(&yp) - f(&ym)) / (2.0 * STEP)
    }
}
