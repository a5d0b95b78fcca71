//! The FMI 3.0 co-simulation state machine (FMI 3.0 §4.2, without event mode, intermediate
//! update and reconfiguration) as a per-function mask over the runtime's one [`Phase`]: its
//! step mode is [`Phase::StepComplete`] or [`Phase::StepFailed`] (after a discarded step,
//! which reported terminateSimulation), and every fmi3Error leads to [`Phase::Error`] (FMI 3.0
//! §2.2.3: after fmi3Error only restoring an FMU state, fmi3Reset or fmi3FreeInstance continue).

use crate::fmu::state::{Mask, Phase, Phase::*, READABLE};

/// FMI 3.0's name of `phase`, for messages.
pub fn name(phase: Phase) -> &'static str {
    match phase {
        StepComplete | StepFailed => "StepMode",
        other => other.name(),
    }
}

/// Every phase with a usable instance: fmi3SetDebugLogging, fmi3Reset, fmi3SetFMUState and the
/// FMU-state bookkeeping (free, serialize, deserialize).
pub const ANY: Mask = Mask::of(&[
    Instantiated,
    ConfigurationMode,
    InitializationMode,
    StepComplete,
    StepFailed,
    Terminated,
    Error,
]);
/// Functions that are refused in their body (not supported by this FMU): every phase but the
/// error state, so that the refusal names the reason.
pub const UNSUPPORTED: Mask = Mask::of(&[
    Instantiated,
    ConfigurationMode,
    InitializationMode,
    StepComplete,
    StepFailed,
    Terminated,
]);
/// fmi3GetFMUState: where the instance has a consistent state.
pub const GET_FMU_STATE: Mask = Mask::of(&[
    Instantiated,
    InitializationMode,
    StepComplete,
    StepFailed,
    Terminated,
]);
/// fmi3EnterConfigurationMode and fmi3EnterInitializationMode.
pub const ENTER_FROM_INSTANTIATED: Mask = Mask::of(&[Instantiated]);
/// fmi3ExitConfigurationMode.
pub const EXIT_CONFIGURATION: Mask = Mask::of(&[ConfigurationMode]);
/// fmi3ExitInitializationMode.
pub const EXIT_INITIALIZATION: Mask = Mask::of(&[InitializationMode]);
/// fmi3Terminate.
pub const TERMINATE: Mask = Mask::of(&[StepComplete, StepFailed]);
/// fmi3GetOutputDerivatives: at a communication point after initialisation.
pub const GET_OUTPUT_DERIVATIVES: Mask = Mask::of(&[StepComplete, StepFailed, Terminated]);
/// fmi3GetDirectionalDerivative: where values can be read after initialisation (the instance
/// refuses it outside step mode).
pub const DIRECTIONAL_DERIVATIVE: Mask =
    Mask::of(&[InitializationMode, StepComplete, StepFailed, Terminated]);
/// fmi3DoStep (refused in its body after a discarded step, with terminateSimulation).
pub const DO_STEP: Mask = Mask::of(&[StepComplete, StepFailed]);
/// fmi3GetFloat64, Int32, Boolean, String: where values can be read, and the error state (for
/// diagnosis).
pub const GET_VALUES: Mask = READABLE;
/// fmi3GetUInt64 (the structural parameter `modes.size`): also before initialisation.
pub const GET_STRUCTURAL: Mask = ANY;
/// fmi3SetFloat64, Int32, Boolean, String: parameters before initialisation ends, inputs also
/// in step mode (the instance checks which variable may be set when).
pub const SET_VALUES: Mask =
    Mask::of(&[Instantiated, InitializationMode, StepComplete, StepFailed]);
/// fmi3SetUInt64 (the structural parameter `modes.size`, variability fixed): configuration
/// mode only.
pub const SET_STRUCTURAL: Mask = Mask::of(&[ConfigurationMode]);
