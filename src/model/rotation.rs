//! Exact finite rotations of a rigid body by Cardan angles.
//!
//! `R = Rx(a) Ry(b) Rz(c)` (body-fixed sequence x, y', z''). The angular velocity used as the
//! velocity state is expressed in the vehicle (world) frame: `ω = G(θ) θ'`. The parametrisation is
//! singular only at `b = ±90°`, far outside any engine motion; [`angle_rates`] reports it as an
//! error instead of dividing by zero.

use nalgebra::{Matrix3, Vector3};

/// Rotation matrix of the Cardan angles `(a, b, c)`.
pub fn rotation_matrix(theta: &Vector3<f64>) -> Matrix3<f64> {
    let (sa, ca) = theta.x.sin_cos();
    let (sb, cb) = theta.y.sin_cos();
    let (sc, cc) = theta.z.sin_cos();
    let rx = Matrix3::new(1.0, 0.0, 0.0, 0.0, ca, -sa, 0.0, sa, ca);
    let ry = Matrix3::new(cb, 0.0, sb, 0.0, 1.0, 0.0, -sb, 0.0, cb);
    let rz = Matrix3::new(cc, -sc, 0.0, sc, cc, 0.0, 0.0, 0.0, 1.0);
    rx * ry * rz
}

/// `G(θ)` with `ω_world = G(θ) θ'`.
pub fn angular_velocity_map(theta: &Vector3<f64>) -> Matrix3<f64> {
    let (sa, ca) = theta.x.sin_cos();
    let (sb, cb) = theta.y.sin_cos();
    Matrix3::new(1.0, 0.0, sb, 0.0, ca, -sa * cb, 0.0, sa, ca * cb)
}

/// Cardan angle rates `θ' = G(θ)⁻¹ ω` for a world-frame angular velocity.
pub fn angle_rates(theta: &Vector3<f64>, omega: &Vector3<f64>) -> Option<Vector3<f64>> {
    if theta.y.cos().abs() < 1e-6 {
        return None;
    }
    angular_velocity_map(theta)
        .try_inverse()
        .map(|g_inv| g_inv * omega)
}

/// Rotation vector (axis × angle) of a rotation matrix; exact for angles below π.
pub fn rotation_vector(r: &Matrix3<f64>) -> Vector3<f64> {
    let cos_angle = ((r.trace() - 1.0) * 0.5).clamp(-1.0, 1.0);
    let angle = cos_angle.acos();
    let axis_sin = Vector3::new(
        r[(2, 1)] - r[(1, 2)],
        r[(0, 2)] - r[(2, 0)],
        r[(1, 0)] - r[(0, 1)],
    ) * 0.5;
    if angle < 1e-8 {
        return axis_sin;
    }
    axis_sin * (angle / angle.sin())
}

/// Skew-symmetric matrix `[a]×` with `[a]× b = a × b`.
pub fn skew(a: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -a.z, a.y, a.z, 0.0, -a.x, -a.y, a.x, 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn angular_velocity_map_matches_differentiated_rotation() {
        // ω× = R' Rᵀ, independent of how G was derived.
        let theta = Vector3::new(0.3, -0.4, 0.7);
        let rate = Vector3::new(0.2, 0.5, -0.9);
        let h = 1e-6;
        let r = rotation_matrix(&theta);
        let rdot = (rotation_matrix(&(theta + rate * h)) - rotation_matrix(&(theta - rate * h)))
            / (2.0 * h);
        let w = rdot * r.transpose();
        let omega = Vector3::new(w[(2, 1)], w[(0, 2)], w[(1, 0)]);
        let mapped = angular_velocity_map(&theta) * rate;
        assert!((omega - mapped).norm() < 1e-8, "{omega} vs {mapped}");
        let back = angle_rates(&theta, &omega).expect("regular");
        assert!((back - rate).norm() < 1e-7);
    }

    #[test]
    fn rotation_vector_recovers_axis_angle() {
        let v = Vector3::new(0.1, -0.2, 0.3);
        let r = nalgebra::Rotation3::new(v).into_inner();
        assert!((rotation_vector(&r) - v).norm() < 1e-12);
    }
}
