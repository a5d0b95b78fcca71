//! Convergence and behaviour tests that need the integrator internals.

mod order;
