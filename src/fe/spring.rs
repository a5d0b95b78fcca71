//! Grounded and two-node spring-dampers, uncoupled per global DOF.

use nalgebra::SMatrix;

use super::error::{require_non_negative, FeError};
use super::mesh::{GroundSpring, Spring};

fn validate(what: &str, k: &[f64; 6], c: &[f64; 6]) -> Result<(), FeError> {
    for d in 0..6 {
        require_non_negative(&format!("{what}: stiffness[{d}]"), k[d])?;
        require_non_negative(&format!("{what}: damping[{d}]"), c[d])?;
    }
    Ok(())
}

/// Diagonal 6 × 6 stiffness and damping of a spring to ground.
pub fn ground_matrices(
    index: usize,
    s: &GroundSpring,
) -> Result<(SMatrix<f64, 6, 6>, SMatrix<f64, 6, 6>), FeError> {
    validate(&format!("ground spring {index}"), &s.stiffness, &s.damping)?;
    let mut k = SMatrix::<f64, 6, 6>::zeros();
    let mut c = SMatrix::<f64, 6, 6>::zeros();
    for d in 0..6 {
        k[(d, d)] = s.stiffness[d];
        c[(d, d)] = s.damping[d];
    }
    Ok((k, c))
}

/// 12 × 12 stiffness and damping of a two-node spring acting on the relative displacement.
pub fn two_node_matrices(
    index: usize,
    s: &Spring,
) -> Result<(SMatrix<f64, 12, 12>, SMatrix<f64, 12, 12>), FeError> {
    validate(&format!("spring {index}"), &s.stiffness, &s.damping)?;
    let mut k = SMatrix::<f64, 12, 12>::zeros();
    let mut c = SMatrix::<f64, 12, 12>::zeros();
    for d in 0..6 {
        for (a, b, sign) in [
            (d, d, 1.0),
            (d + 6, d + 6, 1.0),
            (d, d + 6, -1.0),
            (d + 6, d, -1.0),
        ] {
            k[(a, b)] = sign * s.stiffness[d];
            c[(a, b)] = sign * s.damping[d];
        }
    }
    Ok((k, c))
}
