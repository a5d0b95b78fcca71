//! One evaluation of the coupled equations of motion, and the right-hand side built from it.

use faer::MatMut;
use nalgebra::{Vector3, Vector6};

use super::{CoupledModel, MountTarget};
use crate::model::kinematics::{angle_rates, rotation_matrix};
use crate::model::mount::MountResponse;
use crate::model::powertrain::composite::{BodyDynamics, BodyKinematics, CrankDriveState};
use crate::ode::{BlockLowRankJacobian, BlockLowRankShape, OdeProblem, ProblemError};

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
    /// Crank standing, no gas, nonlinear mounts: the static residual.
    pub(crate) const STATIC: Mode = Mode {
        running: false,
        nonlinear_mounts: true,
    };
    /// Crank standing, no gas, mounts linearised at the operating point: the linearisation of
    /// the modal analysis.
    pub(crate) const AT_REST: Mode = Mode {
        running: false,
        nonlinear_mounts: false,
    };
}

/// Everything one evaluation of the equations of motion produces.
#[derive(Debug, Clone)]
pub struct Evaluation {
    /// Position, rotation and velocities per powertrain body.
    pub kinematics: Vec<BodyKinematics>,
    /// Mass matrix and generalised forces per powertrain body (mount forces included).
    pub dynamics: Vec<BodyDynamics>,
    /// Per configured mount (None when removed).
    pub mounts: Vec<Option<MountResponse>>,
    /// Generalised body forces `Σ_p φ_{p,k} · (−F_p)` per mode.
    pub modal_force: Vec<f64>,
    /// The crank drive as the parts saw it.
    pub crank: CrankDriveState,
    /// Crank angle rate `φ' = ω_c − e·ω_block`.
    pub crank_rate: f64,
    /// Crank speed (rad/s, from the follower or the set-point).
    pub crank_speed: f64,
    /// Crank acceleration (rad/s², from the follower or the set-point).
    pub crank_acceleration: f64,
}

impl Evaluation {
    /// Storage for [`CoupledModel::evaluate_into`], grown on first use.
    pub(crate) fn empty() -> Self {
        Self {
            kinematics: Vec::new(),
            dynamics: Vec::new(),
            mounts: Vec::new(),
            modal_force: Vec::new(),
            crank: CrankDriveState::at_rest(0.0),
            crank_rate: 0.0,
            crank_speed: 0.0,
            crank_acceleration: 0.0,
        }
    }
}

/// `M⁻¹ Q` of one body: Cholesky (the composite mass matrix is symmetric positive definite), LU
/// should rounding leave it indefinite.
fn body_acceleration(d: &BodyDynamics) -> Result<Vector6<f64>, ProblemError> {
    if let Some(c) = d.mass.cholesky() {
        return Ok(c.solve(&d.force));
    }
    d.mass
        .lu()
        .solve(&d.force)
        .ok_or_else(|| ProblemError::Fatal("singular body mass matrix".into()))
}

impl CoupledModel {
    /// Pose and velocity of powertrain body `b` in state `y`.
    pub(crate) fn kinematics(&self, y: &[f64], b: usize) -> BodyKinematics {
        let q = &y[self.layout.q(b)];
        let v = &y[self.layout.v(b)];
        BodyKinematics {
            position: self.powertrain.bodies()[b].reference + Vector3::new(q[0], q[1], q[2]),
            rotation: rotation_matrix(&Vector3::new(q[3], q[4], q[5])),
            velocity: Vector3::new(v[0], v[1], v[2]),
            omega: Vector3::new(v[3], v[4], v[5]),
        }
    }

    /// Crank speed and acceleration at `(t, y)`: the follower's states, or the set-point.
    fn crank_motion(&self, t: f64, y: &[f64]) -> (f64, f64) {
        match self.layout.follower_states() {
            Some((w, a)) => (y[w], y[a]),
            None => (self.inputs.crank_speed.at(t), self.inputs.crank_speed.rate),
        }
    }

