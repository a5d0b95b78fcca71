//! Integration tests of the co-simulation runtime (`src/cosim`): scene 2 stepping and the hard cases.

mod coupling;
mod damping;
mod hard_cases;
mod hybrid_cosim;
#[path = "../common/order_deviation.rs"]
mod order_deviation;
mod periodic_start;
