//! Spring-dampers from a node to ground, uncoupled per DOF of the node (Nastran CELAS/CDAMP
//! with one grid, merged per node).

use nalgebra::SMatrix;

use super::element::{BulkWriter, Element, ElementMatrices};
use super::error::FeError;
use super::mesh::{GroundSpring, Mesh};
use super::nodal_frames;
use super::spring::{validate, write_scalar};

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

impl Element for GroundSpring {
    const NAME: &'static str = "ground spring";

    fn nodes(&self) -> Vec<usize> {
        vec![self.node]
    }

    fn grounds(&self) -> bool {
        true
    }

    /// On the node's components (GRID CD), carried to global axes like a two-node spring.
    fn matrices(&self, index: usize, mesh: &Mesh) -> Result<ElementMatrices, FeError> {
        mesh.position(&format!("ground spring {index}"), self.node)?;
        let (ks, cs) = ground_matrices(index, self)?;
        let frames = &mesh.displacement_frames;
        Ok(ElementMatrices::stiffness_and_damping(
            &nodal_frames::to_global_axes(frames, &[self.node], &ks),
            &nodal_frames::to_global_axes(frames, &[self.node], &cs),
        ))
    }

    fn write_bulk(
        &self,
        index: usize,
        _mesh: &Mesh,
        deck: &mut dyn BulkWriter,
    ) -> Result<(), FeError> {
        let grid = deck.grid(&format!("ground spring {index}"), self.node)?;
        write_scalar(deck, &[grid], &self.stiffness, &self.damping)
    }
}
