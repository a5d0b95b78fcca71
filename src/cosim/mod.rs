//! The co-simulation runtime: a scene, its integrator and its inputs, stepped from one
//! communication point to the next. It knows the physics only through the coupled model
//! ([`crate::model::CoupledModel`]), and nothing of the C ABI: the FMI layer ([`crate::fmi2`]) maps variables onto [`Settings`], [`Inputs`] and
//! [`Outputs`].
//!
//! The integrator keeps its history across communication points and lands exactly on each one
//! (a stop time, not a restart); it restarts at order 1 only where an input really jumps.

pub mod body;
pub mod error;
pub mod export;
mod inputs;
pub mod periodic;
pub mod runtime;
pub mod scene;
pub mod settings;

pub use crate::cms::CacheSetting;
pub use crate::model::scene::{BodyOption, BodyOptions, SceneKind, AUTO_CUTOFF_MARGIN};
pub use crate::model::RampInput;
pub use crate::model::{EffectSwitch, Effects};
pub use body::{BodySimulation, BodyState};
pub use error::{Error, Input};
pub use inputs::Inputs;
pub use runtime::{FmuKind, Runtime, RuntimeState};
pub use scene::{ComfortPoints, FMU_MOUNTS};
pub use settings::{
    EffectOverrides, ExportRequest, Replaced, Settings, VehicleOverrides, VehicleSetting,
};

pub use crate::model::body_alone::PointKinematics;
use crate::model::CoupledModel;
use crate::ode::{Bdf, BdfOptions, BdfSnapshot, OdeProblem};

/// Name of the default configuration in the FMU's resources folder.
pub const DEFAULT_CONFIG_NAME: &str = "vehicle.json";

/// Half-width in s of the central difference of [`Simulation::output_derivatives`]: small
/// against the fastest vibration the model carries (kHz), large against rounding (the outputs'
/// relative rounding 1e-16 becomes 1e-9 of the value per second).
pub const OUTPUT_DERIVATIVE_STEP: f64 = 1e-7;

/// rpm → rad/s: the `rpm` unit of the variable table.
pub const RPM_TO_RAD_PER_S: f64 = crate::variables::units::RPM;

/// Results at a communication point, SI units, vehicle frame.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Outputs {
    /// Force of each mount on the ground/chassis side (zero for a removed mount), N.
    pub mount_force: [[f64; 3]; 4],
    /// Cumulative crank angle, rad.
    pub crank_angle: f64,
    /// Powertrain (housing) CG displacement from its design position, m.
    pub powertrain_displacement: [f64; 3],
    /// Powertrain (housing) rotation vector, rad.
    pub powertrain_rotation: [f64; 3],
    /// Powertrain (housing) CG acceleration from the equations of motion, m/s².
    pub powertrain_acceleration: [f64; 3],
    /// Steering-wheel acceleration from the equations of motion, m/s² (scene 2; zero in scene 1).
    pub steering_wheel_acceleration: [f64; 3],
    /// Seat-rail acceleration from the equations of motion, m/s² (scene 2; zero in scene 1).
    pub seat_acceleration: [f64; 3],
    /// The body alone: motion of the body at each mount point (zero in the engine's scenes).
    pub mount_point: [PointKinematics; 4],
}

/// Work counters of the integrator since initialisation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Counters {
    /// Accepted integrator steps.
    pub steps: u64,
    /// Evaluations of the right-hand side (the model's equations of motion).
    pub rhs_evaluations: u64,
    /// Evaluations of the Jacobian of the right-hand side.
    pub jacobian_evaluations: u64,
    /// LU factorisations of the Newton iteration matrix.
    pub factorizations: u64,
    /// Newton iterations (one linear solve each).
    pub newton_iterations: u64,
    /// Integrator restarts at order 1 for input discontinuities since this simulation was built
    /// or restored.
    pub restarts: u64,
}

/// A step that could not be completed; the simulation stays at `reached`.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{error} (reached t = {reached} s)")]
pub struct StepFailure {
    /// Why the integrator could not go on.
    pub error: Error,
    /// Time in s of the last successful integrator step: where the simulation now is.
    pub reached: f64,
}

