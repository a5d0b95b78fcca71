//! Component mode synthesis of the chassis: Craig-Bampton reduction with constraint-mode
//! orthogonalisation (paper §3.2, eq. 14–15), modal damping, and the recovery of named points.
//!
//! The product is a [`ReducedChassis`]: every coordinate is a mode with a frequency, the reduced
//! mass matrix is the identity and the stiffness diagonal, so the chassis enters the coupled model
//! as `η̈_k + 2 ζ_k ω_k η̇_k + ω_k² η_k = Σ_p φ_{p,k} · F_p`, with `F_p` the force (and moment)
//! acting on recovery point `p` and `φ_{p,k}` that point's 6-DOF motion in mode `k`.

mod reduced;

pub use reduced::{RecoveryPoint, ReducedChassis};
