//! The FMU runtime both C ABIs ([`crate::fmi2`], [`crate::fmi3`]) sit beside: everything an FMU
//! instance is and does, whichever standard a master speaks. The ABIs keep only the standard's
//! exported signatures, their state masks and the mapping of the standard's types and value
//! references onto this runtime.
//!
//! - [`guard`]: the handle a master holds, the one guard every exported function passes
//!   ([`guard::Abi::entry`]: instance pointer, liveness marker, state mask, panics), instantiation
//!   and freeing, and the work both standards share behind their signatures (values at resolved
//!   positions, FMU states).
//! - [`abi`]: each ABI's description of itself ([`abi::Abi`]) and the FMU's GUID and model
//!   identifier, which the instance and the guard read.
//! - [`state`]: the one co-simulation state type of both standards and the masks of phases.
//! - [`instance`]: one instance: life cycle, reading and writing variables, FMU states;
//!   [`step`]: a communication step; [`initial_sensitivity`]: directional derivatives of the
//!   initialisation.
//! - [`values`]: the variable values, one store generic over the four types.
//! - [`parameters`]: the one mapping between FMU variables and the co-simulation runtime's typed
//!   settings, inputs and errors; [`bindings`]: the outputs, bound from the variable table.
//! - [`input_track`]: how the values and derivatives a master sets become input signals.
//! - [`logger`], [`snapshot`], [`fmu_states`]: logging through the environment's callback, the
//!   serialized FMU state, and the FMU states an instance handed out.
//! - [`c_args`]: C arrays, out-parameters and strings as Rust values.
//!
//! No physics lives here: the model is driven through [`crate::cosim::Runtime`].

pub mod abi;
pub mod bindings;
pub mod c_args;
pub mod fmu_states;
pub mod guard;
pub mod initial_sensitivity;
pub mod input_track;
pub mod instance;
pub mod logger;
pub mod parameters;
pub mod snapshot;
pub mod state;
pub mod step;
pub mod values;