    fn crank_state(
        &self,
        t: f64,
        phi: f64,
        speed: f64,
        acceleration: f64,
        mode: Mode,
    ) -> CrankDriveState {
        if !mode.running {
            return CrankDriveState {
                angle: phi,
                speed: 0.0,
                acceleration: 0.0,
                excitation: 0.0,
                spin: 0.0,
            };
        }
        let fx = self.effects();
        let fade = self.excitation(t);
        CrankDriveState {
            angle: if fx.mass_forces {
                phi
            } else {
                self.powertrain.start_angle()
            },
            speed,
            acceleration,
            excitation: if fx.mass_forces { fade } else { 0.0 },
            spin: if fx.gyroscopic { fade * speed } else { 0.0 },
        }
    }

    pub(crate) fn evaluate_mode(&self, t: f64, y: &[f64], mode: Mode) -> Evaluation {
        let mut ev = Evaluation::empty();
        self.evaluate_into(t, y, mode, &mut ev);
        ev
    }

    /// [`Self::evaluate_mode`] into `ev`'s storage: no allocation once it has grown.
    pub(crate) fn evaluate_into(&self, t: f64, y: &[f64], mode: Mode, ev: &mut Evaluation) {
        let nb = self.layout.bodies();
        let phi = y[self.layout.crank_angle()];
        let (speed, acceleration) = self.crank_motion(t, y);
        let crank = self.crank_state(t, phi, speed, acceleration, mode);
        // Combustion needs a turning crank: the gas excitation fades out below the firing speed.
        let gas_scale = if mode.running {
            self.excitation(t) * super::super::powertrain::firing_factor(speed)
        } else {
            0.0
        };
        let load_torque = self.inputs.load_torque.at(t);
        ev.kinematics.clear();
        ev.kinematics.extend((0..nb).map(|b| self.kinematics(y, b)));
        ev.dynamics.clear();
        for b in 0..nb {
            let d = self.powertrain.local_dynamics(
                b,
                &ev.kinematics[b],
                &crank,
                phi,
                gas_scale,
                load_torque,
            );
            ev.dynamics.push(d);
        }
        self.powertrain
            .add_ring_carriers(&ev.kinematics, &mut ev.dynamics);
        let hb = self.powertrain.housing_index();
        self.add_mounts(t, y, hb, mode, ev);
        let k0 = &ev.kinematics[0];
        let e = k0.rotation * Vector3::y();
        ev.crank_rate = if mode.running { speed } else { 0.0 } - e.dot(&k0.omega);
        ev.crank = crank;
        ev.crank_speed = speed;
        ev.crank_acceleration = acceleration;
    }

    /// Mount forces on the housing (body `hb`) and, as generalised forces, on the body: into
    /// `ev.dynamics[hb]`, `ev.mounts` (per configured mount) and `ev.modal_force`.
    fn add_mounts(&self, t: f64, y: &[f64], hb: usize, mode: Mode, ev: &mut Evaluation) {
        let reference = self.powertrain.bodies()[hb].reference;
        let nonlinear = mode.nonlinear_mounts || self.effects().mount_nonlinearity;
        ev.modal_force.clear();
        ev.modal_force.resize(self.layout.modes(), 0.0);
        ev.mounts.clear();
        let h = ev.kinematics[hb];
        for (i, m) in self.mounts.iter().enumerate() {
            let Some(m) = m.as_ref() else {
                ev.mounts.push(None);
                continue;
            };
            let local = m.mount.bracket - reference;
            let x = h.point(&local);
            let xv = h.point_velocity(&local);
            let (a, av) = self.attachment_motion(i, m.target, t, y);
            let (k_scale, c_scale) = self.inputs.mount_scales(i, t);
            let r = m.mount.response(
                &(x - m.mount.attachment - a),
                &(xv - av),
                k_scale,
                c_scale,
                nonlinear,
            );
            ev.dynamics[hb].add_point_force(&h, &x, &r.force);
            if let MountTarget::BodyPoint(p) = m.target {
                for (g, s) in ev.modal_force.iter_mut().zip(&self.body.points[p].shape) {
                    *g -= s[0] * r.force.x + s[1] * r.force.y + s[2] * r.force.z;
                }
            }
            ev.mounts.push(Some(r));
        }
    }

    /// One evaluation of the equations of motion of the running engine at `(t, y)`.
    pub fn evaluate(&self, t: f64, y: &[f64]) -> Evaluation {
        self.evaluate_mode(t, y, Mode::RUNNING)
    }

