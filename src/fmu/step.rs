//! A communication step (fmi2DoStep, fmi3DoStep): check the step, commit the inputs for it,
//! advance the simulation, report.

use super::bindings;
use super::instance::{Instance, Outcome, Status};
use super::logger::Level;
use super::parameters;
use super::state::Phase;
use super::values::Num;
use crate::cosim;
use crate::variables::{Causality, LogCategory, Variability, REALS};

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

/// What committing the inputs for a step found ([`Instance::commit_inputs`]).
pub(super) struct Committed {
    /// A ramp was bent onto a declared bound (logged as a warning).
    pub clipped: bool,
    /// The Real inputs (indices like [`REALS`]) whose signal continued a ramp the master did not
    /// set since the last step: the values they reach are new.
    pub continued: Vec<u32>,
}

fn same_time(a: f64, b: f64) -> bool {
    (a - b).abs() <= TIME_JITTER * a.abs().max(b.abs()).max(1.0)
}

impl Instance {
    /// A communication step from `current` over `step`.
    pub fn do_step(&mut self, current: f64, step: f64) -> Outcome {
        let target = self.validate_step(current, step)?;
        let clipped = self.commit_step_inputs(target - current)?;
        match self.advance(target) {
            Ok(()) => self.report(target, clipped),
            Err(failure) => Ok(self.fail_step(current, target, failure)),
        }
    }

    /// The end of the step, if the step is admissible here and now.
    fn validate_step(&self, current: f64, step: f64) -> Result<f64, String> {
        if !current.is_finite() || !step.is_finite() || step <= 0.0 {
            return Err(format!(
                "communication point {} and step size {} must be finite, step > 0",
                Num(current),
                Num(step)
            ));
        }
        if !same_time(current, self.core.time) {
            return Err(format!(
                "communication point {} s does not match the FMU time {} s \
                 (use {} to go back in time)",
                Num(current),
                Num(self.core.time),
                self.abi.names.set_fmu_state
            ));
        }
        let target = on_grid(current + step);
        if let Some(stop) = self.core.stop_time {
            if target > stop && !same_time(target, stop) {
                return Err(format!("step to {target} s passes the stop time {stop} s"));
            }
        }
        if self.core.simulation.is_none() {
            return Err("the model was not initialised".into());
        }
        Ok(target)
    }

    /// Commits the input signals for the step and hands them to the simulation. Returns whether
    /// a ramp was bent onto a bound; on refusal nothing changed.
    fn commit_step_inputs(&mut self, step: f64) -> Result<bool, String> {
        let tracks_before = self.core.inputs.clone();
        let reals_before = self.core.values.reals.clone();
        let committed = self.commit_inputs(step);
        let time = self.core.time;
        let inputs = parameters::inputs_from(&self.core.inputs, time);
        // An input the master set since the last step was checked when it was set (or, before
        // the model was built, when it was built), and committing it only bends its ramp toward
        // its declared range, which no rule refuses. A signal nobody set continues its ramp and
        // reaches values nobody checked (a body velocity ramping past what a car body does, a
        // force past its bound): those, and only those, are checked here.
        let continued = committed
            .continued
            .iter()
            .filter_map(|&i| parameters::input_at(&self.core.inputs, i, time))
            .collect::<Vec<_>>();
        let Some(simulation) = self.core.simulation.as_mut() else {
            return Err("the model was not initialised".into());
        };
        let applied = continued
            .iter()
            .try_for_each(|(input, ramp)| simulation.check_input(*input, ramp))
            .and_then(|()| simulation.set_checked_inputs(&inputs));
        match applied {
            Ok(restarted) => {
                if restarted {
                    self.event(&format!(
                        "input discontinuity at t = {time} s: integrator restarted at order 1"
                    ));
                }
                Ok(committed.clipped)
            }
            Err(e) => {
                self.core.inputs = tracks_before;
                self.core.values.reals = reals_before;
                Err(parameters::message(&e))
            }
        }
    }

    /// Integrates to `target`.
    fn advance(&mut self, target: f64) -> Result<(), cosim::StepFailure> {
        match self.core.simulation.as_mut() {
            Some(simulation) => simulation.advance_to(target),
            None => Err(cosim::StepFailure {
                error: cosim::Error::Model("the model was not initialised".into()),
                reached: self.core.time,
            }),
        }
    }

