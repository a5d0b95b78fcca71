//! Engine multibody model, mounts, coupled system and outputs (paper §4, DESIGN §4.1).
//!
//! Frame: ISO 8855 vehicle frame, x forward, y left, z up, origin at the front axle centre on the
//! ground. Transverse engine: crank axis +y, cylinders +z in the monoblock, at y = −a, 0, +a.
//! Paper naming of the rigid-body modes: axial = along the crank axis (y), lateral = x,
//! vertical = z, rolling = about the crank axis (y), pitching = about x, yawing = about z.
//!
//! Structure (so the engine equations can be assembled into a larger system later):
//! 1. composite-body dynamics of the monoblock with its internal parts and of the housing
//!    ([`composite`], [`parts`], [`assembly`]): mass matrix and generalised forces from body
//!    coordinates, crank angle, speed and acceleration, gas and gravity;
//! 2. force elements between points: ring carriers ([`ring_carrier`]), mounts ([`mount`],
//!    [`mount_curve`]) as functions of the relative displacement/velocity of their two points,
//!    gas side forces ([`gas`]);
//! 3. scenes implementing [`crate::ode::OdeProblem`]: [`GroundScene`] (mounts on rigid ground).
//!
//! Typical use (what an FMU instance does):
//! ```no_run
//! use engine_mount_chassis::model::{EngineConfig, GroundScene};
//! use engine_mount_chassis::ode::{Bdf, BdfOptions};
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let cfg = EngineConfig::from_json(r#"{"gas": {"load": 0.5}}"#)?; // validated, defaults filled
//! let mut scene = GroundScene::new(cfg)?;
//! scene.set_load_torque(0.0, 40.0, 0.0)?;              // before statics: mean load torque
//! let y0 = scene.static_equilibrium(0.0)?;            // crank at the configured start angle
//! scene.set_crank_speed(0.0, 2000.0 * std::f64::consts::PI / 30.0, 0.0)?; // rad/s, rad/s²
//! let mut bdf = Bdf::new(&mut scene, 0.0, &y0, BdfOptions::default())?;
//! bdf.advance_to(&mut scene, 0.01)?;
//! let out = scene.outputs(0.01, bdf.y()).map_err(|e| format!("{e:?}"))?;
//! println!("front left mount force {:?} N", out.mount_forces[0]);
//! # Ok(()) }
//! ```
//!
//! Crank-drive semantics: the crank-speed input is the crankshaft's spin about its own axis in
//! inertial space (a flywheel held by the drivetrain); the crank angle relative to the monoblock
//! is a state with `φ' = ω(t) − e_crank·ω_block`. That is what lets the mass and gas torques react
//! on the block (paper §4.2) and keeps free vibration with the crank at rest conservative.

pub mod assembly;
pub mod composite;
pub mod config;
mod defaults;
pub mod effects;
pub mod gas;
pub mod ground_scene;
pub mod hybrid_chassis;
mod hybrid_jacobian;
pub mod hybrid_modes;
pub mod hybrid_outputs;
pub mod hybrid_scene;
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
pub mod snapshot;
mod statics;

pub use config::{ConfigError, EngineConfig};
pub use defaults::{POWERTRAIN_CG, POWERTRAIN_MASS, TABLE1_RIGID, TABLE1_RING_CARRIER};
pub use effects::Effects;
pub use ground_scene::{GroundScene, StaticsError};
pub use hybrid_scene::{HybridError, HybridEvaluation, HybridScene};
pub use inputs::{EngineInputs, InputError, RampInput};
pub use modes::{mode_table, Direction, Mode, ModeKind};
pub use outputs::{BodyMotion, EngineOutputs};
pub use reaction::Wrench;
pub use snapshot::SceneSnapshot;
