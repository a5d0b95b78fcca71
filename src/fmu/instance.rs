//! One FMU instance: its state ([`Core`]), its life cycle, and reading and writing variables.
//! Stepping is in [`super::step`].
//!
//! Everything here is safe Rust, and the calls arrive checked: the guard
//! ([`super::guard::Abi::entry`]) has already verified the instance pointer and the state mask, and
//! the ABI the arguments, and mapped the value references to typed positions. A method returns
//! `Err(message)` to refuse a call; the guard logs it once, naming the function. A refused call leaves the instance exactly as it was: values
//! are checked as a whole before any is applied.

use std::collections::BTreeMap;
use std::path::PathBuf;

use super::abi::{self, Abi};
use super::bindings::{self, is_interface_input};
use super::input_track::InputTrack;
use super::logger::{Level, Logger};
use super::parameters::{self, Calculated};
use super::state::Phase;
use super::values::{Num, Store, Typed, Values, VarType};
use crate::cosim::{self, FmuKind, Runtime};
use crate::variables::fmi3::MODES_SIZE_MAX;
use crate::variables::{integer, real, Causality, LogCategory, Variability, Variable, REALS};

/// Result of an FMI call. Both standards number their statuses alike (fmi2OK = fmi3OK = 0, …,
/// Fatal = 4, checked at compile time): an ABI returns `status as u32`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
#[repr(u32)]
pub enum Status {
    /// OK.
    Ok = 0,
    /// Warning: the call did its work, with something logged the master should know (e.g. an
    /// input ramp bent onto its bound).
    Warning = 1,
    /// Discard: the step could not be completed; the FMU stopped at the last successful time.
    Discard = 2,
    /// Error: the call was refused (changing nothing), or the outputs could not be evaluated
    /// after a step.
    Error = 3,
    /// Fatal: the instance is unusable.
    Fatal = 4,
}

// The statuses are numbered as both standards number theirs.
const _: () = {
    use fmi_sys::{fmi2::*, fmi3::*};
    assert!(
        Status::Ok as u32 == fmi2Status_fmi2OK
            && Status::Warning as u32 == fmi2Status_fmi2Warning
            && Status::Discard as u32 == fmi2Status_fmi2Discard
            && Status::Error as u32 == fmi2Status_fmi2Error
            && Status::Fatal as u32 == fmi2Status_fmi2Fatal
            && Status::Ok as u32 == fmi3Status_fmi3OK
            && Status::Warning as u32 == fmi3Status_fmi3Warning
            && Status::Discard as u32 == fmi3Status_fmi3Discard
            && Status::Error as u32 == fmi3Status_fmi3Error
            && Status::Fatal as u32 == fmi3Status_fmi3Fatal
    );
};

/// What a call on an instance gives: a status, or the reason it was refused (an error).
pub type Outcome = Result<Status, String>;

/// Everything an FMU state captures.
#[derive(Clone)]
pub struct Core {
    /// Where the instance is in the co-simulation state machine.
    pub phase: Phase,
    /// The current value of every variable, by type and value reference.
    pub values: Values,
    /// The signal of each Real input (indexed like the Reals; unused for non-inputs).
    pub inputs: Vec<InputTrack>,
    /// Start time of the experiment in s (0 if none was set up).
    pub start_time: f64,
    /// Stop time of the experiment in s, if defined: no step may pass it.
    pub stop_time: Option<f64>,
    /// The experiment's tolerance, if the master defined one.
    pub experiment_tolerance: Option<f64>,
    /// The FMU's current time in s: the last communication point reached.
    pub time: f64,
    /// Set when a step failed: `fmi2GetBooleanStatus(fmi2Terminated)` and fmi3DoStep's
    /// `terminateSimulation` report it.
    pub terminated: bool,
    /// The built model with its integrator; `None` before initialisation ends and after a
    /// parameter change in initialisation mode (rebuilt when next needed).
    pub simulation: Option<Runtime>,
    /// Why building the model failed with the current parameters and inputs: asked again
    /// without a change, the answer is the same, without building again.
    pub setup_failure: Option<String>,
    /// In initialisation mode, the columns `∂(Reals)/∂(Real input k)` of the initialisation at
    /// the current parameters and inputs, by input index, as computed when first asked for
    /// (cleared with the model whenever a value is set).
    pub initial_sensitivities: BTreeMap<usize, Vec<f64>>,
}

