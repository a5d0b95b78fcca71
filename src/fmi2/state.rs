//! The FMI 2.0 co-simulation state machine as a per-function mask (like the Modelica
//! Reference-FMUs): every entry point states the phases in which it may be called.

use crate::fmu::state::{Mask, Phase::*, READABLE};

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
/// fmi2Reset: every phase with a usable instance.
pub const RESET: Mask = ANY_INSTANCE;
/// fmi2GetFMUstate, fmi2SetFMUstate, fmi2FreeFMUstate and the (de)serialisation functions.
pub const FMU_STATE: Mask = ANY_INSTANCE;
/// fmi2SetupExperiment: only before initialisation.
pub const SETUP_EXPERIMENT: Mask = Mask::of(&[Instantiated]);
/// fmi2EnterInitializationMode: only once after instantiation (or reset).
pub const ENTER_INITIALIZATION: Mask = Mask::of(&[Instantiated]);
/// fmi2ExitInitializationMode: only in initialisation mode.
pub const EXIT_INITIALIZATION: Mask = Mask::of(&[InitializationMode]);
/// fmi2Terminate: after initialisation, also after a failed step.
pub const TERMINATE: Mask = Mask::of(&[StepComplete, StepFailed]);
/// fmi2GetReal/Integer/Boolean/String.
pub const GET_VALUES: Mask = READABLE;
/// fmi2SetReal/Integer/Boolean/String (co-simulation: no event or continuous-time mode).
pub const SET_VALUES: Mask = Mask::of(&[Instantiated, InitializationMode, StepComplete]);
/// fmi2GetDirectionalDerivative: where values can be read.
pub const DIRECTIONAL_DERIVATIVE: Mask = GET_VALUES;
/// fmi2SetRealInputDerivatives: wherever inputs may be set.
pub const SET_INPUT_DERIVATIVES: Mask = Mask::of(&[Instantiated, InitializationMode, StepComplete]);
/// fmi2GetRealOutputDerivatives (always refused in the body): after initialisation.
pub const GET_OUTPUT_DERIVATIVES: Mask = Mask::of(&[StepComplete, StepFailed, Terminated, Error]);
/// fmi2DoStep: only after a successful initialisation or step.
pub const DO_STEP: Mask = Mask::of(&[StepComplete]);
/// fmi2CancelStep: only in `stepInProgress`, which never occurs.
pub const CANCEL_STEP: Mask = Mask::of(&[]);
/// fmi2GetStatus and its typed variants.
pub const GET_STATUS: Mask = Mask::of(&[StepComplete, StepFailed, Terminated]);
