//! A body reduced elsewhere: Craig-Bampton matrices in Nastran `DMIG` form
//! ([`crate::nastran::read_dmig_file`]) → the [`ReducedChassis`] the coupled model gets, by
//! the same orthogonalisation ([`orthogonalise`]) and damping table as the in-process reduction.
//!
//! The matrices: stiffness and mass (Nastran's `KAAX`, `MAAX`; symmetric, IFO 6) over the a-set
//! of the component: boundary DOFs (grid points, components 1–6 or 1–3) and modal coordinates
//! (scalar points, component 0: the q-set). The fixed-interface frequency of each modal
//! coordinate is its Rayleigh quotient `√(K_qq / M_qq)`, exact for the mass-normalised
//! fixed-interface modes a Craig-Bampton run writes; the spec's mode selection (count or
//! cut-off) picks among them as it picks among the fixed-interface modes of our own reduction,
//! and every boundary DOF is kept.
//!
//! Points: every mount's body node must be a boundary grid with components 1–3. A point's
//! motion in component `c` is the recovery matrix's row (grid, c) if the file has one
//! (rectangular `DMIG`, rows = physical DOFs, columns = the a-set DOFs as in `KAAX`: the
//! Craig-Bampton basis restricted to the output DOFs), else the boundary DOF itself, else zero.
//! Positions come from the file's `GRID` cards (basic system); a point's `node` is its GRID id.
//!
//! [`crate::cms::dmig_of_reduction`] writes our own reduction of a body in this form.

use std::collections::{BTreeMap, BTreeSet};

use faer::Mat;

use super::craig_bampton::orthogonalise;
use super::damping::table_damping;
use super::damping::DampingTable;
use super::error::CmsError;
use super::reduced::{RecoveryPoint, ReducedChassis};
use super::spec::{DmigBodySource, ModeSelection, ReductionSpec};
use crate::nastran::{DmigDof, DmigFile, DmigMatrix};

/// What a body given as Craig-Bampton matrices needs to become a [`ReducedChassis`].
#[derive(Debug, Clone, Copy)]
pub struct ExternalBody<'a> {
    /// The matrices and grid positions.
    pub file: &'a DmigFile,
    /// Name of the stiffness matrix (e.g. `KAAX`).
    pub stiffness: &'a str,
    /// Name of the mass matrix (e.g. `MAAX`).
    pub mass: &'a str,
    /// Name of the recovery matrix of the output points, if any.
    pub recovery: Option<&'a str>,
    /// GRID id of every named point.
    pub points: &'a BTreeMap<String, u32>,
    /// The mounts' body nodes, in mount order (the interface).
    pub interface: &'a [String],
    /// Points recovered after the mounts.
    pub outputs: &'a [String],
    /// Which modal coordinates (fixed-interface modes) are kept.
    pub selection: ModeSelection,
    /// Modal damping of the final modes.
    pub damping: &'a DampingTable,
}

fn invalid(message: String) -> CmsError {
    CmsError::InvalidInput(message)
}

fn dof_name(d: DmigDof) -> String {
    if d.1 == 0 {
        format!("scalar point {}", d.0)
    } else {
        format!("GRID {} component {}", d.0, d.1)
    }
}

/// The symmetric matrix `name` of the file.
fn symmetric<'f>(file: &'f DmigFile, name: &str) -> Result<&'f DmigMatrix, CmsError> {
    let m = file.matrix(name).map_err(CmsError::from)?;
    if m.form != 6 {
        return Err(invalid(format!(
            "DMIG matrix {} has IFO {}; a Craig-Bampton stiffness or mass matrix is symmetric \
             (IFO 6)",
            m.name, m.form
        )));
    }
    Ok(m)
}

/// The kept modal coordinates, ascending id, and the highest Rayleigh frequency among them (Hz,
/// 0 if none is kept): the Rayleigh frequency of each selects it.
fn select_modal(
    k: &DmigMatrix,
    m: &DmigMatrix,
    modal: &[DmigDof],
    selection: ModeSelection,
) -> Result<(Vec<DmigDof>, f64), CmsError> {
    let mut hz = Vec::with_capacity(modal.len());
    for &q in modal {
        let (kq, mq) = (k.get(q, q), m.get(q, q));
        if !(mq > 0.0 && kq > 0.0) {
            return Err(invalid(format!(
                "modal coordinate {} has K = {kq:e}, M = {mq:e} on the diagonal of {} / {}: a \
                 fixed-interface mode has positive stiffness and mass",
                dof_name(q),
                k.name,
                m.name
            )));
        }
        hz.push(((kq / mq).sqrt() / (2.0 * std::f64::consts::PI), q));
    }
    let kept: Vec<(f64, DmigDof)> = match selection {
        ModeSelection::Count(n) => {
            if n > modal.len() {
                return Err(invalid(format!(
                    "selection.count = {n} exceeds the {} modal coordinates of {}",
                    modal.len(),
                    k.name
                )));
            }
            hz.sort_by(|a, b| a.0.total_cmp(&b.0));
            hz.into_iter().take(n).collect()
        }
        ModeSelection::CutoffHz(f) => hz.into_iter().filter(|(h, _)| *h < f).collect(),
    };
    let top = kept.iter().map(|&(h, _)| h).fold(0.0, f64::max);
    let mut kept: Vec<DmigDof> = kept.into_iter().map(|(_, q)| q).collect();
    kept.sort_unstable();
    Ok((kept, top))
}

