//! The problem's evaluations as the integrator uses them: counted, with NaN/inf refused, and
//! the mass matrix taken from the cache when it is constant.

use faer::Mat;

use super::problem::{OdeProblem, ProblemError};
use super::stats::BdfStats;

/// Evaluates `f` and rejects NaN/inf; counts the evaluation.
pub(super) fn eval_rhs<P: OdeProblem>(
    problem: &mut P,
    stats: &mut BdfStats,
    t: f64,
    y: &[f64],
    f: &mut [f64],
) -> Result<(), ProblemError> {
    stats.rhs_evals += 1;
    problem.rhs(t, y, f)?;
    if f.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(ProblemError::NonFinite)
    }
}

/// Writes `M(t, y)` into `m` (the cached matrix when it is constant) and rejects NaN/inf.
pub(super) fn eval_mass<P: OdeProblem>(
    problem: &mut P,
    constant: Option<&Mat<f64>>,
    t: f64,
    y: &[f64],
    m: &mut Mat<f64>,
) -> Result<(), ProblemError> {
    if let Some(c) = constant {
        m.copy_from(c);
        return Ok(());
    }
    m.fill(0.0);
    problem.mass(t, y, m.as_mut())?;
    if m.col_iter().any(|c| c.iter().any(|v| !v.is_finite())) {
        return Err(ProblemError::NonFinite);
    }
    Ok(())
}
