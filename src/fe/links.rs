//! How the rigid and interpolation links (Nastran RBE2 / RBE3; the elements in
//! [`super::rigid_link`] and [`super::interpolation_link`]) are eliminated, and the rigid map
//! they share.
//!
//! Each dependent DOF becomes one equation u_dep = Σ cᵢ uᵢ over other DOFs; [`super::dof::DofMap`]
//! resolves chains and numbers the remaining independent DOFs, and assembly forms Tᵀ K T exactly
//! (no penalty stiffness). DOFs are addressed as slots `node * 6 + dof`.
//!
//! Interpolation (RBE3): the reference motion q = (u, θ) is the weighted least-squares fit of the
//! rigid-body motion to the source motions: with Sⱼ the rigid map from the reference to source j
//! (u_j = u + θ × (x_j − x_ref), θ_j = θ) restricted to the listed components and Wⱼ the
//! weights, q = (Σ SⱼᵀWⱼSⱼ)⁺ Σ SⱼᵀWⱼ uⱼ. Rotational source components are weighted by WT·L²,
//! L = mean distance of the source nodes from the reference (MSC Nastran's rule, which makes the
//! result independent of the length unit); translational ones by WT. For sources around the
//! reference with translations only, the reference translation is the weighted mean of the
//! source translations. Reference components left undetermined by the sources (e.g. rotation
//! about the line through collinear sources) are an error.

use nalgebra::{Matrix3, Matrix6, Vector3};

pub use super::element::LinkEquation;