/// A scene with its integrator, ready to step.
#[derive(Clone)]
pub struct Simulation {
    scene: CoupledModel,
    /// How the model was built (for the log).
    notes: Vec<String>,
    /// Configuration values the settings replaced.
    replaced: Vec<Replaced>,
    integrator: Bdf,
    restarts: u64,
    /// An interface input (an external body's motion) jumped at the communication time without
    /// a restart: should the next step fail on the kink, it is retried from a restart there.
    interface_jumped: bool,
    /// Communication time and the state there. The integrator steps past communication points
    /// and interpolates, so its own time is usually a little ahead.
    time: f64,
    state: Vec<f64>,
    /// The inputs in force, sized to the configuration's mounts.
    inputs: Inputs,
    /// Where the comfort outputs are among the model's output points.
    comfort: ComfortPoints,
    /// Where and under which inputs the static equilibrium was found: with the settings, this
    /// rebuilds the scene exactly (fade-in start, mount operating points).
    initial_time: f64,
    initial_inputs: Inputs,
    /// The static equilibrium found there (the linearisation point of [`Simulation::natural_modes`]).
    equilibrium: Vec<f64>,
}

impl Simulation {
    /// Builds the scene, finds its static equilibrium under the inputs at `t0` and starts the
    /// integrator there, or, with [`Settings::periodic_start`], on the periodic steady state.
    pub fn new(settings: &Settings, t0: f64, inputs: &Inputs) -> Result<Simulation, Error> {
        let mut sim = Self::at_static_equilibrium(settings, t0, inputs)?;
        if settings.periodic_start {
            sim.start_on_periodic_orbit()?;
        }
        Ok(sim)
    }

    /// The scene at its static equilibrium under the inputs at `t0`, excitation fading in.
    fn at_static_equilibrium(
        settings: &Settings,
        t0: f64,
        inputs: &Inputs,
    ) -> Result<Simulation, Error> {
        let mut options = BdfOptions {
            rtol: settings.rel_tol,
            max_order: settings.max_order,
            stability_limit_detection: settings.stability_limit_detection,
            // The coupled model's Jacobian changes slowly over ~50 steps (one Jacobian per ~0.4
            // revolution at CVODE's 50): at 100 the Newton iterations and factorisations per
            // step stayed the same in both scenes and the Jacobians per step halved
            // (`realtime --breakdown`).
            jacobian_max_age: 100,
            ..BdfOptions::default()
        };
        let scene::BuiltModel {
            model: mut scene,
            replaced,
            mut notes,
        } = scene::build_model(settings)?;
        let inputs = scene::apply_inputs(&mut scene, inputs)?;
        let comfort = ComfortPoints::of(&scene);
        options.magnitude_cap = Some(scene.magnitude_caps());
        let y0 = scene.static_equilibrium(t0).map_err(|e| e.to_string())?;
        options.atol = scene.absolute_tolerance(settings.rel_tol, settings.abs_tol, t0, &y0)?;
        notes.push(crate::model::coupled::describe_absolute_tolerance(
            &options.atol,
        ));
        let integrator = Bdf::new(&mut scene, t0, &y0, options).map_err(|e| e.to_string())?;
        Ok(Simulation {
            scene,
            notes,
            replaced,
            integrator,
            time: t0,
            equilibrium: y0.clone(),
            state: y0,
            initial_inputs: inputs.clone(),
            inputs,
            comfort,
            initial_time: t0,
            restarts: 0,
            interface_jumped: false,
        })
    }

