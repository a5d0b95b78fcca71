//! One FMU instance: variable values, the state machine and the co-simulation stepping.
//!
//! Everything here is safe Rust; [`super::abi`] turns C arguments into these calls. Every
//! rejected call leaves the instance exactly as it was: values are validated as a whole before
//! any is applied.

use std::collections::BTreeSet;
use std::path::PathBuf;

use super::input_track::InputTrack;
use super::logger::{Level, Logger};
use super::state::{self, Mask, Phase};
use super::variables::{
    boolean, integer, real, string, Causality, Parameters, Variability, Variable, BOOLEANS,
    INTEGERS, REALS, STRINGS,
};
use crate::cosim::{self, Simulation};

/// Result of an FMI call, mapped to `fmi2Status` by the ABI layer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Status {
    Ok,
    Warning,
    Discard,
    Error,
    Fatal,
}

/// All variable values, indexed by value reference.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Values {
    pub reals: Vec<f64>,
    pub integers: Vec<i32>,
    pub booleans: Vec<bool>,
    pub strings: Vec<String>,
}

impl Values {
    pub fn start() -> Values {
        Values {
            reals: REALS.iter().map(|v| v.start).collect(),
            integers: INTEGERS.iter().map(|v| v.start).collect(),
            booleans: BOOLEANS.iter().map(|v| v.start).collect(),
            strings: STRINGS.iter().map(|v| v.start.to_owned()).collect(),
        }
    }
}

/// Everything an FMU state (`fmi2GetFMUstate`) captures.
#[derive(Clone)]
pub struct Core {
    pub phase: Phase,
    pub values: Values,
    /// The signal of each Real input (indexed by value reference; unused for non-inputs).
    pub inputs: Vec<InputTrack>,
    pub start_time: f64,
    pub stop_time: Option<f64>,
    /// The tolerance of `fmi2SetupExperiment`, if the master defined one.
    pub experiment_tolerance: Option<f64>,
    /// Parameters the master set itself (by name): they win over the configuration file and
    /// (`solver.relTol`) over the experiment's tolerance.
    pub explicit: BTreeSet<String>,
    pub time: f64,
    pub terminated: bool,
    pub simulation: Option<Simulation>,
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
            explicit: BTreeSet::new(),
            time: 0.0,
            terminated: false,
            simulation: None,
        }
    }
}

/// One instance of the FMU.
pub struct Instance {
    pub name: String,
    pub logger: Logger,
    pub resource_dir: Option<PathBuf>,
    pub core: Core,
}

/// Whether `vr` names a calculated parameter of `table` (the natural modes).
fn is_calculated<T>(table: &[Variable<T>], vr: u32) -> bool {
    table
        .get(vr as usize)
        .is_some_and(|v| v.causality == Causality::CalculatedParameter)
}

/// Relative tolerance on communication points: masters compute them as `t0 + n h`.
const TIME_JITTER: f64 = 1e-9;

/// Communication points are snapped to a 1 ps grid: masters compute the same instant in different
/// ways (`t0 + n h` in seconds, integer nanoseconds), and an integrator that stops at instants one
/// ulp apart takes different steps afterwards. On the grid, every master gets the same run.
fn on_grid(t: f64) -> f64 {
    const GRID: f64 = 1e12;
    if t.abs() < 8e3 {
        (t * GRID).round() / GRID
    } else {
        t
    }
}

fn same_time(a: f64, b: f64) -> bool {
    (a - b).abs() <= TIME_JITTER * a.abs().max(b.abs()).max(1.0)
}

impl Instance {
    pub fn new(name: &str, logger: Logger, resource_dir: Option<PathBuf>) -> Instance {
        Instance {
            name: name.to_owned(),
            logger,
            resource_dir,
            core: Core::fresh(),
        }
    }

    pub fn phase(&self) -> Phase {
        self.core.phase
    }

    pub fn error(&self, message: &str) -> Status {
        self.logger.log(Level::Error, "logStatusError", message);
        Status::Error
    }

    pub fn event(&self, message: &str) {
        self.logger.log(Level::Info, "logEvents", message);
    }

    /// Checks the state mask; on refusal logs why and returns the status to give.
    pub fn allowed(&self, function: &str, mask: Mask) -> Result<(), Status> {
        self.logger.log(Level::Info, "logCalls", function);
        if self.core.phase == Phase::Fatal {
            self.logger.log(
                Level::Fatal,
                "logStatusError",
                &format!("{function}: the instance is in a fatal state; only fmi2FreeInstance is allowed"),
            );
            return Err(Status::Fatal);
        }
        if mask.allows(self.core.phase) {
            Ok(())
        } else {
            Err(self.error(&format!(
                "{function} is not allowed in phase {:?}",
                self.core.phase
            )))
        }
    }

