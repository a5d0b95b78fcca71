//! Rigid links (Nastran RBE2): the listed components of every dependent node follow the
//! rigid-body motion of the independent node; eliminated exactly in assembly (see
//! [`super::links`]).

use super::element::{BulkWriter, Element, Field, LinkEquation};
use super::error::FeError;
use super::links::rigid_map;
use super::mesh::{Mesh, RigidLink, DOF_PER_NODE};
use super::nodal_frames;

fn rigid_equations(
    mesh: &Mesh,
    index: usize,
    link: &RigidLink,
) -> Result<Vec<LinkEquation>, FeError> {
    let origin = format!("rigid link {index}");
    let xi = mesh.position(&origin, link.independent)?;
    let mut out = Vec::new();
    for &dep in &link.dependent {
        if dep == link.independent {
            return Err(FeError::Mesh(format!(
                "{origin}: node {dep} is both independent and dependent"
            )));
        }
        // Components on nodes with a displacement frame (GRID CD) are the node's own: the
        // dependent's listed components in its frame, the independent's six in its frame.
        let s = nodal_frames::node_block(&mesh.displacement_frames, dep).transpose()
            * rigid_map(&(mesh.position(&origin, dep)? - xi))
            * nodal_frames::node_block(&mesh.displacement_frames, link.independent);
        for (row, _) in link.components.iter().enumerate().filter(|(_, on)| **on) {
            let terms = (0..DOF_PER_NODE)
                .filter(|&col| s[(row, col)] != 0.0)
                .map(|col| (link.independent * DOF_PER_NODE + col, s[(row, col)]))
                .collect();
            out.push(LinkEquation {
                dependent: dep * DOF_PER_NODE + row,
                terms,
                origin: origin.clone(),
            });
        }
    }
    Ok(out)
}

impl Element for RigidLink {
    const NAME: &'static str = "rigid link";

    fn nodes(&self) -> Vec<usize> {
        std::iter::once(self.independent)
            .chain(self.dependent.iter().copied())
            .collect()
    }

    fn equations(&self, index: usize, mesh: &Mesh) -> Result<Vec<LinkEquation>, FeError> {
        rigid_equations(mesh, index, self)
    }

    fn write_bulk(
        &self,
        index: usize,
        _mesh: &Mesh,
        deck: &mut dyn BulkWriter,
    ) -> Result<(), FeError> {
        let what = format!("rigid link {index}");
        let mut fields = vec![
            deck.element_id(),
            deck.grid(&what, self.independent)?,
            Field::components(&self.components)?,
        ];
        for &d in &self.dependent {
            fields.push(deck.grid(&what, d)?);
        }
        deck.card("RBE2", &fields)
    }
}
