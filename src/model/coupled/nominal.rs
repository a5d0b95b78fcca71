//! Nominal magnitudes of the states: the scale each state's absolute tolerance is relative to.
//!
//! Production integrator front ends set `atol_i = rtol · nominal_i`, so that one relative
//! tolerance controls the whole error. A single absolute tolerance in state units cannot do that
//! here: the powertrain vibrates by tens of µm and mrad and its velocities by mm/s to rad/s, so
//! an `atol` of 1e-8 decides the error of the displacements at every tolerance and that of the
//! velocities below rtol 1e-6, whatever the relative tolerance asks for.
//!
//! The nominals come from the amplitudes of the engine's forced vibration, taken from the model
//! at the operating point (the state the simulation starts from, at the crank-speed set-point `ω`
//! then), times [`RESOLVED_FRACTION`]: the error of a state is held relative to its value down
//! to that fraction of its amplitude, and absolute below.
//! - powertrain velocities and positions: the right-hand side at the operating point with the
//!   excitation in full and the crank turned through one working cycle gives each powertrain
//!   velocity coordinate its excitation acceleration; each harmonic `h` of the cycle (amplitude
//!   `A_h`, frequency `Ω_h`) moves a free mass by `A_h/Ω_h` (velocity) and `A_h/Ω_h²`
//!   (displacement) — the response above the suspension resonances, where the engine runs. The
//!   peaks of the harmonics added, the largest over the translational coordinates of all bodies
//!   is the amplitude of every translation, the largest over the rotational ones that of every
//!   angle (a coordinate the excitation does not reach by symmetry still vibrates through the
//!   couplings);
//! - the crank angle relative to the monoblock: one radian (a phase error of `rtol` rad is a
//!   relative error of `k·rtol` in an order-`k` excitation; the relative part of the weight is
//!   capped at one revolution, [`CoupledModel::magnitude_caps`]);
//! - the speed follower: `ω` for the crank speed, `ω/τ` for its acceleration (the follower's
//!   response to a set-point step of the whole speed);
//! - body modes: the modal force the mounts pass when the powertrain moves by its nominal
//!   displacement or angle (largest over the powertrain's position coordinates), divided by
//!   `max(ω_k, ω)²` (quasi-static below the mode, mass-controlled above it), and `ω` times that
//!   for the modal rates (the forced response at the excitation frequency).
//!
//! A nominal the excitation does not reach falls back so that every weight stays finite: a
//! powertrain coordinate of an engine without excitation to [`FALLBACK_NOMINAL`], a mode the
//! mounts hardly load to a millionth of the largest modal nominal. "Without excitation" means an
//! acceleration amplitude below [`NEGLIGIBLE_EXCITATION`], not exactly zero: with the gas and
//! mass forces off, the accelerations still flicker over the cycle in their last bits (the
//! round-off of the static balance, 1e-27 … 1e-24 m/s² on the default car), and nominals
//! scaled from that flicker gave absolute tolerances of 1e-37 m, twenty orders below the
//! round-off of the states themselves: an error test no step size can pass (the absolute
//! tolerance is the level below which a state is noise, as CVODE's guide puts it).

use super::CoupledModel;
use crate::model::RampInput;
use crate::ode::{OdeProblem, ProblemError, Tolerance};

/// Nominal (state units) of a powertrain coordinate when the engine excites nothing at all: the
/// one the former fixed absolute tolerance (1e-8 at the default rtol 1e-5) amounted to.
pub const FALLBACK_NOMINAL: f64 = 1e-3;

/// Crank speed (rad/s) below which the nominals are taken at this speed: an engine at rest has
/// no excitation to scale by, and a run-up from standstill should keep the scale of its idle.
pub const MIN_NOMINAL_SPEED: f64 = 600.0 * std::f64::consts::PI / 30.0;

/// Crank positions per working cycle at which the excitation is sampled: orders up to 12.
const CYCLE_SAMPLES: usize = 48;

/// The nominal as a fraction of the forced-vibration amplitude: the error of a state is held
/// relative to its value down to a tenth of its amplitude (through the zero crossings of the
/// oscillation) and absolute below. Measured at the default rtol 1e-5
/// (`docs/src/evidence/accuracy.md`) against the former fixed absolute tolerance of 1e-8: scene 2
/// takes −2 … +11 % steps for 0.5–1× its mount-force error, scene 1 3–36 % fewer for 1.6–2.8×;
/// 1/20 cost scene 2 12 % more steps, 1/5 was within the scatter of 1/10.
pub const RESOLVED_FRACTION: f64 = 0.1;

