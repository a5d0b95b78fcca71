//! Gear/BDF integrator (variable order 1–5, variable step) in the style of SUNDIALS CVODE.
//!
//! The integrator knows nothing about the model: it integrates any [`OdeProblem`] in linearly
//! implicit form `M(t, y) y' = f(t, y)`. See [`Bdf`] for the driver API.

// Index loops mirror CVODE's formulas, which address several arrays by one index.
#[allow(clippy::needless_range_loop)]
mod bdf;
// Index loops mirror CVODE's formulas, which address several arrays by one index.
#[allow(clippy::needless_range_loop)]
mod coefficients;
mod error;
mod jacobian;
// Index loops mirror CVODE's formulas, which address several arrays by one index.
#[allow(clippy::needless_range_loop)]
mod linear_solver;
mod newton;
// Index loops mirror CVODE's formulas, which address several arrays by one index.
#[allow(clippy::needless_range_loop)]
mod nordsieck;
mod options;
mod problem;
mod snapshot;
mod stability;
mod stats;
pub mod test_problems;

#[cfg(test)]
#[allow(clippy::needless_range_loop)]
mod tests;

pub use bdf::Bdf;
pub use error::BdfError;
pub use jacobian::JacobianPattern;
pub use options::{BdfOptions, Tolerance};
pub use problem::{OdeProblem, ProblemError};
pub use snapshot::BdfSnapshot;
pub use stats::BdfStats;
