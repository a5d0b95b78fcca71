//! Scene "engine supported by ground" (paper Table 1, left column): the engine model with its
//! mounts attached to rigid ground, as an [`OdeProblem`].
//!
//! State `y = [q_1 … q_n, v_1 … v_n, φ]` with per body `q = [u, θ]` (displacement of the reference
//! point from its reference position, Cardan angles) and `v = [u', ω]` (ω in the vehicle frame),
//! and `φ` the crank angle relative to the monoblock. Linearly implicit form
//! `blockdiag(I, M(q, φ), 1) y' = f(t, y)`.

use faer::MatMut;
use nalgebra::{Matrix6, Vector3, Vector6};

use super::assembly::{build_bodies, v3, Body};
use super::composite::{add_parts, BodyDynamics, BodyKinematics, CrankDriveState};
use super::config::{ConfigError, EngineConfig};
use super::effects::Effects;
use super::gas::{side_force, CylinderGeometry, GasModel, PressureCurve};
use super::inputs::{EngineInputs, InputError, RampInput};
use super::mount::{Mount, MountResponse};
use super::parts::slider_crank;
use super::ring_carrier::RingCarrier;
use super::rotation::{angle_rates, rotation_matrix};
use crate::ode::{OdeProblem, ProblemError};

/// Gas excitation prepared from the configuration.
#[derive(Debug, Clone, PartialEq)]
struct GasExcitation {
    curve: PressureCurve,
    /// Idle and full-load curves of the Wiebe model, for changing the load at run time.
    load_points: Option<(PressureCurve, PressureCurve)>,
    area: f64,
    crankcase_pressure: f64,
    radius: f64,
    conrod: f64,
    /// (y offset, throw, firing TDC) per cylinder, radians.
    cylinders: Vec<(f64, f64, f64)>,
    /// Crank centre relative to body 0's reference point.
    crank_centre: Vector3<f64>,
}

/// Everything one evaluation of the equations of motion produces.
#[derive(Debug, Clone)]
pub struct Evaluation {
    pub kinematics: Vec<BodyKinematics>,
    pub dynamics: Vec<BodyDynamics>,
    /// Per configured mount (None when removed).
    pub mounts: Vec<Option<MountResponse>>,
    pub crank_rate: f64,
}

/// How the model is evaluated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Mode {
    /// Engine running (crank speed, gas, fade-in); false: crank at rest, no gas (statics, modes).
    pub(crate) running: bool,
    /// Force the nonlinear mount curves (statics determine the operating point with them).
    pub(crate) nonlinear_mounts: bool,
}

impl Mode {
    pub(crate) const RUNNING: Mode = Mode {
        running: true,
        nonlinear_mounts: false,
    };
}

/// Engine on mounts attached to rigid ground.
#[derive(Debug, Clone)]
pub struct GroundScene {
    config: EngineConfig,
    bodies: Vec<Body>,
    /// Per configured mount; `None` for a removed mount.
    mounts: Vec<Option<Mount>>,
    ring_carriers: Vec<RingCarrier>,
    gas: Option<GasExcitation>,
    gravity: Vector3<f64>,
    inputs: EngineInputs,
    fade_start: f64,
}

/// The static equilibrium could not be found.
#[derive(Debug, Clone, PartialEq)]
pub struct StaticsError(pub String);

impl std::fmt::Display for StaticsError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "static equilibrium: {}", self.0)
    }
}

impl std::error::Error for StaticsError {}

fn smooth_step(x: f64) -> f64 {
    let x = x.clamp(0.0, 1.0);
    x * x * x * (10.0 + x * (-15.0 + 6.0 * x))
}

