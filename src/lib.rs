//! Engine – mount – elastic chassis vibration model as an FMI 2.0 co-simulation FMU.
//!
//! Data flows one way: configuration → chassis FE → reduction → coupled model → integrator →
//! FMI layer. Each concern lives in its own module:
//!
//! - [`ode`]: the Gear/BDF integrator, generic over [`ode::OdeProblem`]; knows nothing of engines.
//! - [`fe`]: finite elements, assembly and the procedural chassis.
//! - [`model`]: engine multibody model, mounts, coupled system, outputs.

pub mod fe;
pub mod model;
pub mod ode;
