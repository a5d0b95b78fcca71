//! Point masses with rotary inertia.

use nalgebra::SMatrix;

use super::element::{dynamic, BulkWriter, Element, ElementMatrices, Field};
use super::error::{require_non_negative, FeError};
use super::mesh::{Mesh, PointMass};

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

impl Element for PointMass {
    const NAME: &'static str = "point mass";
    const HOLDS: bool = false;

    fn nodes(&self) -> Vec<usize> {
        vec![self.node]
    }

    fn matrices(&self, index: usize, mesh: &Mesh) -> Result<ElementMatrices, FeError> {
        mesh.position(&format!("point mass {index}"), self.node)?;
        Ok(ElementMatrices {
            m: Some(dynamic(&matrix(index, self)?)),
            ..ElementMatrices::default()
        })
    }

    /// A CONM2 at the node, the inertia about it in basic.
    fn write_bulk(
        &self,
        index: usize,
        _mesh: &Mesh,
        deck: &mut dyn BulkWriter,
    ) -> Result<(), FeError> {
        let j = &self.inertia;
        // Products of inertia are entered positive (I21 = ∫x1 x2 dm = −J21), as the deck
        // reader takes them.
        let fields = [
            deck.element_id(),
            deck.grid(&format!("point mass {index}"), self.node)?,
            Field::Blank,
            Field::Real(self.mass),
            Field::Blank,
            Field::Blank,
            Field::Blank,
            Field::Blank,
            Field::Real(j[(0, 0)]),
            Field::Real(-j[(1, 0)]),
            Field::Real(j[(1, 1)]),
            Field::Real(-j[(2, 0)]),
            Field::Real(-j[(2, 1)]),
            Field::Real(j[(2, 2)]),
        ];
        deck.card("CONM2", &fields)
    }
}