impl GroundScene {
    /// Builds the scene from a configuration (validated here).
    pub fn new(config: EngineConfig) -> Result<Self, ConfigError> {
        config.validate()?;
        let bodies = build_bodies(&config);
        let mounts = config
            .mounts
            .iter()
            .map(|m| m.active.then(|| Mount::from_config(m)))
            .collect();
        let ring_carriers = if bodies.len() == 2 {
            config
                .ring_carriers
                .iter()
                .map(|r| RingCarrier::from_config(r, &bodies[0].reference, &bodies[1].reference))
                .collect()
        } else {
            Vec::new()
        };
        let c = &config.crank_drive;
        let gas = if !config.effects.gas_forces {
            None
        } else {
            Some({
                let geometry = CylinderGeometry {
                    bore: c.bore,
                    crank_radius: c.crank_radius,
                    conrod: c.conrod_length,
                };
                let (curve, load_points) = match &config.gas.model {
                    GasModel::Wiebe(w) => {
                        let idle = PressureCurve::wiebe(w, &w.idle, &geometry);
                        let full = PressureCurve::wiebe(w, &w.full_load, &geometry);
                        (
                            PressureCurve::blend(&idle, &full, config.gas.load),
                            Some((idle, full)),
                        )
                    }
                    GasModel::Table(t) => (
                        PressureCurve::from_table(t).map_err(|message| ConfigError {
                            field: "gas.model".into(),
                            message,
                        })?,
                        None,
                    ),
                };
                GasExcitation {
                    curve,
                    load_points,
                    area: geometry.piston_area(),
                    crankcase_pressure: config.gas.crankcase_pressure,
                    radius: c.crank_radius,
                    conrod: c.conrod_length,
                    cylinders: c
                        .cylinders
                        .iter()
                        .map(|k| {
                            (
                                k.y_offset,
                                k.throw_deg.to_radians(),
                                k.firing_tdc_deg.to_radians(),
                            )
                        })
                        .collect(),
                    crank_centre: v3(&c.crank_centre) - bodies[0].reference,
                }
            })
        };
        let gravity = Vector3::new(0.0, 0.0, -config.gravity);
        let inputs = EngineInputs::new(config.mounts.len());
        Ok(Self {
            config,
            bodies,
            mounts,
            ring_carriers,
            gas,
            gravity,
            inputs,
            fade_start: 0.0,
        })
    }

    pub fn config(&self) -> &EngineConfig {
        &self.config
    }

    pub fn effects(&self) -> &Effects {
        &self.config.effects
    }

    pub fn bodies(&self) -> &[Body] {
        &self.bodies
    }

    pub fn ring_carriers(&self) -> &[RingCarrier] {
        &self.ring_carriers
    }

    /// Mounts by configuration index (`None`: removed).
    pub fn mounts(&self) -> &[Option<Mount>] {
        &self.mounts
    }

    pub fn inputs(&self) -> &EngineInputs {
        &self.inputs
    }

    /// Number of free bodies (2 with elastic ring carriers, else 1).
    pub fn body_count(&self) -> usize {
        self.bodies.len()
    }

    /// Index of the crank-angle state.
    pub fn crank_index(&self) -> usize {
        12 * self.bodies.len()
    }

    /// Index of the body carrying the mount brackets (housing or the rigid powertrain).
    pub fn housing_index(&self) -> usize {
        self.bodies.len() - 1
    }

    /// Crank spin `ω(t) = value + rate (t − since)` (rad/s).
    pub fn set_crank_speed(&mut self, since: f64, value: f64, rate: f64) -> Result<(), InputError> {
        if !(value.is_finite() && rate.is_finite() && since.is_finite()) {
            return Err(InputError(format!(
                "crank speed {value} rad/s, rate {rate} rad/s² must be finite"
            )));
        }
        self.inputs.crank_speed = RampInput { value, rate, since };
        Ok(())
    }

    /// Load torque on the housing about +y (N m) and its time derivative.
    pub fn set_load_torque(&mut self, since: f64, value: f64, rate: f64) -> Result<(), InputError> {
        if !(value.is_finite() && rate.is_finite() && since.is_finite()) {
            return Err(InputError(format!(
                "load torque {value} N m, rate {rate} N m/s must be finite"
            )));
        }
        self.inputs.load_torque = RampInput { value, rate, since };
        Ok(())
    }