    /// Moves the start onto the periodic orbit at the current inputs: excitation in full from
    /// the start time, state from [`periodic::periodic_start`], integrator restarted there.
    fn start_on_periodic_orbit(&mut self) -> Result<(), Error> {
        let t0 = self.time;
        let fade_in = self.scene.powertrain().config().excitation_fade_in;
        self.scene
            .set_fade_start(t0 - fade_in)
            .map_err(|e| e.to_string())?;
        let options = self.integrator.options().clone();
        let start = periodic::periodic_start(&mut self.scene, &options, t0, &self.state)
            .map_err(|m| format!("periodic start: {m}"))?;
        self.notes.push(format!(
            "periodic start: orbit of one working cycle ({:.3} ms) closed to {:.2e} of the error \
             weights after {} iterations (start guess {:.2e})",
            start.period * 1e3,
            start.residual,
            start.iterations,
            start.initial_residual
        ));
        self.integrator =
            Bdf::new(&mut self.scene, t0, &start.state, options).map_err(|e| e.to_string())?;
        self.state = start.state;
        Ok(())
    }

    /// Lines for the log describing the scene.
    pub fn describe(&self) -> Vec<String> {
        self.notes.clone()
    }

    /// The vehicle configuration's values that the settings replaced.
    pub fn replaced(&self) -> &[Replaced] {
        &self.replaced
    }

    /// Natural modes of the model linearised at its static equilibrium under the initial inputs
    /// (engine at rest, mounts at their operating points), ascending in frequency: the coupled
    /// frequencies of a Campbell diagram. Independent of how far the simulation has run.
    pub fn natural_modes(&self) -> Result<Vec<crate::model::Mode>, Error> {
        Ok(self.linearisation_model()?.modes(&self.equilibrium)?)
    }

    /// The model as it was at the static equilibrium (initial inputs, fade-in start): what
    /// [`Self::natural_modes`] and the analysis export linearise at [`Self::equilibrium`].
    fn linearisation_model(&self) -> Result<CoupledModel, Error> {
        let mut model = self.scene.clone();
        scene::apply_checked_inputs(&mut model, &self.initial_inputs)?;
        model
            .set_fade_start(self.initial_time)
            .map_err(|e| e.to_string())?;
        Ok(model)
    }

    /// The coupled model being integrated.
    pub fn model(&self) -> &CoupledModel {
        &self.scene
    }

    /// The state at the communication time.
    pub fn state(&self) -> &[f64] {
        &self.state
    }

    /// Number of integrator states (what a switched-off effect saves).
    pub fn state_count(&self) -> usize {
        self.scene.dim()
    }

    /// The communication time reached.
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Whether the model accepts `inputs` ([`crate::model::ModelInputs::validate`]), changing
    /// nothing.
    pub fn check_inputs(&self, inputs: &Inputs) -> Result<(), Error> {
        let mounts = self.scene.mounts().len();
        Ok(inputs.sized(mounts).model.validate(mounts)?)
    }

    /// The model's rule for one input ([`crate::model::Input::check`]), changing nothing; an
    /// input this model does not have passes.
    pub fn check_input(&self, input: Input, ramp: &RampInput) -> Result<(), Error> {
        Ok(self.scene.check_input(input, ramp)?)
    }

    /// Applies inputs valid from the current time on (checked by the model first; on refusal
    /// nothing changed). Returns whether an input jumped ([`Self::set_checked_inputs`]).
    pub fn set_inputs(&mut self, inputs: &Inputs) -> Result<bool, Error> {
        self.check_inputs(inputs)?;
        self.set_checked_inputs(inputs)
    }

