//! The serialized FMU state: [`Core`] in the crate's one saved-state format
//! ([`crate::saved_state`]), tied to this FMU's GUID.
//!
//! The model itself is not stored: it is rebuilt from the stored parameters, so a buffer stays
//! small and cannot smuggle in a model.

use serde::{Deserialize, Serialize};

use super::input_track::InputTrack;
use super::instance::Core;
use super::state::Phase;
use super::values::Values;
use crate::cosim::{Runtime, RuntimeState};
use crate::saved_state;

const MAGIC: &[u8; 8] = b"EMCSTATE";
/// 6: the runtime's inputs as ramps, one list per mount; 4: values with the variables the master
/// set; 3: postcard; 1 and 2 were hand-written byte layouts.
const FORMAT_VERSION: u32 = 6;

/// What a serialized state holds: the co-simulation state machine, every variable value, the
/// input signals and the simulation's dynamic state.
#[derive(Serialize, Deserialize)]
struct SavedCore {
    guid: String,
    phase: Phase,
    start_time: f64,
    stop_time: Option<f64>,
    time: f64,
    terminated: bool,
    experiment_tolerance: Option<f64>,
    values: Values,
    inputs: Vec<InputTrack>,
    simulation: Option<RuntimeState>,
}

/// Serializes a captured FMU state.
pub fn serialize(core: &Core, guid: &str) -> Vec<u8> {
    let saved = SavedCore {
        guid: guid.to_string(),
        phase: core.phase,
        start_time: core.start_time,
        stop_time: core.stop_time,
        time: core.time,
        terminated: core.terminated,
        experiment_tolerance: core.experiment_tolerance,
        values: core.values.clone(),
        inputs: core.inputs.clone(),
        simulation: core.simulation.as_ref().map(Runtime::dynamic_state),
    };
    saved_state::encode(MAGIC, FORMAT_VERSION, &saved)
}

/// Rebuilds a state from bytes; `rebuild` constructs the simulation from the stored values and
/// the simulation's dynamic state.
pub fn deserialize(
    bytes: &[u8],
    guid: &str,
    rebuild: impl FnOnce(&Core, &RuntimeState) -> Result<Runtime, String>,
) -> Result<Core, String> {
    let saved: SavedCore =
        saved_state::decode(bytes, MAGIC, FORMAT_VERSION, "an FMU state of this model")?;
    if saved.guid != guid {
        return Err(format!(
            "FMU state belongs to GUID {}, this FMU is {guid}",
            saved.guid
        ));
    }
    let mut core = Core {
        phase: saved.phase,
        values: saved.values,
        inputs: saved.inputs,
        start_time: saved.start_time,
        stop_time: saved.stop_time,
        experiment_tolerance: saved.experiment_tolerance,
        time: saved.time,
        terminated: saved.terminated,
        simulation: None,
        setup_failure: None,
        initial_sensitivities: Default::default(),
    };
    core.check()?;
    if let Some(dynamic) = &saved.simulation {
        core.simulation = Some(rebuild(&core, dynamic)?);
    }
    Ok(core)
}