impl Core {
    fn fresh() -> Core {
        Core {
            phase: Phase::Instantiated,
            values: Values::start(),
            inputs: REALS
                .iter()
                .map(|v| InputTrack::constant(v.start, 0.0))
                .collect(),
            start_time: 0.0,
            stop_time: None,
            experiment_tolerance: None,
            time: 0.0,
            terminated: false,
            simulation: None,
            setup_failure: None,
            initial_sensitivities: BTreeMap::new(),
        }
    }

    /// Whether the stored values and input signals are admissible (an FMU state from outside).
    pub fn check(&self) -> Result<(), String> {
        self.values.check()?;
        if self.inputs.len() != REALS.len() {
            return Err(format!(
                "{} input signals, this FMU has {}",
                self.inputs.len(),
                REALS.len()
            ));
        }
        let times = [self.start_time, self.time];
        if times.iter().chain(&self.stop_time).any(|t| !t.is_finite()) {
            return Err("a time of the state is not finite".into());
        }
        for v in REALS.iter().filter(|v| v.causality == Causality::Input) {
            let t = &self.inputs[v.index as usize];
            if t.lo.partial_cmp(&t.hi).is_none_or(|o| o.is_gt()) {
                return Err(format!("the signal of {} has no valid range", v.name));
            }
            let numbers = [t.value, t.slope, t.since];
            let landing = t.landing.map(|(time, bound)| [time, bound]);
            let pending = [t.pending_value, t.pending_slope, t.last_slope];
            if landing.iter().flatten().any(|x| !x.is_finite()) {
                return Err(format!("the signal of {} is not finite", v.name));
            }
            if numbers
                .iter()
                .chain(pending.iter().flatten())
                .any(|x| !x.is_finite())
            {
                return Err(format!("the signal of {} is not finite", v.name));
            }
        }
        Ok(())
    }
}

/// One instance of the FMU.
pub struct Instance {
    /// The `instanceName` it was instantiated with.
    pub name: String,
    /// Which of the library's FMUs this instance is (from the GUID it was instantiated with).
    pub kind: FmuKind,
    /// The standard it was instantiated through (function names for messages).
    pub abi: &'static Abi,
    /// FMI 3.0's structural parameter `modes.size`: how many natural modes the mode arrays
    /// have (FMI 2.0: always all slots).
    pub modes_size: u64,
    /// The master's logger callback with the enabled categories.
    pub logger: Logger,
    /// The FMU's `resources` directory; relative `configFile` paths are resolved against it.
    pub resource_dir: Option<PathBuf>,
    /// Everything an FMU state captures; replaced as a whole when one is restored.
    pub core: Core,
    /// Whether the warning on body-point inputs outside scene 3 was given (once per instance).
    warned_unused_body_point: bool,
}

impl Instance {
    /// A freshly instantiated instance with start values and no model.
    pub fn new(
        name: &str,
        kind: FmuKind,
        abi: &'static Abi,
        logger: Logger,
        resource_dir: Option<PathBuf>,
    ) -> Instance {
        Instance {
            name: name.to_owned(),
            kind,
            abi,
            modes_size: MODES_SIZE_MAX,
            logger,
            resource_dir,
            core: Core::fresh(),
            warned_unused_body_point: false,
        }
    }

