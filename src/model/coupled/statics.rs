//! Static equilibrium of the powertrain on its mounts in the body (gravity, preloads, mean load
//! torque) by a damped Newton iteration on the powertrain positions and the modal coordinates.

use faer::linalg::solvers::Solve;
use faer::Mat;
use nalgebra::Vector3;

use super::evaluate::Mode;
use super::CoupledModel;

/// The static equilibrium could not be found.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("static equilibrium: {0}")]
pub struct StaticsError(pub String);

/// Newton iteration limit.
const MAX_ITERATIONS: usize = 100;
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
/// step is scaled so that no component `i` moves more than `limit(i)` (None: unlimited). The
/// tangent (2n residuals) is kept while each step achieves at least three quarters of the
/// decrease the linear model promised for it (a step scaled by `s` promises the factor `1 − s`;
/// a chord step costs one residual), and formed anew otherwise. `x` holds the last iterate on
/// return.
pub(crate) fn damped_newton(
    x: &mut [f64],
    tol: f64,
    max_iterations: usize,
    limit: impl Fn(usize) -> Option<f64>,
    mut residual: impl FnMut(&[f64]) -> Vec<f64>,
) -> Result<(), NewtonFailure> {
    let n = x.len();
    let mut last = f64::INFINITY;
    let mut tangent: Option<faer::linalg::solvers::PartialPivLu<f64>> = None;
    let mut last_scale: f64 = 1.0;
    for _ in 0..max_iterations {
        let r = residual(x);
        let norm = r.iter().map(|v| v * v).sum::<f64>().sqrt();
        if !norm.is_finite() {
            return Err(NewtonFailure::NonFinite(norm));
        }
        if norm < tol {
            return Ok(());
        }
        if norm > (1.0 - 0.75 * last_scale) * last {
            tangent = None;
        }
        last = norm;
        let lu = tangent.get_or_insert_with(|| {
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
            k.partial_piv_lu()
        });
        let mut rhs = Mat::<f64>::zeros(n, 1);
        for i in 0..n {
            rhs[(i, 0)] = -r[i];
        }
        lu.solve_in_place(rhs.as_mut());
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
        last_scale = scale;
        for i in 0..n {
            x[i] += scale * rhs[(i, 0)];
        }
    }
    Err(NewtonFailure::NotConverged(last))
}

impl CoupledModel {
    /// The static residual for the unknowns `z = [powertrain positions, η]` (crank at rest, no
    /// gas, nonlinear mounts): the powertrain's generalised forces, then the modal forces minus
    /// the modal stiffness forces. `y` is scratch holding the rest of the state.
    fn static_residual(&self, z: &[f64], y: &mut [f64]) -> Vec<f64> {
        let l = self.layout;
        let nq = l.positions().len();
        let m = l.modes();
        y[l.positions()].copy_from_slice(&z[..nq]);
        y[l.eta()].copy_from_slice(&z[nq..]);
        let ev = self.evaluate_mode(self.fade_start, y, Mode::STATIC);
        let mut r: Vec<f64> = ev
            .dynamics
            .iter()
            .flat_map(|d| d.force.iter().copied().collect::<Vec<_>>())
            .collect();
        for k in 0..m {
            let w2 = self.body.omega[k] * self.body.omega[k];
            r.push(ev.modal_force[k] - w2 * z[nq + k]);
        }
        r
    }