    /// Stiffness and damping scale factors of mount `index` (configuration order).
    pub fn set_mount_scales(
        &mut self,
        index: usize,
        stiffness: f64,
        damping: f64,
    ) -> Result<(), InputError> {
        let n = self.config.mounts.len();
        if index >= n {
            return Err(InputError(format!(
                "mount index {index} out of range (0..{n})"
            )));
        }
        if !(stiffness.is_finite() && stiffness > 0.0) {
            return Err(InputError(format!(
                "mounts[{index}] stiffness scale {stiffness} must be positive and finite"
            )));
        }
        if !(damping.is_finite() && damping >= 0.0) {
            return Err(InputError(format!(
                "mounts[{index}] damping scale {damping} must be non-negative and finite"
            )));
        }
        self.inputs.stiffness_scale[index] = stiffness;
        self.inputs.damping_scale[index] = damping;
        Ok(())
    }

    /// Engine load between idle (0) and full load (1) of the Wiebe gas model, at run time.
    /// Ignored (Ok) when gas forces are off; an error for a user pressure table.
    pub fn set_gas_load(&mut self, load: f64) -> Result<(), InputError> {
        if !(load.is_finite() && (0.0..=1.0).contains(&load)) {
            return Err(InputError(format!("gas load {load} must lie in [0, 1]")));
        }
        if let Some(gas) = &mut self.gas {
            let Some((idle, full)) = &gas.load_points else {
                return Err(InputError(
                    "the gas pressure comes from a user table; its load cannot change".into(),
                ));
            };
            gas.curve = PressureCurve::blend(idle, full, load);
        }
        self.config.gas.load = load;
        Ok(())
    }

    /// Start of the excitation fade-in.
    pub fn fade_start(&self) -> f64 {
        self.fade_start
    }

    /// Sets the operating points of the linearised mounts (per configured mount).
    pub(crate) fn set_operating_points(&mut self, points: &[Vector3<f64>]) {
        for (m, p) in self.mounts.iter_mut().zip(points) {
            if let Some(m) = m {
                m.operating_point = *p;
            }
        }
    }

    /// Time from which the excitation fades in (set by [`Self::static_equilibrium`]).
    pub fn set_fade_start(&mut self, t: f64) -> Result<(), InputError> {
        if !t.is_finite() {
            return Err(InputError(format!(
                "excitation fade-in start {t} s must be finite"
            )));
        }
        self.fade_start = t;
        Ok(())
    }

    /// Excitation scale at `t` (C² ramp over `excitation_fade_in`).
    pub fn excitation(&self, t: f64) -> f64 {
        let tf = self.config.excitation_fade_in;
        if tf <= 0.0 {
            1.0
        } else {
            smooth_step((t - self.fade_start) / tf)
        }
    }

    fn start_angle(&self) -> f64 {
        self.config.start_crank_angle_deg.to_radians()
    }

    /// Pose and velocity of body `b` in state `y`.
    pub(crate) fn kinematics(&self, y: &[f64], b: usize) -> BodyKinematics {
        let nb = self.bodies.len();
        let q = &y[6 * b..6 * b + 6];
        let v = &y[6 * nb + 6 * b..6 * nb + 6 * b + 6];
        BodyKinematics {
            position: self.bodies[b].reference + Vector3::new(q[0], q[1], q[2]),
            rotation: rotation_matrix(&Vector3::new(q[3], q[4], q[5])),
            velocity: Vector3::new(v[0], v[1], v[2]),
            omega: Vector3::new(v[3], v[4], v[5]),
        }
    }

    fn crank_state(&self, t: f64, y: &[f64], mode: Mode) -> CrankDriveState {
        let phi = y[self.crank_index()];
        let fx = &self.config.effects;
        if !mode.running {
            return CrankDriveState {
                angle: phi,
                speed: 0.0,
                acceleration: 0.0,
                excitation: 0.0,
                spin: 0.0,
            };
        }
        let fade = self.excitation(t);
        let speed = self.inputs.crank_speed.at(t);
        CrankDriveState {
            angle: if fx.mass_forces {
                phi
            } else {
                self.start_angle()
            },
            speed,
            acceleration: self.inputs.crank_speed.rate,
            excitation: if fx.mass_forces { fade } else { 0.0 },
            spin: if fx.gyroscopic { fade * speed } else { 0.0 },
        }
    }

