//! Opt-in recovery of a reduced body's modes on every node: what operating deflection shapes
//! need. The coupled model keeps only the rows of the named points (a few kB); the full shapes
//! of a body are `6 × nodes × modes` numbers (a few MB for the default body, gigabytes for a
//! million-DOF deck), so they are formed only when asked for and never kept in an instance.
//!
//! The reduction is run again from its spec and each mode of the body the model simulates is
//! found among the recomputed ones by its frequency, its sign fixed and its recovery rows
//! checked against the body's: the full shapes are those of the simulated modes or an error,
//! never a second set that could drift from them.

use super::error::CmsError;
use super::reduce::reduce_detailed;
use super::reduced::ReducedChassis;
use super::spec::ReductionSpec;
use crate::fe::mesh::Mesh;

/// Relative frequency difference within which a recomputed mode is the body's mode.
const SAME_FREQUENCY: f64 = 1e-8;

/// Largest difference of the recovery rows of a matched mode, relative to their norm.
const SAME_ROWS: f64 = 1e-6;

/// The body's mesh and its modes at every node.
#[derive(Debug, Clone)]
pub struct FullRecovery {
    /// Node positions (vehicle frame, m).
    pub nodes: Vec<[f64; 3]>,
    /// `shapes[(node · 6 + dof) · modes + k]`: node's motion (ux, uy, uz, rx, ry, rz; m, rad per
    /// unit modal coordinate) in mode `k` of the simulated body.
    pub shapes: Vec<f64>,
    /// Number of modes (those of the simulated body, in its order).
    pub modes: usize,
    /// Cells by VTK type name (`quad`, `triangle`, `line`, `tetra`, `hexahedron`, `wedge`,
    /// `tetra10`), each a list of node indices.
    pub cells: Vec<(&'static str, Vec<Vec<usize>>)>,
    /// What each mode is (torsion, steering wheel vertical, …; [`crate::chassis::modal`]), where
    /// the body's regions allow a description (empty otherwise).
    pub descriptions: Vec<String>,
}

/// The cells of `mesh` grouped by type.
fn cells(mesh: &Mesh) -> Vec<(&'static str, Vec<Vec<usize>>)> {
    let mut groups: Vec<(&'static str, Vec<Vec<usize>>)> = vec![
        (
            "quad",
            mesh.shells.iter().map(|s| s.nodes.to_vec()).collect(),
        ),
        (
            "triangle",
            mesh.triangles.iter().map(|s| s.nodes.to_vec()).collect(),
        ),
        (
            "line",
            mesh.beams.iter().map(|b| b.nodes.to_vec()).collect(),
        ),
    ];
    for (kind, count) in [
        ("tetra", 4),
        ("hexahedron", 8),
        ("wedge", 6),
        ("tetra10", 10),
    ] {
        groups.push((
            kind,
            mesh.solids
                .iter()
                .filter(|s| s.nodes.len() == count)
                .map(|s| s.nodes.clone())
                .collect(),
        ));
    }
    groups.retain(|(_, c)| !c.is_empty());
    groups
}

/// The modes of `body` (reduced from `spec`, then possibly filtered: a rigid chassis keeps its
/// lowest modes only) on every node of the body's mesh.
///
/// Long on purpose: per mode, the recomputed reduction is matched to the simulated body (the
/// mode of the same frequency, its sign and identity checked on the recovery rows of every named
/// point) and then spread over every node; the matching and the spreading share the indices.
pub fn recover_all_nodes(
    spec: &ReductionSpec,
    body: &ReducedChassis,
) -> Result<FullRecovery, CmsError> {
    let reduction = reduce_detailed(spec)?;
    let modes = &reduction.modes;
    let recomputed = &reduction.reduced;
    let dofs = &reduction.assembled.dofs;
    let transformation = dofs.transformation()?;
    let n_nodes = reduction.chassis.mesh.nodes.len();
    let m = body.n_modes();
    let mut shapes = vec![0.0; n_nodes * 6 * m];
    let described = reduction.describe_modes().ok();
    let mut descriptions = Vec::with_capacity(m);
    for (k, &w) in body.omega.iter().enumerate() {
        let hz = w / (2.0 * std::f64::consts::PI);
        let j = recomputed
            .omega
            .iter()
            .position(|&v| (v - w).abs() <= SAME_FREQUENCY * w)
            .ok_or_else(|| {
                CmsError::Numerical(format!(
                    "full recovery: mode {k} ({hz:.4} Hz) of the simulated body is not among the \
                     recomputed modes; the body was reduced by another build (clear the \
                     reduction cache)"
                ))
            })?;
        // Sign and identity from the recovery rows of every named point.
        let (mut dot, mut norm) = (0.0, 0.0);
        for p in &body.points {
            let q = recomputed.point(&p.name).ok_or_else(|| {
                CmsError::Numerical(format!("full recovery: point '{}' not recomputed", p.name))
            })?;
            for d in 0..6 {
                dot += p.shape[k][d] * q.shape[j][d];
                norm += p.shape[k][d] * p.shape[k][d];
            }
        }
        let sign = if dot < 0.0 { -1.0 } else { 1.0 };
        let mut diff = 0.0;
        for p in &body.points {
            let q = recomputed.point(&p.name).expect("checked above");
            for d in 0..6 {
                diff += (p.shape[k][d] - sign * q.shape[j][d]).powi(2);
            }
        }
        if diff.sqrt() > SAME_ROWS * norm.sqrt().max(f64::MIN_POSITIVE) {
            return Err(CmsError::Numerical(format!(
                "full recovery: mode {k} ({hz:.4} Hz) recomputed with other recovery rows \
                 (relative difference {:.2e}); a repeated frequency or another build",
                diff.sqrt() / norm.sqrt().max(f64::MIN_POSITIVE)
            )));
        }
        if let Some(d) = described.as_ref().and_then(|d| d.get(j)) {
            descriptions.push(d.kind_label());
        }
        // Node motion = T · (the mode over the equations).
        let (cp, ri, val) = (
            transformation.symbolic().col_ptr(),
            transformation.symbolic().row_idx(),
            transformation.val(),
        );
        for g in 0..transformation.ncols() {
            let x = sign * modes.shapes[(g, j)];
            if x == 0.0 {
                continue;
            }
            for p in cp[g]..cp[g + 1] {
                shapes[ri[p] * m + k] += val[p] * x;
            }
        }
    }
    let mesh = &reduction.chassis.mesh;
    Ok(FullRecovery {
        nodes: mesh.nodes.iter().map(|p| [p.x, p.y, p.z]).collect(),
        shapes,
        modes: m,
        cells: cells(mesh),
        descriptions: if descriptions.len() == m {
            descriptions
        } else {
            Vec::new()
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cms::ModeSelection;

    fn small_spec() -> ReductionSpec {
        ReductionSpec {
            selection: ModeSelection::Count(6),
            ..ReductionSpec::default()
        }
    }

    #[test]
    fn full_shapes_hold_the_body_rows_at_its_points() {
        let spec = small_spec();
        let body = crate::cms::reduce(&spec).unwrap();
        let full = recover_all_nodes(&spec, &body).unwrap();
        assert_eq!(full.modes, body.n_modes());
        for p in &body.points {
            for k in 0..body.n_modes() {
                for d in 0..6 {
                    let x = full.shapes[(p.node * 6 + d) * full.modes + k];
                    assert!((x - p.shape[k][d]).abs() <= 1e-9 * (1.0 + p.shape[k][d].abs()));
                }
            }
        }
        assert!(full
            .cells
            .iter()
            .any(|(kind, c)| *kind == "quad" && !c.is_empty()));
    }

    #[test]
    fn a_filtered_body_keeps_its_modes_and_a_flipped_mode_its_sign() {
        let spec = small_spec();
        let mut body = crate::cms::reduce(&spec).unwrap().keep_below(10.0);
        for p in &mut body.points {
            for d in 0..6 {
                p.shape[0][d] = -p.shape[0][d];
            }
        }
        let full = recover_all_nodes(&spec, &body).unwrap();
        let p = &body.points[0];
        assert_eq!(full.modes, body.n_modes());
        assert!((full.shapes[(p.node * 6 + 2) * full.modes] - p.shape[0][2]).abs() < 1e-9);
    }

    #[test]
    fn a_foreign_mode_is_refused() {
        let spec = small_spec();
        let mut body = crate::cms::reduce(&spec).unwrap();
        body.omega[1] *= 1.001;
        let e = recover_all_nodes(&spec, &body).unwrap_err().to_string();
        assert!(e.contains("mode 1") && e.contains("not among"), "{e}");
    }
}
