//! The contract between the integrator and the equations it integrates.

use faer::MatMut;

use super::block_low_rank::{BlockLowRankJacobian, BlockLowRankShape};
use super::pattern::JacobianPattern;

/// Why a problem could not evaluate its equations at the requested point.
#[derive(Debug, Clone, PartialEq)]
pub enum ProblemError {
    /// The evaluation produced NaN or infinity; the integrator may retry with a smaller step.
    NonFinite,
    /// The point is outside the problem's domain; the integrator may retry with a smaller step.
    Recoverable(String),
    /// The problem cannot continue at all.
    Fatal(String),
}

/// Equations in linearly implicit form `M(t, y) y' = f(t, y)`.
///
/// `M` is the identity unless [`OdeProblem::has_mass_matrix`] says otherwise. A problem that has an
/// analytic Jacobian `df/dy` returns `Ok(true)` from [`OdeProblem::jacobian`]; otherwise the
/// integrator differentiates `f` numerically.
pub trait OdeProblem {
    /// Number of states.
    fn dim(&self) -> usize;

    /// Writes `f(t, y)` into `f`.
    fn rhs(&mut self, t: f64, y: &[f64], f: &mut [f64]) -> Result<(), ProblemError>;

    /// Whether `M(t, y)` differs from the identity.
    fn has_mass_matrix(&self) -> bool {
        false
    }

    /// Writes the dense `M(t, y)` into `m` (called only when [`Self::has_mass_matrix`] is true).
    fn mass(&mut self, _t: f64, _y: &[f64], _m: MatMut<'_, f64>) -> Result<(), ProblemError> {
        Ok(())
    }

    /// Writes the dense Jacobian `df/dy` into `j` and returns `Ok(true)`, or returns `Ok(false)`
    /// to let the integrator form it by finite differences.
    fn jacobian(&mut self, _t: f64, _y: &[f64], _j: MatMut<'_, f64>) -> Result<bool, ProblemError> {
        Ok(false)
    }

    /// Optional structure of `df/dy`: which rows each column may touch. When given, the
    /// finite-difference Jacobian perturbs structurally independent columns together.
    fn jacobian_pattern(&self) -> Option<JacobianPattern> {
        None
    }

    /// Optional structure `J = blockdiag(J_1, …, J_k) + U Vᵀ` (requires `M = I`). When given, the
    /// integrator never forms an n × n matrix: it calls [`Self::structured_jacobian`] instead of
    /// [`Self::jacobian`] and solves with `I − γ J` by the Woodbury identity.
    fn jacobian_structure(&self) -> Option<BlockLowRankShape> {
        None
    }

    /// Writes `J` in the shape of [`Self::jacobian_structure`] (called only when that is given;
    /// `j` arrives zeroed).
    fn structured_jacobian(
        &mut self,
        _t: f64,
        _y: &[f64],
        _j: &mut BlockLowRankJacobian,
    ) -> Result<(), ProblemError> {
        Err(ProblemError::Fatal(
            "the problem declares a Jacobian structure but does not supply it".into(),
        ))
    }

    /// Whether `M` is constant in `t` and `y`; then it is evaluated once and cached.
    fn mass_is_constant(&self) -> bool {
        false
    }
}