    /// Outputs, time and inputs at the end of a successful step.
    fn report(&mut self, target: f64, clipped: bool) -> Outcome {
        let Some(simulation) = self.core.simulation.as_mut() else {
            return Err("the model was not initialised".into());
        };
        let counters = simulation.counters();
        let outputs = match simulation.outputs() {
            Ok(o) => o,
            Err(e) => {
                self.core.phase = Phase::Error;
                return Err(format!(
                    "output evaluation failed: {}",
                    parameters::message(&e)
                ));
            }
        };
        self.write_outputs(&outputs, &counters);
        self.core.time = target;
        // Inputs read back as the values their signals have reached.
        for v in REALS.iter().filter(|v| v.causality == Causality::Input) {
            let value = self.core.inputs[v.index as usize].at(target);
            self.core.values.reals.put(v.index, value);
        }
        if self.logger.wants(Level::Info, LogCategory::Solver) {
            self.logger.log(
                Level::Info,
                LogCategory::Solver,
                &format!(
                    "t = {target} s: {} steps, {} RHS, {} Jacobians, {} factorisations",
                    counters.steps,
                    counters.rhs_evaluations,
                    counters.jacobian_evaluations,
                    counters.factorizations
                ),
            );
        }
        Ok(if clipped { Status::Warning } else { Status::Ok })
    }

    /// A step the integrator could not complete: it kept its last successful step, which is
    /// reported, and the run stops there (a discard; the instance then reports itself
    /// terminated).
    fn fail_step(&mut self, current: f64, target: f64, failure: cosim::StepFailure) -> Status {
        if let Some(simulation) = self.core.simulation.as_mut() {
            if let Ok(o) = simulation.outputs() {
                let counters = simulation.counters();
                self.write_outputs(&o, &counters);
            }
        }
        let reached = failure.reached;
        self.core.time = reached;
        self.core.phase = Phase::StepFailed;
        self.core.terminated = true;
        self.log_error(&format!(
            "{} from {current} s to {target} s failed at {reached} s: {}",
            self.abi.names.do_step,
            parameters::message(&failure.error)
        ));
        Status::Discard
    }

    /// Starts the step `[t, t + step]` for every input ([`super::input_track::InputTrack::commit`]):
    /// the signals in force from now on. The input values the master reads back are the signals'
    /// values at `t`. Says whether a ramp had to be bent onto a declared bound (logged as a
    /// warning) and which signals continued a ramp without being set.
    pub(super) fn commit_inputs(&mut self, step: f64) -> Committed {
        let t = self.core.time;
        let mut committed = Committed {
            clipped: false,
            continued: Vec::new(),
        };
        for v in REALS.iter().filter(|v| v.causality == Causality::Input) {
            let i = v.index as usize;
            let track = &mut self.core.inputs[i];
            if track.pending_value.is_none() && track.pending_slope.is_none() && track.slope != 0.0
            {
                committed.continued.push(v.index);
            }
            let commit = track.commit(
                t,
                step,
                v.min.unwrap_or(f64::NEG_INFINITY),
                v.max.unwrap_or(f64::INFINITY),
            );
            let (value, lo, hi) = (track.value, track.lo, track.hi);
            self.core.values.reals.put(v.index, value);
            if let Some(bound) = commit.clipped {
                committed.clipped = true;
                self.log_warning(&format!(
                    "{}: the ramp from {} with slope {} per s would leave the declared range [{}, {}] within the step from {t} s; it ends on {} at {} s and stays there until a new value or derivative is set",
                    v.name,
                    Num(value),
                    Num(commit.requested_slope),
                    Num(lo),
                    Num(hi),
                    Num(bound),
                    t + step
                ));
            }
        }
        committed
    }

    /// The first time derivatives of the Real outputs at `indices` at the current communication
    /// point ([`cosim::Simulation::output_derivatives`]), for FMI 3.0's
    /// fmi3GetOutputDerivatives; refused for anything but a continuous output.
    pub fn output_derivatives(&mut self, indices: &[usize]) -> Result<Vec<f64>, String> {
        if let Some(v) = indices
            .iter()
            .map(|&i| &REALS[i])
            .find(|v| v.causality != Causality::Output || v.variability != Variability::Continuous)
        {
            return Err(format!("{} is not a continuous output", v.name));
        }
        let Some(simulation) = self.core.simulation.as_mut() else {
            return Err("the model was not initialised".into());
        };
        let derivatives = simulation
            .output_derivatives()
            .map_err(|e| parameters::message(&e))?;
        let counters = simulation.counters();
        // The one mapping from outputs to variables, applied to the derivatives on a copy.
        let values = self.core.values.clone();
        self.write_outputs(&derivatives, &counters);
        let reals = std::mem::replace(&mut self.core.values, values).reals;
        Ok(indices.iter().map(|&i| reals.as_slice()[i]).collect())
    }

    /// Writes the outputs and the solver counters, each where its row of the variable table
    /// binds it.
    pub(super) fn write_outputs(&mut self, o: &cosim::Outputs, c: &cosim::Counters) {
        bindings::put_outputs(&mut self.core.values.reals, o);
        bindings::put_counters(&mut self.core.values.integers, c);
    }
}
