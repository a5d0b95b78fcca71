//! Jacobian `∂f/∂y` of the coupled model, and the Newton strategy that follows from its
//! structure: `J = blockdiag(J_engine, J_mode 1, …, J_mode m) + U Vᵀ`
//! ([`BlockLowRankJacobian`]).
//!
//! - The engine block (the powertrain's states, [`super::StateLayout::engine`]) is a forward
//!   difference of the engine rows; it contains the stiffness of every mount on the powertrain
//!   side, so it is the powertrain on its mounts, not a free body.
//! - Each body mode is the exact 2×2 block `[[0, 1], [−ω², −2ζω]]` on `(η_k, η̇_k)`.
//! - Everything that couples the powertrain and the body, or one mode to another, passes through
//!   the forces `F_p` of the mounts attached to body points (3 per mount). With
//!   `R_c = ∂F/∂(η, η̇)` (exact: the attachment moves with `φ_p`, so `∂F/∂η_k = −S_p φ_{p,k}`,
//!   `∂F/∂η̇_k = −D_p φ_{p,k}`), `R_e = ∂F/∂y_engine` (forward differences, taken with the
//!   engine block), `H = ∂(housing acceleration)/∂F` (`M_h⁻¹` times the point-force map) and
//!   `B = ∂η̈/∂F = −Φᵀ`: `J_engine,body = H R_c`, `J_body,body += B R_c`, `J_body,engine = B R_e`.
//!   So `U = [[H, 0], [B, B]]` and `Vᵀ = [[0, R_c], [R_e, 0]]`: rank 6 per body mount, whatever
//!   the number of modes.
//!
//! Strategy: without body modes (rigid ground) the Jacobian is the engine block alone and the
//! integrator factorises it densely; with modes it never forms an `n × n` matrix and solves by
//! the Woodbury identity.

use faer::MatMut;
use nalgebra::Vector3;

use super::evaluate::{Evaluation, Mode};
use super::CoupledModel;
use crate::model::powertrain::composite::BodyDynamics;
use crate::ode::{BlockLowRankJacobian, BlockLowRankShape, ProblemError};

impl CoupledModel {
    /// Whether the integrator gets the block-diagonal plus low-rank Newton matrix (the body has
    /// modes and no dense comparison was asked for).
    pub fn uses_block_low_rank(&self) -> bool {
        self.layout.modes() > 0 && !self.dense_newton
    }

    /// The shape of [`Self::structured`]: the engine block, one 2×2 block per mode, rank 6 per
    /// mount attached to the body.
    pub fn jacobian_shape(&self) -> BlockLowRankShape {
        let l = &self.layout;
        let mut blocks = vec![l.engine().collect::<Vec<_>>()];
        let (eta, rate) = (l.eta().start, l.eta_rate().start);
        blocks.extend((0..l.modes()).map(|k| vec![eta + k, rate + k]));
        BlockLowRankShape {
            blocks,
            rank: 6 * self.body_mounts().count(),
        }
    }

    /// Writes `∂f/∂y` at `(t, y)` into `j` (shaped by [`Self::jacobian_shape`], zeroed).
    ///
    /// Long on purpose: one pass over the block structure (powertrain, mounts, body), one short section per block.
    pub fn structured(
        &self,
        t: f64,
        y: &[f64],
        j: &mut BlockLowRankJacobian,
    ) -> Result<(), ProblemError> {
        self.check_state(y)?;
        let l = self.layout;
        if j.shape().blocks.len() != 1 + l.modes() || j.dim() != y.len() {
            return Err(ProblemError::Fatal(
                "the Jacobian storage does not have the coupled model's shape".into(),
            ));
        }
        let ne = l.engine_dim();
        let n_links = self.body_mounts().count();
        let mount_force = |ev: &Evaluation, i: usize| {
            ev.mounts[i].map(|r| r.force).unwrap_or_else(Vector3::zeros)
        };

        // Engine block and R_e: forward differences of the engine rows and the mount forces (a
        // Newton matrix needs no more than the square root of the working precision).
        let ev = self.evaluate(t, y);
        let mut f0 = vec![0.0; y.len()];
        self.write_rhs(t, y, &ev, Mode::RUNNING, &mut f0)?;
        let mut yp = y.to_vec();
        let mut fp = vec![0.0; y.len()];
        for c in 0..ne {
            let h = f64::EPSILON.sqrt() * y[c].abs().max(1.0);
            yp[c] = y[c] + h;
            let h = yp[c] - y[c];
            let ev_p = self.evaluate(t, &yp);
            self.write_rhs(t, &yp, &ev_p, Mode::RUNNING, &mut fp)?;
            yp[c] = y[c];
            let mut block = j.block_mut(0);
            for r in 0..ne {
                block[(r, c)] = (fp[r] - f0[r]) / h;
            }
            let mut v = j.v_mut();
            for (a, (i, _, _)) in self.body_mounts().enumerate() {
                let df = (mount_force(&ev_p, i) - mount_force(&ev, i)) / h;
                for d in 0..3 {
                    v[(c, 3 * n_links + 3 * a + d)] = df[d];
                }
            }
        }

        // Modal blocks.
        for k in 0..l.modes() {
            let w = self.body.omega[k];
            let mut b = j.block_mut(1 + k);
            b[(0, 1)] = 1.0;
            b[(1, 0)] = -w * w;
            b[(1, 1)] = -2.0 * self.body.zeta[k] * w;
        }

        // Coupling through the mount forces: H, B, R_c.
        let hb = self.powertrain.housing_index();
        let housing_row = l.v(hb).start;
        let (eta_row, rate_row) = (l.eta().start, l.eta_rate().start);
        let h = &ev.kinematics[hb];
        let housing_mass = ev.dynamics[hb].mass.lu();
        let reference = self.powertrain.bodies()[hb].reference;
        for (a, (i, mount, p)) in self.body_mounts().enumerate() {
            let Some(r) = ev.mounts[i] else {
                continue;
            };
            let x = h.point(&(mount.bracket - reference));
            let shape = &self.body.points[p].shape;
            let (stiffness, damping) = (r.stiffness(), r.damping());
            for d in 0..3 {
                let (c_body, c_engine) = (3 * a + d, 3 * n_links + 3 * a + d);
                let mut unit = Vector3::zeros();
                unit[d] = 1.0;
                let mut q = BodyDynamics::zero();
                q.add_point_force(h, &x, &unit);
                let acc = housing_mass
                    .solve(&q.force)
                    .ok_or_else(|| ProblemError::Fatal("singular housing mass matrix".into()))?;
                let mut u = j.u_mut();
                for e in 0..6 {
                    u[(housing_row + e, c_body)] = acc[e];
                }
                for (k, s) in shape.iter().enumerate() {
                    u[(rate_row + k, c_body)] = -s[d];
                    u[(rate_row + k, c_engine)] = -s[d];
                }
                let mut v = j.v_mut();
                for (k, s) in shape.iter().enumerate() {
                    let phi = Vector3::new(s[0], s[1], s[2]);
                    v[(eta_row + k, c_body)] = -(stiffness * phi)[d];
                    v[(rate_row + k, c_body)] = -(damping * phi)[d];
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
        let mut j = BlockLowRankJacobian::new(self.jacobian_shape());
        self.structured(t, y, &mut j)?;
        j.to_dense(out);
        Ok(())
    }
}
