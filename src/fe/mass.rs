//! Point masses with rotary inertia.

use nalgebra::SMatrix;

use super::error::{require_non_negative, FeError};
use super::mesh::PointMass;

/// 6 × 6 nodal mass matrix of a point mass: m I for translations, the inertia tensor for rotations.
pub fn matrix(index: usize, pm: &PointMass) -> Result<SMatrix<f64, 6, 6>, FeError> {
    require_non_negative(&format!("point mass {index}: mass"), pm.mass)?;
    let j = &pm.inertia;
    if j.iter().any(|v| !v.is_finite()) {
        return Err(FeError::InvalidInput(format!(
            "point mass {index}: inertia is not finite"
        )));
    }
    let asym = (j - j.transpose()).abs().max();
    if asym > 1e-9 * j.abs().max().max(1e-300) {
        return Err(FeError::InvalidInput(format!(
            "point mass {index}: inertia is not symmetric"
        )));
    }
    if (0..3).any(|d| j[(d, d)] < 0.0) {
        return Err(FeError::InvalidInput(format!(
            "point mass {index}: negative principal inertia on the diagonal {:?}",
            [j[(0, 0)], j[(1, 1)], j[(2, 2)]]
        )));
    }
    let mut m = SMatrix::<f64, 6, 6>::zeros();
    for d in 0..3 {
        m[(d, d)] = pm.mass;
    }
    m.fixed_view_mut::<3, 3>(3, 3).copy_from(j);
    Ok(m)
}
