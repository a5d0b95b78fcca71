//! The FMI 3.0 co-simulation state machine (FMI 3.0 §4.2, without event mode, intermediate
//! update and reconfiguration) as a per-function mask, like [`crate::fmi2::state`].
//!
//! The instance underneath keeps the 2.0 phase ([`crate::fmi2::state::Phase`]), which also
//! travels in FMU states; the 3.0 phase is derived from it and two flags of the 3.0 handle:
//! configuration mode, and the error state every `fmi3Error` leads to (FMI 3.0 §2.2.3: after
//! fmi3Error only restoring an FMU state, fmi3Reset or fmi3FreeInstance continue).

use crate::fmi2::state::Phase as Phase2;

/// Where a 3.0 instance is in the co-simulation state machine.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// After fmi3InstantiateCoSimulation or fmi3Reset.
    Instantiated,
    /// Between fmi3EnterConfigurationMode and fmi3ExitConfigurationMode: structural parameters
    /// (`modes.size`) may be set.
    ConfigurationMode,
    /// Between fmi3EnterInitializationMode and fmi3ExitInitializationMode.
    InitializationMode,
    /// After initialisation: fmi3DoStep may be called (refused after a discarded step, which
    /// reported terminateSimulation).
    StepMode,
    /// After fmi3Terminate.
    Terminated,
    /// A call returned fmi3Error: only fmi3SetFMUState, fmi3Reset, fmi3FreeInstance (and
    /// reading values, logging settings and FMU-state bookkeeping) are allowed.
    Error,
    /// A panic (a bug) made the instance unusable; only fmi3FreeInstance is allowed.
    Fatal,
}

impl Phase {
    /// The 3.0 phase of an instance in 2.0 phase `phase` with the 3.0 handle's flags.
    pub fn of(phase: Phase2, configuration: bool, error: bool) -> Phase {
        match phase {
            Phase2::Fatal => Phase::Fatal,
            _ if error => Phase::Error,
            _ if configuration => Phase::ConfigurationMode,
            Phase2::Instantiated => Phase::Instantiated,
            Phase2::InitializationMode => Phase::InitializationMode,
            Phase2::StepComplete | Phase2::StepFailed => Phase::StepMode,
            Phase2::Terminated => Phase::Terminated,
            Phase2::Error => Phase::Error,
        }
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

    /// Whether `phase` is in the set.
    pub fn allows(self, phase: Phase) -> bool {
        self.0 & (1 << (phase as u16)) != 0
    }
}

use Phase::*;

/// Every phase with a usable instance: fmi3SetDebugLogging, fmi3Reset, fmi3SetFMUState and the
/// FMU-state bookkeeping (free, serialize, deserialize).
pub const ANY: Mask = Mask::of(&[
    Instantiated,
    ConfigurationMode,
    InitializationMode,
    StepMode,
    Terminated,
    Error,
]);
/// Functions that are refused in their body (not supported by this FMU): every phase but the
/// error state, so that the refusal names the reason.
pub const UNSUPPORTED: Mask = Mask::of(&[
    Instantiated,
    ConfigurationMode,
    InitializationMode,
    StepMode,
    Terminated,
]);
/// fmi3GetFMUState: where the instance has a consistent state.
pub const GET_FMU_STATE: Mask = Mask::of(&[Instantiated, InitializationMode, StepMode, Terminated]);
/// fmi3EnterConfigurationMode and fmi3EnterInitializationMode.
pub const ENTER_FROM_INSTANTIATED: Mask = Mask::of(&[Instantiated]);
/// fmi3ExitConfigurationMode.
pub const EXIT_CONFIGURATION: Mask = Mask::of(&[ConfigurationMode]);
/// fmi3ExitInitializationMode.
pub const EXIT_INITIALIZATION: Mask = Mask::of(&[InitializationMode]);
/// fmi3Terminate.
pub const TERMINATE: Mask = Mask::of(&[StepMode]);
/// fmi3GetOutputDerivatives: at a communication point after initialisation.
pub const GET_OUTPUT_DERIVATIVES: Mask = Mask::of(&[StepMode, Terminated]);
/// fmi3DoStep.
pub const DO_STEP: Mask = Mask::of(&[StepMode]);
/// fmi3GetFloat64, Int32, Boolean, String: the 2.0 phases where values can be read, and the
/// error state (for diagnosis).
pub const GET_VALUES: Mask = Mask::of(&[InitializationMode, StepMode, Terminated, Error]);
/// fmi3GetUInt64 (the structural parameter `modes.size`): also before initialisation.
pub const GET_STRUCTURAL: Mask = Mask::of(&[
    Instantiated,
    ConfigurationMode,
    InitializationMode,
    StepMode,
    Terminated,
    Error,
]);
/// fmi3SetFloat64, Int32, Boolean, String: parameters before initialisation ends, inputs also
/// in step mode (the instance checks which variable may be set when).
pub const SET_VALUES: Mask = Mask::of(&[Instantiated, InitializationMode, StepMode]);
/// fmi3SetUInt64 (the structural parameter `modes.size`, variability fixed): configuration
/// mode only.
pub const SET_STRUCTURAL: Mask = Mask::of(&[ConfigurationMode]);
