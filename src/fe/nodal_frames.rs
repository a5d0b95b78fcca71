//! Displacement frames of nodes (Nastran GRID CD): the DOFs of a node with a frame are its
//! components along the frame's axes, u_global = R u_node per translation and rotation block
//! (R's columns are the axes in global coordinates).
//!
//! Elements and masses are formed in global axes; [`super::dof::DofMap`] expresses the global
//! motion of a framed node through the node's own equations, so assembling through it forms
//! Bᵀ K B (B = diag(R, R) per node) without touching the element code. Scalar springs and
//! dampers, constraints and rigid/interpolation link components name a node's own components; the few
//! matrices given per node component are carried to global axes here first
//! ([`to_global_axes`]), so that the assembly's Bᵀ (·) B gives them back unchanged.

use std::collections::BTreeMap;

use nalgebra::{Matrix3, Matrix6, SMatrix};

use super::error::FeError;
use super::mesh::DOF_PER_NODE;

/// Checks that every frame is a rotation (orthonormal, right-handed) of an existing node.
pub fn validate(frames: &BTreeMap<usize, Matrix3<f64>>, n_nodes: usize) -> Result<(), FeError> {
    for (&node, r) in frames {
        if node >= n_nodes {
            return Err(FeError::Mesh(format!(
                "displacement frame of node {node}: mesh has {n_nodes} nodes"
            )));
        }
        let defect = (r.transpose() * r - Matrix3::identity()).abs().max();
        if !(defect < 1e-9 && r.determinant() > 0.0) {
            return Err(FeError::Mesh(format!(
                "displacement frame of node {node} is not a rotation (|RᵀR − I| = {defect:.3e}, \
                 det = {:.6})",
                r.determinant()
            )));
        }
    }
    Ok(())
}

/// B = diag(R, R): node components → global components of one node (identity without a frame).
pub fn node_block(frames: &BTreeMap<usize, Matrix3<f64>>, node: usize) -> Matrix6<f64> {
    let mut b = Matrix6::identity();
    if let Some(r) = frames.get(&node) {
        b.fixed_view_mut::<3, 3>(0, 0).copy_from(r);
        b.fixed_view_mut::<3, 3>(3, 3).copy_from(r);
    }
    b
}

/// A matrix given on the node components of `nodes` (node by node, six DOFs each) carried to
/// global axes: B a Bᵀ with B block-diagonal of the nodes' [`node_block`]s. Assembly's Bᵀ (·) B
/// then returns `a` on the node components.
pub fn to_global_axes<const N: usize>(
    frames: &BTreeMap<usize, Matrix3<f64>>,
    nodes: &[usize],
    a: &SMatrix<f64, N, N>,
) -> SMatrix<f64, N, N> {
    if !nodes.iter().any(|n| frames.contains_key(n)) {
        return *a;
    }
    let mut b = SMatrix::<f64, N, N>::identity();
    for (k, &node) in nodes.iter().enumerate() {
        b.fixed_view_mut::<6, 6>(DOF_PER_NODE * k, DOF_PER_NODE * k)
            .copy_from(&node_block(frames, node));
    }
    b * a * b.transpose()
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Rotation3, Vector3};

    #[test]
    fn a_spring_on_node_components_survives_the_round_trip_through_global_axes() {
        let r = *Rotation3::from_axis_angle(&Vector3::z_axis(), 0.4).matrix();
        let frames = BTreeMap::from([(3, r)]);
        validate(&frames, 4).unwrap();
        let k = Matrix6::from_diagonal(&nalgebra::Vector6::new(1.0, 2.0, 3.0, 4.0, 5.0, 6.0));
        let global = to_global_axes(&frames, &[3], &k);
        let b = node_block(&frames, 3);
        assert!((b.transpose() * global * b - k).abs().max() < 1e-14);
        // A spring on node component 1 alone acts along global (cos 0.4, sin 0.4, 0).
        let mut k1 = Matrix6::zeros();
        k1[(0, 0)] = 1.0;
        let g1 = to_global_axes(&frames, &[3], &k1);
        let (c, s) = (0.4f64.cos(), 0.4f64.sin());
        assert!((g1[(0, 0)] - c * c).abs() < 1e-14 && (g1[(0, 1)] - c * s).abs() < 1e-14);
    }

    #[test]
    fn a_reflection_or_a_missing_node_is_refused() {
        let flip = Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, -1.0));
        let err = validate(&BTreeMap::from([(0, flip)]), 1).unwrap_err();
        assert!(err.to_string().contains("not a rotation"), "{err}");
        let err = validate(&BTreeMap::from([(5, Matrix3::identity())]), 2).unwrap_err();
        assert!(err.to_string().contains("node 5"), "{err}");
    }
}