    /// Applies inputs valid from the current time on, each of which passed its rule where it
    /// was set ([`Self::check_input`]): the rules do not run again. Returns whether an input
    /// jumped, in which case the integrator restarted at order 1 from the state at the
    /// communication time (its history, and any step it took past that time, describe the old
    /// inputs).
    pub fn set_checked_inputs(&mut self, inputs: &Inputs) -> Result<bool, Error> {
        let t = self.time;
        let previous = self.inputs.clone();
        // Sized to the mounts; on refusal nothing changed.
        let inputs = scene::apply_checked_inputs(&mut self.scene, inputs)?;
        // With the speed follower the crank speed is a state: a set-point jump bends its
        // trajectory but does not break it. It only needs a restart when the kink it puts into
        // the crank acceleration would fail the error test of the next step anyway.
        let mut compared = inputs.model.clone();
        let mut sharp_kink = false;
        if self.scene.layout().has_follower() {
            compared.crank_speed = previous.model.crank_speed;
            sharp_kink = self.follower_kink_is_sharp(&inputs, t);
        }
        let jumped = sharp_kink || !previous.model.continue_into(&compared, t);
        let interface_jumped = !previous.interface_continues_into(&inputs, t);
        // An external body may move a mount beyond its characteristic: refuse the inputs
        // (naming the mount) rather than extrapolate a curve the mount does not have.
        if let Err(e) = self.interface_in_range() {
            scene::apply_checked_inputs(&mut self.scene, &previous)?;
            return Err(e);
        }
        self.inputs = inputs;
        self.interface_jumped = interface_jumped && !jumped;
        if jumped {
            if let Err(e) = self.integrator.restart_at(&mut self.scene, t, &self.state) {
                // Leave everything as it was: the old inputs still describe the integrator.
                scene::apply_checked_inputs(&mut self.scene, &previous)?;
                self.inputs = previous;
                return Err(Error::Model(e.to_string()));
            }
            self.restarts += 1;
        }
        Ok(jumped)
    }

    /// Whether the crank-speed set-point change at `t` bends the follower's acceleration so
    /// sharply that the next step, at the step size the integrator plans, would fail its error
    /// test: the jump `Δα' = Δs/τ² + 2Δṡ/τ` in the acceleration's derivative makes a local error
    /// of about `Δα'·h`, compared with the acceleration's error weight.
    fn follower_kink_is_sharp(&self, inputs: &Inputs, t: f64) -> bool {
        let Some((_, acceleration)) = self.scene.layout().follower_states() else {
            return false;
        };
        let tau = self.scene.follower().time_constant;
        let (old, new) = (&self.inputs.model.crank_speed, &inputs.model.crank_speed);
        let kink =
            (new.at(t) - old.at(t)).abs() / (tau * tau) + 2.0 * (new.rate - old.rate).abs() / tau;
        let options = self.integrator.options();
        let weight = options.atol.get(acceleration) + options.rtol * self.state[acceleration].abs();
        kink * self.integrator.stats().h_next > weight
    }

    /// Integrates to `t`, keeping the history for the next call. The integrator takes the
    /// steps its error control wants, past `t` if need be, and the state at `t` is
    /// interpolated: communication points cost no extra steps.
    pub fn advance_to(&mut self, t: f64) -> Result<(), StepFailure> {
        if t < self.time {
            return Err(StepFailure {
                error: Error::Model(format!("{t} is behind the current time {}", self.time)),
                reached: self.time,
            });
        }
        let start = self.state.clone();
        let mut result = self
            .integrator
            .advance_past(&mut self.scene, t, &mut self.state);
        if result.is_err() && self.interface_jumped {
            // The history carried across the external body's jump did not fit the new inputs
            // (a large zero-order-hold step of a stiff coupling): start afresh at the
            // communication time, as for any other input jump.
            self.state.copy_from_slice(&start);
            result = self
                .integrator
                .restart_at(&mut self.scene, self.time, &start)
                .and_then(|()| {
                    self.restarts += 1;
                    self.integrator
                        .advance_past(&mut self.scene, t, &mut self.state)
                });
        }
        result.map_err(|e| StepFailure {
            error: Error::Model(e.to_string()),
            reached: self.integrator.t().min(t),
        })?;
        self.interface_jumped = false;
        self.time = t;
        Ok(())
    }

    /// Outputs at the communication time, with accelerations from one evaluation of the
    /// equations of motion.
    pub fn outputs(&mut self) -> Result<Outputs, Error> {
        scene::outputs(&self.scene, self.comfort, self.time, &self.state)
    }

    /// The inputs in force.
    pub fn inputs(&self) -> &Inputs {
        &self.inputs
    }