    /// `fmi2Reset`: back to the freshly instantiated state with start values.
    pub fn reset(&mut self) -> Status {
        self.core = Core::fresh();
        Status::Ok
    }

    /// `fmi2SetupExperiment`. A defined tolerance becomes the integrator's relative tolerance
    /// unless the master set `solver.relTol` itself (which then wins); either way it is logged.
    pub fn setup_experiment(
        &mut self,
        start: f64,
        stop: Option<f64>,
        tolerance: Option<f64>,
    ) -> Status {
        if let Some(tol) = tolerance {
            let range = &REALS[real::SOLVER_REL_TOL as usize];
            let (lo, hi) = (range.min.unwrap_or(0.0), range.max.unwrap_or(f64::INFINITY));
            if !(tol.is_finite() && tol >= lo && tol <= hi) {
                return self.error(&format!(
                    "fmi2SetupExperiment: tolerance {tol} is outside [{lo}, {hi}] (solver.relTol's range)"
                ));
            }
        }
        if !start.is_finite() {
            return self.error(&format!(
                "fmi2SetupExperiment: start time {start} is not finite"
            ));
        }
        if let Some(stop) = stop {
            if !stop.is_finite() || stop < start {
                return self.error(&format!(
                    "fmi2SetupExperiment: stop time {stop} must be finite and >= start time {start}"
                ));
            }
        }
        self.core.start_time = start;
        self.core.stop_time = stop;
        self.core.time = start;
        self.core.experiment_tolerance = tolerance;
        Status::Ok
    }

    pub fn enter_initialization(&mut self) -> Status {
        self.core.phase = Phase::InitializationMode;
        Status::Ok
    }

    pub fn exit_initialization(&mut self) -> Status {
        if let Err(status) = self.ensure_simulation() {
            return status;
        }
        self.core.phase = Phase::StepComplete;
        Status::Ok
    }

    pub fn terminate(&mut self) -> Status {
        self.core.phase = Phase::Terminated;
        Status::Ok
    }

    /// Builds the model from the parameters and finds its static equilibrium, once per
    /// initialisation (parameters set afterwards in initialisation mode rebuild it).
    fn ensure_simulation(&mut self) -> Result<(), Status> {
        if self.core.simulation.is_some() {
            return Ok(());
        }
        self.commit_inputs(0.0);
        let mut simulation = self.build_simulation().map_err(|m| self.error(&m))?;
        for line in simulation.describe() {
            self.event(&line);
        }
        let outputs = simulation.outputs().map_err(|m| self.error(&m))?;
        self.write_outputs(&outputs, &simulation.counters());
        self.write_effective_parameters(&simulation);
        // The natural modes of this model are computed when first read.
        self.core.values.integers[integer::MODES_COUNT as usize] = -1;
        self.core.simulation = Some(simulation);
        Ok(())
    }

