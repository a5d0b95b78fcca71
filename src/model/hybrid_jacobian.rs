//! Jacobian `∂f/∂y` of the hybrid scene in block-diagonal plus low-rank form
//! ([`BlockLowRankJacobian`]): `J = blockdiag(J_engine, J_mode 1, …, J_mode m) + U Vᵀ`.
//!
//! - The engine block (a few dozen states) is a forward difference of the engine rows.
//! - Each chassis mode is the exact 2×2 block `[[0, 1], [−ω², −2ζω]]` on `(η_k, η̇_k)`.
//! - Everything that couples engine and chassis, or one mode to another, passes through the
//!   mount forces `F_p` (3 per connected mount). With `R_c = ∂F/∂(η, η̇)` (exact: the attachment
//!   moves with `φ_p`, so `∂F/∂η_k = −S_p φ_{p,k}`, `∂F/∂η̇_k = −D_p φ_{p,k}`), `R_e = ∂F/∂y_engine`
//!   (forward differences, taken with the engine block), `H = ∂(housing acceleration)/∂F`
//!   (`M_h⁻¹` times the point-force map) and `B = ∂η̈/∂F = −Φᵀ`:
//!   `J_engine,chassis = H R_c`, `J_chassis,chassis += B R_c`, `J_chassis,engine = B R_e`.
//!   So `U = [[H, 0], [B, B]]` and `Vᵀ = [[0, R_c], [R_e, 0]]`: rank 6 per connected mount,
//!   whatever the number of modes. (`H R_e`, the engine's own mount stiffness, stays inside the
//!   engine block, which therefore is the engine on mounts, not a free body.)

use faer::MatMut;
use nalgebra::Vector3;

use super::composite::BodyDynamics;
use super::hybrid_scene::HybridScene;
use crate::ode::{BlockLowRankJacobian, BlockLowRankShape, ProblemError};

impl HybridScene {
    /// The shape of [`Self::coupled_jacobian`]: the engine block, one 2×2 block per mode.
    pub fn coupled_jacobian_shape(&self) -> BlockLowRankShape {
        let ne = self.engine_dim();
        let m = self.modes_count();
        let mut blocks = vec![(0..ne).collect::<Vec<_>>()];
        blocks.extend((0..m).map(|k| vec![ne + k, ne + m + k]));
        BlockLowRankShape {
            blocks,
            rank: 6 * self.connected_mounts().count(),
        }
    }

    /// Writes `∂f/∂y` at `(t, y)` into `j` (shaped by [`Self::coupled_jacobian_shape`], zeroed).
    pub fn coupled_jacobian(
        &self,
        t: f64,
        y: &[f64],
        j: &mut BlockLowRankJacobian,
    ) -> Result<(), ProblemError> {
        self.check_state(y)?;
        if j.shape().blocks.len() != 1 + self.modes_count() || j.dim() != y.len() {
            return Err(ProblemError::Fatal(
                "the Jacobian storage does not have the hybrid scene's shape".into(),
            ));
        }
        let ne = self.engine_dim();
        let m = self.modes_count();
        let (eta_row, rate_row) = (self.eta_index(), self.eta_rate_index());
        let n_links = self.connected_mounts().count();
        let mount_force = |ev: &super::hybrid_scene::HybridEvaluation, i: usize| {
            ev.engine.mounts[i]
                .map(|r| r.force)
                .unwrap_or_else(Vector3::zeros)
        };

        // Engine block and R_e: forward differences of the engine rows and the mount forces (a
        // Newton matrix needs no more than the square root of the working precision).
        let ev = self.evaluate(t, y);
        let mut f0 = vec![0.0; y.len()];
        self.write_rhs(y, &ev, &mut f0)?;
        let mut yp = y.to_vec();
        let mut fp = vec![0.0; y.len()];
        for c in 0..ne {
            let h = f64::EPSILON.sqrt() * y[c].abs().max(1.0);
            yp[c] = y[c] + h;
            let h = yp[c] - y[c];
            let ev_p = self.evaluate(t, &yp);
            self.write_rhs(&yp, &ev_p, &mut fp)?;
            yp[c] = y[c];
            let mut block = j.block_mut(0);
            for r in 0..ne {
                block[(r, c)] = (fp[r] - f0[r]) / h;
            }
            let mut v = j.v_mut();
            for (a, (i, _, _)) in self.connected_mounts().enumerate() {
                let df = (mount_force(&ev_p, i) - mount_force(&ev, i)) / h;
                for d in 0..3 {
                    v[(c, 3 * n_links + 3 * a + d)] = df[d];
                }
            }
        }

        // Modal blocks.
        let chassis = self.chassis();
        for k in 0..m {
            let w = chassis.omega[k];
            let mut b = j.block_mut(1 + k);
            b[(0, 1)] = 1.0;
            b[(1, 0)] = -w * w;
            b[(1, 1)] = -2.0 * chassis.zeta[k] * w;
        }

        // Coupling through the mount forces: H, B, R_c.
        let hb = self.engine().housing_index();
        let housing_row = 6 * self.engine().body_count() + 6 * hb;
        let h = &ev.engine.kinematics[hb];
        let housing_mass = ev.engine.dynamics[hb].mass.lu();
        let reference = self.engine().bodies()[hb].reference;
        for (a, (i, mount, p)) in self.connected_mounts().enumerate() {
            let Some(r) = ev.engine.mounts[i] else {
                continue;
            };
            let x = h.point(&(mount.bracket - reference));
            let shape = &chassis.points[p].shape;
            for d in 0..3 {
                let (c_chassis, c_engine) = (3 * a + d, 3 * n_links + 3 * a + d);
                let mut unit = Vector3::zeros();
                unit[d] = 1.0;
                let mut q = BodyDynamics::zero();
                q.add_point_force(h, &x, &unit);
                let acc = housing_mass
                    .solve(&q.force)
                    .ok_or_else(|| ProblemError::Fatal("singular housing mass matrix".into()))?;
                let mut u = j.u_mut();
                for e in 0..6 {
                    u[(housing_row + e, c_chassis)] = acc[e];
                }
                for (k, s) in shape.iter().enumerate() {
                    u[(rate_row + k, c_chassis)] = -s[d];
                    u[(rate_row + k, c_engine)] = -s[d];
                }
                let mut v = j.v_mut();
                for (k, s) in shape.iter().enumerate() {
                    let phi = Vector3::new(s[0], s[1], s[2]);
                    v[(eta_row + k, c_chassis)] = -(r.stiffness * phi)[d];
                    v[(rate_row + k, c_chassis)] = -(r.damping * phi)[d];
                }
            }
        }
        Ok(())
    }

    /// The same Jacobian as a dense matrix (`dim × dim`).
    pub fn dense_jacobian(
        &self,
        t: f64,
        y: &[f64],
        out: MatMut<'_, f64>,
    ) -> Result<(), ProblemError> {
        let mut j = BlockLowRankJacobian::new(self.coupled_jacobian_shape());
        self.coupled_jacobian(t, y, &mut j)?;
        j.to_dense(out);
        Ok(())
    }
}
