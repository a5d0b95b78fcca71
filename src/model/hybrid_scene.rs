//! Scene "engine in the elastic chassis" (paper §6.2, Table 1 middle column): the engine model of
//! [`GroundScene`] with its mounts attached to the interface points of a Craig-Bampton reduced,
//! orthogonalised chassis ([`ReducedChassis`]), as one [`OdeProblem`].
//!
//! State `y = [engine state (q, v, φ) | η_1 … η_m | η̇_1 … η̇_m]`: the engine part is laid out
//! exactly as in [`GroundScene`], followed by the chassis modal coordinates and their rates.
//! Explicit form `y' = f(t, y)`: the engine's velocity rows are its accelerations `M_b⁻¹ Q_b`
//! (one 6×6 solve per body), so the integrator needs no mass matrix — assembling and scanning a
//! dense mass matrix of all states at every Newton set-up cost more than these small solves — and
//! `η̈_k = −2ζ_k ω_k η̇_k − ω_k² η_k + Σ_mounts φ_{p,k} · (−F_mount)`.
//!
//! A mount force depends on the motion of its housing bracket relative to its attachment, and the
//! attachment moves with the chassis: `a_p = Σ_k φ_{p,k}[0..3] η_k` (velocity likewise). The
//! equal and opposite force acts on the chassis at the interface node; the mounts transmit forces
//! only (the lever arm between bracket and node is below 1 mm, so no moment is passed on).
//!
//! The chassis is linear about a reference state that already carries its own weight: only the
//! mount forces act on it (its gravity load and the matching suspension preload are not part of
//! the modal equations). At the static equilibrium the chassis therefore deflects by the engine's
//! weight only.

use faer::MatMut;
use nalgebra::Vector3;

use super::ground_scene::{Evaluation, GroundScene, Mode, StaticsError};
use super::mount::Mount;
use super::statics::{damped_newton, NewtonFailure};
use crate::cms::ReducedChassis;
use crate::fe::chassis::{SEAT_RAIL, STEERING_WHEEL};
use crate::ode::{BlockLowRankJacobian, BlockLowRankShape, OdeProblem, ProblemError};

/// Largest distance (m) between an engine mount's attachment and the chassis point it is
/// connected to.
pub const MOUNT_MATCH_TOLERANCE: f64 = 1e-3;

/// One evaluation of the coupled equations of motion.
#[derive(Debug, Clone)]
pub struct HybridEvaluation {
    /// The engine's evaluation, mount responses taken against the moving attachments.
    pub engine: Evaluation,
    /// Generalised chassis forces `Σ_p φ_{p,k} · (−F_p)` per mode.
    pub modal_force: Vec<f64>,
}

/// The engine on its mounts in the elastic chassis.
#[derive(Debug, Clone)]
pub struct HybridScene {
    engine: GroundScene,
    chassis: ReducedChassis,
    /// Per configured engine mount: the chassis point it is attached to (`None`: mount removed).
    links: Vec<Option<usize>>,
    steering_wheel: usize,
    seat_rail: usize,
    /// Hand the integrator a dense Jacobian instead of the block-low-rank one (comparisons).
    dense_newton: bool,
}

/// Why the hybrid scene could not be assembled.
#[derive(Debug, Clone, PartialEq)]
pub struct HybridError(pub String);

impl std::fmt::Display for HybridError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "hybrid scene: {}", self.0)
    }
}

impl std::error::Error for HybridError {}

fn check_chassis(chassis: &ReducedChassis) -> Result<(), HybridError> {
    let m = chassis.n_modes();
    if m == 0 {
        return Err(HybridError("the reduced chassis has no modes".into()));
    }
    if chassis.zeta.len() != m {
        return Err(HybridError(format!(
            "the reduced chassis has {m} frequencies but {} damping ratios",
            chassis.zeta.len()
        )));
    }
    for (k, (&w, &z)) in chassis.omega.iter().zip(&chassis.zeta).enumerate() {
        if !(w.is_finite() && w >= 0.0) {
            return Err(HybridError(format!(
                "chassis mode {k}: omega {w} rad/s must be finite and non-negative"
            )));
        }
        if !(z.is_finite() && z >= 0.0) {
            return Err(HybridError(format!(
                "chassis mode {k}: damping ratio {z} must be finite and non-negative"
            )));
        }
    }
    for p in &chassis.points {
        if p.shape.len() != m {
            return Err(HybridError(format!(
                "chassis point '{}' has {} mode-shape rows for {m} modes",
                p.name,
                p.shape.len()
            )));
        }
        if p.shape.iter().flatten().any(|v| !v.is_finite()) {
            return Err(HybridError(format!(
                "chassis point '{}' has a non-finite mode-shape entry",
                p.name
            )));
        }
    }
    Ok(())
}

