//! Static equilibrium of the engine on its mounts (gravity, preloads, mean load torque) by Newton.

use faer::linalg::solvers::Solve;
use faer::Mat;

use super::ground_scene::{GroundScene, StaticsError};
use crate::ode::OdeProblem;

/// Newton iteration limits.
const MAX_ITERATIONS: usize = 60;
/// Largest translation (m) and rotation (rad) per Newton step; keeps the iteration on the curve
/// branch it starts from instead of jumping across bump stops.
const MAX_STEP: [f64; 2] = [0.002, 0.02];

/// Why [`damped_newton`] stopped without a solution.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum NewtonFailure {
    /// The residual norm became NaN or infinite.
    NonFinite(f64),
    /// The tangent stiffness could not be solved.
    Singular,
    /// The iteration limit was reached with this residual norm.
    NotConverged(f64),
}

/// Newton on `residual(x) = 0` with a central-difference tangent and a damped step: the whole
/// step is scaled so that no component `i` moves more than `limit(i)` (None: unlimited). Shared by
/// the ground and the hybrid statics; `x` holds the last iterate on return.
pub(crate) fn damped_newton(
    x: &mut [f64],
    tol: f64,
    max_iterations: usize,
    limit: impl Fn(usize) -> Option<f64>,
    mut residual: impl FnMut(&[f64]) -> Vec<f64>,
) -> Result<(), NewtonFailure> {
    let n = x.len();
    let mut last = f64::INFINITY;
    for _ in 0..max_iterations {
        let r = residual(x);
        let norm = r.iter().map(|v| v * v).sum::<f64>().sqrt();
        if !norm.is_finite() {
            return Err(NewtonFailure::NonFinite(norm));
        }
        last = norm;
        if norm < tol {
            return Ok(());
        }
        let mut k = Mat::<f64>::zeros(n, n);
        for j in 0..n {
            let h = 1e-7;
            let mut xp = x.to_vec();
            xp[j] += h;
            let mut xm = x.to_vec();
            xm[j] -= h;
            let (rp, rm) = (residual(&xp), residual(&xm));
            for i in 0..n {
                k[(i, j)] = (rp[i] - rm[i]) / (2.0 * h);
            }
        }
        let mut rhs = Mat::<f64>::zeros(n, 1);
        for i in 0..n {
            rhs[(i, 0)] = -r[i];
        }
        k.partial_piv_lu().solve_in_place(rhs.as_mut());
        let mut scale: f64 = 1.0;
        for i in 0..n {
            let d = rhs[(i, 0)];
            if !d.is_finite() {
                return Err(NewtonFailure::Singular);
            }
            if let Some(limit) = limit(i) {
                if d.abs() > limit {
                    scale = scale.min(limit / d.abs());
                }
            }
        }
        for i in 0..n {
            x[i] += scale * rhs[(i, 0)];
        }
    }
    Err(NewtonFailure::NotConverged(last))
}

impl GroundScene {
    /// Solves the static equilibrium (crank at rest at the configured start angle, no gas) under
    /// gravity, mount preloads and the current load torque, sets the operating point of the
    /// linearised mounts and the excitation fade-in start `t0`, and returns the initial state.
    ///
    /// Fails with a message when Newton does not converge or a mount is pressed beyond its curve
    /// (mounts too soft to carry the weight).
    pub fn static_equilibrium(&mut self, t0: f64) -> Result<Vec<f64>, StaticsError> {
        self.set_fade_start(t0).map_err(|e| StaticsError(e.0))?;
        let nb = self.body_count();
        let nq = 6 * nb;
        let mut y = self.reference_state();
        let weight: f64 = self
            .bodies()
            .iter()
            .flat_map(|b| b.parts.iter())
            .map(|p| p.mass)
            .sum::<f64>()
            * self.config().gravity;
        let tol = 1e-9 * weight.max(1.0);
        let limit = |i: usize| Some(MAX_STEP[(i % 6) / 3]);
        let at_rest = y.clone();
        match damped_newton(&mut y[..nq], tol, MAX_ITERATIONS, limit, |q| {
            let mut full = at_rest.clone();
            full[..nq].copy_from_slice(q);
            self.static_residual(&full)
        }) {
            Ok(()) => {}
            Err(NewtonFailure::NonFinite(norm)) => {
                return Err(StaticsError(format!("residual became {norm}")))
            }
            Err(NewtonFailure::Singular) => return Err(StaticsError(
                "the tangent stiffness is singular: the mounts do not hold the powertrain in every direction".into(),
            )),
            Err(NewtonFailure::NotConverged(last)) => return Err(StaticsError(format!(
                "Newton did not converge in {MAX_ITERATIONS} iterations (residual {last:.3e} N, tolerance {tol:.3e} N); the mounts may be too soft to carry the weight"
            ))),
        }
        self.check_mount_range(&y)?;
        self.set_operating_point(&y);
        debug_assert_eq!(y.len(), self.dim());
        Ok(y)
    }

    fn check_mount_range(&self, y: &[f64]) -> Result<(), StaticsError> {
        let hb = self.housing_index();
        let h = self.kinematics(y, hb);
        let reference = self.bodies()[hb].reference;
        for (i, m) in self.mounts().iter().enumerate() {
            let Some(m) = m else { continue };
            let d = m.deflection(
                &h.point(&(m.bracket - reference)),
                &nalgebra::Vector3::zeros(),
            );
            for k in 0..3 {
                let (lo, hi) = m.curves[k].range();
                if d[k] < lo || d[k] > hi {
                    return Err(StaticsError(format!(
                        "mount {i} ({}) deflects {:.1} mm along its axis {k}, beyond its curve [{:.1}, {:.1}] mm: the mounts are too soft to carry the powertrain",
                        m.name,
                        d[k] * 1e3,
                        lo * 1e3,
                        hi * 1e3
                    )));
                }
            }
        }
        Ok(())
    }
}
