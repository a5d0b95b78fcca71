//! End-to-end tests of the FMI 2.0 and 3.0 C ABIs: the built cdylib loaded with libloading.

mod abi;
mod bad_inputs;
mod common;
mod coupling;
mod fmi3;
mod fmi3_coupling;
mod inputs;
mod model_structure;
mod natural_modes;
#[path = "../common/order_deviation.rs"]
mod order_deviation;
mod precedence;
mod properties;
mod schema;
