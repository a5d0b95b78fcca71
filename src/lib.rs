//! Engine – mount – elastic chassis vibration model as an FMI 2.0 co-simulation FMU.
//!
//! Data flows one way: configuration → chassis FE → reduction → coupled model → integrator →
//! FMI layer. Each concern lives in its own module:
//!
//! - [`ode`]: the Gear/BDF integrator, generic over [`ode::OdeProblem`]; knows nothing of engines.
//! - [`fe`]: general finite elements (beams, shells, solids, masses, springs, links) and sparse
//!   assembly.
//! - [`chassis`]: the product's procedural car body (the paper's phenomenological chassis).
//! - [`nastran`]: a user's body from a Nastran bulk data deck (read, write, DMIG).
//! - [`eigen`]: eigensolvers for the sparse pencil (shift-invert Lanczos, spectrum slicing).
//! - [`cms`]: Craig-Bampton reduction of a body (procedural, deck, or reduced elsewhere).
//! - [`model`]: engine multibody model, mounts, coupled system, outputs.
//! - [`cosim`]: a scene with its integrator and inputs, stepped between communication points.
//! - [`fmu`]: the FMU runtime both ABIs share: instance, values, input signals, FMU states,
//!   logging, stepping, the one guard of every exported function; its [`fmu::parameters`] is the
//!   one mapping between FMU variables and the typed settings.
//! - [`fmi2`], [`fmi3`]: the FMI 2.0 and 3.0 co-simulation C ABIs, the standards' signatures over
//!   the runtime (with the runtime's guard and C-argument helpers, the only `unsafe` code).
//! - [`variables`]: the variable table generated from `modelDescription/variables.json` (a leaf:
//!   it imports nothing from the model), with [`variables::Parameters`], every parameter as one
//!   typed structure.

#![deny(rustdoc::broken_intra_doc_links)]
#![deny(missing_docs)]

pub mod chassis;
pub mod cms;
pub mod cosim;
pub mod eigen;
pub mod fe;
pub mod fmi2;
pub mod fmi3;
pub mod fmu;
pub mod model;
pub mod nastran;
pub mod ode;
pub mod paper;
pub mod saved_state;
pub mod text_file;
pub mod variables;

/// The user guide's Rust examples (`docs/src/inside/library.md`), compiled and run by
/// `cargo test` as doctests so that the guide cannot drift from the API. Exists only for rustdoc's
/// doctest collection; no build of the library contains it.
#[cfg(doctest)]
#[doc = include_str!("../docs/src/inside/library.md")]
pub struct UserGuideExamples;
