//! The coupled engine–mount–body model (paper §4, §6; DESIGN §2.1, §4).
//!
//! Frame: ISO 8855 vehicle frame, x forward, y left, z up, origin at the front axle centre on the
//! ground. Transverse engine: crank axis +y. Paper naming of the rigid-body modes: axial = along
//! the crank axis (y), lateral = x, vertical = z, rolling = about the crank axis (y),
//! pitching = about x, yawing = about z.
//!
//! Map (data flows down):
//! - [`vehicle`]: the configuration — which powertrain, mounts, body source and output points;
//! - [`powertrain`]: the engine component — monoblock with its crank drive and balance shafts
//!   ([`powertrain::parts`], [`powertrain::composite`]), housing, ring carriers, gas pressure;
//! - [`mount`]: the mount connector between a housing bracket and ground or a body point;
//! - [`follower`]: how the crank speed follows the engine-speed set-point;
//! - [`coupled`]: the one coupled model ([`CoupledModel`], an [`crate::ode::OdeProblem`]) with its
//!   state layout, Jacobian structure, statics, modes and outputs;
//! - [`scene`]: scenes as configurations of components (rigid ground, or the reduced body).
//!
//! Typical use (what an FMU instance does):
//! ```no_run
//! use engine_mount_chassis::model::{CoupledModel, VehicleConfig};
//! use engine_mount_chassis::ode::{Bdf, BdfOptions};
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let cfg = VehicleConfig::from_json(r#"{"extends": "default", "engine": {"gas": {"load": 0.5}}}"#)?;
//! let mut model = CoupledModel::on_ground(&cfg)?;
//! model.set_load_torque(0.0, 40.0, 0.0)?;              // before statics: mean load torque
//! model.set_crank_speed(0.0, 2000.0 * std::f64::consts::PI / 30.0, 0.0)?; // rad/s, rad/s²
//! let y0 = model.static_equilibrium(0.0)?;            // crank at the configured start angle
//! let mut bdf = Bdf::new(&mut model, 0.0, &y0, BdfOptions::default())?;
//! bdf.advance_to(&mut model, 0.01)?;
//! let out = model.outputs(0.01, bdf.y()).map_err(|e| format!("{e:?}"))?;
//! println!("front left mount force {:?} N", out.mount_forces[0]);
//! # Ok(()) }
//! ```

pub mod blend;
pub mod body_alone;
pub mod coupled;
pub mod effects;
pub mod follower;
pub mod inputs;
pub mod kinematics;
pub mod mount;
pub mod orders;
pub mod powertrain;
pub mod scene;
pub mod strict_json;
mod validate;
pub mod vehicle;

pub use coupled::{
    mode_table, CoupledModel, Direction, Evaluation, Mode, ModeKind, ModelError, ModelSnapshot,
    Outputs, StaticsError,
};
pub use effects::{EffectSwitch, Effects};
pub use follower::SpeedFollower;
pub use inputs::{Input, InputError, ModelInputs, RampInput};
pub use mount::{MountConfig, MountCurve};
pub use powertrain::config::EngineConfig;
pub use powertrain::defaults::{POWERTRAIN_CG, POWERTRAIN_MASS};
pub use powertrain::reaction::Wrench;
pub use powertrain::Powertrain;
pub use validate::ConfigError;
pub use vehicle::{BodyConfig, VehicleConfig};
