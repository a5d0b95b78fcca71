//! Generalised spring-dampers in their own axes (Nastran CBUSH), to ground or between two
//! nodes, acting on the relative motion of a point carried rigidly by both ends.

use nalgebra::{DMatrix, Matrix3, Vector3};

use super::element::{BulkWriter, Element, ElementMatrices};
use super::error::FeError;
use super::mesh::{Bush, Mesh};
use super::spring::validate;

/// Stiffness and damping of a bush (6 × 6 to ground, 12 × 12 between `a` and `b`, node order
/// a, b): Bᵀ diag(k) B with B the relative motion at the spring point in element axes,
/// u(p) = u_n + θ_n × (p − x_n) for each end n.
pub fn bush_matrices(
    index: usize,
    bush: &Bush,
    xa: &Vector3<f64>,
    xb: Option<&Vector3<f64>>,
) -> Result<(DMatrix<f64>, DMatrix<f64>), FeError> {
    let what = format!("bush {index}");
    validate(&what, &bush.stiffness, &bush.damping)?;
    let r = &bush.frame;
    if (r.transpose() * r - Matrix3::identity()).abs().max() > 1e-9 {
        return Err(FeError::InvalidInput(format!(
            "{what}: frame is not orthonormal"
        )));
    }
    // Rows: element components of the motion of the spring point due to one end's six DOFs.
    let carried = |x: &Vector3<f64>| {
        let mut t = DMatrix::<f64>::zeros(6, 6);
        let lever = -r.transpose() * (bush.point - x).cross_matrix();
        t.view_mut((0, 0), (3, 3)).copy_from(&r.transpose());
        t.view_mut((0, 3), (3, 3)).copy_from(&lever);
        t.view_mut((3, 3), (3, 3)).copy_from(&r.transpose());
        t
    };
    let b = match xb {
        None => carried(xa),
        Some(xb) => {
            let mut b = DMatrix::<f64>::zeros(6, 12);
            b.view_mut((0, 0), (6, 6)).copy_from(&(-carried(xa)));
            b.view_mut((0, 6), (6, 6)).copy_from(&carried(xb));
            b
        }
    };
    let diag = |v: &[f64; 6]| DMatrix::from_diagonal(&nalgebra::DVector::from_row_slice(v));
    let k = b.transpose() * diag(&bush.stiffness) * &b;
    let c = b.transpose() * diag(&bush.damping) * &b;
    Ok((k, c))
}

impl Element for Bush {
    const NAME: &'static str = "bush";

    fn nodes(&self) -> Vec<usize> {
        std::iter::once(self.a).chain(self.b).collect()
    }

    fn grounds(&self) -> bool {
        self.b.is_none()
    }

    fn matrices(&self, index: usize, mesh: &Mesh) -> Result<ElementMatrices, FeError> {
        let what = format!("bush {index}");
        let xa = mesh.position(&what, self.a)?;
        let xb = match self.b {
            Some(b) => Some(mesh.position(&what, b)?),
            None => None,
        };
        let (k, c) = bush_matrices(index, self, &xa, xb.as_ref())?;
        Ok(ElementMatrices {
            k: Some(k),
            m: None,
            c: Some(c),
        })
    }

    /// Not written: refused naming the bush.
    fn write_bulk(
        &self,
        index: usize,
        _mesh: &Mesh,
        _deck: &mut dyn BulkWriter,
    ) -> Result<(), FeError> {
        Err(FeError::Mesh(format!(
            "bush {index}: writing bushes (CBUSH) is not supported"
        )))
    }
}
