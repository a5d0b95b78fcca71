//! The FMI 2.0 co-simulation state machine as a per-function mask (like the Modelica
//! Reference-FMUs): every entry point states the phases in which it may be called.

/// Where an instance is in the co-simulation state machine.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Phase {
    Instantiated,
    InitializationMode,
    StepComplete,
    StepFailed,
    Terminated,
    Error,
    Fatal,
}

impl Phase {
    fn bit(self) -> u16 {
        1 << (self as u16)
    }
}

/// A set of phases.
#[derive(Debug, Clone, Copy)]
pub struct Mask(u16);

impl Mask {
    const fn of(phases: &[Phase]) -> Mask {
        let mut bits = 0u16;
        let mut i = 0;
        while i < phases.len() {
            bits |= 1 << (phases[i] as u16);
            i += 1;
        }
        Mask(bits)
    }

    pub fn allows(self, phase: Phase) -> bool {
        self.0 & phase.bit() != 0
    }
}

use Phase::*;

// The masks of the co-simulation state machine (FMI 2.0 §4.2.4, Table 4.2.4; the same as the
// Modelica Reference-FMUs'). `stepInProgress` and `stepCanceled` never occur here: fmi2DoStep
// always completes before it returns.

/// fmi2SetDebugLogging: every state with an instance.
pub const SET_DEBUG_LOGGING: Mask = Mask::of(&[
    Instantiated,
    InitializationMode,
    StepComplete,
    StepFailed,
    Terminated,
    Error,
]);
/// fmi2FreeInstance, fmi2Reset and the FMU-state functions.
pub const ANY_INSTANCE: Mask = SET_DEBUG_LOGGING;
pub const RESET: Mask = ANY_INSTANCE;
pub const FMU_STATE: Mask = ANY_INSTANCE;
pub const SETUP_EXPERIMENT: Mask = Mask::of(&[Instantiated]);
pub const ENTER_INITIALIZATION: Mask = Mask::of(&[Instantiated]);
pub const EXIT_INITIALIZATION: Mask = Mask::of(&[InitializationMode]);
pub const TERMINATE: Mask = Mask::of(&[StepComplete, StepFailed]);
/// fmi2GetReal/Integer/Boolean/String.
pub const GET_VALUES: Mask = Mask::of(&[
    InitializationMode,
    StepComplete,
    StepFailed,
    Terminated,
    Error,
]);
/// fmi2SetReal/Integer/Boolean/String (co-simulation: no event or continuous-time mode).
pub const SET_VALUES: Mask = Mask::of(&[Instantiated, InitializationMode, StepComplete]);
pub const DIRECTIONAL_DERIVATIVE: Mask = GET_VALUES;
pub const SET_INPUT_DERIVATIVES: Mask = Mask::of(&[Instantiated, InitializationMode, StepComplete]);
pub const GET_OUTPUT_DERIVATIVES: Mask = Mask::of(&[StepComplete, StepFailed, Terminated, Error]);
pub const DO_STEP: Mask = Mask::of(&[StepComplete]);
/// fmi2CancelStep: only in `stepInProgress`, which never occurs.
pub const CANCEL_STEP: Mask = Mask::of(&[]);
/// fmi2GetStatus and its typed variants.
pub const GET_STATUS: Mask = Mask::of(&[StepComplete, StepFailed, Terminated]);
