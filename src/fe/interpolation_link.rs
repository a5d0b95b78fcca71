//! Interpolation links (Nastran RBE3): the reference node moves with the weighted
//! least-squares fit of the rigid-body motion to its source nodes; eliminated exactly in
//! assembly (see [`super::links`] for the weighting).

use nalgebra::{Matrix6, SMatrix, Vector3};

use super::element::{BulkWriter, Element, Field, LinkEquation};
use super::error::FeError;
use super::links::rigid_map;
use super::mesh::{InterpolationLink, Mesh, DOF_PER_NODE};
use super::nodal_frames;

const DOF_NAMES: [&str; 6] = ["ux", "uy", "uz", "rx", "ry", "rz"];

/// Long on purpose: one RBE3 formulation (weights, centroid, rigid-body projection, dependent DOFs) in Nastran's order.
fn interpolation_equations(
    mesh: &Mesh,
    index: usize,
    link: &InterpolationLink,
) -> Result<Vec<LinkEquation>, FeError> {
    let origin = format!("interpolation link {index}");
    let xr = mesh.position(&origin, link.reference)?;
    let mut sources = Vec::new();
    for group in &link.sources {
        if !(group.weight.is_finite() && group.weight > 0.0) {
            return Err(FeError::InvalidInput(format!(
                "{origin}: weight must be finite and > 0, got {}",
                group.weight
            )));
        }
        if !group.components.iter().any(|c| *c) {
            return Err(FeError::InvalidInput(format!(
                "{origin}: a source group lists no components"
            )));
        }
        for &node in &group.nodes {
            if node == link.reference {
                return Err(FeError::Mesh(format!(
                    "{origin}: reference node {node} is also a source node"
                )));
            }
            sources.push((node, mesh.position(&origin, node)? - xr, group));
        }
    }
    if sources.is_empty() {
        return Err(FeError::InvalidInput(format!("{origin}: no source nodes")));
    }
    let mean_distance =
        sources.iter().map(|(_, d, _)| d.norm()).sum::<f64>() / sources.len() as f64;
    let length = if mean_distance > 0.0 {
        mean_distance
    } else {
        1.0
    };
    let weight_of = |group: &super::mesh::InterpolationSource, c: usize| {
        if !group.components[c] {
            0.0
        } else if c < 3 {
            group.weight
        } else {
            group.weight * length * length
        }
    };
    // Source components are those of each source node's displacement frame (GRID CD):
    // Sⱼ maps the reference's global motion to them; the reference's own components are
    // B_refᵀ times its global motion.
    let frames = &mesh.displacement_frames;
    let source_map = |node: usize, d: &Vector3<f64>| {
        nodal_frames::node_block(frames, node).transpose() * rigid_map(d)
    };
    let to_reference = nodal_frames::node_block(frames, link.reference).transpose();
    let mut normal = Matrix6::<f64>::zeros();
    for (node, d, group) in &sources {
        let s = source_map(*node, d);
        let w = Matrix6::from_diagonal(&SMatrix::<f64, 6, 1>::from_fn(|c, _| weight_of(group, c)));
        normal += s.transpose() * w * s;
    }
    // Pseudo-inverse: reference components in the null space are reported below rather than
    // silently set to zero.
    let eig = normal.symmetric_eigen();
    let largest = eig.eigenvalues.amax();
    let mut pinv = Matrix6::<f64>::zeros();
    for k in 0..6 {
        let v = eig.eigenvectors.column(k);
        if eig.eigenvalues[k] > 1e-10 * largest {
            pinv += v * v.transpose() / eig.eigenvalues[k];
        } else {
            let v = to_reference * v;
            for (c, _) in link
                .reference_components
                .iter()
                .enumerate()
                .filter(|(_, on)| **on)
            {
                if v[c].abs() > 1e-6 {
                    return Err(FeError::Mesh(format!(
                        "{origin}: reference component {} of node {} is not determined by the \
                         source nodes and components (collinear or too few sources)",
                        DOF_NAMES[c], link.reference
                    )));
                }
            }
        }
    }
    let pinv = to_reference * pinv;
    let mut out = Vec::new();
    for (row, _) in link
        .reference_components
        .iter()
        .enumerate()
        .filter(|(_, on)| **on)
    {
        let mut terms = Vec::new();
        for (node, d, group) in &sources {
            let s = source_map(*node, d);
            // Row `row` of pinv · Sⱼᵀ Wⱼ: the coefficient of each source component.
            let coupling = pinv.row(row) * s.transpose();
            for c in 0..DOF_PER_NODE {
                let coefficient = coupling[c] * weight_of(group, c);
                if coefficient != 0.0 {
                    terms.push((node * DOF_PER_NODE + c, coefficient));
                }
            }
        }
        out.push(LinkEquation {
            dependent: link.reference * DOF_PER_NODE + row,
            terms,
            origin: origin.clone(),
        });
    }
    Ok(out)
}

impl Element for InterpolationLink {
    const NAME: &'static str = "interpolation link";

    fn nodes(&self) -> Vec<usize> {
        std::iter::once(self.reference)
            .chain(self.sources.iter().flat_map(|s| s.nodes.iter().copied()))
            .collect()
    }

    fn equations(&self, index: usize, mesh: &Mesh) -> Result<Vec<LinkEquation>, FeError> {
        interpolation_equations(mesh, index, self)
    }

    fn write_bulk(
        &self,
        index: usize,
        _mesh: &Mesh,
        deck: &mut dyn BulkWriter,
    ) -> Result<(), FeError> {
        let what = format!("interpolation link {index}");
        let mut fields = vec![
            deck.element_id(),
            Field::Blank,
            deck.grid(&what, self.reference)?,
            Field::components(&self.reference_components)?,
        ];
        for group in &self.sources {
            fields.push(Field::Real(group.weight));
            fields.push(Field::components(&group.components)?);
            for &n in &group.nodes {
                fields.push(deck.grid(&what, n)?);
            }
        }
        deck.card("RBE3", &fields)
    }
}
