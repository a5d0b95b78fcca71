//! Gear/BDF integrator (variable order 1–5, variable step) in the style of SUNDIALS CVODE.
//!
//! The integrator knows nothing about the model: it integrates any [`OdeProblem`] in linearly
//! implicit form `M(t, y) y' = f(t, y)`. See [`Bdf`] for the driver API.
//!
//! - Output times: [`Bdf::advance_to`] lands exactly on a stop time (the last step is
//!   shortened); [`Bdf::advance_past`] steps freely and interpolates, so dense output times cost
//!   no extra steps. [`Bdf::restart_at`] restarts from an interpolated state after an input jump.
//! - Newton matrix `M − γ J`: dense (faer LU; analytic or finite-difference `J`) by default. A
//!   problem whose Jacobian is block-diagonal plus low rank (a modal body coupled through a few
//!   forces) declares it with [`OdeProblem::jacobian_structure`]; the integrator then solves by
//!   the Woodbury identity ([`BlockLowRankLu`]) and never forms an `n × n` matrix.
//!
//! ```
//! use engine_mount_chassis::ode::{Bdf, BdfOptions, OdeProblem, ProblemError, Tolerance};
//!
//! /// y' = -50 (y - cos t)
//! struct Relax;
//! impl OdeProblem for Relax {
//!     fn dim(&self) -> usize {
//!         1
//!     }
//!     fn rhs(&mut self, t: f64, y: &[f64], f: &mut [f64]) -> Result<(), ProblemError> {
//!         f[0] = -50.0 * (y[0] - t.cos());
//!         Ok(())
//!     }
//! }
//!
//! let mut problem = Relax;
//! let opts = BdfOptions { rtol: 1e-6, atol: Tolerance::Scalar(1e-9), ..Default::default() };
//! let mut bdf = Bdf::new(&mut problem, 0.0, &[0.0], opts)?;
//! for k in 1..=10 {
//!     // Communication points: the integrator lands exactly on each and keeps its history.
//!     bdf.advance_to(&mut problem, 0.1 * k as f64)?;
//! }
//! let saved = bdf.snapshot(); // e.g. for fmi2GetFMUstate
//! let bytes = saved.to_bytes(); // for fmi2SerializeFMUstate
//! assert_eq!(bdf.t(), 1.0);
//! assert!((bdf.y()[0] - 0.5403).abs() < 0.02);
//! bdf.restore(&engine_mount_chassis::ode::BdfSnapshot::from_bytes(&bytes)?)?;
//! println!("{} steps, {} RHS evaluations", bdf.stats().steps, bdf.stats().rhs_evals);
//! # Ok::<(), engine_mount_chassis::ode::BdfError>(())
//! ```

// Index loops mirror CVODE's formulas, which address several arrays by one index.
#[allow(clippy::needless_range_loop)]
mod bdf;
mod block_low_rank;
// Index loops mirror CVODE's formulas, which address several arrays by one index.
#[allow(clippy::needless_range_loop)]
mod coefficients;
// Index loops mirror CVODE's formulas, which address several arrays by one index.
#[allow(clippy::needless_range_loop)]
mod dense_lu;
mod error;
mod evaluation;
mod jacobian;
mod pattern;
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
pub use block_low_rank::{BlockLowRankJacobian, BlockLowRankLu, BlockLowRankShape};
pub use dense_lu::DenseLu;
pub use error::BdfError;
pub use options::{BdfOptions, Tolerance};
pub use pattern::JacobianPattern;
pub use problem::{OdeProblem, ProblemError};
pub use snapshot::BdfSnapshot;
pub use stats::BdfStats;