fn point_index(chassis: &ReducedChassis, name: &str) -> Result<usize, HybridError> {
    chassis
        .points
        .iter()
        .position(|p| p.name == name)
        .ok_or_else(|| {
            HybridError(format!(
                "the reduced chassis has no output point '{name}' (points: {})",
                chassis
                    .points
                    .iter()
                    .map(|p| p.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            ))
        })
}

impl HybridScene {
    /// Connects every active mount of `engine` to the chassis point at its attachment position
    /// (within [`MOUNT_MATCH_TOLERANCE`]); the chassis must provide the steering-wheel and
    /// seat-rail points.
    pub fn new(engine: GroundScene, chassis: ReducedChassis) -> Result<Self, HybridError> {
        check_chassis(&chassis)?;
        let mut links = Vec::with_capacity(engine.mounts().len());
        for (i, m) in engine.mounts().iter().enumerate() {
            let Some(m) = m else {
                links.push(None);
                continue;
            };
            let nearest = chassis
                .points
                .iter()
                .enumerate()
                .map(|(p, point)| {
                    let x = Vector3::new(point.position[0], point.position[1], point.position[2]);
                    (p, (x - m.attachment).norm())
                })
                .min_by(|a, b| a.1.total_cmp(&b.1));
            match nearest {
                Some((p, d)) if d <= MOUNT_MATCH_TOLERANCE => links.push(Some(p)),
                Some((p, d)) => {
                    return Err(HybridError(format!(
                        "mount {i} ('{}') attaches at ({:.4}, {:.4}, {:.4}) m; the nearest chassis point '{}' is {:.1} mm away (limit {:.1} mm)",
                        m.name,
                        m.attachment.x,
                        m.attachment.y,
                        m.attachment.z,
                        chassis.points[p].name,
                        d * 1e3,
                        MOUNT_MATCH_TOLERANCE * 1e3
                    )))
                }
                None => {
                    return Err(HybridError(format!(
                        "mount {i} ('{}'): the reduced chassis has no points",
                        m.name
                    )))
                }
            }
        }
        let steering_wheel = point_index(&chassis, STEERING_WHEEL)?;
        let seat_rail = point_index(&chassis, SEAT_RAIL)?;
        Ok(Self {
            engine,
            chassis,
            links,
            steering_wheel,
            seat_rail,
            dense_newton: false,
        })
    }

    /// Makes the integrator use a dense `n × n` Newton matrix (`true`) instead of the
    /// block-diagonal plus low-rank one (the default): the two must give the same solution; the
    /// dense one costs `O(n³)` per factorisation.
    pub fn set_dense_newton(&mut self, dense: bool) {
        self.dense_newton = dense;
    }

    pub fn engine(&self) -> &GroundScene {
        &self.engine
    }

    /// The engine, for setting its inputs.
    pub fn engine_mut(&mut self) -> &mut GroundScene {
        &mut self.engine
    }

    pub fn chassis(&self) -> &ReducedChassis {
        &self.chassis
    }

    /// Chassis point index each configured mount is attached to (`None`: removed).
    pub fn links(&self) -> &[Option<usize>] {
        &self.links
    }

    /// The connected mounts: (index among the configured mounts, the mount, its chassis point).
    pub fn connected_mounts(&self) -> impl Iterator<Item = (usize, &Mount, usize)> + '_ {
        self.engine
            .mounts()
            .iter()
            .zip(&self.links)
            .enumerate()
            .filter_map(|(i, (mount, link))| Some((i, mount.as_ref()?, (*link)?)))
    }

    /// Number of engine states (the first block of the state vector).
    pub fn engine_dim(&self) -> usize {
        self.engine.dim()
    }

    /// Number of chassis modes.
    pub fn modes_count(&self) -> usize {
        self.chassis.n_modes()
    }

    /// Index of the first modal coordinate η_0.
    pub fn eta_index(&self) -> usize {
        self.engine_dim()
    }

    /// Index of the first modal rate η̇_0.
    pub fn eta_rate_index(&self) -> usize {
        self.engine_dim() + self.modes_count()
    }

    /// Indices of the steering-wheel and seat-rail points in the chassis.
    pub fn output_points(&self) -> (usize, usize) {
        (self.steering_wheel, self.seat_rail)
    }

    /// Translation (or, with `rates`, velocity) of chassis point `p` for modal vector `x`.
    pub fn point_translation(&self, p: usize, x: &[f64]) -> Vector3<f64> {
        let mut u = Vector3::zeros();
        for (s, &e) in self.chassis.points[p].shape.iter().zip(x) {
            u += Vector3::new(s[0], s[1], s[2]) * e;
        }
        u
    }

    /// State with the engine at its reference pose, the crank at the start angle and the chassis
    /// undeformed.
    pub fn reference_state(&self) -> Vec<f64> {
        let mut y = self.engine.reference_state();
        y.resize(self.dim(), 0.0);
        y
    }

    pub(crate) fn evaluate_mode(&self, t: f64, y: &[f64], mode: Mode) -> HybridEvaluation {
        let ne = self.engine_dim();
        let m = self.modes_count();
        let eta = &y[ne..ne + m];
        let eta_rate = &y[ne + m..ne + 2 * m];
        let mut ev = self.engine.evaluate_mode(t, &y[..ne], mode);
        let hb = self.engine.housing_index();
        let reference = self.engine.bodies()[hb].reference;
        let nonlinear = mode.nonlinear_mounts || self.engine.effects().mount_nonlinearity;
        let inputs = self.engine.inputs();
        let mut modal_force = vec![0.0; m];
        for (i, mount, p) in self.connected_mounts() {
            let h = &ev.kinematics[hb];
            let local = mount.bracket - reference;
            let x = h.point(&local);
            let xv = h.point_velocity(&local);
            let a = self.point_translation(p, eta);
            let av = self.point_translation(p, eta_rate);
            let r = mount.response(
                &(x - mount.attachment - a),
                &(xv - av),
                inputs.stiffness_scale[i],
                inputs.damping_scale[i],
                nonlinear,
            );
            // The engine evaluation took this mount against a fixed attachment: replace its force.
            let on_ground = ev.mounts[i].map(|g| g.force).unwrap_or_else(Vector3::zeros);
            let h = ev.kinematics[hb];
            ev.dynamics[hb].add_point_force(&h, &x, &(r.force - on_ground));
            ev.mounts[i] = Some(r);
            for (g, s) in modal_force.iter_mut().zip(&self.chassis.points[p].shape) {
                *g -= s[0] * r.force.x + s[1] * r.force.y + s[2] * r.force.z;
            }
        }
        HybridEvaluation {
            engine: ev,
            modal_force,
        }
    }

    /// One evaluation of the coupled equations of motion of the running engine at `(t, y)`.
    pub fn evaluate(&self, t: f64, y: &[f64]) -> HybridEvaluation {
        self.evaluate_mode(t, y, Mode::RUNNING)
    }

    pub(crate) fn write_rhs(
        &self,
        y: &[f64],
        ev: &HybridEvaluation,
        f: &mut [f64],
    ) -> Result<(), ProblemError> {
        let ne = self.engine_dim();
        let m = self.modes_count();
        self.engine.write_rhs(&y[..ne], &ev.engine, &mut f[..ne])?;
        let nb = self.engine.body_count();
        for (b, acc) in self.engine.accelerations(&ev.engine)?.iter().enumerate() {
            f[6 * nb + 6 * b..6 * nb + 6 * b + 6].copy_from_slice(acc.as_slice());
        }
        let c = &self.chassis;
        for k in 0..m {
            let (eta, rate) = (y[ne + k], y[ne + m + k]);
            f[ne + k] = rate;
            f[ne + m + k] = ev.modal_force[k]
                - 2.0 * c.zeta[k] * c.omega[k] * rate
                - c.omega[k] * c.omega[k] * eta;
        }
        if let Some(i) = f[ne..].iter().position(|v| !v.is_finite()) {
            return Err(ProblemError::Recoverable(format!(
                "chassis state derivative {i} is not finite"
            )));
        }
        Ok(())
    }

    /// Right-hand side with the engine at rest (crank standing, no gas, linearised mounts): the
    /// linearisation point of the coupled modal analysis.
    pub(crate) fn rhs_at_rest(&self, y: &[f64], f: &mut [f64]) -> Result<(), ProblemError> {
        let ev = self.evaluate_mode(
            self.engine.fade_start(),
            y,
            Mode {
                running: false,
                nonlinear_mounts: false,
            },
        );
        self.write_rhs(y, &ev, f)
    }

    /// Checks that `y` is a state of this scene.
    pub fn check_state(&self, y: &[f64]) -> Result<(), ProblemError> {
        if y.len() != self.dim() {
            return Err(ProblemError::Fatal(format!(
                "state has {} entries, the hybrid model has {}",
                y.len(),
                self.dim()
            )));
        }
        if let Some(i) = y.iter().position(|v| !v.is_finite()) {
            return Err(ProblemError::Fatal(format!("state entry {i} is {}", y[i])));
        }
        Ok(())
    }

    /// The static residual (engine generalised forces, then chassis modal forces) at rest with
    /// the nonlinear mount curves, for the unknowns `z = [engine q, η]`.
    fn static_residual(&self, z: &[f64], y: &mut [f64]) -> Vec<f64> {
        let nq = 6 * self.engine.body_count();
        let ne = self.engine_dim();
        let m = self.modes_count();
        y[..nq].copy_from_slice(&z[..nq]);
        y[ne..ne + m].copy_from_slice(&z[nq..]);
        let ev = self.evaluate_mode(
            self.engine.fade_start(),
            y,
            Mode {
                running: false,
                nonlinear_mounts: true,
            },
        );
        let mut r: Vec<f64> = ev
            .engine
            .dynamics
            .iter()
            .flat_map(|d| d.force.iter().copied().collect::<Vec<_>>())
            .collect();
        for k in 0..m {
            let w2 = self.chassis.omega[k] * self.chassis.omega[k];
            r.push(ev.modal_force[k] - w2 * z[nq + k]);
        }
        r
    }

    /// Solves the static equilibrium of engine and chassis together (crank at rest at the start
    /// angle, no gas, nonlinear mounts, current load torque), sets the mount operating points and
    /// the fade-in start `t0`, and returns the initial state.
    pub fn static_equilibrium(&mut self, t0: f64) -> Result<Vec<f64>, StaticsError> {
        const MAX_ITERATIONS: usize = 100;
        // Largest engine translation (m) and rotation (rad) per Newton step, as in the ground
        // scene; the chassis coordinates are linear and need no limit.
        const MAX_STEP: [f64; 2] = [0.002, 0.02];
        self.engine
            .set_fade_start(t0)
            .map_err(|e| StaticsError(e.0))?;
        let nq = 6 * self.engine.body_count();
        let ne = self.engine_dim();
        let m = self.modes_count();
        let n = nq + m;
        let mut y = self.reference_state();
        let mut z = vec![0.0; n];
        let weight = self.powertrain_weight();
        let tol = 1e-9 * weight.max(1.0);
        let limit = |i: usize| (i < nq).then(|| MAX_STEP[(i % 6) / 3]);
        let mut scratch = y.clone();
        let outcome = damped_newton(&mut z, tol, MAX_ITERATIONS, limit, |z| {
            self.static_residual(z, &mut scratch)
        });
        match outcome {
            Ok(()) => {}
            Err(NewtonFailure::NonFinite(norm)) => {
                return Err(StaticsError(format!("residual became {norm}")))
            }
            Err(NewtonFailure::Singular) => return Err(StaticsError(
                "the coupled tangent stiffness is singular: the mounts or the chassis do not hold the powertrain in every direction".into(),
            )),
            Err(NewtonFailure::NotConverged(last)) => return Err(StaticsError(format!(
                "engine and chassis: Newton did not converge in {MAX_ITERATIONS} iterations (residual {last:.3e}, tolerance {tol:.3e})"
            ))),
        }
        y[..nq].copy_from_slice(&z[..nq]);
        y[ne..ne + m].copy_from_slice(&z[nq..]);
        let points = self.mount_deflections(&y)?;
        self.engine.set_operating_points(&points);
        Ok(y)
    }

    /// Weight of the powertrain (N).
    pub fn powertrain_weight(&self) -> f64 {
        self.engine
            .bodies()
            .iter()
            .flat_map(|b| b.parts.iter())
            .map(|p| p.mass)
            .sum::<f64>()
            * self.engine.config().gravity
    }

    /// Deflection of every configured mount at state `y` (zero for a removed one), checked
    /// against the range of its curves.
    fn mount_deflections(&self, y: &[f64]) -> Result<Vec<Vector3<f64>>, StaticsError> {
        let ne = self.engine_dim();
        let m = self.modes_count();
        let hb = self.engine.housing_index();
        let h = self.engine.kinematics(&y[..ne], hb);
        let reference = self.engine.bodies()[hb].reference;
        let mut out = Vec::with_capacity(self.links.len());
        for (i, (mount, link)) in self.engine.mounts().iter().zip(&self.links).enumerate() {
            let (Some(mount), Some(p)) = (mount, link) else {
                out.push(Vector3::zeros());
                continue;
            };
            let a = self.point_translation(*p, &y[ne..ne + m]);
            let d = mount.deflection(&h.point(&(mount.bracket - reference)), &a);
            for k in 0..3 {
                let (lo, hi) = mount.curves[k].range();
                if d[k] < lo || d[k] > hi {
                    return Err(StaticsError(format!(
                        "mount {i} ({}) deflects {:.1} mm along its axis {k}, beyond its curve [{:.1}, {:.1}] mm: the mounts are too soft to carry the powertrain",
                        mount.name,
                        d[k] * 1e3,
                        lo * 1e3,
                        hi * 1e3
                    )));
                }
            }
            out.push(d);
        }
        Ok(out)
    }

    /// Modal accelerations η̈ from one evaluation of the equations of motion at `(t, y)`.
    pub fn modal_accelerations(&self, t: f64, y: &[f64]) -> Result<Vec<f64>, ProblemError> {
        self.check_state(y)?;
        let ev = self.evaluate(t, y);
        let mut f = vec![0.0; self.dim()];
        self.write_rhs(y, &ev, &mut f)?;
        Ok(f[self.eta_rate_index()..].to_vec())
    }
}

impl OdeProblem for HybridScene {
    fn dim(&self) -> usize {
        self.engine.dim() + 2 * self.chassis.n_modes()
    }

    fn rhs(&mut self, t: f64, y: &[f64], f: &mut [f64]) -> Result<(), ProblemError> {
        if y.len() != self.dim() || f.len() != self.dim() {
            return Err(ProblemError::Fatal(format!(
                "state/derivative lengths {}/{} differ from {}",
                y.len(),
                f.len(),
                self.dim()
            )));
        }
        let ev = self.evaluate(t, y);
        self.write_rhs(y, &ev, f)
    }

    fn jacobian(&mut self, t: f64, y: &[f64], j: MatMut<'_, f64>) -> Result<bool, ProblemError> {
        self.dense_jacobian(t, y, j)?;
        Ok(true)
    }

    fn jacobian_structure(&self) -> Option<BlockLowRankShape> {
        (!self.dense_newton).then(|| self.coupled_jacobian_shape())
    }

    fn structured_jacobian(
        &mut self,
        t: f64,
        y: &[f64],
        j: &mut BlockLowRankJacobian,
    ) -> Result<(), ProblemError> {
        self.coupled_jacobian(t, y, j)
    }
}
