//! The product's own car body: the procedural "phenomenological" chassis of the paper (§5),
//! generated from a small parametric description.
//!
//! - [`config`]: the parametric description ([`config::ChassisConfig`], JSON with serde
//!   defaults).
//! - [`body`]: the generator, [`Chassis::build`] → a [`crate::fe::mesh::Mesh`] with named nodes
//!   (mount points, steering wheel, seat rail, wheel centres) and regions.
//! - [`modal`]: what a mode shape of the body does (torsion, bending, steering wheel, front end),
//!   from energy fractions in its named regions.
//!
//! ```no_run
//! use engine_mount_chassis::chassis::{config::ChassisConfig, modal, Chassis, MountLayout};
//! use engine_mount_chassis::{eigen, fe::assembly};
//! # fn main() -> Result<(), engine_mount_chassis::fe::FeError> {
//! let body = Chassis::build(&ChassisConfig::default())?;
//! let asm = assembly::assemble(&body.mesh)?;
//! let mounts = body.mount_nodes(MountLayout::Four)?; // [(name, node id)]
//! let row = asm.dofs.global(mounts[0].1, 2); // equation index of the first mount's uz
//! let modes = eigen::lowest_modes(&asm.k, &asm.m, 30, -1.0)?;
//! for d in modal::describe(&body.mesh, &asm, &modes)? {
//!     println!("{}", d.summary());
//! }
//! # let _ = row;
//! # Ok(())
//! # }
//! ```

pub mod body;
pub mod config;
pub mod modal;

pub use body::{
    region, Chassis, MountLayout, MOUNT_NAMES, SEAT_RAIL, STEERING_WHEEL, WHEEL_CENTRES,
};
