//! What the runtime knows of the standard an instance was created through ([`Abi`]: each C ABI
//! describes itself once) and of the FMU it is (its GUID and model identifier). A leaf of the
//! runtime: the instance reads it, the guard ([`super::guard`]) acts on it.

use super::state::Phase;
use crate::cosim::FmuKind;
use crate::variables::{BODY_GUID, BODY_MODEL_IDENTIFIER, GUID, MODEL_IDENTIFIER};

/// The names of an ABI's functions that the runtime's messages mention.
#[derive(Debug)]
pub struct FunctionNames {
    /// Instantiation (`fmi2Instantiate`, `fmi3InstantiateCoSimulation`).
    pub instantiate: &'static str,
    /// Freeing an instance.
    pub free_instance: &'static str,
    /// Where the experiment's tolerance comes from (`fmi2SetupExperiment`,
    /// `fmi3EnterInitializationMode`).
    pub setup_experiment: &'static str,
    /// Leaving initialisation mode.
    pub exit_initialization: &'static str,
    /// A communication step.
    pub do_step: &'static str,
    /// Restoring an FMU state.
    pub set_fmu_state: &'static str,
}

/// What the runtime needs to know of the standard an instance was created through.
#[derive(Debug)]
pub struct Abi {
    /// Marks a live instance of this standard; another value than the other standard's, so an
    /// instance of one standard is never used through the other.
    pub live: u64,
    /// The FMUs this ABI instantiates.
    pub kinds: &'static [FmuKind],
    /// Its word for the instantiation token (`GUID`, `instantiation token`).
    pub token: &'static str,
    /// Its word for the resources argument (`resource location`, `resource path`).
    pub resources: &'static str,
    /// FMI 3.0: every call answered with an error leads to [`Phase::Error`]; FMI 2.0 leaves
    /// the phase of a refused call as it was.
    pub errors_enter_error_state: bool,
    /// How the standard names the phases, for messages.
    pub phase_name: fn(Phase) -> &'static str,
    /// What to do in the error state, said when a call is refused there.
    pub error_state_hint: &'static str,
    /// Function names for messages.
    pub names: FunctionNames,
}

/// The GUID (FMI 3.0: instantiation token) of an FMU of this library.
pub fn guid(kind: FmuKind) -> &'static str {
    match kind {
        FmuKind::Engine => GUID,
        FmuKind::Body => BODY_GUID,
    }
}

/// The `modelIdentifier` of an FMU of this library.
pub fn model_identifier(kind: FmuKind) -> &'static str {
    match kind {
        FmuKind::Engine => MODEL_IDENTIFIER,
        FmuKind::Body => BODY_MODEL_IDENTIFIER,
    }
}