/// Acceleration amplitude over a working cycle (m/s² for translations, rad/s² for rotations)
/// below which the engine excites nothing and the powertrain nominals fall back to
/// [`FALLBACK_NOMINAL`]: about 1e-8 g, five orders below the vibration a vehicle's occupants
/// perceive (ISO 2631-1: about 0.01 m/s²) and far above the round-off the static balance leaves
/// in the accelerations (see the module documentation).
pub const NEGLIGIBLE_EXCITATION: f64 = 1e-7;

/// Smallest modal nominal relative to the largest: the modes the mounts hardly load.
const MODAL_FLOOR: f64 = 1e-6;

impl CoupledModel {
    /// Per state, its nominal magnitude at the operating point `(t, y_op)` (see the module
    /// documentation). `y_op` is the state the simulation starts from; the crank-speed set-point
    /// at `t` is the operating speed.
    ///
    /// Long on purpose: the powertrain's accelerations sampled over one working cycle, the forced
    /// response of each coordinate to their harmonics, and the modes' nominals from those
    /// positions are one computation on the same cycle samples.
    pub fn state_nominals(&mut self, t: f64, y_op: &[f64]) -> Result<Vec<f64>, ProblemError> {
        self.check_state(y_op)?;
        let l = self.layout;
        let n = l.dim();
        let omega = self.inputs.crank_speed.at(t).abs().max(MIN_NOMINAL_SPEED);
        // A balance shaft without a whole number of turns per cycle leaves the excitation without
        // a period; two revolutions still sample it well enough for a scale.
        let cycle = self
            .powertrain
            .cycle_angle()
            .unwrap_or(4.0 * std::f64::consts::PI);
        // The excitation in full: the fade-in is over at `t` when it started long before.
        let fade_start = self.fade_start;
        self.fade_start = t - self.powertrain.config().excitation_fade_in - 1.0;
        let set_point = self.inputs.crank_speed;
        self.inputs.crank_speed = RampInput::constant(omega);
        let mut y = y_op.to_vec();
        if let Some((w, a)) = l.follower_states() {
            y[w] = omega;
            y[a] = 0.0;
        }
        // Per powertrain velocity coordinate, its acceleration over one working cycle.
        let velocities: Vec<usize> = (0..l.bodies()).flat_map(|b| l.v(b)).collect();
        let mut history = vec![[0.0; CYCLE_SAMPLES]; velocities.len()];
        let mut f = vec![0.0; n];
        let mut sampled = Ok(());
        for k in 0..CYCLE_SAMPLES {
            y[l.crank_angle()] = y_op[l.crank_angle()] + cycle * k as f64 / CYCLE_SAMPLES as f64;
            if let Err(e) = self.rhs(t, &y, &mut f) {
                sampled = Err(e);
                break;
            }
            for (h, &i) in history.iter_mut().zip(&velocities) {
                h[k] = f[i];
            }
        }
        self.fade_start = fade_start;
        self.inputs.crank_speed = set_point;
        sampled?;
        // The forced response of a mass to each harmonic of the cycle, its peaks added: the
        // harmonic at `Ω_h` with acceleration amplitude `A_h` moves it by `A_h/Ω_h` and `A_h/Ω_h²`.
        let (mut translational, mut rotational) = ([0.0f64; 3], [0.0f64; 3]);
        for (c, h) in history.iter().enumerate() {
            let response = forced_response(h, omega * 2.0 * std::f64::consts::PI / cycle);
            let kind = if c % 6 < 3 {
                &mut translational
            } else {
                &mut rotational
            };
            for (k, r) in kind.iter_mut().zip(response) {
                *k = k.max(r);
            }
        }
        // `power` 1: velocity, 2: position.
        let scale = |kind: [f64; 3], power: usize| {
            if kind[0] > NEGLIGIBLE_EXCITATION {
                RESOLVED_FRACTION * kind[power]
            } else {
                FALLBACK_NOMINAL
            }
        };
        let mut nominal = vec![0.0; n];
        for b in 0..l.bodies() {
            let (q, v) = (l.q(b).start, l.v(b).start);
            for i in 0..3 {
                nominal[q + i] = scale(translational, 2);
                nominal[q + 3 + i] = scale(rotational, 2);
                nominal[v + i] = scale(translational, 1);
                nominal[v + 3 + i] = scale(rotational, 1);
            }
        }
        nominal[l.crank_angle()] = 1.0;
        if let Some((w, a)) = l.follower_states() {
            nominal[w] = omega;
            nominal[a] = omega / self.follower.time_constant;
        }
        if l.modes() > 0 {
            let modal = self.modal_force_scale(t, y_op, &nominal)?;
            let (eta, rate) = (l.eta().start, l.eta_rate().start);
            let largest = (0..l.modes())
                .map(|k| modal[k] / self.body.omega[k].max(omega).powi(2))
                .fold(0.0, f64::max);
            for k in 0..l.modes() {
                let amplitude = modal[k] / self.body.omega[k].max(omega).powi(2);
                let amplitude = if largest > 0.0 {
                    amplitude.max(MODAL_FLOOR * largest)
                } else {
                    FALLBACK_NOMINAL
                };
                nominal[eta + k] = amplitude;
                nominal[rate + k] = amplitude * omega;
            }
        }
        Ok(nominal)
    }

