//! Helpers of the element unit tests.

use nalgebra::Vector3;

/// Rigid-body motion `mode` of nodes at `points` as six DOFs per node (ux, uy, uz, rx, ry, rz):
/// modes 0–2 a unit translation along x, y, z; modes 3–5 a unit rotation about the x, y, z axis
/// through the origin.
pub(crate) fn rigid_motion(points: &[Vector3<f64>], mode: usize) -> Vec<f64> {
    let mut u = vec![0.0; 6 * points.len()];
    for (n, p) in points.iter().enumerate() {
        if mode < 3 {
            u[6 * n + mode] = 1.0;
            continue;
        }
        let mut w = Vector3::zeros();
        w[mode - 3] = 1.0;
        let t = w.cross(p);
        for d in 0..3 {
            u[6 * n + d] = t[d];
            u[6 * n + 3 + d] = w[d];
        }
    }
    u
}