/// The recovery matrix `name`, checked before anything is computed with it: a rectangular matrix
/// (Nastran's `PHIOUT`) whose columns are the a-set DOFs of the stiffness matrix — all of them,
/// as its header's `NCOL` must say — and whose rows are DOFs outside the a-set.
fn recovery_matrix<'f>(
    body: &ExternalBody<'f>,
    name: &str,
    k: &DmigMatrix,
    m: &DmigMatrix,
    a_set: &BTreeSet<DmigDof>,
) -> Result<&'f DmigMatrix, CmsError> {
    let rec = body.file.matrix(name).map_err(CmsError::from)?;
    if rec.name == k.name || rec.name == m.name {
        return Err(invalid(format!(
            "recovery matrix {} is also the {} matrix: a recovery matrix (Nastran's PHIOUT) \
             gives the motion of output DOFs outside the a-set in terms of the a-set DOFs of {}",
            rec.name,
            if rec.name == k.name {
                "stiffness"
            } else {
                "mass"
            },
            k.name
        )));
    }
    if !matches!(rec.form, 2 | 9) {
        return Err(invalid(format!(
            "recovery matrix {} has form IFO = {}: a recovery matrix is rectangular (IFO 2 or \
             9), rows the output DOFs, columns the a-set DOFs of {}",
            rec.name, rec.form, k.name
        )));
    }
    if let Some(ncol) = rec.ncol.filter(|&n| n != a_set.len()) {
        return Err(invalid(format!(
            "recovery matrix {} declares NCOL = {ncol} in its header, but {} has {} DOFs (the \
             a-set): the recovery matrix has one column per a-set DOF",
            rec.name,
            k.name,
            a_set.len()
        )));
    }
    if let Some(&(col, _)) = rec.entries.keys().find(|(c, _)| !a_set.contains(c)) {
        return Err(invalid(format!(
            "recovery matrix {} has a column for {}, which is not a DOF of {}",
            rec.name,
            dof_name(col),
            k.name
        )));
    }
    if let Some(&(_, row)) = rec.entries.keys().find(|(_, r)| a_set.contains(r)) {
        return Err(invalid(format!(
            "recovery matrix {} has a row for {}, which is a DOF of {}: its rows are the output \
             DOFs outside the a-set",
            rec.name,
            dof_name(row),
            k.name
        )));
    }
    Ok(rec)
}

