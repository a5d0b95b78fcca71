//! Our own reduction of a body written as Craig-Bampton matrices in Nastran `DMIG` form, as a
//! Nastran `EXTSEOUT(DMIGPCH)` run hands them over: what [`super::reduce_external`] reads back.

use std::collections::{BTreeMap, BTreeSet};

use faer::Mat;

use super::craig_bampton::craig_bampton_basis;
use super::error::CmsError;
use super::reduce::{model, named_points};
use super::spec::ReductionSpec;
use crate::nastran::{write_dmig_file, DmigDof, DmigFile, DmigMatrix};

/// Our own reduction of a body as Craig-Bampton matrices in `DMIG` form.
#[derive(Debug, Clone, PartialEq)]
pub struct DmigBody {
    /// The matrices `KAAX`, `MAAX` (symmetric, upper triangle) and `PHIOUT` (the basis at the
    /// named points' DOFs that are not boundary DOFs), and the named points' GRID cards.
    pub file: DmigFile,
    /// GRID id of every named point (mounts, outputs): FE node index + 1.
    pub points: BTreeMap<String, u32>,
}

impl DmigBody {
    /// The file's text (free field, 17 significant digits).
    pub fn text(&self) -> String {
        let order = ["KAAX", "MAAX", "PHIOUT"];
        let matrices: Vec<DmigMatrix> = order
            .iter()
            .filter_map(|n| self.file.matrices.get(*n).cloned())
            .collect();
        write_dmig_file(&self.file.grids, &matrices)
    }
}

/// The Craig-Bampton matrices of the body `spec` describes (the same basis our reduction
/// orthogonalises), as a Nastran `EXTSEOUT(DMIGPCH)` run would hand them over: boundary DOFs
/// at the mount grids (`spec.interface_dofs`), the kept fixed-interface modes as scalar points
/// numbered from the first power of ten above the GRID ids, plus the recovery matrix `PHIOUT`
/// for the named points.
pub fn dmig_of_reduction(spec: &ReductionSpec) -> Result<DmigBody, CmsError> {
    let model = model(spec)?;
    let basis = craig_bampton_basis(
        &model.assembled.k,
        &model.assembled.m,
        &model.interface,
        spec.selection,
    )?;
    let n_nodes = model.chassis.mesh.nodes.len() as u64;
    let first_spoint = 10u64.pow((n_nodes + 1).to_string().len() as u32) + 1;
    let nf = basis.fixed_interface_hz.len();
    let local = spec.interface_dofs.local();
    let mut coords: Vec<DmigDof> = (0..nf)
        .map(|q| {
            u32::try_from(first_spoint + q as u64)
                .map(|id| (id, 0))
                .map_err(|_| {
                    CmsError::InvalidInput("too many nodes and modes for Nastran ids".into())
                })
        })
        .collect::<Result<_, _>>()?;
    for (_, node) in &model.mounts {
        coords.extend(local.iter().map(|&d| (*node as u32 + 1, d as u8 + 1)));
    }
    let r = coords.len();
    let triangle = |name: &str, a: &Mat<f64>| {
        let mut mat = DmigMatrix::new(name, 6);
        mat.ncol = Some(r);
        for j in 0..r {
            for i in 0..=j {
                if a[(i, j)] != 0.0 {
                    mat.entries.insert((coords[j], coords[i]), a[(i, j)]);
                }
            }
        }
        mat
    };
    let mut file = DmigFile::default();
    file.matrices
        .insert("KAAX".into(), triangle("KAAX", &basis.k_r));
    file.matrices
        .insert("MAAX".into(), triangle("MAAX", &basis.m_r));
    let mut phi = DmigMatrix::new("PHIOUT", 9);
    phi.ncol = Some(r);
    let boundary: BTreeSet<DmigDof> = coords.iter().copied().filter(|d| d.1 > 0).collect();
    let mut points = BTreeMap::new();
    for (name, node) in named_points(&model, &spec.outputs)? {
        let g = node as u32 + 1;
        points.insert(name, g);
        let p = &model.chassis.mesh.nodes[node];
        file.grids.insert(g, [p.x, p.y, p.z]);
        for d in 0..6 {
            if boundary.contains(&(g, d as u8 + 1)) {
                continue;
            }
            // A node of a rigid or interpolation link moves with its independent nodes.
            let combination = model.assembled.dofs.motion_row(node, d)?;
            for (j, &col) in coords.iter().enumerate() {
                let v: f64 = combination.iter().map(|(e, c)| c * basis.t[(*e, j)]).sum();
                if v != 0.0 {
                    phi.entries.insert((col, (g, d as u8 + 1)), v);
                }
            }
        }
    }
    file.matrices.insert("PHIOUT".into(), phi);
    Ok(DmigBody { file, points })
}