/// Rigid map from the motion (u, θ) of a point to the motion of a point at offset `d` from it:
/// u' = u + θ × d = u − [d]× θ, θ' = θ.
pub(crate) fn rigid_map(d: &Vector3<f64>) -> Matrix6<f64> {
    let mut s = Matrix6::identity();
    let skew = Matrix3::new(0.0, -d.z, d.y, d.z, 0.0, -d.x, -d.y, d.x, 0.0);
    s.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-skew));
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fe::assembly::link_equations as equations;
    use crate::fe::element::LinkEquation;
    use crate::fe::mesh::InterpolationSource;
    use crate::fe::mesh::{InterpolationLink, Mesh, RigidLink};
    use crate::fe::nodal_frames;
    use nalgebra::SMatrix;

    fn evaluate(eq: &LinkEquation, u: &dyn Fn(usize) -> f64) -> f64 {
        eq.terms.iter().map(|&(slot, c)| c * u(slot)).sum()
    }

    /// Rigid-body motion (translation t, rotation w) evaluated at every slot of `mesh`.
    fn rigid_field(mesh: &Mesh, t: Vector3<f64>, w: Vector3<f64>) -> impl Fn(usize) -> f64 + '_ {
        move |slot| {
            let (node, dof) = (slot / 6, slot % 6);
            let v = t + w.cross(&mesh.nodes[node]);
            if dof < 3 {
                v[dof]
            } else {
                w[dof - 3]
            }
        }
    }

    #[test]
    fn rigid_link_components_are_those_of_the_nodes_displacement_frames() {
        // Independent node 0 in a frame rotated 40° about z, dependent node 1 in one rotated
        // −25° about x; only the dependent's component 2 (its own y axis) is tied.
        let rot = |axis: Vector3<f64>, deg: f64| {
            *nalgebra::Rotation3::from_axis_angle(
                &nalgebra::Unit::new_normalize(axis),
                deg.to_radians(),
            )
            .matrix()
        };
        let (r0, r1) = (rot(Vector3::z(), 40.0), rot(Vector3::x(), -25.0));
        let mut mesh = Mesh::default();
        mesh.add_node(Vector3::new(0.3, -0.2, 0.1));
        mesh.add_node(Vector3::new(1.0, 0.5, -0.7));
        mesh.displacement_frames.insert(0, r0);
        mesh.displacement_frames.insert(1, r1);
        let mut components = [false; 6];
        components[1] = true;
        mesh.rigid_links.push(RigidLink {
            independent: 0,
            dependent: vec![1],
            components,
        });
        let eqs = equations(&mesh).unwrap();
        assert_eq!(eqs.len(), 1);
        assert_eq!(eqs[0].dependent, 6 + 1);
        let (t, w) = (Vector3::new(0.2, -0.5, 0.9), Vector3::new(0.4, 0.1, -0.3));
        // Node 0's own components of the rigid motion, and the tied one of node 1.
        let (t0, w0) = (r0.transpose() * t, r0.transpose() * w);
        let own = |slot: usize| {
            if slot % 6 < 3 {
                t0[slot % 6]
            } else {
                w0[slot % 6 - 3]
            }
        };
        let d = mesh.nodes[1] - mesh.nodes[0];
        let expected = r1.column(1).dot(&(t + w.cross(&d)));
        assert!((evaluate(&eqs[0], &own) - expected).abs() < 1e-14);
    }

    #[test]
    fn rigid_link_reproduces_a_rigid_body_motion() {
        let mut mesh = Mesh::default();
        mesh.add_node(Vector3::new(0.3, -0.2, 0.1));
        mesh.add_node(Vector3::new(1.0, 0.5, -0.7));
        mesh.rigid_links.push(RigidLink {
            independent: 0,
            dependent: vec![1],
            components: [true; 6],
        });
        let eqs = equations(&mesh).unwrap();
        assert_eq!(eqs.len(), 6);
        let u = rigid_field(
            &mesh,
            Vector3::new(1.0, 2.0, 3.0),
            Vector3::new(0.3, -0.4, 0.5),
        );
        for eq in &eqs {
            assert!((evaluate(eq, &u) - u(eq.dependent)).abs() < 1e-14);
        }
    }

    #[test]
    fn interpolation_link_is_exact_for_rigid_motion_and_a_mean_at_the_centroid() {
        let mut mesh = Mesh::default();
        let pts = [
            [1.0, 0.0, 0.0],
            [0.0, 2.0, 0.0],
            [-1.0, 0.0, 0.5],
            [0.0, -2.0, -0.5],
        ];
        for p in pts {
            mesh.add_node(Vector3::from(p));
        }
        let reference = mesh.add_node(Vector3::new(0.4, 0.1, 0.2));
        mesh.interpolation_links.push(InterpolationLink {
            reference,
            reference_components: [true; 6],
            sources: vec![InterpolationSource {
                nodes: vec![0, 1, 2, 3],
                weight: 1.0,
                components: [true, true, true, false, false, false],
            }],
        });
        {
            let eqs = equations(&mesh).unwrap();
            let u = rigid_field(
                &mesh,
                Vector3::new(-1.0, 0.5, 2.0),
                Vector3::new(0.2, 0.7, -0.1),
            );
            for eq in &eqs {
                assert!((evaluate(eq, &u) - u(eq.dependent)).abs() < 1e-12);
            }
        }
        // At the centroid of equal weights, translations average the source translations.
        mesh.nodes[reference] = Vector3::zeros();
        let eqs = equations(&mesh).unwrap();
        let arbitrary = |slot: usize| ((slot * 7919) % 23) as f64 - 11.0;
        for eq in eqs.iter().filter(|e| e.dependent % 6 < 3) {
            let dof = eq.dependent % 6;
            let mean = (0..4).map(|n| arbitrary(6 * n + dof)).sum::<f64>() / 4.0;
            assert!((evaluate(eq, &arbitrary) - mean).abs() < 1e-12);
        }
    }

    #[test]
    fn interpolation_link_on_framed_nodes_is_exact_for_rigid_motion_in_their_components() {
        let mut mesh = Mesh::default();
        for p in [
            [1.0, 0.0, 0.0],
            [0.0, 2.0, 0.0],
            [-1.0, 0.0, 0.5],
            [0.0, -2.0, -0.5],
        ] {
            mesh.add_node(Vector3::from(p));
        }
        let reference = mesh.add_node(Vector3::new(0.4, 0.1, 0.2));
        for (node, (axis, deg)) in [
            (0, (Vector3::z(), 30.0)),
            (2, (Vector3::x(), -70.0)),
            (4, (Vector3::new(1.0, 1.0, 0.3), 50.0)),
        ] {
            let r = nalgebra::Rotation3::from_axis_angle(
                &nalgebra::Unit::new_normalize(axis),
                f64::to_radians(deg),
            );
            mesh.displacement_frames.insert(node, *r.matrix());
        }
        mesh.interpolation_links.push(InterpolationLink {
            reference,
            reference_components: [true, false, true, true, true, false],
            sources: vec![InterpolationSource {
                nodes: vec![0, 1, 2, 3],
                weight: 1.0,
                components: [true, true, true, false, false, false],
            }],
        });
        let (t, w) = (Vector3::new(-1.0, 0.5, 2.0), Vector3::new(0.2, 0.7, -0.1));
        let global = rigid_field(&mesh, t, w);
        // The rigid motion seen in each node's own components.
        let own = |slot: usize| {
            let (node, dof) = (slot / 6, slot % 6);
            let g = SMatrix::<f64, 6, 1>::from_fn(|d, _| global(node * 6 + d));
            (nodal_frames::node_block(&mesh.displacement_frames, node).transpose() * g)[dof]
        };
        let eqs = equations(&mesh).unwrap();
        assert_eq!(eqs.len(), 4);
        for eq in &eqs {
            assert!((evaluate(eq, &own) - own(eq.dependent)).abs() < 1e-12);
        }
    }

    #[test]
    fn collinear_sources_cannot_fix_the_rotation_about_their_line() {
        let mut mesh = Mesh::default();
        mesh.add_node(Vector3::new(-1.0, 0.0, 0.0));
        mesh.add_node(Vector3::new(1.0, 0.0, 0.0));
        let reference = mesh.add_node(Vector3::zeros());
        let mut link = InterpolationLink {
            reference,
            reference_components: [true, true, true, false, false, false],
            sources: vec![InterpolationSource {
                nodes: vec![0, 1],
                weight: 1.0,
                components: [true, true, true, false, false, false],
            }],
        };
        mesh.interpolation_links.push(link.clone());
        assert_eq!(equations(&mesh).unwrap().len(), 3);
        link.reference_components = [true; 6];
        mesh.interpolation_links[0] = link;
        let err = equations(&mesh).unwrap_err().to_string();
        assert!(err.contains("component rx of node 2"), "{err}");
    }
}
