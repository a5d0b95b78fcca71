//! The chassis reduction: body description → FE model → Craig-Bampton → recovery rows and
//! modal damping of the named points the coupled model needs (the interface nodes, by name, then
//! the output points).

use super::craig_bampton::{craig_bampton, CraigBampton};
use super::damping::{table_damping, DampingTable, DampingUnit, OwnDamping};
use super::error::CmsError;
use super::external::reduce_dmig_source;
use super::reduced::{RecoveryPoint, ReducedChassis};
use super::spec::{BodySource, BulkDeckBody, ReductionSpec};
use crate::chassis::config::ChassisConfig;
use crate::chassis::modal::{describe, ModeDescription};
use crate::chassis::Chassis;
use crate::eigen::Modes;
use crate::fe::assembly::{assemble, mat_vec, Assembled, SparseMat};
use crate::fe::checks::{check_mesh_named, CheckLimits, MeshIndices, Naming, DOF_NAMES};
use crate::fe::dof::{DofMap, DOF_PER_NODE};
use crate::nastran::DeckNames;

/// A reduction together with the full model it came from, for verification and tools. The
/// coupled model needs only [`Reduction::reduced`]; use [`reduce`] to drop the rest.
#[derive(Debug, Clone)]
pub struct Reduction {
    /// The generated body.
    pub chassis: Chassis,
    /// Its assembled K, M, C.
    pub assembled: Assembled,
    /// Global equations of the interface DOFs, mount by mount, DOF order of the spec.
    pub interface: Vec<usize>,
    /// The orthogonalised modes over all equations.
    pub modes: CraigBampton,
    /// What the coupled model gets.
    pub reduced: ReducedChassis,
    /// What the user should know about the body (a deck's dropped grids and element-shape
    /// warnings), one log line each.
    pub notes: Vec<String>,
}

impl Reduction {
    /// The FE description (torsion, steering wheel, front end, …) of every reduced mode, in the
    /// order of [`ReducedChassis::omega`].
    pub fn describe_modes(&self) -> Result<Vec<ModeDescription>, CmsError> {
        let modes = Modes {
            eigenvalues: self.modes.omega.iter().map(|w| w * w).collect(),
            shapes: self.modes.shapes.clone(),
        };
        Ok(describe(&self.chassis.mesh, &self.assembled, &modes)?)
    }
}

/// The reduced chassis described by `spec` (only recovery rows are kept).
pub fn reduce(spec: &ReductionSpec) -> Result<ReducedChassis, CmsError> {
    Ok(reduce_with_notes(spec)?.0)
}

/// The reduced chassis described by `spec` and the notes on its body for the log
/// ([`Reduction::notes`]). A body given as DMIG matrices is taken from its file
/// ([`crate::cms::reduce_external`]); the others are built and reduced here.
pub fn reduce_with_notes(spec: &ReductionSpec) -> Result<(ReducedChassis, Vec<String>), CmsError> {
    if let BodySource::Dmig(source) = &spec.body {
        spec.validate()?;
        return Ok((reduce_dmig_source(spec, source)?, Vec::new()));
    }
    let r = reduce_detailed(spec)?;
    Ok((r.reduced, r.notes))
}

/// The body of `spec` built and assembled, its interface: the named mount nodes and their
/// global interface equations (mount by mount, DOF order of the spec).
pub(crate) struct Model {
    pub chassis: Chassis,
    pub assembled: Assembled,
    pub mounts: Vec<(String, usize)>,
    pub interface: Vec<usize>,
    pub notes: Vec<String>,
    pub own_damping: Option<OwnDamping>,
}

/// Builds and assembles the body `spec` describes (procedural or deck; a DMIG body has no FE
/// model).
pub(crate) fn model(spec: &ReductionSpec) -> Result<Model, CmsError> {
    spec.validate()?;
    let (chassis, names, notes, own_damping) = match &spec.body {
        BodySource::Procedural(config) => (
            Chassis::build(config)?,
            BodyNames::Mesh(MeshIndices),
            Vec::new(),
            None,
        ),
        BodySource::Deck(deck) => deck_body(deck)?,
        BodySource::Dmig(_) => {
            return Err(CmsError::InvalidInput(format!(
                "{} is reduced already: it has no FE model to build",
                spec.body.describe()
            )))
        }
    };
    let assembled = assemble(&chassis.mesh)?;
    let mounts = spec
        .interface
        .iter()
        .map(|name| Ok((name.clone(), chassis.node(name)?)))
        .collect::<Result<Vec<_>, CmsError>>()?;
    check_interface(
        &assembled.dofs,
        &mounts,
        spec.interface_dofs.local(),
        &names,
    )?;
    let mount_ids: Vec<usize> = mounts.iter().map(|(_, id)| *id).collect();
    let interface = assembled
        .dofs
        .indices_of(&mount_ids, spec.interface_dofs.local())?;
    Ok(Model {
        chassis,
        assembled,
        mounts,
        interface,
        notes,
        own_damping,
    })
}