    /// Per mode, the largest change of the modal force when one powertrain position coordinate
    /// moves by its nominal.
    fn modal_force_scale(
        &mut self,
        t: f64,
        y_op: &[f64],
        nominal: &[f64],
    ) -> Result<Vec<f64>, ProblemError> {
        let l = self.layout;
        let rate = l.eta_rate();
        let mut base = vec![0.0; l.dim()];
        self.rhs(t, y_op, &mut base)?;
        let mut moved = vec![0.0; l.dim()];
        let mut y = y_op.to_vec();
        let mut scale = vec![0.0f64; l.modes()];
        for j in l.positions() {
            y[j] = y_op[j] + nominal[j];
            self.rhs(t, &y, &mut moved)?;
            y[j] = y_op[j];
            for (k, i) in rate.clone().enumerate() {
                scale[k] = scale[k].max((moved[i] - base[i]).abs());
            }
        }
        Ok(scale)
    }

    /// The integrator's absolute tolerance: `abs_tol` for every state when it is set (> 0),
    /// otherwise `rel_tol` times each state's nominal at the operating point `(t, y_op)`
    /// ([`Self::state_nominals`]), so that the relative tolerance alone sets the accuracy.
    pub fn absolute_tolerance(
        &mut self,
        rel_tol: f64,
        abs_tol: f64,
        t: f64,
        y_op: &[f64],
    ) -> Result<Tolerance, String> {
        if abs_tol != 0.0 {
            // A negative or non-finite value is the integrator's to reject, with its message.
            return Ok(Tolerance::Scalar(abs_tol));
        }
        let nominals = self.state_nominals(t, y_op).map_err(|e| {
            let cause = match e {
                ProblemError::NonFinite => "a non-finite right-hand side".to_owned(),
                ProblemError::Recoverable(m) | ProblemError::Fatal(m) => m,
            };
            format!("nominal state magnitudes at the operating point: {cause}")
        })?;
        Ok(Tolerance::Vector(
            nominals.into_iter().map(|x| rel_tol * x).collect(),
        ))
    }
}

/// Acceleration, velocity and displacement amplitude (peaks of the harmonics added) of a free
/// mass driven by the periodic acceleration `a` sampled evenly over one period of fundamental
/// `omega` (rad/s).
fn forced_response(a: &[f64], omega: f64) -> [f64; 3] {
    let n = a.len();
    let mut out = [0.0; 3];
    for h in 1..n.div_ceil(2) {
        let (mut re, mut im) = (0.0, 0.0);
        for (k, x) in a.iter().enumerate() {
            let phase = 2.0 * std::f64::consts::PI * (h * k) as f64 / n as f64;
            re += x * phase.cos();
            im -= x * phase.sin();
        }
        let amplitude = 2.0 * re.hypot(im) / n as f64;
        let w = h as f64 * omega;
        out[0] += amplitude;
        out[1] += amplitude / w;
        out[2] += amplitude / (w * w);
    }
    out
}