    /// Fills the natural-mode calculated parameters (`modes.count`, `mode[k].*`) if this
    /// simulation's have not been computed yet: a linearisation and a dense eigenproblem of the
    /// vibration coordinates, tens of milliseconds that a sweep which never reads them saves.
    fn ensure_natural_modes(&mut self) -> Result<(), Status> {
        self.ensure_simulation()?;
        let count = integer::MODES_COUNT as usize;
        if self.core.values.integers[count] >= 0 {
            return Ok(());
        }
        let Some(simulation) = self.core.simulation.as_ref() else {
            return Err(self.error("natural modes: the model is not built"));
        };
        let modes = simulation
            .natural_modes()
            .map_err(|m| self.error(&format!("natural modes: {m}")))?;
        let slots = real::MODE_FREQUENCY.len();
        let r = &mut self.core.values.reals;
        for k in 0..slots {
            let (f, zeta, share) = modes.get(k).map_or((0.0, 0.0, 0.0), |m| {
                (m.frequency_hz, m.damping_ratio, m.powertrain_fraction)
            });
            r[real::MODE_FREQUENCY[k] as usize] = f;
            r[real::MODE_DAMPING[k] as usize] = zeta;
            r[real::MODE_POWERTRAIN_SHARE[k] as usize] = share;
        }
        let shown = modes.len().min(slots);
        self.core.values.integers[count] = i32::try_from(shown).unwrap_or(i32::MAX);
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

    /// The vehicle parameters as the model uses them (a configuration file's values where the
    /// master did not set the parameter), so that reading a parameter tells the truth.
    fn write_effective_parameters(&mut self, simulation: &Simulation) {
        let model = simulation.model();
        let engine = model.powertrain().config();
        let r = &mut self.core.values.reals;
        r[real::ENGINE_LOAD as usize] = engine.gas.load;
        r[real::FADE_IN_TIME as usize] = engine.excitation_fade_in;
        r[real::CRANK_START_ANGLE as usize] = engine.start_crank_angle_deg.to_radians();
        r[real::CRANK_SPEED_TIME_CONSTANT as usize] = model.follower().time_constant;
        let e = model.effects();
        let b = &mut self.core.values.booleans;
        b[boolean::EFFECT_GAS_FORCES as usize] = e.gas_forces;
        b[boolean::EFFECT_MASS_FORCES as usize] = e.mass_forces;
        b[boolean::EFFECT_BALANCE_SHAFT as usize] = e.balance_shaft;
        b[boolean::EFFECT_GYROSCOPIC as usize] = e.gyroscopic;
        b[boolean::EFFECT_RING_CARRIER as usize] = e.ring_carrier_elasticity;
        b[boolean::EFFECT_MOUNT_NONLINEARITY as usize] = e.mount_nonlinearity;
        b[boolean::EFFECT_CHASSIS_FLEXIBILITY as usize] = e.chassis_flexibility;
    }

    /// A simulation built from the current parameters and inputs, at its static equilibrium.
    pub fn build_simulation(&self) -> Result<Simulation, String> {
        let settings = self.settings()?;
        let inputs = self.inputs_at_time();
        self.event(&match (self.core.experiment_tolerance, self.core.explicit.contains("solver.relTol")) {
            (Some(t), false) => format!("relative tolerance {t} from fmi2SetupExperiment"),
            (Some(t), true) => format!(
                "relative tolerance {} from solver.relTol (set explicitly; fmi2SetupExperiment's {t} not used)",
                settings.rel_tol
            ),
            (None, _) => format!("relative tolerance {} (solver.relTol)", settings.rel_tol),
        });
        self.event(&format!(
            "building scene {} at t = {} s (config: {})",
            settings.scene,
            self.core.time,
            settings
                .config_file
                .as_ref()
                .map(|p| p.display().to_string())
                .unwrap_or_else(|| "built-in defaults".to_owned())
        ));
        Simulation::new(&settings, self.core.time, &inputs)
            .map_err(|m| format!("model set-up failed: {m}"))
    }

    /// A simulation for a deserialized FMU state, rebuilt from that state's own parameters.
    pub fn restore_simulation(
        &self,
        core: &Core,
        dynamic: &cosim::SimulationState,
    ) -> Result<Simulation, String> {
        Simulation::restore(&self.settings_for(core)?, dynamic)
    }

    fn settings(&self) -> Result<cosim::Settings, String> {
        self.settings_for(&self.core)
    }

    /// The model settings the parameters in `v` describe.
    fn settings_for(&self, core: &Core) -> Result<cosim::Settings, String> {
        let v = &core.values;
        let config_file = {
            let given = v.strings[string::CONFIG_FILE as usize].trim();
            if !given.is_empty() {
                let p = PathBuf::from(given);
                Some(if p.is_relative() {
                    self.resource_dir.as_ref().map(|r| r.join(&p)).unwrap_or(p)
                } else {
                    p
                })
            } else {
                // The FMU's own vehicle: missing from an unpacked FMU is an error, not a silent
                // switch to the built-in data.
                match &self.resource_dir {
                    Some(r) => {
                        let p = r.join(cosim::DEFAULT_CONFIG_NAME);
                        if !p.is_file() {
                            return Err(format!(
                                "the FMU's resources {} have no {} (configFile is empty)",
                                r.display(),
                                cosim::DEFAULT_CONFIG_NAME
                            ));
                        }
                        Some(p)
                    }
                    None => None,
                }
            }
        };
        let parameters = Parameters::from_values(&v.reals, &v.integers, &v.booleans, &v.strings);
        let settings = cosim::Settings::from_parameters(&parameters, config_file)?;
        Ok(cosim::Settings {
            // The experiment's tolerance is the relative tolerance unless the master set
            // solver.relTol itself.
            rel_tol: match (
                core.experiment_tolerance,
                core.explicit.contains("solver.relTol"),
            ) {
                (Some(tolerance), false) => tolerance,
                _ => settings.rel_tol,
            },
            explicit: Some(core.explicit.clone()),
            ..settings
        })
    }

    /// The inputs as signals from the current time on (what the master set, not yet committed).
    fn inputs_at_time(&self) -> cosim::Inputs {
        inputs_from(&self.core.inputs, self.core.time)
    }

    /// Starts the step `[t, t + step]` for every input ([`InputTrack::commit`]): the signals in
    /// force from now on. The input values the master reads back are the signals' values at `t`.
    /// Returns whether a ramp had to be bent onto a declared bound (logged as a warning).
    fn commit_inputs(&mut self, step: f64) -> bool {
        let t = self.core.time;
        let mut clipped = false;
        for v in REALS.iter().filter(|v| v.causality == Causality::Input) {
            let i = v.vr as usize;
            let track = &mut self.core.inputs[i];
            let commit = track.commit(
                t,
                step,
                v.min.unwrap_or(f64::NEG_INFINITY),
                v.max.unwrap_or(f64::INFINITY),
            );
            self.core.values.reals[i] = track.value;
            if let Some(bound) = commit.clipped {
                clipped = true;
                self.logger.log(
                    Level::Warning,
                    "logStatusWarning",
                    &format!(
                        "{}: the ramp from {} with slope {} per s would leave the declared range within the step from {t} s; it ends on {bound} at {} s",
                        v.name,
                        track.value,
                        track.slope,
                        t + step
                    ),
                );
            }
        }
        clipped
    }

    fn write_outputs(&mut self, o: &cosim::Outputs, c: &cosim::Counters) {
        let r = &mut self.core.values.reals;
        for (i, mount) in o.mount_force.iter().enumerate() {
            for (j, f) in mount.iter().enumerate() {
                r[real::MOUNT_F[i][j] as usize] = *f;
            }
        }
        r[real::CRANK_ANGLE as usize] = o.crank_angle;
        for k in 0..3 {
            r[real::POWERTRAIN_R[k] as usize] = o.powertrain_displacement[k];
            r[real::POWERTRAIN_PHI[k] as usize] = o.powertrain_rotation[k];
            r[real::POWERTRAIN_A[k] as usize] = o.powertrain_acceleration[k];
            r[real::STEERING_WHEEL_A[k] as usize] = o.steering_wheel_acceleration[k];
            r[real::SEAT_A[k] as usize] = o.seat_acceleration[k];
        }
        let n = &mut self.core.values.integers;
        let clamp = |x: u64| x.min(i32::MAX as u64) as i32;
        n[integer::SOLVER_STEPS as usize] = clamp(c.steps);
        n[integer::SOLVER_RHS_EVALUATIONS as usize] = clamp(c.rhs_evaluations);
        n[integer::SOLVER_JACOBIAN_EVALUATIONS as usize] = clamp(c.jacobian_evaluations);
        n[integer::SOLVER_FACTORIZATIONS as usize] = clamp(c.factorizations);
    }

    // ----- get -------------------------------------------------------------------------------

    /// Outputs asked for in initialisation mode are the static equilibrium's.
    fn prepare_get(
        &mut self,
        function: &str,
        vrs: &[u32],
        outputs_of: impl Fn(u32) -> bool,
    ) -> Result<(), Status> {
        self.allowed(function, state::GET_VALUES)?;
        if self.core.phase == Phase::InitializationMode && vrs.iter().any(|vr| outputs_of(*vr)) {
            self.ensure_simulation()?;
        }
        Ok(())
    }

    pub fn get_real(&mut self, vrs: &[u32], out: &mut [f64]) -> Status {
        let is_output = |vr: u32| {
            REALS
                .get(vr as usize)
                .is_some_and(|v| v.causality == Causality::Output)
        };
        if let Err(s) = self.prepare_get("fmi2GetReal", vrs, is_output) {
            return s;
        }
        if vrs.iter().any(|vr| is_calculated(REALS, *vr)) {
            if let Err(s) = self.ensure_natural_modes() {
                return s;
            }
        }
        self.get_values(
            vrs,
            out,
            &self.core.values.reals,
            REALS,
            "fmi2GetReal",
            |x| *x,
        )
    }

    pub fn get_integer(&mut self, vrs: &[u32], out: &mut [i32]) -> Status {
        let is_output = |vr: u32| {
            INTEGERS
                .get(vr as usize)
                .is_some_and(|v| v.causality == Causality::Output)
        };
        if let Err(s) = self.prepare_get("fmi2GetInteger", vrs, is_output) {
            return s;
        }
        if vrs.iter().any(|vr| is_calculated(INTEGERS, *vr)) {
            if let Err(s) = self.ensure_natural_modes() {
                return s;
            }
        }
        self.get_values(
            vrs,
            out,
            &self.core.values.integers,
            INTEGERS,
            "fmi2GetInteger",
            |x| *x,
        )
    }

    pub fn get_boolean(&mut self, vrs: &[u32], out: &mut [bool]) -> Status {
        if let Err(s) = self.prepare_get("fmi2GetBoolean", vrs, |_| false) {
            return s;
        }
        self.get_values(
            vrs,
            out,
            &self.core.values.booleans,
            BOOLEANS,
            "fmi2GetBoolean",
            |x| *x,
        )
    }

    pub fn get_string(&mut self, vrs: &[u32], out: &mut Vec<String>) -> Status {
        if let Err(s) = self.prepare_get("fmi2GetString", vrs, |_| false) {
            return s;
        }
        let mut tmp = vec![String::new(); vrs.len()];
        let status = self.get_values(
            vrs,
            &mut tmp,
            &self.core.values.strings,
            STRINGS,
            "fmi2GetString",
            |x| x.clone(),
        );
        *out = tmp;
        status
    }

    fn get_values<T, S: 'static, F: Fn(&T) -> O, O>(
        &self,
        vrs: &[u32],
        out: &mut [O],
        values: &[T],
        table: &[Variable<S>],
        function: &str,
        convert: F,
    ) -> Status {
        if let Some(bad) = vrs.iter().find(|vr| (**vr as usize) >= table.len()) {
            return self.error(&format!("{function}: unknown value reference {bad}"));
        }
        for (slot, vr) in out.iter_mut().zip(vrs) {
            *slot = convert(&values[*vr as usize]);
        }
        Status::Ok
    }