    /// Solves the static equilibrium of powertrain and body together (crank at rest at the start
    /// angle, no gas, nonlinear mounts, current load torque), sets the mount operating points and
    /// the fade-in start `t0`, and returns the initial state.
    ///
    /// Fails with a message when Newton does not converge or a mount is pressed beyond its curve
    /// (mounts too soft to carry the weight).
    pub fn static_equilibrium(&mut self, t0: f64) -> Result<Vec<f64>, StaticsError> {
        self.set_fade_start(t0)
            .map_err(|e| StaticsError(e.to_string()))?;
        let l = self.layout;
        let nq = l.positions().len();
        let n = nq + l.modes();
        let mut y = self.reference_state();
        let mut z = vec![0.0; n];
        // The forces balance to a part in 1e9 of the weight; mounts stiffened by a scale s carry
        // rounding errors s times larger, so the tolerance grows with the stiffest scale.
        let stiffest = (0..self.mounts.len())
            .map(|i| self.inputs.mount_scales(i, t0).0)
            .fold(1.0, f64::max);
        let tol = 1e-9 * self.powertrain_weight().max(1.0) * stiffest;
        // The body's coordinates are linear and need no step limit.
        let limit = |i: usize| (i < nq).then(|| MAX_STEP[(i % 6) / 3]);
        let mut scratch = y.clone();
        match damped_newton(&mut z, tol, MAX_ITERATIONS, limit, |z| {
            self.static_residual(z, &mut scratch)
        }) {
            Ok(()) => {}
            Err(NewtonFailure::NonFinite(norm)) => {
                return Err(StaticsError(format!("residual became {norm}")))
            }
            Err(NewtonFailure::Singular) => {
                let unstiff: Vec<&str> = self
                    .mounts
                    .iter()
                    .enumerate()
                    .filter_map(|(i, m)| Some((i, m.as_ref()?)))
                    .filter(|(i, _)| self.inputs.mount_scales(*i, t0).0 == 0.0)
                    .map(|(_, m)| m.mount.name.as_str())
                    .collect();
                let why = if unstiff.is_empty() {
                    String::new()
                } else {
                    format!(
                        " (stiffness scale 0 on {}: such a mount keeps its preload, its static share of the weight, but has no stiffness)",
                        unstiff.join(", ")
                    )
                };
                return Err(StaticsError(format!(
                    "the tangent stiffness is singular: the mounts (and the body) do not hold the powertrain in every direction{why}"
                )));
            }
            Err(NewtonFailure::NotConverged(last)) => return Err(StaticsError(format!(
                "Newton did not converge in {MAX_ITERATIONS} iterations (residual {last:.3e} N, tolerance {tol:.3e} N); the mounts may be too soft to carry the weight (stiffness scales up to {stiffest})"
            ))),
        }
        y[l.positions()].copy_from_slice(&z[..nq]);
        y[l.eta()].copy_from_slice(&z[nq..]);
        let points = self.mount_deflections(t0, &y).map_err(|e| {
            let why = if self.has_external_body() {
                "the external body's displacement at the start moves it beyond its characteristic"
            } else {
                "the mounts are too soft to carry the powertrain"
            };
            StaticsError(format!("{}: {why}", e.0))
        })?;
        for (m, p) in self.mounts.iter_mut().zip(points) {
            if let Some(m) = m {
                m.mount.operating_point = p;
            }
        }
        Ok(y)
    }

    /// Checks that every mount at `(t, y)` deflects within the range of its curves: an external
    /// body's attachment input may push a mount beyond what its characteristic describes.
    pub fn check_mount_ranges(&self, t: f64, y: &[f64]) -> Result<(), StaticsError> {
        self.mount_deflections(t, y).map(|_| ())
    }

    /// Deflection of every configured mount at `(t, y)` (zero for a removed one), checked
    /// against the range of its curves.
    fn mount_deflections(&self, t: f64, y: &[f64]) -> Result<Vec<Vector3<f64>>, StaticsError> {
        let hb = self.powertrain.housing_index();
        let h = self.kinematics(y, hb);
        let reference = self.powertrain.bodies()[hb].reference;
        let mut out = Vec::with_capacity(self.mounts.len());
        for (i, m) in self.mounts.iter().enumerate() {
            let Some(m) = m else {
                out.push(Vector3::zeros());
                continue;
            };
            let (a, _) = self.attachment_motion(i, m.target, t, y);
            let mount = &m.mount;
            let d = mount.deflection(&h.point(&(mount.bracket - reference)), &a);
            for k in 0..3 {
                let (lo, hi) = mount.curves[k].range();
                if d[k] < lo || d[k] > hi {
                    return Err(StaticsError(format!(
                        "mount {} ({}) deflects {:.1} mm along its axis {}, beyond its curve [{:.1}, {:.1}] mm",
                        i + 1,
                        mount.name,
                        d[k] * 1e3,
                        k + 1,
                        lo * 1e3,
                        hi * 1e3
                    )));
                }
            }
            out.push(d);
        }
        Ok(out)
    }

    /// Operating points (static deflections) of the mounts, per configured mount (zero when
    /// removed).
    pub fn operating_points(&self) -> Vec<[f64; 3]> {
        self.mounts
            .iter()
            .map(|m| {
                m.as_ref()
                    .map(|m| m.mount.operating_point.into())
                    .unwrap_or([0.0; 3])
            })
            .collect()
    }

    /// Sets the operating points of the linearised mounts (per configured mount).
    pub(crate) fn set_operating_points(&mut self, points: &[[f64; 3]]) {
        for (m, p) in self.mounts.iter_mut().zip(points) {
            if let Some(m) = m {
                m.mount.operating_point = Vector3::from(*p);
            }
        }
    }
}