    /// The GUID of this instance's FMU.
    pub fn guid(&self) -> &'static str {
        abi::guid(self.kind)
    }

    /// The bit of this instance's FMU in [`Variable::fmus`].
    pub(crate) fn fmu_bit(&self) -> u8 {
        match self.kind {
            FmuKind::Engine => crate::variables::ENGINE_FMU,
            FmuKind::Body => crate::variables::BODY_FMU,
        }
    }

    /// Refuses variables the model description of this instance's FMU does not list (the two
    /// FMUs share one value-reference space).
    fn check_members<T: Typed>(&self, indices: &[usize]) -> Result<(), String> {
        let bit = self.fmu_bit();
        match indices.iter().find(|&&i| T::table()[i].fmus & bit == 0) {
            Some(&i) => {
                let v = &T::table()[i];
                Err(format!(
                    "value reference {} ({}) is not a variable of {}",
                    v.vr,
                    v.name,
                    abi::model_identifier(self.kind)
                ))
            }
            None => Ok(()),
        }
    }

    /// The current phase of the state machine.
    pub fn phase(&self) -> Phase {
        self.core.phase
    }

    /// Logs an error (always shown).
    pub fn log_error(&self, message: &str) {
        self.logger
            .log(Level::Error, LogCategory::StatusError, message);
    }

    /// Logs a warning (always shown).
    pub fn log_warning(&self, message: &str) {
        self.logger
            .log(Level::Warning, LogCategory::StatusWarning, message);
    }

    /// Logs how the model was set up and what it did (shown when asked for).
    pub fn event(&self, message: &str) {
        self.logger.log(Level::Info, LogCategory::Events, message);
    }

    // ----- life cycle ------------------------------------------------------------------------

    /// Reset: back to the freshly instantiated state with start values.
    pub fn reset(&mut self) -> Outcome {
        self.core = Core::fresh();
        self.modes_size = MODES_SIZE_MAX;
        Ok(Status::Ok)
    }

    /// FMI 3.0's configuration mode, entered (`true`) or left.
    pub fn configuration_mode(&mut self, enter: bool) -> Outcome {
        self.core.phase = if enter {
            Phase::ConfigurationMode
        } else {
            Phase::Instantiated
        };
        Ok(Status::Ok)
    }

    /// Sets up the experiment (fmi2SetupExperiment; FMI 3.0 as part of entering
    /// initialisation). A defined tolerance becomes the integrator's relative tolerance
    /// unless the master set `solver.relTol` itself (which then wins); either way it is logged.
    pub fn setup_experiment(
        &mut self,
        start: f64,
        stop: Option<f64>,
        tolerance: Option<f64>,
    ) -> Outcome {
        if let Some(tol) = tolerance {
            let v = &REALS[real::SOLVER_REL_TOL as usize];
            if f64::admissible(v, &tol).is_err() {
                return Err(format!(
                    "tolerance {} is outside [{}, {}] ({}'s range)",
                    Num(tol),
                    Num(v.min.unwrap_or(0.0)),
                    Num(v.max.unwrap_or(f64::INFINITY)),
                    v.name
                ));
            }
        }
        if !start.is_finite() {
            return Err(format!("start time {} is not finite", Num(start)));
        }
        if let Some(stop) = stop {
            if !stop.is_finite() || stop < start {
                return Err(format!(
                    "stop time {} must be finite and >= start time {}",
                    Num(stop),
                    Num(start)
                ));
            }
        }
        self.core.setup_failure = None;
        self.core.start_time = start;
        self.core.stop_time = stop;
        self.core.time = start;
        self.core.experiment_tolerance = tolerance;
        Ok(Status::Ok)
    }

    /// Enters initialisation mode.
    pub fn enter_initialization(&mut self) -> Outcome {
        self.core.phase = Phase::InitializationMode;
        Ok(Status::Ok)
    }

    /// Exits initialisation mode: builds the model and its initial state; refused, with the
    /// reason, if the parameters or the configuration do not give a valid model.
    pub fn exit_initialization(&mut self) -> Outcome {
        self.ensure_simulation()?;
        self.core.phase = Phase::StepComplete;
        let reals = &self.core.values.reals;
        let set: Vec<usize> = (0..REALS.len())
            .filter(|&i| parameters::is_body_point_input(i) && reals.set_by_master(i as u32))
            .collect();
        Ok(self.warn_unused_body_point(&set))
    }

    /// Warns, once per instance, when the engine FMU gets a moving body point (`mount[i].body.*`
    /// not zero) in a scene without an external body, which ignores it (an SSP whose scene
    /// binding was lost would otherwise run uncoupled with no sign). A body point at rest is what
    /// those scenes assume: a master that feeds every input (fmusim, the cross-check rules, the
    /// packaged reference experiments) sets them to zero and gets no warning it did not cause.
    fn warn_unused_body_point(&mut self, indices: &[usize]) -> Status {
        if self.warned_unused_body_point || self.kind != FmuKind::Engine {
            return Status::Ok;
        }
        let reals = self.core.values.reals.as_slice();
        let Some(&first) = indices
            .iter()
            .find(|&&i| parameters::is_body_point_input(i) && reals[i] != 0.0)
        else {
            return Status::Ok;
        };
        match parameters::unused_body_point_input(&self.core.values, first) {
            Some(warning) => {
                self.warned_unused_body_point = true;
                self.log_warning(&warning);
                Status::Warning
            }
            None => Status::Ok,
        }
    }

    /// Terminates.
    pub fn terminate(&mut self) -> Outcome {
        self.core.phase = Phase::Terminated;
        Ok(Status::Ok)
    }

    /// Builds the model from the parameters and finds its static equilibrium, once per
    /// initialisation (parameters set afterwards in initialisation mode rebuild it).
    pub(super) fn ensure_simulation(&mut self) -> Result<(), String> {
        if self.core.simulation.is_some() {
            return Ok(());
        }
        if let Some(failure) = &self.core.setup_failure {
            return Err(failure.clone());
        }
        self.commit_inputs(0.0);
        let mut simulation = match self.build_simulation() {
            Ok(simulation) => simulation,
            Err(failure) => {
                self.core.setup_failure = Some(failure.clone());
                return Err(failure);
            }
        };
        for r in simulation.replaced() {
            self.event(&parameters::replaced_note(r));
        }
        for line in simulation.describe() {
            match line.strip_prefix("warning: ") {
                Some(warning) => self.log_warning(warning),
                None => self.event(&line),
            }
        }
        let outputs = simulation.outputs().map_err(|e| parameters::message(&e))?;
        self.write_outputs(&outputs, &simulation.counters());
        parameters::write_effective_parameters(&mut self.core.values, &simulation);
        // The natural modes of this model are computed when first read.
        self.core.values.integers.put(integer::MODES_COUNT, -1);
        self.core.simulation = Some(simulation);
        Ok(())
    }

    /// A simulation built from the current parameters and inputs, at its static equilibrium.
    fn build_simulation(&self) -> Result<Runtime, String> {
        let settings = self.settings_for(&self.core)?;
        let inputs = parameters::inputs_from(&self.core.inputs, self.core.time);
        self.event(&parameters::tolerance_note(
            &self.core.values,
            &settings,
            self.core.experiment_tolerance,
            self.abi.names.setup_experiment,
        ));
        let what = match self.kind {
            FmuKind::Engine => format!("scene {}", settings.scene.number()),
            FmuKind::Body => "the body alone".to_owned(),
        };
        self.event(&format!(
            "building {what} at t = {} s (config: {})",
            self.core.time,
            settings
                .config_file
                .as_ref()
                .map(|p| p.display().to_string())
                .unwrap_or_else(|| "built-in defaults".to_owned())
        ));
        Runtime::new(self.kind, &settings, self.core.time, &inputs)
            .map_err(|e| format!("model set-up failed: {}", parameters::message(&e)))
    }

    /// A simulation for a deserialized FMU state, rebuilt from that state's own parameters.
    pub fn restore_simulation(
        &self,
        core: &Core,
        dynamic: &cosim::RuntimeState,
    ) -> Result<Runtime, String> {
        Runtime::restore(&self.settings_for(core)?, dynamic).map_err(|e| parameters::message(&e))
    }

    /// The model settings the parameters of `core` describe.
    pub(super) fn settings_for(&self, core: &Core) -> Result<cosim::Settings, String> {
        let config_file = parameters::config_file(&core.values, self.resource_dir.as_deref())?;
        parameters::settings(&core.values, config_file, core.experiment_tolerance)
    }

    /// Fills the natural-mode calculated parameters (`modes.count`, `mode[k].*`) if this
    /// simulation's have not been computed yet: a linearisation and a dense eigenproblem of the
    /// vibration coordinates, tens of milliseconds that a sweep which never reads them saves.
    fn ensure_natural_modes(&mut self) -> Result<(), String> {
        self.ensure_simulation()?;
        if *self.core.values.integers.get(integer::MODES_COUNT) >= 0 {
            return Ok(());
        }
        let Some(simulation) = self.core.simulation.as_ref() else {
            return Err("natural modes: the model is not built".into());
        };
        let modes = simulation
            .natural_modes()
            .map_err(|e| format!("natural modes: {}", parameters::message(&e)))?;
        let slots = real::MODE_FREQUENCY.len();
        let r = &mut self.core.values.reals;
        for k in 0..slots {
            let (f, zeta, share) = modes.get(k).map_or((0.0, 0.0, 0.0), |m| {
                (m.frequency_hz, m.damping_ratio, m.powertrain_fraction)
            });
            r.put(real::MODE_FREQUENCY[k], f);
            r.put(real::MODE_DAMPING[k], zeta);
            r.put(real::MODE_POWERTRAIN_SHARE[k], share);
        }
        let shown = modes.len().min(slots);
        self.core.values.integers.put(
            integer::MODES_COUNT,
            i32::try_from(shown).unwrap_or(i32::MAX),
        );
        self.event(&format!(
            "natural modes: {} oscillatory modes of the linearised model, the lowest {shown} \
             reported ({:.2}..{:.2} Hz)",
            modes.len(),
            modes.first().map_or(0.0, |m| m.frequency_hz),
            modes
                .get(shown.saturating_sub(1))
                .map_or(0.0, |m| m.frequency_hz)
        ));
        Ok(())
    }

    // ----- get and set -------------------------------------------------------------------------

    /// Reads the variables at `indices`. Outputs asked for in initialisation mode are the
    /// static equilibrium's; calculated parameters (the natural modes) are computed when first
    /// asked for. In the error state entered before the model was built nothing is read: a
    /// natural mode would build the model as a side effect of a diagnostic read.
    pub fn get<T: Typed>(&mut self, indices: &[usize]) -> Result<Vec<T>, String> {
        self.check_members::<T>(indices)?;
        if self.core.phase == Phase::Error && self.core.simulation.is_none() {
            return Err("nothing to read before initialisation".into());
        }
        let causality = |i: &usize| T::table()[*i].causality;
        if self.core.phase == Phase::InitializationMode
            && indices.iter().any(|i| causality(i) == Causality::Output)
        {
            self.ensure_simulation()?;
        }
        let needs = |what: Calculated| {
            indices.iter().any(|i| {
                causality(i) == Causality::CalculatedParameter
                    && parameters::calculated(T::table()[*i].vr) == what
            })
        };
        if needs(Calculated::FromParameters) {
            parameters::write_derived_parameters(&mut self.core.values)?;
        }
        if needs(Calculated::FromModel) {
            self.ensure_simulation()?;
        }
        if needs(Calculated::NaturalModes) {
            self.ensure_natural_modes()?;
        }
        let values = self.core.values.of::<T>().as_slice();
        Ok(indices.iter().map(|&i| values[i].clone()).collect())
    }

    /// Sets the variables at `indices`: all checked before any is applied.
    pub fn set<T: Typed>(&mut self, indices: &[usize], values: &[T]) -> Outcome {
        self.check_members::<T>(indices)?;
        let phase = self.core.phase;
        let next = self
            .core
            .values
            .of::<T>()
            .with_set(indices, values, |v| settable(v, phase))?;
        let before = std::mem::replace(self.core.values.of_mut::<T>(), next);
        if T::TYPE_INDEX == <f64 as VarType>::TYPE_INDEX {
            let tracks = self.core.inputs.clone();
            let refreshed = self.follow_real_inputs(indices).and_then(|()| {
                if phase == Phase::StepComplete
                    && indices.iter().any(|&i| is_interface_input(i as u32))
                {
                    self.refresh_feedthrough()
                } else {
                    Ok(())
                }
            });
            if let Err(m) = refreshed {
                // `before` is the whole Real store: inputs and any output a refresh wrote.
                *self.core.values.of_mut::<T>() = before;
                self.core.inputs = tracks;
                return Err(m);
            }
        }
        if phase != Phase::StepComplete {
            // Parameters or initial inputs changed before the model started: rebuild lazily
            // (the scene is only fixed when initialisation ends, where unused body-point inputs
            // are warned about).
            self.core.simulation = None;
            self.core.setup_failure = None;
            self.core.initial_sensitivities.clear();
            return Ok(Status::Ok);
        }
        Ok(if T::TYPE_INDEX == <f64 as VarType>::TYPE_INDEX {
            self.warn_unused_body_point(indices)
        } else {
            Status::Ok
        })
    }

    /// Recomputes the outputs with direct feedthrough from the interface inputs just set (the
    /// state held): a coupling master reads the mount forces for the body motion it has just
    /// given, within the same communication point.
    fn refresh_feedthrough(&mut self) -> Result<(), String> {
        let interface = parameters::inputs_from(&self.core.inputs, self.core.time);
        let Some(runtime) = self.core.simulation.as_mut() else {
            return Ok(());
        };
        let outputs = runtime
            .outputs_with(&interface)
            .map_err(|e| parameters::message(&e))?;
        bindings::put_outputs(&mut self.core.values.reals, &outputs);
        Ok(())
    }

    /// Directional derivatives `Σ_k ∂unknown/∂known_k · seed_k` of Real outputs with respect to
    /// Real inputs. A known with a zero seed adds nothing, whatever it is: a host may pass an
    /// unknown's whole `dependencies` list (parameters included) and seed the input it wants;
    /// a non-zero seed must be on an input.
    ///
    /// Between steps: at the current communication point, the state held — the same
    /// instantaneous dependence the model structure's `Outputs` declare (non-zero only through
    /// the interface inputs), exact: from the mounts' tangent stiffness and damping and the
    /// housing's mass matrix, or the body's modal shapes.
    ///
    /// In initialisation mode: of the initial unknowns, the outputs of the initialisation at
    /// the current parameters and inputs (the static equilibrium re-solved, or the periodic
    /// orbit), as `InitialUnknowns` declare them; by central differences of the initialisation
    /// (`initial_sensitivity`), which FMI 2.0 §2.1.9 permits ("may compute the directional
    /// derivatives by numerical differentiation").
    pub fn directional_derivative(
        &mut self,
        unknowns: &[usize],
        knowns: &[usize],
        seeds: &[f64],
    ) -> Result<Vec<f64>, String> {
        self.check_members::<f64>(unknowns)?;
        self.check_members::<f64>(knowns)?;
        if let Some(s) = seeds.iter().find(|s| !s.is_finite()) {
            return Err(format!("seed {} is not finite", Num(*s)));
        }
        let seeded: Vec<(usize, f64)> = knowns
            .iter()
            .zip(seeds)
            .filter(|(_, &s)| s != 0.0)
            .map(|(&k, &s)| (k, s))
            .collect();
        if let Some(&(i, _)) = seeded
            .iter()
            .find(|(i, _)| REALS[*i].causality != Causality::Input)
        {
            return Err(format!(
                "{} is not an input: the derivatives provided are with respect to inputs (any \
                 other known may be listed with a zero seed)",
                REALS[i].name
            ));
        }
        if let Some(&i) = unknowns
            .iter()
            .find(|&&i| REALS[i].causality != Causality::Output)
        {
            return Err(format!(
                "{} is not an output: the derivatives provided are of outputs with respect to inputs",
                REALS[i].name
            ));
        }
        match self.core.phase {
            Phase::StepComplete => self.step_sensitivity(unknowns, &seeded),
            Phase::InitializationMode => {
                let mut out = vec![0.0; unknowns.len()];
                for &(k, s) in &seeded {
                    let column = self.initial_sensitivity(k)?;
                    for (o, &u) in out.iter_mut().zip(unknowns) {
                        *o += column[u] * s;
                    }
                }
                Ok(out)
            }
            _ => Err(format!(
                "directional derivatives are provided in initialisation mode and between \
                 steps, after {}",
                self.abi.names.exit_initialization
            )),
        }
    }

    /// Between steps: the response of the outputs at `unknowns` to the input increments
    /// `seeded`, the state held.
    fn step_sensitivity(
        &mut self,
        unknowns: &[usize],
        seeded: &[(usize, f64)],
    ) -> Result<Vec<f64>, String> {
        let mut increments = vec![0.0; REALS.len()];
        for &(k, s) in seeded {
            increments[k] += s;
        }
        let seed = parameters::input_increments(&increments);
        let at = parameters::inputs_from(&self.core.inputs, self.core.time);
        let Some(runtime) = self.core.simulation.as_mut() else {
            return Err("the model is not built".into());
        };
        let response = runtime
            .input_sensitivities(&at, &seed)
            .map_err(|e| parameters::message(&e))?;
        let mut scratch = self.core.values.reals.clone();
        bindings::put_outputs(&mut scratch, &response);
        Ok(unknowns.iter().map(|&u| *scratch.get(u as u32)).collect())
    }

    /// The input signals after the Reals at `indices` were set: each input set continues from
    /// its new value. Refused, changing nothing, if an input set would be inadmissible.
    fn follow_real_inputs(&mut self, indices: &[usize]) -> Result<(), String> {
        let mut tracks = self.core.inputs.clone();
        for &i in indices {
            if REALS[i].causality == Causality::Input {
                tracks[i].set_value(self.core.values.reals.as_slice()[i]);
            }
        }
        self.check_inputs(&tracks, indices)?;
        self.core.inputs = tracks;
        Ok(())
    }

    /// The one check of an input, when the master sets it: whether the model accepts, for each
    /// Real input at `indices`, the signal `tracks` give it from now on (the model's rule, in SI
    /// units, refused naming the variable). A model not built yet checks every input when it is
    /// built; a step checks only the signals that continued without being set
    /// ([`super::step`]).
    fn check_inputs(&self, tracks: &[InputTrack], indices: &[usize]) -> Result<(), String> {
        let Some(runtime) = &self.core.simulation else {
            return Ok(());
        };
        for &i in indices {
            let Some((input, ramp)) = parameters::input_at(tracks, i as u32, self.core.time) else {
                continue;
            };
            runtime
                .check_input(input, &ramp)
                .map_err(|e| parameters::message(&e))?;
        }
        Ok(())
    }

    /// First time derivatives of the Real inputs at `indices` (fmi2SetRealInputDerivatives).
    pub fn set_real_input_derivatives(
        &mut self,
        indices: &[usize],
        orders: &[i32],
        values: &[f64],
    ) -> Outcome {
        self.check_members::<f64>(indices)?;
        let mut candidate = self.core.inputs.clone();
        for ((&i, order), value) in indices.iter().zip(orders).zip(values) {
            let v = &REALS[i];
            if v.causality != Causality::Input {
                return Err(format!("{} is not an input", v.name));
            }
            if *order != 1 {
                return Err(format!(
                    "derivative order {order} of {} is not supported (only 1)",
                    v.name
                ));
            }
            if !value.is_finite() {
                return Err(format!("d{}/dt = {} is not finite", v.name, Num(*value)));
            }
            candidate[i].set_slope(*value);
        }
        self.check_inputs(&candidate, indices)?;
        self.core.inputs = candidate;
        self.core.setup_failure = None;
        Ok(Status::Ok)
    }

    // ----- FMU states --------------------------------------------------------------------------

    /// Whether `core` (of a restored FMU state) can become this instance's state: its values are
    /// admissible and, once this instance has built its model, it was taken with the same
    /// parameters (a state of another scene or configuration would silently change the model).
    pub fn check_state_fits(&self, core: &Core) -> Result<(), String> {
        core.check()?;
        if self.core.simulation.is_none() || core.simulation.is_none() {
            return Ok(());
        }
        let (theirs, ours) = (&core.values, &self.core.values);
        let difference = parameter_difference(&theirs.reals, &ours.reals)
            .or_else(|| parameter_difference(&theirs.integers, &ours.integers))
            .or_else(|| parameter_difference(&theirs.booleans, &ours.booleans))
            .or_else(|| parameter_difference(&theirs.strings, &ours.strings));
        match difference {
            Some(d) => Err(d),
            None => Ok(()),
        }
    }

    /// The last successful time in s: the time reached, also after a discarded step.
    pub fn last_successful_time(&self) -> f64 {
        self.core.time
    }
}

