//! Engine mounts: a connector between a bracket on the powertrain housing and an attachment (a
//! ground point, or a node of the elastic body). The force law is written once
//! ([`connector::Mount::response`]) as a function of the relative motion of the two points, so
//! the same mount works on ground and in any body.

pub mod config;
pub mod connector;
pub mod curve;

pub use config::MountConfig;
pub use connector::{Mount, MountResponse};
pub use curve::{MountCurve, StiffnessKnot};
