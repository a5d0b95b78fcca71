//! Where an instance is in the co-simulation state machine, one type for both standards, and a
//! set of phases ([`Mask`]) in which a function may be called. Each ABI states its masks
//! (`fmi2::state`, `fmi3::state`, like the Modelica Reference-FMUs' per-function masks) and how
//! it names the phases.

/// Where an instance is in the co-simulation state machine of FMI 2.0 (§4.2.4) or FMI 3.0
/// (§4.2, without event mode, intermediate update and reconfiguration). The two standards share
/// all phases but configuration mode, which only FMI 3.0 has; in FMI 3.0 `StepComplete` and
/// `StepFailed` are both its step mode, and every call answered with fmi3Error leads to `Error`.
///
/// Serialized FMU states store it by variant position: new variants go at the end.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Phase {
    /// After instantiation or reset: parameters may be set, the experiment set up.
    Instantiated,
    /// Between entering and exiting initialisation mode.
    InitializationMode,
    /// The model is built and the last step (if any) succeeded: a step may be taken.
    StepComplete,
    /// A step was discarded: values can be read, the simulation cannot continue.
    StepFailed,
    /// After terminate.
    Terminated,
    /// Output evaluation failed after a step, or (FMI 3.0) a call returned fmi3Error: values
    /// can be read; restoring an FMU state or a reset continue.
    Error,
    /// A panic (a bug) made the instance unusable; only freeing it is allowed.
    Fatal,
    /// FMI 3.0 only: between fmi3EnterConfigurationMode and fmi3ExitConfigurationMode, where
    /// structural parameters (`modes.size`) may be set.
    ConfigurationMode,
}

impl Phase {
    fn bit(self) -> u16 {
        1 << (self as u16)
    }

    /// The phase's name as FMI 2.0 (and, but for step mode, FMI 3.0) writes it.
    pub fn name(self) -> &'static str {
        match self {
            Phase::Instantiated => "Instantiated",
            Phase::InitializationMode => "InitializationMode",
            Phase::StepComplete => "StepComplete",
            Phase::StepFailed => "StepFailed",
            Phase::Terminated => "Terminated",
            Phase::Error => "Error",
            Phase::Fatal => "Fatal",
            Phase::ConfigurationMode => "ConfigurationMode",
        }
    }
}

/// A set of phases.
#[derive(Debug, Clone, Copy)]
pub struct Mask(u16);

impl Mask {
    /// The set of `phases`.
    pub const fn of(phases: &[Phase]) -> Mask {
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
        self.0 & phase.bit() != 0
    }
}

/// Where values can be read in both standards: from initialisation on, also after a failed step
/// and in the error state (for diagnosis).
pub const READABLE: Mask = Mask::of(&[
    Phase::InitializationMode,
    Phase::StepComplete,
    Phase::StepFailed,
    Phase::Terminated,
    Phase::Error,
]);