    pub(crate) fn evaluate_mode(&self, t: f64, y: &[f64], mode: Mode) -> Evaluation {
        let nb = self.bodies.len();
        let kin: Vec<BodyKinematics> = (0..nb).map(|b| self.kinematics(y, b)).collect();
        let mut dynamics: Vec<BodyDynamics> = (0..nb)
            .map(|b| self.local_dynamics(t, y, &kin[b], b, mode))
            .collect();
        self.add_ring_carriers(&kin, &mut dynamics);
        let hb = nb - 1;
        let mounts = self.add_mounts(&kin[hb], mode, &mut dynamics[hb]);
        let e = kin[0].rotation * Vector3::y();
        let crank_rate = if mode.running {
            self.inputs.crank_speed.at(t)
        } else {
            0.0
        } - e.dot(&kin[0].omega);
        Evaluation {
            kinematics: kin,
            dynamics,
            mounts,
            crank_rate,
        }
    }

    /// Contributions that depend on one body's coordinates only (and on the crank angle): its
    /// parts with gravity, the gas side forces (monoblock), the load torque (housing).
    pub(crate) fn local_dynamics(
        &self,
        t: f64,
        y: &[f64],
        kin: &BodyKinematics,
        b: usize,
        mode: Mode,
    ) -> BodyDynamics {
        let mut d = BodyDynamics::zero();
        let crank = self.crank_state(t, y, mode);
        add_parts(&self.bodies[b].parts, kin, &crank, &self.gravity, &mut d);
        if b == 0 && mode.running {
            self.add_gas_forces(kin, y[self.crank_index()], self.excitation(t), &mut d);
        }
        if b == self.bodies.len() - 1 {
            let torque = self.inputs.load_torque.at(t);
            d.add_wrench(&Vector3::zeros(), &(kin.rotation * Vector3::y() * torque));
        }
        d
    }

    /// Ring-carrier forces on monoblock and housing (nothing for a rigid powertrain).
    pub(crate) fn add_ring_carriers(&self, kin: &[BodyKinematics], dynamics: &mut [BodyDynamics]) {
        if kin.len() != 2 {
            return;
        }
        for rc in &self.ring_carriers {
            let w = rc.wrench(&kin[0], &kin[1]);
            dynamics[0].add_point_force(&kin[0], &w.monoblock_point, &w.monoblock_force);
            dynamics[0].add_wrench(&Vector3::zeros(), &w.monoblock_moment);
            dynamics[1].add_point_force(&kin[1], &w.housing_point, &w.housing_force);
            dynamics[1].add_wrench(&Vector3::zeros(), &w.housing_moment);
        }
    }

    /// Mount forces on the housing `h`; returns the responses per configured mount.
    fn add_mounts(
        &self,
        h: &BodyKinematics,
        mode: Mode,
        out: &mut BodyDynamics,
    ) -> Vec<Option<MountResponse>> {
        let hb = self.bodies.len() - 1;
        let nonlinear = mode.nonlinear_mounts || self.config.effects.mount_nonlinearity;
        self.mounts
            .iter()
            .enumerate()
            .map(|(i, m)| {
                let m = m.as_ref()?;
                let local = m.bracket - self.bodies[hb].reference;
                let x = h.point(&local);
                let xv = h.point_velocity(&local);
                let r = m.response(
                    &(x - m.attachment),
                    &xv,
                    self.inputs.stiffness_scale[i],
                    self.inputs.damping_scale[i],
                    nonlinear,
                );
                out.add_point_force(h, &x, &r.force);
                Some(r)
            })
            .collect()
    }

