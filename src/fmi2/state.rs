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

/// Every phase but `Fatal`.
pub const ANY_BUT_FATAL: Mask = Mask::of(&[
    Instantiated,
    InitializationMode,
    StepComplete,
    StepFailed,
    Terminated,
    Error,
]);
pub const SETUP_EXPERIMENT: Mask = Mask::of(&[Instantiated]);
pub const ENTER_INITIALIZATION: Mask = Mask::of(&[Instantiated]);
pub const EXIT_INITIALIZATION: Mask = Mask::of(&[InitializationMode]);
pub const TERMINATE: Mask = Mask::of(&[StepComplete, StepFailed, Error]);
pub const GET_VALUES: Mask = Mask::of(&[
    InitializationMode,
    StepComplete,
    StepFailed,
    Terminated,
    Error,
]);
pub const SET_VALUES: Mask = Mask::of(&[Instantiated, InitializationMode, StepComplete]);
pub const SET_INPUT_DERIVATIVES: Mask = Mask::of(&[Instantiated, InitializationMode, StepComplete]);
pub const GET_OUTPUT_DERIVATIVES: Mask = Mask::of(&[StepComplete, StepFailed, Terminated, Error]);
pub const DO_STEP: Mask = Mask::of(&[StepComplete]);
pub const GET_STATUS: Mask = Mask::of(&[StepComplete, StepFailed, Terminated, Error]);
pub const FMU_STATE: Mask = ANY_BUT_FATAL;