/// The body given by Craig-Bampton matrices, reduced to its modes like our own reduction.
///
/// Long on purpose: the coordinates, their selection, the modes and the points are one reading
/// of the same matrices, each step indexing by the coordinates the previous one chose.
pub fn reduce_external(body: &ExternalBody<'_>) -> Result<ReducedChassis, CmsError> {
    body.damping.validate()?;
    let k = symmetric(body.file, body.stiffness)?;
    let m = symmetric(body.file, body.mass)?;
    let a_set: BTreeSet<DmigDof> = k.dofs().union(&m.dofs()).copied().collect();
    let modal: Vec<DmigDof> = a_set.iter().copied().filter(|d| d.1 == 0).collect();
    let boundary: BTreeSet<DmigDof> = a_set.iter().copied().filter(|d| d.1 > 0).collect();
    let grid_of = |name: &str, what: &str| {
        body.points.get(name).copied().ok_or_else(|| {
            invalid(format!(
                "{what} '{name}' has no GRID id in the body's points ({})",
                body.points.keys().cloned().collect::<Vec<_>>().join(", ")
            ))
        })
    };
    let boundary_grids = || {
        boundary
            .iter()
            .map(|d| d.0)
            .collect::<BTreeSet<_>>()
            .iter()
            .map(u32::to_string)
            .collect::<Vec<_>>()
            .join(", ")
    };

    // Coordinates: the kept modal ones, then the mounts' boundary DOFs in mount order (the
    // order of our own reduction's constraint modes), then any other boundary DOF.
    let (mut coords, cutoff_hz) = select_modal(k, m, &modal, body.selection)?;
    let mut interface_dofs = Vec::new();
    let mut interface_grids: Vec<(u32, &String)> = Vec::new();
    for name in body.interface {
        let g = grid_of(name, "mount body node")?;
        if let Some((_, other)) = interface_grids.iter().find(|(h, _)| *h == g) {
            return Err(invalid(format!(
                "mount body nodes '{other}' and '{name}' are both GRID {g}: two mounts on one \
                 grid (each mount needs its own boundary grid)"
            )));
        }
        interface_grids.push((g, name));
        for c in 1..=3u8 {
            if !boundary.contains(&(g, c)) {
                return Err(invalid(format!(
                    "mount body node '{name}' is GRID {g}, whose component {c} is not a \
                     boundary DOF of {} (boundary grids: {}); the mounts attach at boundary grids",
                    k.name,
                    boundary_grids()
                )));
            }
        }
        interface_dofs.extend(boundary.range((g, 1)..=(g, 6)).copied());
    }
    coords.extend(interface_dofs.iter().copied());
    coords.extend(
        boundary
            .iter()
            .filter(|d| !interface_dofs.contains(d))
            .copied(),
    );
    let index: BTreeMap<DmigDof, usize> = coords.iter().enumerate().map(|(i, d)| (*d, i)).collect();
    let r = coords.len();
    let k_r = Mat::from_fn(r, r, |i, j| k.get(coords[i], coords[j]));
    let m_r = Mat::from_fn(r, r, |i, j| m.get(coords[i], coords[j]));
    if let Some(d) = coords.iter().find(|d| m.get(**d, **d) <= 0.0) {
        return Err(invalid(format!(
            "{} has no positive mass on the diagonal of {}: every coordinate needs mass",
            dof_name(*d),
            m.name
        )));
    }
    let recovery = match body.recovery {
        Some(name) => Some(recovery_matrix(body, name, k, m, &a_set)?),
        None => None,
    };
    let (omega, coefficients) = orthogonalise(&k_r, &m_r)?;

    let rows: BTreeMap<DmigDof, Vec<(DmigDof, f64)>> = recovery.map_or_else(BTreeMap::new, |rec| {
        let mut rows: BTreeMap<DmigDof, Vec<(DmigDof, f64)>> = BTreeMap::new();
        for (&(col, row), &v) in &rec.entries {
            rows.entry(row).or_default().push((col, v));
        }
        rows
    });

    let mut names: Vec<&String> = body.interface.iter().collect();
    names.extend(body.outputs.iter().filter(|o| !body.interface.contains(o)));
    let mut points = Vec::with_capacity(names.len());
    for name in names {
        let g = grid_of(name, "point")?;
        let position = *body.file.grids.get(&g).ok_or_else(|| {
            invalid(format!(
                "point '{name}' is GRID {g}, which has no GRID card in the DMIG file (its \
                 position is needed)"
            ))
        })?;
        let mut basis_rows: Vec<Vec<(usize, f64)>> = vec![Vec::new(); 6];
        let mut moves = false;
        for c in 1..=6u8 {
            let row = &mut basis_rows[usize::from(c - 1)];
            if let Some(entries) = rows.get(&(g, c)) {
                // Columns of modal coordinates left out by the selection drop out here.
                row.extend(
                    entries
                        .iter()
                        .filter_map(|(col, v)| index.get(col).map(|&j| (j, *v))),
                );
                moves = true;
            } else if let Some(&j) = index.get(&(g, c)) {
                row.push((j, 1.0));
                moves = true;
            }
        }
        if !moves {
            return Err(invalid(format!(
                "point '{name}' is GRID {g}, which is neither a boundary grid of {} (boundary \
                 grids: {}) nor has rows in {}",
                k.name,
                boundary_grids(),
                body.recovery.unwrap_or("a recovery matrix (none is named)")
            )));
        }
        let shape = (0..r)
            .map(|mode| {
                let mut s = [0.0; 6];
                for (c, row) in basis_rows.iter().enumerate() {
                    s[c] = row.iter().map(|&(j, v)| v * coefficients[(j, mode)]).sum();
                }
                s
            })
            .collect();
        points.push(RecoveryPoint {
            name: name.clone(),
            node: g as usize,
            position,
            shape,
        });
    }
    Ok(ReducedChassis {
        zeta: table_damping(&omega, body.damping),
        omega,
        points,
        cutoff_hz: Some(cutoff_hz),
        own_damping: None,
    })
}

/// The reduced body of a spec whose body is given as DMIG matrices: the file read (its content
/// must still be what the spec's checksum says: the cache key was made from it) and taken from
/// there by [`reduce_external`] with the spec's interface, outputs, selection and damping.
pub(crate) fn reduce_dmig_source(
    spec: &ReductionSpec,
    source: &DmigBodySource,
) -> Result<ReducedChassis, CmsError> {
    let options = crate::nastran::DeckOptions {
        include_root: source.include_root.clone(),
        ..Default::default()
    };
    let (file, sha256) = crate::nastran::read_dmig_file(&source.path, &options)?;
    if sha256 != source.sha256 {
        return Err(invalid(format!(
            "DMIG file {} (or a file it includes) changed after its checksum was taken",
            source.path.display()
        )));
    }
    reduce_external(&ExternalBody {
        file: &file,
        stiffness: &source.stiffness,
        mass: &source.mass,
        recovery: source.recovery.as_deref(),
        points: &source.points,
        interface: &spec.interface,
        outputs: &spec.outputs,
        selection: spec.selection,
        damping: &spec.damping,
    })
}
