//! Two-node spring-dampers acting on the relative displacement, uncoupled per DOF of the nodes
//! (Nastran CELAS/CDAMP between two grids, merged per node pair), and what scalar springs share
//! with [`super::ground_spring`]: their checks and their cards.

use nalgebra::SMatrix;

use super::element::{BulkWriter, Element, ElementMatrices, Field};
use super::error::{require_non_negative, FeError};
use super::mesh::{Mesh, Spring};
use super::nodal_frames;

/// Checks the six stiffnesses and dampings of a spring-damper `what`.
pub(crate) fn validate(what: &str, k: &[f64; 6], c: &[f64; 6]) -> Result<(), FeError> {
    for d in 0..6 {
        require_non_negative(&format!("{what}: stiffness[{d}]"), k[d])?;
        require_non_negative(&format!("{what}: damping[{d}]"), c[d])?;
    }
    Ok(())
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

impl Element for Spring {
    const NAME: &'static str = "spring";

    fn nodes(&self) -> Vec<usize> {
        self.nodes.to_vec()
    }

    /// Scalar springs act on node components (GRID CD): carried to global axes so that
    /// scattering through the DOF map gives them back on the components.
    fn matrices(&self, index: usize, mesh: &Mesh) -> Result<ElementMatrices, FeError> {
        let what = format!("spring {index}");
        mesh.positions(&what, &self.nodes)?;
        let (ks, cs) = two_node_matrices(index, self)?;
        let frames = &mesh.displacement_frames;
        Ok(ElementMatrices::stiffness_and_damping(
            &nodal_frames::to_global_axes(frames, &self.nodes, &ks),
            &nodal_frames::to_global_axes(frames, &self.nodes, &cs),
        ))
    }

    fn write_bulk(
        &self,
        index: usize,
        _mesh: &Mesh,
        deck: &mut dyn BulkWriter,
    ) -> Result<(), FeError> {
        let what = format!("spring {index}");
        let ends = [
            deck.grid(&what, self.nodes[0])?,
            deck.grid(&what, self.nodes[1])?,
        ];
        write_scalar(deck, &ends, &self.stiffness, &self.damping)
    }
}

/// CELAS2 and CDAMP2 of the non-zero components of a spring-damper between `grids` (one
/// grid: to ground).
pub(crate) fn write_scalar(
    deck: &mut dyn BulkWriter,
    grids: &[Field],
    stiffness: &[f64; 6],
    damping: &[f64; 6],
) -> Result<(), FeError> {
    for d in 0..6 {
        for (name, value) in [("CELAS2", stiffness[d]), ("CDAMP2", damping[d])] {
            if value != 0.0 {
                let mut fields = vec![deck.element_id(), Field::Real(value)];
                for &g in grids {
                    fields.push(g);
                    fields.push(Field::Int(d as u64 + 1));
                }
                deck.card(name, &fields)?;
            }
        }
    }
    Ok(())
}
