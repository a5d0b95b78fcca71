//! End-to-end tests of the FMI 2.0 and 3.0 C ABIs: the built cdylib loaded with libloading.

mod abi;
mod bad_inputs;
mod common;
mod coupling;
mod fmi3;
mod inputs;
mod model_structure;
mod natural_modes;
mod precedence;
mod properties;
mod schema;