    /// Outputs at the communication time, the state held, with the interface signals of
    /// `interface`: the mount forces and the powertrain acceleration respond at once to the
    /// external body's motion (scene 3). Each signal passed its rule where it was set
    /// ([`Self::check_input`]); the mounts' range is checked here, for the state held.
    pub fn outputs_with(&mut self, interface: &Inputs) -> Result<Outputs, Error> {
        let trial = self.inputs.with_interface(interface);
        scene::apply_checked_inputs(&mut self.scene, &trial)?;
        let outputs = self
            .interface_in_range()
            .and_then(|()| scene::outputs(&self.scene, self.comfort, self.time, &self.state));
        scene::apply_checked_inputs(&mut self.scene, &self.inputs)?;
        outputs
    }

    /// With an external body, whether its motion at the communication time keeps every mount
    /// within its characteristic (an error naming the mount otherwise).
    fn interface_in_range(&self) -> Result<(), Error> {
        if !self.scene.has_external_body() {
            return Ok(());
        }
        self.scene
            .check_mount_ranges(self.time, &self.state)
            .map_err(|e| {
                Error::Model(format!(
                    "the external body's motion at t = {} s: {}",
                    self.time, e.0
                ))
            })
    }

    /// The response of the mount forces and the powertrain acceleration to the attachment
    /// increments in `seed` (values only), the state held, at the interface signals of `at`
    /// (checked where they were set): the exact derivatives of [`Self::outputs_with`] (zero
    /// outside scene 3).
    pub fn input_sensitivities(&mut self, at: &Inputs, seed: &Inputs) -> Result<Outputs, Error> {
        let trial = self.inputs.with_interface(at);
        scene::apply_checked_inputs(&mut self.scene, &trial)?;
        let sensitivities = self
            .scene
            .interface_sensitivities(self.time, &self.state)
            .map_err(|e| Error::Model(format!("{e:?}")));
        scene::apply_checked_inputs(&mut self.scene, &self.inputs)?;
        let mut out = Outputs::default();
        let seed = seed.sized(self.inputs.model.body_motion.len());
        for (i, s) in sensitivities?.iter().enumerate().take(FMU_MOUNTS) {
            let Some(s) = s else { continue };
            let motion = &seed.model.body_motion[i];
            let u = nalgebra::Vector3::from(motion.displacement.map(|x| x.value));
            let v = nalgebra::Vector3::from(motion.velocity.map(|x| x.value));
            let force = s.force_per_displacement * u + s.force_per_velocity * v;
            let acceleration = s.housing_acceleration_per_force * force;
            out.mount_force[i] = force.into();
            for (a, d) in out
                .powertrain_acceleration
                .iter_mut()
                .zip(acceleration.iter())
            {
                *a += d;
            }
        }
        Ok(out)
    }

    /// The first time derivatives of the outputs at the communication time, along the
    /// trajectory the integrator follows there: the state derivative `f(t, y)` from the
    /// equations of motion, and the outputs' central difference along the tangent
    /// `(t ± ε, y ± ε f)`, ε = [`OUTPUT_DERIVATIVE_STEP`] (truncation ~ ε²ω²/6 relative for a
    /// vibration of angular frequency ω: 3e-7 at 2 kHz). The right-hand side only uses the
    /// model's scratch space, so the run continues exactly as without this call.
    pub fn output_derivatives(&mut self) -> Result<Outputs, Error> {
        let mut f = vec![0.0; self.state.len()];
        self.scene
            .rhs(self.time, &self.state, &mut f)
            .map_err(|e| Error::Model(format!("{e:?}")))?;
        let eps = OUTPUT_DERIVATIVE_STEP;
        let along = |sign: f64| -> Vec<f64> {
            self.state
                .iter()
                .zip(&f)
                .map(|(y, d)| y + sign * eps * d)
                .collect()
        };
        let plus = scene::outputs(&self.scene, self.comfort, self.time + eps, &along(1.0))?;
        let minus = scene::outputs(&self.scene, self.comfort, self.time - eps, &along(-1.0))?;
        let d = |a: f64, b: f64| (a - b) / (2.0 * eps);
        let d3 = |a: [f64; 3], b: [f64; 3]| [d(a[0], b[0]), d(a[1], b[1]), d(a[2], b[2])];
        let mut mount_force = [[0.0; 3]; 4];
        for (k, m) in mount_force.iter_mut().enumerate() {
            *m = d3(plus.mount_force[k], minus.mount_force[k]);
        }
        Ok(Outputs {
            mount_force,
            crank_angle: d(plus.crank_angle, minus.crank_angle),
            powertrain_displacement: d3(
                plus.powertrain_displacement,
                minus.powertrain_displacement,
            ),
            powertrain_rotation: d3(plus.powertrain_rotation, minus.powertrain_rotation),
            powertrain_acceleration: d3(
                plus.powertrain_acceleration,
                minus.powertrain_acceleration,
            ),
            steering_wheel_acceleration: d3(
                plus.steering_wheel_acceleration,
                minus.steering_wheel_acceleration,
            ),
            seat_acceleration: d3(plus.seat_acceleration, minus.seat_acceleration),
            mount_point: Default::default(),
        })
    }