    /// Piston side-force pairs (paper §4.2) on the monoblock `body`: `−F_N` at each piston pin,
    /// `+F_N` at the main bearing on the same cylinder axis, `F_N = p A tan β`, scaled by `scale`.
    pub(crate) fn add_gas_forces(
        &self,
        body: &BodyKinematics,
        phi: f64,
        scale: f64,
        out: &mut BodyDynamics,
    ) {
        let Some(gas) = &self.gas else { return };
        let ex = body.rotation * Vector3::x();
        for &(yo, throw, firing) in &gas.cylinders {
            let psi = phi - throw;
            let p = gas.curve.pressure(phi - firing);
            let f_gas = (p - gas.crankcase_pressure) * gas.area * scale;
            let n = side_force(f_gas, psi, gas.radius / gas.conrod);
            let (s, _, _) = slider_crank(psi, gas.radius, gas.conrod);
            let pin = body.point(&(gas.crank_centre + Vector3::new(0.0, yo, s)));
            let bearing = body.point(&(gas.crank_centre + Vector3::new(0.0, yo, 0.0)));
            out.add_point_force(body, &pin, &(-n * ex));
            out.add_point_force(body, &bearing, &(n * ex));
        }
    }

    /// Cylinder pressure of cylinder `i` at crank angle `phi` (Pa), if gas forces are on.
    pub fn cylinder_pressure(&self, i: usize, phi: f64) -> Option<f64> {
        let gas = self.gas.as_ref()?;
        let &(_, _, firing) = gas.cylinders.get(i)?;
        Some(gas.curve.pressure(phi - firing))
    }

    /// One evaluation of the equations of motion of the running engine at `(t, y)`.
    pub(crate) fn evaluate(&self, t: f64, y: &[f64]) -> Evaluation {
        self.evaluate_mode(t, y, Mode::RUNNING)
    }

    /// Generalised forces at rest (crank standing, no gas), nonlinear mounts: the static residual.
    pub(crate) fn static_residual(&self, y: &[f64]) -> Vec<f64> {
        let ev = self.evaluate_mode(
            self.fade_start,
            y,
            Mode {
                running: false,
                nonlinear_mounts: true,
            },
        );
        ev.dynamics
            .iter()
            .flat_map(|d| d.force.iter().cloned().collect::<Vec<_>>())
            .collect()
    }

    /// Right-hand side in "engine at rest" mode (used for the linearisation at equilibrium).
    pub(crate) fn rhs_at_rest(&self, y: &[f64], f: &mut [f64]) -> Result<(), ProblemError> {
        let ev = self.evaluate_mode(
            self.fade_start,
            y,
            Mode {
                running: false,
                nonlinear_mounts: false,
            },
        );
        self.write_rhs(y, &ev, f)
    }

    pub(crate) fn write_rhs(
        &self,
        y: &[f64],
        ev: &Evaluation,
        f: &mut [f64],
    ) -> Result<(), ProblemError> {
        let nb = self.bodies.len();
        for b in 0..nb {
            let q = &y[6 * b..6 * b + 6];
            let k = &ev.kinematics[b];
            let theta = Vector3::new(q[3], q[4], q[5]);
            let rates = angle_rates(&theta, &k.omega).ok_or_else(|| {
                ProblemError::Recoverable(format!(
                    "{} rotation reached the Cardan singularity",
                    self.bodies[b].name
                ))
            })?;
            for i in 0..3 {
                f[6 * b + i] = k.velocity[i];
                f[6 * b + 3 + i] = rates[i];
            }
            for i in 0..6 {
                f[6 * nb + 6 * b + i] = ev.dynamics[b].force[i];
            }
        }
        f[12 * nb] = ev.crank_rate;
        if f.iter().any(|x| !x.is_finite()) {
            return Err(ProblemError::NonFinite);
        }
        Ok(())
    }

    /// Mass matrix blocks (one 6×6 per body) at `(t, y)`.
    pub(crate) fn body_mass(&self, t: f64, y: &[f64]) -> Vec<Matrix6<f64>> {
        self.evaluate(t, y)
            .dynamics
            .iter()
            .map(|d| d.mass)
            .collect()
    }