    // ----- set -------------------------------------------------------------------------------

    /// Whether a variable may be set now (FMI 2.0 §3.2.3 for co-simulation).
    fn settable<T>(&self, v: &Variable<T>) -> Result<(), String> {
        let phase = self.core.phase;
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

    /// Applies validated values and tells the simulation what changed.
    fn after_set(&mut self, structural: bool) {
        if self.core.phase != Phase::StepComplete && structural {
            // Parameters or initial inputs changed before the model started: rebuild lazily.
            self.core.simulation = None;
        }
    }

    /// Whether `core` (from `fmi2SetFMUstate`) can become this instance's state: its values are
    /// admissible and, once this instance has built its model, it was taken with the same
    /// parameters (a state of another scene or configuration would silently change the model).
    pub fn check_state_fits(&self, core: &Core) -> Result<(), String> {
        check_values(&core.values, &core.inputs)?;
        if self.core.simulation.is_none() || core.simulation.is_none() {
            return Ok(());
        }
        let differs = |name: &str, theirs: String, ours: String| {
            Err(format!(
                "the state was taken with {name} = {theirs}, this instance runs with {ours}"
            ))
        };
        let (a, b) = (&core.values, &self.core.values);
        for v in REALS.iter().filter(|v| v.causality == Causality::Parameter) {
            let i = v.vr as usize;
            if a.reals[i].to_bits() != b.reals[i].to_bits() {
                return differs(v.name, a.reals[i].to_string(), b.reals[i].to_string());
            }
        }
        for v in INTEGERS
            .iter()
            .filter(|v| v.causality == Causality::Parameter)
        {
            let i = v.vr as usize;
            if a.integers[i] != b.integers[i] {
                return differs(v.name, a.integers[i].to_string(), b.integers[i].to_string());
            }
        }
        for v in BOOLEANS
            .iter()
            .filter(|v| v.causality == Causality::Parameter)
        {
            let i = v.vr as usize;
            if a.booleans[i] != b.booleans[i] {
                return differs(v.name, a.booleans[i].to_string(), b.booleans[i].to_string());
            }
        }
        for v in STRINGS
            .iter()
            .filter(|v| v.causality == Causality::Parameter)
        {
            let i = v.vr as usize;
            if a.strings[i] != b.strings[i] {
                return differs(
                    v.name,
                    format!("{:?}", a.strings[i]),
                    format!("{:?}", b.strings[i]),
                );
            }
        }
        Ok(())
    }

    /// The values after `vrs := values`, if every reference is known, settable now and passes
    /// `check`; otherwise the logged refusal. Nothing is applied here.
    fn mark_explicit<S: 'static>(&mut self, table: &[Variable<S>], vrs: &[u32]) {
        for vr in vrs {
            let v = &table[*vr as usize];
            if v.causality == Causality::Parameter {
                self.core.explicit.insert(v.name.to_owned());
            }
        }
    }