/// Whether a variable may be set in `phase` (FMI 2.0 §3.2.3 and §4.2.4 for co-simulation).
fn settable<T>(v: &Variable<T>, phase: Phase) -> Result<(), String> {
    let ok = match v.causality {
        Causality::Input => true,
        Causality::Parameter => match v.variability {
            Variability::Tunable => true,
            _ => matches!(phase, Phase::Instantiated | Phase::InitializationMode),
        },
        _ => false,
    };
    if ok {
        Ok(())
    } else {
        Err(format!(
            "variable {} ({:?}, {:?}) cannot be set in phase {phase:?}",
            v.name, v.causality, v.variability
        ))
    }
}

/// The first parameter whose value differs between two stores, as a message.
fn parameter_difference<T: Typed + std::fmt::Debug>(
    theirs: &Store<T>,
    ours: &Store<T>,
) -> Option<String> {
    T::table()
        .iter()
        .zip(theirs.as_slice().iter().zip(ours.as_slice()))
        .find(|(v, (a, b))| v.causality == Causality::Parameter && a != b)
        .map(|(v, (a, b))| {
            format!(
                "the state was taken with {} = {a:?}, this instance runs with {b:?}",
                v.name
            )
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn deserialized_state_continues_bit_for_bit() {
        let logger = Logger::new(None, std::ptr::null_mut(), "t", false);
        let resources = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("resources");
        let mut inst = Instance::new(
            "t",
            FmuKind::Engine,
            &crate::fmi2::abi::ABI,
            logger,
            Some(resources),
        );
        assert_eq!(inst.setup_experiment(0.0, None, None), Ok(Status::Ok));
        inst.enter_initialization().unwrap();
        assert_eq!(inst.exit_initialization(), Ok(Status::Ok));
        let mut t = 0.0;
        for _ in 0..20 {
            assert_eq!(inst.do_step(t, 1e-3), Ok(Status::Ok));
            t += 1e-3;
        }
        let bytes = crate::fmu::snapshot::serialize(&inst.core, inst.guid());
        let saved = inst.core.clone();
        let mut reference = Vec::new();
        let mut tt = t;
        for _ in 0..30 {
            assert_eq!(inst.do_step(tt, 1e-3), Ok(Status::Ok));
            tt += 1e-3;
            reference.push(inst.core.values.reals.clone());
        }
        inst.core = saved.clone();
        let mut tt = t;
        for r in &reference {
            assert_eq!(inst.do_step(tt, 1e-3), Ok(Status::Ok));
            tt += 1e-3;
            assert_eq!(&inst.core.values.reals, r, "in-memory");
        }
        let core = crate::fmu::snapshot::deserialize(&bytes, inst.guid(), |c, d| {
            inst.restore_simulation(c, d)
        })
        .unwrap();
        let a = saved.simulation.as_ref().unwrap().dynamic_state();
        let b = core.simulation.as_ref().unwrap().dynamic_state();
        assert_eq!(a, b);
        inst.core = core;
        let mut tt = t;
        for r in &reference {
            assert_eq!(inst.do_step(tt, 1e-3), Ok(Status::Ok));
            tt += 1e-3;
            assert_eq!(&inst.core.values.reals, r);
        }
    }
}