    /// Accelerations `[u'', ω']` per body from one evaluation of the equations of motion.
    pub(crate) fn accelerations(&self, ev: &Evaluation) -> Result<Vec<Vector6<f64>>, ProblemError> {
        ev.dynamics
            .iter()
            .map(|d| {
                d.mass
                    .lu()
                    .solve(&d.force)
                    .ok_or_else(|| ProblemError::Fatal("singular body mass matrix".into()))
            })
            .collect()
    }

    /// Checks that `y` is a state of this scene.
    pub fn check_state(&self, y: &[f64]) -> Result<(), ProblemError> {
        let n = self.dim();
        if y.len() != n {
            return Err(ProblemError::Fatal(format!(
                "state has {} entries, the engine model has {n}",
                y.len()
            )));
        }
        if let Some(i) = y.iter().position(|v| !v.is_finite()) {
            return Err(ProblemError::Fatal(format!("state entry {i} is {}", y[i])));
        }
        Ok(())
    }

    /// Total mechanical energy: kinetic + gravity + mounts + ring carriers (for energy checks).
    pub fn energy(&self, t: f64, y: &[f64]) -> Result<f64, ProblemError> {
        self.check_state(y)?;
        let ev = self.evaluate(t, y);
        let nb = self.bodies.len();
        let mut e = 0.0;
        for b in 0..nb {
            let v = Vector6::from_column_slice(&y[6 * nb + 6 * b..6 * nb + 6 * b + 6]);
            e += 0.5 * v.dot(&(ev.dynamics[b].mass * v));
            let crank = self.crank_state(
                t,
                y,
                Mode {
                    running: true,
                    nonlinear_mounts: false,
                },
            );
            for part in &self.bodies[b].parts {
                let x = ev.kinematics[b].point(&part.path(crank.angle).rho);
                e -= part.mass * self.gravity.dot(&x);
            }
        }
        for (i, m) in self.mounts.iter().enumerate() {
            if let (Some(m), Some(r)) = (m, &ev.mounts[i]) {
                e += m.energy(
                    &r.deflection,
                    self.inputs.stiffness_scale[i],
                    self.config.effects.mount_nonlinearity,
                );
            }
        }
        if nb == 2 {
            for rc in &self.ring_carriers {
                e += rc.energy(&rc.wrench(&ev.kinematics[0], &ev.kinematics[1]).deflection);
            }
        }
        Ok(e)
    }

    /// State with every body at its reference pose and the crank at the start angle.
    pub fn reference_state(&self) -> Vec<f64> {
        let mut y = vec![0.0; self.dim()];
        y[self.crank_index()] = self.start_angle();
        y
    }

    /// Sets the operating point of the linearised mounts from state `y`.
    pub(crate) fn set_operating_point(&mut self, y: &[f64]) {
        let hb = self.housing_index();
        let h = self.kinematics(y, hb);
        let reference = self.bodies[hb].reference;
        for m in self.mounts.iter_mut().flatten() {
            let x = h.point(&(m.bracket - reference));
            m.operating_point = m.deflection(&x, &Vector3::zeros());
        }
    }
}

impl OdeProblem for GroundScene {
    fn dim(&self) -> usize {
        12 * self.bodies.len() + 1
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

    fn has_mass_matrix(&self) -> bool {
        true
    }

    fn jacobian(&mut self, t: f64, y: &[f64], j: MatMut<'_, f64>) -> Result<bool, ProblemError> {
        self.assembled_jacobian(t, y, j)?;
        Ok(true)
    }

    fn mass(&mut self, t: f64, y: &[f64], mut m: MatMut<'_, f64>) -> Result<(), ProblemError> {
        let n = self.dim();
        let nb = self.bodies.len();
        for i in 0..n {
            for j in 0..n {
                m[(i, j)] = if i == j { 1.0 } else { 0.0 };
            }
        }
        let ev = self.evaluate(t, y);
        for b in 0..nb {
            let o = 6 * nb + 6 * b;
            for i in 0..6 {
                for j in 0..6 {
                    m[(o + i, o + j)] = ev.dynamics[b].mass[(i, j)];
                }
            }
        }
        Ok(())
    }
}