    /// The integrator's work since this simulation was built (or restored).
    pub fn counters(&self) -> Counters {
        let s = self.integrator.stats();
        Counters {
            steps: s.steps,
            rhs_evaluations: s.rhs_evals,
            jacobian_evaluations: s.jac_evals,
            factorizations: s.factorizations,
            newton_iterations: s.newton_iters,
            restarts: self.restarts,
        }
    }

    /// Everything that is not in the settings: where the simulation started, the inputs, and
    /// the integrator state. [`Simulation::restore`] rebuilds from it.
    pub fn dynamic_state(&self) -> SimulationState {
        SimulationState {
            initial_time: self.initial_time,
            initial_inputs: self.initial_inputs.clone(),
            fade_start: self.scene.fade_start(),
            inputs: self.inputs.clone(),
            time: self.time,
            state: self.state.clone(),
            integrator: self.integrator.snapshot(),
        }
    }

    /// Rebuilds a simulation from its settings and [`Simulation::dynamic_state`]; continuing it
    /// reproduces the original run bit for bit.
    pub fn restore(settings: &Settings, saved: &SimulationState) -> Result<Simulation, Error> {
        let times = [saved.initial_time, saved.time, saved.fade_start];
        if times.iter().chain(&saved.state).any(|x| !x.is_finite()) {
            return Err(Error::Model(
                "simulation state holds a non-finite time or state".into(),
            ));
        }
        let mut sim =
            Simulation::at_static_equilibrium(settings, saved.initial_time, &saved.initial_inputs)?;
        sim.scene
            .set_fade_start(saved.fade_start)
            .map_err(|e| e.to_string())?;
        if saved.state.len() != sim.state.len() {
            return Err(Error::Model(format!(
                "simulation state has {} states, this model {}",
                saved.state.len(),
                sim.state.len()
            )));
        }
        sim.integrator
            .restore(&saved.integrator)
            .map_err(|e| e.to_string())?;
        sim.inputs = scene::apply_inputs(&mut sim.scene, &saved.inputs)?;
        sim.time = saved.time;
        sim.state.copy_from_slice(&saved.state);
        Ok(sim)
    }
}

/// The part of a [`Simulation`] its settings do not determine (see [`Simulation::dynamic_state`]).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SimulationState {
    initial_time: f64,
    initial_inputs: Inputs,
    /// Start of the excitation fade-in (before the start time for a periodic start).
    fade_start: f64,
    inputs: Inputs,
    time: f64,
    state: Vec<f64>,
    integrator: BdfSnapshot,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn restored_dynamic_state_continues_bit_for_bit() {
        let settings = Settings::default();
        let mut a = Simulation::new(&settings, 0.0, &Inputs::steady(1200.0)).unwrap();
        for k in 1..=20 {
            a.advance_to(k as f64 * 1e-3).unwrap();
        }
        let saved = a.dynamic_state();
        let mut b = Simulation::restore(&settings, &saved).unwrap();
        assert_eq!(b.dynamic_state(), saved);
        for k in 21..=40 {
            let t = k as f64 * 1e-3;
            a.advance_to(t).unwrap();
            b.advance_to(t).unwrap();
            assert_eq!(a.outputs().unwrap(), b.outputs().unwrap(), "t = {t}");
        }
    }
}