/// One log line on the absolute tolerance in use.
pub fn describe_absolute_tolerance(atol: &Tolerance) -> String {
    match atol {
        Tolerance::Scalar(a) => format!("absolute tolerance {a:e} for every state (as given)"),
        Tolerance::Vector(v) => {
            let (lo, hi) = v.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), a| {
                (lo.min(*a), hi.max(*a))
            });
            format!(
                "absolute tolerance follows the relative one: rtol times each state's nominal \
                 magnitude, {lo:.1e} to {hi:.1e} in state units"
            )
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cosim::{EffectOverrides, Effects, Inputs, Settings, Simulation};

    fn engine_on_ground(effects: Effects) -> (Simulation, Vec<f64>) {
        let mut settings = Settings::default();
        settings.vehicle.effects = EffectOverrides::all(effects);
        let sim = Simulation::new(&settings, 0.0, &Inputs::steady(2000.0)).unwrap();
        let y0 = sim.state().to_vec();
        (sim, y0)
    }

    /// The amplitudes behind the nominals against the vibration of a run at that operating
    /// point: an estimate, but of the right size for each kind of coordinate.
    #[test]
    fn nominals_scale_with_the_vibration_they_describe() {
        let (mut sim, y0) = engine_on_ground(Effects::default());
        let mut model = sim.model().clone();
        let nominal = model.state_nominals(0.0, &y0).unwrap();
        let l = *model.layout();
        let kinds: [(&str, Vec<usize>); 4] = [
            (
                "translation",
                (0..l.bodies()).flat_map(|b| l.q(b).take(3)).collect(),
            ),
            (
                "angle",
                (0..l.bodies()).flat_map(|b| l.q(b).skip(3)).collect(),
            ),
            (
                "velocity",
                (0..l.bodies()).flat_map(|b| l.v(b).take(3)).collect(),
            ),
            (
                "angular velocity",
                (0..l.bodies()).flat_map(|b| l.v(b).skip(3)).collect(),
            ),
        ];
        let mut largest = [0.0f64; 4];
        // The fade-in ends at 0.1 s; the window is the stationary vibration after it.
        for k in 1..=300 {
            sim.advance_to(k as f64 * 1e-3).unwrap();
            if k > 150 {
                for (m, (_, idx)) in largest.iter_mut().zip(&kinds) {
                    for &i in idx {
                        *m = m.max((sim.state()[i] - y0[i]).abs());
                    }
                }
            }
        }
        for ((name, idx), measured) in kinds.iter().zip(largest) {
            let estimate = nominal[idx[0]] / RESOLVED_FRACTION;
            assert!(idx.iter().all(|&i| nominal[i] == nominal[idx[0]]));
            let ratio = estimate / measured;
            assert!(
                (0.5..5.0).contains(&ratio),
                "{name}: amplitude estimate {estimate:.3e}, vibration {measured:.3e}"
            );
        }
        assert_eq!(nominal[l.crank_angle()], 1.0);
        let (w, a) = l.follower_states().unwrap();
        assert!((nominal[w] - 2000.0 * crate::cosim::RPM_TO_RAD_PER_S).abs() < 1e-9);
        assert!((nominal[a] - nominal[w] / model.follower().time_constant).abs() < 1e-6);
    }

    #[test]
    fn a_set_absolute_tolerance_wins_and_zero_follows_the_relative_one() {
        let (sim, y0) = engine_on_ground(Effects::default());
        let mut model = sim.model().clone();
        assert_eq!(
            model.absolute_tolerance(1e-6, 3e-9, 0.0, &y0).unwrap(),
            Tolerance::Scalar(3e-9)
        );
        let nominal = model.state_nominals(0.0, &y0).unwrap();
        let Tolerance::Vector(atol) = model.absolute_tolerance(1e-6, 0.0, 0.0, &y0).unwrap() else {
            panic!("abs_tol 0 must give a tolerance per state");
        };
        for (a, x) in atol.iter().zip(&nominal) {
            assert!((a - 1e-6 * x).abs() <= 1e-12 * a.abs());
        }
        // The evaluation must leave the model as it found it.
        assert_eq!(model.fade_start(), sim.model().fade_start());
        assert_eq!(model.inputs(), sim.model().inputs());
    }

    #[test]
    fn an_engine_without_excitation_gets_finite_positive_nominals() {
        let quiet = Effects {
            gas_forces: false,
            mass_forces: false,
            ..Effects::default()
        };
        let (sim, y0) = engine_on_ground(quiet);
        let mut model = sim.model().clone();
        let nominal = model.state_nominals(0.0, &y0).unwrap();
        assert!(
            nominal.iter().all(|x| x.is_finite() && *x > 0.0),
            "{nominal:?}"
        );
        // The accelerations still change over the cycle in their last bits (the round-off of
        // the static balance): that is no excitation to scale the tolerances by.
        let l = *model.layout();
        for b in 0..l.bodies() {
            for i in l.q(b).chain(l.v(b)) {
                assert_eq!(nominal[i], FALLBACK_NOMINAL, "state {i}");
            }
        }
    }

    /// The threshold lies far from both sides: the engine's smallest real excitation (idle, 600
    /// rpm, no gas forces) and the round-off of an engine without any.
    #[test]
    fn the_excitation_threshold_separates_idle_from_round_off() {
        let mass_only = Effects {
            gas_forces: false,
            ..Effects::default()
        };
        let mut settings = Settings::default();
        settings.vehicle.effects = EffectOverrides::all(mass_only);
        let sim = Simulation::new(&settings, 0.0, &Inputs::steady(0.0)).unwrap();
        let y0 = sim.state().to_vec();
        let mut model = sim.model().clone();
        let nominal = model.state_nominals(0.0, &y0).unwrap();
        let l = *model.layout();
        let velocity = nominal[l.v(0).start];
        // A nominal scaled from the excitation, not the fallback: the velocity amplitude
        // (nominal / RESOLVED_FRACTION) at the lowest harmonic bounds the acceleration from below.
        assert_ne!(velocity, FALLBACK_NOMINAL);
        let omega = MIN_NOMINAL_SPEED / 2.0;
        let acceleration = velocity / RESOLVED_FRACTION * omega;
        assert!(
            acceleration > 1e3 * NEGLIGIBLE_EXCITATION,
            "idle excitation {acceleration:e} m/s²"
        );
    }
}