/// How the body's messages name nodes: the procedural body by mesh index, a deck body by its
/// GRID ids (and which grids it dropped).
enum BodyNames {
    Mesh(MeshIndices),
    Deck {
        names: DeckNames,
        unused: std::collections::BTreeSet<u32>,
    },
}

impl BodyNames {
    fn naming(&self) -> &dyn Naming {
        match self {
            BodyNames::Mesh(m) => m,
            BodyNames::Deck { names, .. } => names,
        }
    }
}

/// Every interface DOF must be an equation of its own: not constrained, not dependent in a
/// link, not on a grid dropped for lack of elements. Messages name the point and its GRID.
fn check_interface(
    dofs: &DofMap,
    mounts: &[(String, usize)],
    local: &[usize],
    names: &BodyNames,
) -> Result<(), CmsError> {
    for (point, node) in mounts {
        let grid = names.naming().node(*node);
        if let BodyNames::Deck { names, unused } = names {
            if names.grid(*node).is_some_and(|g| unused.contains(&g)) {
                return Err(CmsError::InvalidInput(format!(
                    "interface point '{point}' is {grid}, which no element, spring, bush, mass \
                     or link references: the reader dropped it (no DOFs, as Nastran's AUTOSPC); \
                     name a grid of the structure"
                )));
            }
        }
        for &d in local {
            let dof = DOF_NAMES.get(d).copied().unwrap_or("?");
            if dofs.is_dependent(*node, d) {
                return Err(CmsError::InvalidInput(format!(
                    "interface point '{point}' ({grid}) dof {dof} is dependent in a rigid or \
                     interpolation link (RBE2/RBE3) and has no equation of its own: use the \
                     link's independent grid"
                )));
            }
            if dofs.global(*node, d).is_none() {
                return Err(CmsError::InvalidInput(format!(
                    "interface point '{point}' ({grid}) dof {dof} is constrained (SPC, GRID PS, \
                     or a rotation no element holds): an interface DOF must be free"
                )));
            }
        }
    }
    Ok(())
}

/// The recovered points in order: the mounts, then the outputs not among them.
pub(crate) fn named_points(
    model: &Model,
    outputs: &[String],
) -> Result<Vec<(String, usize)>, CmsError> {
    let mut named = model.mounts.clone();
    for name in outputs {
        if !named.iter().any(|(n, _)| n == name) {
            named.push((name.clone(), model.chassis.node(name)?));
        }
    }
    Ok(named)
}

/// The reduction of `spec` with the full model and full mode shapes kept.
pub fn reduce_detailed(spec: &ReductionSpec) -> Result<Reduction, CmsError> {
    let model = model(spec)?;
    let modes = craig_bampton(
        &model.assembled.k,
        &model.assembled.m,
        &model.interface,
        spec.selection,
    )?;
    let points = named_points(&model, &spec.outputs)?
        .into_iter()
        .map(|(name, node)| {
            recovery_point(&model.chassis, &model.assembled.dofs, &modes, name, node)
        })
        .collect::<Result<Vec<_>, _>>()?;
    // A body's own table (a deck's TABDMP1) comes before the spec's.
    let table = model
        .own_damping
        .as_ref()
        .map_or(&spec.damping, |own| &own.table);
    let mut zeta = table_damping(&modes.omega, table);
    if spec.discrete_dampers {
        for (k, z) in zeta.iter_mut().enumerate() {
            *z += projected_damping(&model.assembled.c, &modes, k) / (2.0 * modes.omega[k]);
        }
    }
    let reduced = ReducedChassis {
        omega: modes.omega.clone(),
        zeta,
        points,
        cutoff_hz: Some(modes.fixed_interface_hz.iter().copied().fold(0.0, f64::max)),
        own_damping: model.own_damping,
    };
    Ok(Reduction {
        chassis: model.chassis,
        assembled: model.assembled,
        interface: model.interface,
        modes,
        reduced,
        notes: model.notes,
    })
}