    fn candidate<T: Clone, S: 'static>(
        &self,
        function: &str,
        table: &[Variable<S>],
        current: &[T],
        vrs: &[u32],
        values: &[T],
        check: impl Fn(&Variable<S>, &T) -> Result<(), String>,
    ) -> Result<Vec<T>, Status> {
        let mut candidate = current.to_vec();
        for (vr, value) in vrs.iter().zip(values) {
            let Some(v) = table.get(*vr as usize) else {
                return Err(self.error(&format!("{function}: unknown value reference {vr}")));
            };
            if let Err(m) = self.settable(v).and_then(|()| check(v, value)) {
                return Err(self.error(&format!("{function}: {m}")));
            }
            candidate[*vr as usize] = value.clone();
        }
        Ok(candidate)
    }

    pub fn set_real(&mut self, vrs: &[u32], values: &[f64]) -> Status {
        const F: &str = "fmi2SetReal";
        if let Err(s) = self.allowed(F, state::SET_VALUES) {
            return s;
        }
        let check = |v: &Variable<f64>, value: &f64| {
            if !value.is_finite() {
                return Err(format!("{} = {value} is not finite", v.name));
            }
            if v.min.is_some_and(|m| *value < m) || v.max.is_some_and(|m| *value > m) {
                return Err(format!(
                    "{} = {value} is outside [{}, {}]",
                    v.name,
                    v.min.unwrap_or(f64::NEG_INFINITY),
                    v.max.unwrap_or(f64::INFINITY)
                ));
            }
            Ok(())
        };
        let candidate = match self.candidate(F, REALS, &self.core.values.reals, vrs, values, check)
        {
            Ok(c) => c,
            Err(s) => return s,
        };
        let mut tracks = self.core.inputs.clone();
        for vr in vrs {
            if REALS[*vr as usize].causality == Causality::Input {
                tracks[*vr as usize].set_value(candidate[*vr as usize]);
            }
        }
        if let Err(m) = inputs_from(&tracks, self.core.time).validate() {
            return self.error(&format!("{F}: {m}"));
        }
        self.core.inputs = tracks;
        self.core.values.reals = candidate;
        self.mark_explicit(REALS, vrs);
        self.after_set(true);
        Status::Ok
    }

    pub fn set_integer(&mut self, vrs: &[u32], values: &[i32]) -> Status {
        const F: &str = "fmi2SetInteger";
        if let Err(s) = self.allowed(F, state::SET_VALUES) {
            return s;
        }
        let check = |v: &Variable<i32>, value: &i32| {
            if v.min.is_some_and(|m| *value < m) || v.max.is_some_and(|m| *value > m) {
                return Err(format!(
                    "{} = {value} is outside [{}, {}]",
                    v.name,
                    v.min.unwrap_or(i32::MIN),
                    v.max.unwrap_or(i32::MAX)
                ));
            }
            Ok(())
        };
        match self.candidate(F, INTEGERS, &self.core.values.integers, vrs, values, check) {
            Ok(c) => self.core.values.integers = c,
            Err(s) => return s,
        }
        self.mark_explicit(INTEGERS, vrs);
        self.after_set(true);
        Status::Ok
    }

    pub fn set_boolean(&mut self, vrs: &[u32], values: &[bool]) -> Status {
        const F: &str = "fmi2SetBoolean";
        if let Err(s) = self.allowed(F, state::SET_VALUES) {
            return s;
        }
        match self.candidate(
            F,
            BOOLEANS,
            &self.core.values.booleans,
            vrs,
            values,
            |_, _| Ok(()),
        ) {
            Ok(c) => self.core.values.booleans = c,
            Err(s) => return s,
        }
        self.mark_explicit(BOOLEANS, vrs);
        self.after_set(true);
        Status::Ok
    }

    pub fn set_string(&mut self, vrs: &[u32], values: &[String]) -> Status {
        const F: &str = "fmi2SetString";
        if let Err(s) = self.allowed(F, state::SET_VALUES) {
            return s;
        }
        match self.candidate(
            F,
            STRINGS,
            &self.core.values.strings,
            vrs,
            values,
            |_, _| Ok(()),
        ) {
            Ok(c) => self.core.values.strings = c,
            Err(s) => return s,
        }
        self.mark_explicit(STRINGS, vrs);
        self.after_set(true);
        Status::Ok
    }

    pub fn set_real_input_derivatives(
        &mut self,
        vrs: &[u32],
        orders: &[i32],
        values: &[f64],
    ) -> Status {
        if let Err(s) = self.allowed("fmi2SetRealInputDerivatives", state::SET_INPUT_DERIVATIVES) {
            return s;
        }
        let mut candidate = self.core.inputs.clone();
        for ((vr, order), value) in vrs.iter().zip(orders).zip(values) {
            let Some(v) = REALS.get(*vr as usize) else {
                return self.error(&format!(
                    "fmi2SetRealInputDerivatives: unknown value reference {vr}"
                ));
            };
            if v.causality != Causality::Input {
                return self.error(&format!(
                    "fmi2SetRealInputDerivatives: {} is not an input",
                    v.name
                ));
            }
            if *order != 1 {
                return self.error(&format!(
                    "fmi2SetRealInputDerivatives: derivative order {order} of {} is not supported (only 1)",
                    v.name
                ));
            }
            if !value.is_finite() {
                return self.error(&format!(
                    "fmi2SetRealInputDerivatives: d{}/dt = {value} is not finite",
                    v.name
                ));
            }
            candidate[*vr as usize].set_slope(*value);
        }
        if let Err(m) = inputs_from(&candidate, self.core.time).validate() {
            return self.error(&format!("fmi2SetRealInputDerivatives: {m}"));
        }
        self.core.inputs = candidate;
        Status::Ok
    }

    // ----- stepping --------------------------------------------------------------------------

    pub fn do_step(&mut self, current: f64, step: f64) -> Status {
        if let Err(s) = self.allowed("fmi2DoStep", state::DO_STEP) {
            return s;
        }
        if !current.is_finite() || !step.is_finite() || step <= 0.0 {
            return self.error(&format!(
                "fmi2DoStep: communication point {current} and step size {step} must be finite, step > 0"
            ));
        }
        if !same_time(current, self.core.time) {
            return self.error(&format!(
                "fmi2DoStep: communication point {current} s does not match the FMU time {} s \
                 (use fmi2SetFMUstate to go back in time)",
                self.core.time
            ));
        }
        let target = on_grid(current + step);
        if let Some(stop) = self.core.stop_time {
            if target > stop && !same_time(target, stop) {
                return self.error(&format!(
                    "fmi2DoStep: step to {target} s passes the stop time {stop} s"
                ));
            }
        }
        if self.core.simulation.is_none() {
            return self.error("fmi2DoStep: the model was not initialised");
        }
        let (tracks_before, reals_before) =
            (self.core.inputs.clone(), self.core.values.reals.clone());
        let clipped = self.commit_inputs(target - current);
        let inputs = self.inputs_at_time();
        let Some(simulation) = self.core.simulation.as_mut() else {
            return Status::Error;
        };
        match simulation.set_inputs(&inputs) {
            Ok(true) => self.event(&format!(
                "input discontinuity at t = {} s: integrator restarted at order 1",
                self.core.time
            )),
            Ok(false) => {}
            Err(m) => {
                self.core.inputs = tracks_before;
                self.core.values.reals = reals_before;
                return self.error(&format!("fmi2DoStep: {m}"));
            }
        }
        let Some(simulation) = self.core.simulation.as_mut() else {
            return Status::Error;
        };
        match simulation.advance_to(target) {
            Ok(()) => {
                let outputs = simulation.outputs();
                let counters = simulation.counters();
                match outputs {
                    Ok(o) => {
                        self.write_outputs(&o, &counters);
                        self.core.time = target;
                        // Inputs read back as the values their signals have reached.
                        for v in REALS.iter().filter(|v| v.causality == Causality::Input) {
                            let i = v.vr as usize;
                            self.core.values.reals[i] = self.core.inputs[i].at(target);
                        }
                        if self.logger.wants(Level::Info, "logSolver") {
                            self.logger.log(
                                Level::Info,
                                "logSolver",
                                &format!(
                                    "t = {target} s: {} steps, {} RHS, {} Jacobians, {} factorisations",
                                    counters.steps,
                                    counters.rhs_evaluations,
                                    counters.jacobian_evaluations,
                                    counters.factorizations
                                ),
                            );
                        }
                        if clipped {
                            Status::Warning
                        } else {
                            Status::Ok
                        }
                    }
                    Err(m) => {
                        self.core.phase = Phase::Error;
                        self.error(&format!("fmi2DoStep: output evaluation failed: {m}"))
                    }
                }
            }
            Err(failure) => {
                // The integrator kept its last successful step; report it and stop the run.
                if let Ok(o) = simulation.outputs() {
                    let counters = simulation.counters();
                    self.write_outputs(&o, &counters);
                }
                let reached = failure.reached;
                self.core.time = reached;
                self.core.phase = Phase::StepFailed;
                self.core.terminated = true;
                self.logger.log(
                    Level::Error,
                    "logStatusError",
                    &format!(
                        "fmi2DoStep from {current} s to {target} s failed at {reached} s: {}",
                        failure.message
                    ),
                );
                Status::Discard
            }
        }
    }

    pub fn last_successful_time(&self) -> f64 {
        self.core.time
    }
}

