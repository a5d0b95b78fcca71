//! Work counters of the integrator, readable after every call.

/// Cumulative counters (since construction) and the current step size and order.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BdfStats {
    /// Successful internal steps.
    pub steps: u64,
    /// Right-hand side evaluations, including those for finite-difference Jacobians.
    pub rhs_evals: u64,
    /// Right-hand side evaluations spent on finite-difference Jacobians only.
    pub rhs_evals_jac: u64,
    /// Jacobian evaluations (analytic or finite-difference).
    pub jac_evals: u64,
    /// LU factorisations of the Newton iteration matrix `M - gamma J`.
    pub factorizations: u64,
    /// Newton iterations.
    pub newton_iters: u64,
    /// Local error test failures.
    pub err_test_fails: u64,
    /// Nonlinear convergence failures (each one forces a smaller step).
    pub conv_fails: u64,
    /// Steps on which stability-limit detection reduced the order.
    pub stability_order_reductions: u64,
    /// Order used on the last successful step.
    pub order: usize,
    /// Step size used on the last successful step.
    pub h: f64,
    /// Step size that will be attempted next.
    pub h_next: f64,
    /// Order that will be attempted next.
    pub order_next: usize,
}
