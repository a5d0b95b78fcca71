//! The FMI 3.0 co-simulation layer: a second C ABI over the same instance as FMI 2.0.
//!
//! - [`abi`]: the exported `fmi3*` functions, each behind one guard (instance pointer, state
//!   machine, panics) like [`crate::fmi2::abi`], delegating to [`crate::fmi2::instance::Instance`]:
//!   the model, its stepping, its variable stores and its FMU states are the 2.0 layer's.
//! - [`state`]: the FMI 3.0 co-simulation state machine (no event mode, no intermediate update)
//!   with its error and fatal states.
//! - [`values`]: 3.0 value references (arrays such as `mount.F`) resolved to the elements of the
//!   2.0 variable table.
//!
//! `build.rs` (`build/fmi3_description.rs`) writes the 3.0 model description and
//! `terminalsAndIcons.xml` from the same variable table.

pub mod abi;
pub mod state;
pub mod values;

/// The FMI 3.0 `modelDescription.xml` that `build.rs` generated from the variable table.
pub const MODEL_DESCRIPTION_XML: &str =
    include_str!(concat!(env!("OUT_DIR"), "/fmi3/modelDescription.xml"));

/// The FMU's `terminalsAndIcons/terminalsAndIcons.xml`.
pub const TERMINALS_AND_ICONS_XML: &str =
    include_str!(concat!(env!("OUT_DIR"), "/fmi3/terminalsAndIcons.xml"));