/// Whether stored values (an FMU state) are admissible: every Real finite, inputs and
/// parameters within their declared ranges, input signals finite.
pub fn check_values(values: &Values, tracks: &[InputTrack]) -> Result<(), String> {
    for v in REALS {
        let x = values.reals[v.vr as usize];
        if !x.is_finite() {
            return Err(format!("{} = {x} is not finite", v.name));
        }
        let ranged = matches!(v.causality, Causality::Input | Causality::Parameter);
        if ranged && (v.min.is_some_and(|m| x < m) || v.max.is_some_and(|m| x > m)) {
            return Err(format!(
                "{} = {x} is outside [{}, {}]",
                v.name,
                v.min.unwrap_or(f64::NEG_INFINITY),
                v.max.unwrap_or(f64::INFINITY)
            ));
        }
    }
    for v in INTEGERS
        .iter()
        .filter(|v| v.causality == Causality::Parameter)
    {
        let x = values.integers[v.vr as usize];
        if v.min.is_some_and(|m| x < m) || v.max.is_some_and(|m| x > m) {
            return Err(format!("{} = {x} is outside its range", v.name));
        }
    }
    for v in REALS.iter().filter(|v| v.causality == Causality::Input) {
        let t = &tracks[v.vr as usize];
        let numbers = [t.value, t.slope, t.since];
        if numbers.iter().any(|x| !x.is_finite())
            || [t.pending_value, t.pending_slope, t.last_slope]
                .iter()
                .flatten()
                .any(|x| !x.is_finite())
        {
            return Err(format!("the signal of {} is not finite", v.name));
        }
    }
    Ok(())
}

