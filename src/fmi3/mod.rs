//! The FMI 3.0 co-simulation C ABI: the standard's signatures over the same runtime
//! ([`crate::fmu`]) as FMI 2.0's, and nothing else.
//!
//! - [`abi`]: the exported `fmi3*` functions, each behind the runtime's guard with its state
//!   mask, delegating to the runtime: the model, its stepping, its variable stores and its FMU
//!   states are shared with FMI 2.0.
//! - [`state`]: the FMI 3.0 co-simulation state machine (no event mode, no intermediate update)
//!   as a mask per function over the runtime's one phase type.
//! - [`values`]: 3.0 value references (arrays such as `mount.F`) resolved to the elements of the
//!   variable table.
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

/// The body FMU's FMI 3.0 `modelDescription.xml`.
pub const BODY_MODEL_DESCRIPTION_XML: &str =
    include_str!(concat!(env!("OUT_DIR"), "/fmi3/body.modelDescription.xml"));

/// The body FMU's `terminalsAndIcons/terminalsAndIcons.xml`.
pub const BODY_TERMINALS_AND_ICONS_XML: &str =
    include_str!(concat!(env!("OUT_DIR"), "/fmi3/body.terminalsAndIcons.xml"));
