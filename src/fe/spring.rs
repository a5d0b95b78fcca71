//! Grounded and two-node spring-dampers, uncoupled per global DOF.

use nalgebra::{DMatrix, Matrix3, SMatrix, Vector3};

use super::error::{require_non_negative, FeError};
use super::mesh::{Bush, GroundSpring, Spring};

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

/// Stiffness and damping of a bush (6 × 6 to ground, 12 × 12 between `a` and `b`, node order
/// a, b): Bᵀ diag(k) B with B the relative motion at the spring point in element axes,
/// u(p) = u_n + θ_n × (p − x_n) for each end n.
pub fn bush_matrices(
    index: usize,
    bush: &Bush,
    xa: &Vector3<f64>,
    xb: Option<&Vector3<f64>>,
) -> Result<(DMatrix<f64>, DMatrix<f64>), FeError> {
    let what = format!("bush {index}");
    validate(&what, &bush.stiffness, &bush.damping)?;
    let r = &bush.frame;
    if (r.transpose() * r - Matrix3::identity()).abs().max() > 1e-9 {
        return Err(FeError::InvalidInput(format!(
            "{what}: frame is not orthonormal"
        )));
    }
    // Rows: element components of the motion of the spring point due to one end's six DOFs.
    let carried = |x: &Vector3<f64>| {
        let mut t = DMatrix::<f64>::zeros(6, 6);
        let lever = -r.transpose() * (bush.point - x).cross_matrix();
        t.view_mut((0, 0), (3, 3)).copy_from(&r.transpose());
        t.view_mut((0, 3), (3, 3)).copy_from(&lever);
        t.view_mut((3, 3), (3, 3)).copy_from(&r.transpose());
        t
    };
    let b = match xb {
        None => carried(xa),
        Some(xb) => {
            let mut b = DMatrix::<f64>::zeros(6, 12);
            b.view_mut((0, 0), (6, 6)).copy_from(&(-carried(xa)));
            b.view_mut((0, 6), (6, 6)).copy_from(&carried(xb));
            b
        }
    };
    let diag = |v: &[f64; 6]| DMatrix::from_diagonal(&nalgebra::DVector::from_row_slice(v));
    let k = b.transpose() * diag(&bush.stiffness) * &b;
    let c = b.transpose() * diag(&bush.damping) * &b;
    Ok((k, c))
}
