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

/// Rotation vector (axis × angle) of a rotation matrix, angle below π.
///
/// Through the unit quaternion: nalgebra's `Rotation3::scaled_axis` takes the angle from `acos`
/// of the trace and loses half the digits at the small relative rotations of the ring carriers
/// (1e-9 relative error at 1e-4 rad); the quaternion route keeps full precision.
pub fn rotation_vector(r: &Matrix3<f64>) -> Vector3<f64> {
    let rotation = nalgebra::Rotation3::from_matrix_unchecked(*r);
    nalgebra::UnitQuaternion::from_rotation_matrix(&rotation).scaled_axis()
}

/// `J_l(θ)⁻ᵀ`: maps the gradient with respect to the rotation vector `θ` of `Q = exp([θ]×)` to
/// the moment conjugate to a small rotation `δQ = [δφ]× Q`.
pub fn left_jacobian_inverse_transpose(theta: &Vector3<f64>) -> Matrix3<f64> {
    let t = theta.norm();
    let k = theta.cross_matrix();
    let c = if t < 1e-4 {
        1.0 / 12.0 + t * t / 720.0
    } else {
        1.0 / (t * t) - (1.0 + t.cos()) / (2.0 * t * t.sin())
    };
    Matrix3::identity() + k * 0.5 + k * k * c
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
    fn left_jacobian_inverse_transpose_is_the_gradient_map() {
        // d/dε log(exp([ε]×) Q) at ε = 0 is J_l⁻¹(θ); check its transpose against differences.
        let theta = Vector3::new(0.3, -0.5, 0.2);
        let q = nalgebra::Rotation3::new(theta).into_inner();
        let jt = left_jacobian_inverse_transpose(&theta);
        let h = 1e-6;
        for i in 0..3 {
            let e = Vector3::ith(i, h);
            let plus = rotation_vector(&(nalgebra::Rotation3::new(e).into_inner() * q));
            let minus = rotation_vector(&(nalgebra::Rotation3::new(-e).into_inner() * q));
            let col = (plus - minus) / (2.0 * h);
            assert!((col - jt.row(i).transpose()).norm() < 1e-8, "column {i}");
        }
    }

    #[test]
    fn rotation_vector_recovers_axis_angle() {
        let v = Vector3::new(0.1, -0.2, 0.3);
        let r = nalgebra::Rotation3::new(v).into_inner();
        assert!((rotation_vector(&r) - v).norm() < 1e-12);
    }
}
