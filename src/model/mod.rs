//! Engine multibody model, mounts, coupled system and outputs.
//!
//! Structure (so the engine equations can be assembled into a larger system):
//! 1. composite-body dynamics of the monoblock with its internal parts and of the housing
//!    ([`composite`], [`parts`], [`assembly`]),
//! 2. force elements acting between points: ring carriers ([`ring_carrier`]), mounts ([`mount`],
//!    [`mount_curve`]), gas side forces ([`gas`]),
//! 3. scenes that implement [`crate::ode::OdeProblem`]: [`GroundScene`] (mounts on rigid ground).

pub mod assembly;
pub mod composite;
pub mod config;
mod defaults;
pub mod effects;
pub mod gas;
pub mod ground_scene;
pub mod inputs;
mod jacobian;
pub mod modes;
pub mod mount;
pub mod mount_curve;
pub mod orders;
pub mod outputs;
pub mod parts;
pub mod reaction;
pub mod ring_carrier;
pub mod rotation;
mod statics;

pub use config::{ConfigError, EngineConfig};
pub use defaults::{POWERTRAIN_CG, POWERTRAIN_MASS, TABLE1_RIGID, TABLE1_RING_CARRIER};
pub use effects::Effects;
pub use ground_scene::{Evaluation, GroundScene, StaticsError};
pub use inputs::{EngineInputs, InputError, RampInput};
pub use modes::{mode_table, Direction, Mode, ModeKind};
pub use outputs::{BodyMotion, EngineOutputs};
pub use reaction::Wrench;
