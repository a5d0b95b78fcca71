//! Finite elements, sparse assembly and the procedural chassis body.
//!
//! Frame: ISO 8855 vehicle axes (x forward, y left, z up), origin at the front-axle centre on the
//! ground. SI units throughout. Six DOFs per node: ux, uy, uz, rx, ry, rz in global axes.

pub mod assembly;
pub mod beam;
pub mod chassis;
pub mod chassis_config;
pub mod checks;
pub mod dof;
pub mod eigen;
pub mod error;
pub mod export;
pub mod mass;
pub mod mesh;
pub mod modal;
pub mod shell;
pub mod spring;

pub use error::FeError;