/// The body of a bulk data deck, its points named, checked (poor element shapes are warnings,
/// as in Nastran), with its names and the notes for the log; the content must still be what
/// the spec's checksum says (the cache key was made from it).
fn deck_body(
    deck: &BulkDeckBody,
) -> Result<(Chassis, BodyNames, Vec<String>, Option<OwnDamping>), CmsError> {
    let options = crate::nastran::DeckOptions {
        include_root: deck.include_root.clone(),
        ..Default::default()
    };
    let (mut body, sha256) = crate::nastran::read_bulk_deck_with(&deck.path, &options)
        .map_err(|e| CmsError::InvalidInput(format!("bulk data deck: {e}")))?;
    if sha256 != deck.sha256 {
        return Err(CmsError::InvalidInput(format!(
            "bulk data deck {} (or a file it includes) changed after its checksum was taken",
            deck.path.display()
        )));
    }
    body.name_points(&deck.points)?;
    let names = DeckNames::new(&body);
    let warnings = check_mesh_named(&body.mesh, &CheckLimits::nastran_deck(), &names)
        .map_err(|e| CmsError::InvalidInput(format!("bulk data deck: {e}")))?;
    let mut notes = std::mem::take(&mut body.notes);
    notes.extend(warnings);
    let unused = body.unused_grids.iter().copied().collect();
    let own_damping = body
        .damping
        .as_ref()
        .map(|card| deck_damping(card, deck))
        .transpose()?;
    Ok((
        Chassis {
            mesh: body.mesh,
            config: ChassisConfig::default(),
        },
        BodyNames::Deck { names, unused },
        notes,
        own_damping,
    ))
}

/// The deck's `TABDMP1` as the body's damping table, checked; a bad table is refused naming the
/// card, its id and the line of the offending point.
fn deck_damping(
    card: &crate::nastran::DampingTableCard,
    deck: &BulkDeckBody,
) -> Result<OwnDamping, CmsError> {
    let unit = DampingUnit::from_nastran(card.kind).ok_or_else(|| {
        CmsError::InvalidInput(format!(
            "bulk data deck {}: TABDMP1 {} at line {}: damping type '{}' is not handled",
            deck.path.display(),
            card.id,
            card.loc,
            card.kind
        ))
    })?;
    let table = DampingTable {
        unit,
        points: card.points.clone(),
    };
    table.check().map_err(|e| {
        let at = e
            .point
            .and_then(|i| card.point_lines.get(i))
            .unwrap_or(&card.loc);
        CmsError::InvalidInput(format!(
            "bulk data deck {}: Nastran bulk data line {at}: TABDMP1 {} (card at line {}): {e}",
            deck.path.display(),
            card.id,
            card.loc
        ))
    })?;
    Ok(OwnDamping {
        source: format!("TABDMP1 {} at line {} of the deck", card.id, card.loc),
        table,
    })
}

/// `φ_kᵀ C φ_k` of mode `k`.
fn projected_damping(c: &SparseMat, modes: &CraigBampton, k: usize) -> f64 {
    let phi: Vec<f64> = modes.shapes.col(k).iter().copied().collect();
    mat_vec(c, &phi).iter().zip(&phi).map(|(a, b)| a * b).sum()
}

/// The rows of node `node` in every mode; constrained DOFs of the node do not move.
fn recovery_point(
    chassis: &Chassis,
    dofs: &DofMap,
    modes: &CraigBampton,
    name: String,
    node: usize,
) -> Result<RecoveryPoint, CmsError> {
    let p = chassis.mesh.nodes.get(node).ok_or_else(|| {
        CmsError::InvalidInput(format!(
            "recovery point '{name}' refers to missing node {node}"
        ))
    })?;
    // A node of a rigid or interpolation link (RBE2, RBE3) moves with its independent nodes.
    let rows = (0..DOF_PER_NODE)
        .map(|d| dofs.motion_row(node, d))
        .collect::<Result<Vec<_>, _>>()?;
    let shape = (0..modes.omega.len())
        .map(|k| {
            let mut row = [0.0; 6];
            for (d, combination) in rows.iter().enumerate() {
                row[d] = combination
                    .iter()
                    .map(|(g, c)| c * modes.shapes[(*g, k)])
                    .sum();
            }
            row
        })
        .collect();
    Ok(RecoveryPoint {
        name,
        node,
        position: [p.x, p.y, p.z],
        shape,
    })
}