/// The input signals the tracks will give from `time` on (SI units).
fn inputs_from(tracks: &[InputTrack], time: f64) -> cosim::Inputs {
    let signal = |vr: u32| {
        let (value, derivative) = tracks[vr as usize].preview(time);
        cosim::Signal {
            value,
            derivative,
            reference_time: time,
        }
    };
    let rpm = signal(real::RPM);
    cosim::Inputs {
        crank_speed: cosim::Signal {
            value: rpm.value * cosim::RPM_TO_RAD_PER_S,
            derivative: rpm.derivative * cosim::RPM_TO_RAD_PER_S,
            reference_time: time,
        },
        load_torque: signal(real::LOAD_TORQUE),
        stiffness_scale: real::MOUNT_STIFFNESS_SCALE.map(signal),
        damping_scale: real::MOUNT_DAMPING_SCALE.map(signal),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The vehicle parameters' start values are the built-in vehicle's: one set of defaults.
    #[test]
    fn parameter_start_values_are_the_built_in_vehicle() {
        let v = crate::model::VehicleConfig::default();
        let start = Values::start();
        let r = &start.reals;
        assert_eq!(r[real::ENGINE_LOAD as usize], v.engine.gas.load);
        assert_eq!(r[real::FADE_IN_TIME as usize], v.engine.excitation_fade_in);
        assert_eq!(
            r[real::CRANK_START_ANGLE as usize],
            v.engine.start_crank_angle_deg.to_radians()
        );
        assert_eq!(
            r[real::CRANK_SPEED_TIME_CONSTANT as usize],
            v.speed_follower.time_constant
        );
        let b = &start.booleans;
        let e = v.effects;
        assert_eq!(b[boolean::EFFECT_GAS_FORCES as usize], e.gas_forces);
        assert_eq!(b[boolean::EFFECT_MASS_FORCES as usize], e.mass_forces);
        assert_eq!(b[boolean::EFFECT_BALANCE_SHAFT as usize], e.balance_shaft);
        assert_eq!(b[boolean::EFFECT_GYROSCOPIC as usize], e.gyroscopic);
        assert_eq!(
            b[boolean::EFFECT_RING_CARRIER as usize],
            e.ring_carrier_elasticity
        );
        assert_eq!(
            b[boolean::EFFECT_MOUNT_NONLINEARITY as usize],
            e.mount_nonlinearity
        );
        assert_eq!(
            b[boolean::EFFECT_CHASSIS_FLEXIBILITY as usize],
            e.chassis_flexibility
        );
        let settings = crate::cosim::Settings::default();
        assert_eq!(r[real::SOLVER_REL_TOL as usize], settings.rel_tol);
        assert_eq!(r[real::SOLVER_ABS_TOL as usize], settings.abs_tol);
    }

    #[test]
    fn deserialized_state_continues_bit_for_bit() {
        let logger = Logger::new(None, std::ptr::null_mut(), "t", false);
        let resources = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("resources");
        let mut inst = Instance::new("t", logger, Some(resources));
        assert_eq!(inst.setup_experiment(0.0, None, None), Status::Ok);
        inst.enter_initialization();
        assert_eq!(inst.exit_initialization(), Status::Ok);
        let mut t = 0.0;
        for _ in 0..20 {
            assert_eq!(inst.do_step(t, 1e-3), Status::Ok);
            t += 1e-3;
        }
        let bytes = super::super::snapshot::serialize(&inst.core);
        let saved = inst.core.clone();
        let mut reference = Vec::new();
        let mut tt = t;
        for _ in 0..30 {
            assert_eq!(inst.do_step(tt, 1e-3), Status::Ok);
            tt += 1e-3;
            reference.push(inst.core.values.reals.clone());
        }
        inst.core = saved.clone();
        let mut tt = t;
        for r in &reference {
            assert_eq!(inst.do_step(tt, 1e-3), Status::Ok);
            tt += 1e-3;
            assert_eq!(&inst.core.values.reals, r, "in-memory");
        }
        let core =
            super::super::snapshot::deserialize(&bytes, |c, d| inst.restore_simulation(c, d))
                .unwrap();
        let a = saved.simulation.as_ref().unwrap().dynamic_state();
        let b = core.simulation.as_ref().unwrap().dynamic_state();
        assert_eq!(a, b);
        inst.core = core;
        let mut tt = t;
        for r in &reference {
            assert_eq!(inst.do_step(tt, 1e-3), Status::Ok);
            tt += 1e-3;
            assert_eq!(&inst.core.values.reals, r);
        }
    }
}