    /// Writes `f(t, y)` from an evaluation at `(t, y)` in mode `mode`.
    pub(crate) fn write_rhs(
        &self,
        t: f64,
        y: &[f64],
        ev: &Evaluation,
        mode: Mode,
        f: &mut [f64],
    ) -> Result<(), ProblemError> {
        let l = &self.layout;
        for (b, dynamics) in ev.dynamics.iter().enumerate() {
            let acc = body_acceleration(dynamics)?;
            let q = &y[l.q(b)];
            let k = &ev.kinematics[b];
            let theta = Vector3::new(q[3], q[4], q[5]);
            let rates = angle_rates(&theta, &k.omega).ok_or_else(|| {
                ProblemError::Recoverable(format!(
                    "{} rotation reached the Cardan singularity",
                    self.powertrain.bodies()[b].name
                ))
            })?;
            let qr = l.q(b).start;
            for i in 0..3 {
                f[qr + i] = k.velocity[i];
                f[qr + 3 + i] = rates[i];
            }
            f[l.v(b)].copy_from_slice(acc.as_slice());
        }
        f[l.crank_angle()] = ev.crank_rate;
        if let Some((w, a)) = l.follower_states() {
            let (dw, da) = if mode.running {
                let s = &self.inputs.crank_speed;
                self.follower
                    .rates(ev.crank_speed, ev.crank_acceleration, s.at(t), s.rate)
            } else {
                (0.0, 0.0)
            };
            f[w] = dw;
            f[a] = da;
        }
        let (eta, rate) = (l.eta().start, l.eta_rate().start);
        let body = &self.body;
        for k in 0..l.modes() {
            let (x, v) = (y[eta + k], y[rate + k]);
            f[eta + k] = v;
            f[rate + k] = ev.modal_force[k]
                - 2.0 * body.zeta[k] * body.omega[k] * v
                - body.omega[k] * body.omega[k] * x;
        }
        if f.iter().any(|x| !x.is_finite()) {
            return Err(ProblemError::NonFinite);
        }
        Ok(())
    }

    /// Right-hand side with the engine at rest (crank standing, no gas, linearised mounts): the
    /// linearisation point of the modal analysis.
    pub(crate) fn rhs_at_rest(&self, y: &[f64], f: &mut [f64]) -> Result<(), ProblemError> {
        let t = self.fade_start;
        let ev = self.evaluate_mode(t, y, Mode::AT_REST);
        self.write_rhs(t, y, &ev, Mode::AT_REST, f)
    }

    /// Body-point accelerations: modal accelerations η̈ from one evaluation at `(t, y)`.
    pub fn modal_accelerations(&self, t: f64, y: &[f64]) -> Result<Vec<f64>, ProblemError> {
        self.check_state(y)?;
        let mut f = vec![0.0; y.len()];
        let ev = self.evaluate(t, y);
        self.write_rhs(t, y, &ev, Mode::RUNNING, &mut f)?;
        Ok(f[self.layout.eta_rate()].to_vec())
    }
}

impl OdeProblem for CoupledModel {
    fn dim(&self) -> usize {
        self.layout.dim()
    }

    fn rhs(&mut self, t: f64, y: &[f64], f: &mut [f64]) -> Result<(), ProblemError> {
        let n = self.layout.dim();
        if y.len() != n || f.len() != n {
            return Err(ProblemError::Fatal(format!(
                "state/derivative lengths {}/{} differ from {n}",
                y.len(),
                f.len()
            )));
        }
        // The evaluation's vectors are the model's own scratch, so the right-hand side does not
        // allocate.
        let mut ev = std::mem::replace(&mut self.scratch, Evaluation::empty());
        self.evaluate_into(t, y, Mode::RUNNING, &mut ev);
        let result = self.write_rhs(t, y, &ev, Mode::RUNNING, f);
        self.scratch = ev;
        result
    }

    fn jacobian(&mut self, t: f64, y: &[f64], j: MatMut<'_, f64>) -> Result<bool, ProblemError> {
        self.dense_jacobian(t, y, j)?;
        Ok(true)
    }

    fn jacobian_structure(&self) -> Option<BlockLowRankShape> {
        self.uses_block_low_rank().then(|| self.jacobian_shape())
    }

    fn structured_jacobian(
        &mut self,
        t: f64,
        y: &[f64],
        j: &mut BlockLowRankJacobian,
    ) -> Result<(), ProblemError> {
        self.structured(t, y, j)
    }
}
