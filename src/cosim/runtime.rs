//! One runtime for either FMU the library serves: the engine's [`Simulation`] (scenes 1–3) or
//! the body alone ([`BodySimulation`]). The FMI layer holds a [`Runtime`] and never needs to
//! know which, except where the two FMUs' variables differ.

use super::body::{BodySimulation, BodyState};
use super::settings::Replaced;
use super::{
    Counters, Error, Input, Inputs, Outputs, RampInput, Settings, Simulation, SimulationState,
    StepFailure,
};
use crate::model::Mode;

/// Which FMU an instance is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum FmuKind {
    /// `EngineMountChassis`: the powertrain on its mounts (scenes 1–3).
    Engine,
    /// `EngineMountBody`: the reduced body alone, driven by the mount forces.
    Body,
}

/// A built model ready to step.
#[derive(Clone)]
pub enum Runtime {
    /// The engine FMU's simulation (both boxed: large and of different sizes).
    Engine(Box<Simulation>),
    /// The body FMU's.
    Body(Box<BodySimulation>),
}

/// What a [`Runtime`]'s settings do not determine.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum RuntimeState {
    /// Of an engine simulation (both boxed: large and of different sizes).
    Engine(Box<SimulationState>),
    /// Of the body alone.
    Body(Box<BodyState>),
}

impl Runtime {
    /// Builds the model of `kind` at its start under the inputs at `t0`.
    pub fn new(
        kind: FmuKind,
        settings: &Settings,
        t0: f64,
        inputs: &Inputs,
    ) -> Result<Self, Error> {
        let mut runtime = match kind {
            FmuKind::Engine => Runtime::Engine(Box::new(Simulation::new(settings, t0, inputs)?)),
            FmuKind::Body => Runtime::Body(Box::new(BodySimulation::new(settings, t0, inputs)?)),
        };
        if let Some(request) = &settings.export {
            match &mut runtime {
                Runtime::Engine(s) => {
                    let line = super::export::write_engine(s, settings, request)?;
                    s.notes.push(line);
                }
                Runtime::Body(s) => {
                    let line = super::export::write_body(s, settings, request)?;
                    s.notes.push(line);
                }
            }
        }
        Ok(runtime)
    }

    /// Rebuilds from the settings and a saved [`RuntimeState`].
    pub fn restore(settings: &Settings, saved: &RuntimeState) -> Result<Self, Error> {
        Ok(match saved {
            RuntimeState::Engine(s) => Runtime::Engine(Box::new(Simulation::restore(settings, s)?)),
            RuntimeState::Body(s) => Runtime::Body(Box::new(BodySimulation::restore(settings, s)?)),
        })
    }

    /// The engine simulation, if this is one.
    pub fn engine(&self) -> Option<&Simulation> {
        match self {
            Runtime::Engine(s) => Some(s),
            Runtime::Body(_) => None,
        }
    }

    /// Lines for the log describing the model.
    pub fn describe(&self) -> Vec<String> {
        match self {
            Runtime::Engine(s) => s.describe(),
            Runtime::Body(s) => s.describe(),
        }
    }

    /// Configuration values the settings replaced.
    pub fn replaced(&self) -> &[Replaced] {
        match self {
            Runtime::Engine(s) => s.replaced(),
            Runtime::Body(s) => s.replaced(),
        }
    }

    /// Outputs at the communication time.
    pub fn outputs(&mut self) -> Result<Outputs, Error> {
        match self {
            Runtime::Engine(s) => s.outputs(),
            Runtime::Body(s) => Ok(s.outputs()),
        }
    }

    /// Outputs at the communication time, the state held, with the interface signals of
    /// `interface` (attachment motion, forces on the body) in place of those in force: what the
    /// outputs with direct feedthrough are as soon as the master sets those inputs.
    pub fn outputs_with(&mut self, interface: &Inputs) -> Result<Outputs, Error> {
        match self {
            Runtime::Engine(s) => s.outputs_with(interface),
            Runtime::Body(s) => s.outputs_with(interface),
        }
    }

    /// The response of the outputs to the interface increments in `seed` (values only), the
    /// state held, evaluated with the interface signals of `at`.
    pub fn input_sensitivities(&mut self, at: &Inputs, seed: &Inputs) -> Result<Outputs, Error> {
        match self {
            Runtime::Engine(s) => s.input_sensitivities(at, seed),
            Runtime::Body(s) => Ok(s.input_sensitivities(seed)),
        }
    }

    /// The outputs' first time derivatives at the communication time (the engine's; the body
    /// FMU has no FMI 3.0 twin that would ask).
    pub fn output_derivatives(&mut self) -> Result<Outputs, Error> {
        match self {
            Runtime::Engine(s) => s.output_derivatives(),
            Runtime::Body(_) => Err(Error::Model(
                "output derivatives are provided by the engine FMU only".into(),
            )),
        }
    }

    /// Work counters.
    pub fn counters(&self) -> Counters {
        match self {
            Runtime::Engine(s) => s.counters(),
            Runtime::Body(s) => s.counters(),
        }
    }

    /// Natural modes, ascending.
    pub fn natural_modes(&self) -> Result<Vec<Mode>, Error> {
        match self {
            Runtime::Engine(s) => s.natural_modes(),
            Runtime::Body(s) => Ok(s.natural_modes()),
        }
    }

    /// The model's rule for one input ([`crate::model::Input::check`]), changing nothing: the
    /// check of an input when it is set. An input the model does not have passes.
    pub fn check_input(&self, input: Input, ramp: &RampInput) -> Result<(), Error> {
        match self {
            Runtime::Engine(s) => s.check_input(input, ramp),
            Runtime::Body(s) => s.check_input(input, ramp),
        }
    }

    /// Applies inputs from the current time on; whether the integrator restarted.
    pub fn set_inputs(&mut self, inputs: &Inputs) -> Result<bool, Error> {
        match self {
            Runtime::Engine(s) => s.set_inputs(inputs),
            Runtime::Body(s) => s.set_inputs(inputs),
        }
    }

    /// Applies inputs each of which passed its rule ([`Self::check_input`]) where it was set:
    /// the rules do not run again. Whether the integrator restarted.
    pub fn set_checked_inputs(&mut self, inputs: &Inputs) -> Result<bool, Error> {
        match self {
            Runtime::Engine(s) => s.set_checked_inputs(inputs),
            Runtime::Body(s) => s.set_checked_inputs(inputs),
        }
    }

    /// Advances to `t`.
    pub fn advance_to(&mut self, t: f64) -> Result<(), StepFailure> {
        match self {
            Runtime::Engine(s) => s.advance_to(t),
            Runtime::Body(s) => s.advance_to(t),
        }
    }

    /// The communication time reached.
    pub fn time(&self) -> f64 {
        match self {
            Runtime::Engine(s) => s.time(),
            Runtime::Body(s) => s.time(),
        }
    }

    /// Number of states.
    pub fn state_count(&self) -> usize {
        match self {
            Runtime::Engine(s) => s.state_count(),
            Runtime::Body(s) => s.state_count(),
        }
    }

    /// Everything the settings do not determine.
    pub fn dynamic_state(&self) -> RuntimeState {
        match self {
            Runtime::Engine(s) => RuntimeState::Engine(Box::new(s.dynamic_state())),
            Runtime::Body(s) => RuntimeState::Body(Box::new(s.dynamic_state())),
        }
    }
}
