//! End-to-end tests of the FMI 2.0 C ABI: the built cdylib loaded with libloading.

mod abi;
mod bad_inputs;
mod common;
mod coupling;
mod inputs;
mod model_structure;
mod natural_modes;
mod precedence;
mod properties;
