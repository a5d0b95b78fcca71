//! Gear/BDF integrator (variable order 1–5, variable step) in the style of SUNDIALS CVODE.

mod problem;

pub use problem::{OdeProblem, ProblemError};
