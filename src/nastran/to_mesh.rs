//! Typed cards → [`Mesh`]: coordinate systems resolved to basic, properties and materials
//! looked up, scalar springs merged per node, supports of the selected SPC set applied.

use std::collections::{BTreeMap, BTreeSet};

use nalgebra::{Matrix3, Vector3};

use super::card_table;
use super::cards::{self, deck_error as mesh_error, Cards, Orientation, ScalarValue, SystemKind};
use super::lexer::{CardSink, Loc, RawCard};
use super::reader::DeckInfo;
use super::NastranBody;
use crate::fe::elements::{all_nodes, Entity};
use crate::fe::error::FeError;
use crate::fe::mesh::{
    Beam, BeamEnds, BeamSection, Bush, GroundSpring, InterpolationLink, InterpolationSource,
    Material, Mesh, PointMass, RigidLink, Spring,
};

mod shells;
mod solids;

/// A resolved system: origin and rotation (columns: axes in basic) of its Cartesian frame.
#[derive(Debug, Clone, Copy)]
struct System {
    kind: SystemKind,
    origin: Vector3<f64>,
    axes: Matrix3<f64>,
}

impl System {
    /// Basic position of a point given by its coordinates in this system (angles in degrees,
    /// as Nastran enters them).
    fn to_basic(self, p: [f64; 3]) -> Vector3<f64> {
        let local = match self.kind {
            SystemKind::Rectangular => Vector3::from(p),
            SystemKind::Cylindrical => {
                let (s, c) = p[1].to_radians().sin_cos();
                Vector3::new(p[0] * c, p[0] * s, p[2])
            }
            SystemKind::Spherical => {
                let (st, ct) = p[1].to_radians().sin_cos();
                let (sp, cp) = p[2].to_radians().sin_cos();
                Vector3::new(p[0] * st * cp, p[0] * st * sp, p[0] * ct)
            }
        };
        self.origin + self.axes * local
    }

    /// Axes (columns, in basic) of this system's components at the basic point `p`: for
    /// CORD2C the r, θ, z directions there, for CORD2S r, θ, φ. On the axis (r = 0 in the x-y
    /// plane of the system) θ and φ are taken as 0.
    fn axes_at(self, p: &Vector3<f64>) -> Matrix3<f64> {
        let l = self.axes.transpose() * (p - self.origin);
        let local = match self.kind {
            SystemKind::Rectangular => Matrix3::identity(),
            SystemKind::Cylindrical => {
                let (s, c) = l.y.atan2(l.x).sin_cos();
                Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
            }
            SystemKind::Spherical => {
                let (sp, cp) = l.y.atan2(l.x).sin_cos();
                let (st, ct) = l.x.hypot(l.y).atan2(l.z).sin_cos();
                Matrix3::from_columns(&[
                    Vector3::new(st * cp, st * sp, ct),
                    Vector3::new(ct * cp, ct * sp, -st),
                    Vector3::new(-sp, cp, 0.0),
                ])
            }
        };
        self.axes * local
    }
}

/// Resolved systems by id.
struct Systems {
    resolved: BTreeMap<u32, System>,
}

impl Systems {
    fn new(defs: &BTreeMap<u32, cards::Cord2r>) -> Result<Self, FeError> {
        let mut resolved: BTreeMap<u32, System> = BTreeMap::new();
        for &id in defs.keys() {
            let mut chain = vec![id];
            // Walk down to a resolved or basic system, then back up.
            loop {
                let cur = defs[chain.last().unwrap_or(&id)].rid;
                match cur {
                    Some(rid) if !resolved.contains_key(&rid) => {
                        let d = &defs[chain.last().unwrap_or(&id)];
                        if chain.contains(&rid) {
                            return Err(mesh_error(
                                &defs[&id].line,
                                format!("{} {id}: reference systems form a cycle", d.kind.card()),
                            ));
                        }
                        if !defs.contains_key(&rid) {
                            return Err(mesh_error(
                                &d.line,
                                format!(
                                    "{} {}: reference system RID {rid} not found",
                                    d.kind.card(),
                                    d.id
                                ),
                            ));
                        }
                        chain.push(rid);
                    }
                    _ => break,
                }
            }
            while let Some(cid) = chain.pop() {
                let d = &defs[&cid];
                // A, B, C are coordinates in RID, whatever its kind.
                let to_basic = |p: [f64; 3]| -> Vector3<f64> {
                    match d.rid.and_then(|rid| resolved.get(&rid)) {
                        Some(s) => s.to_basic(p),
                        None => Vector3::from(p),
                    }
                };
                let (a, b, c) = (to_basic(d.a), to_basic(d.b), to_basic(d.c));
                let z = b - a;
                let x = (c - a) - z * (z.dot(&(c - a)) / z.norm_squared());
                if !(z.norm() > 0.0 && x.norm() > 1e-12 * z.norm() && x.norm().is_finite()) {
                    return Err(mesh_error(
                        &d.line,
                        format!(
                            "{} {cid}: points A, B, C are coincident or collinear",
                            d.kind.card()
                        ),
                    ));
                }
                let (ez, ex) = (z.normalize(), x.normalize());
                let axes = Matrix3::from_columns(&[ex, ez.cross(&ex), ez]);
                resolved.insert(
                    cid,
                    System {
                        kind: d.kind,
                        origin: a,
                        axes,
                    },
                );
            }
        }
        Ok(Self { resolved })
    }

    fn get(&self, id: u32, line: &Loc, user: &str) -> Result<&System, FeError> {
        self.resolved.get(&id).ok_or_else(|| {
            mesh_error(
                line,
                format!("{user}: coordinate system {id} not found (CORD2R/CORD2C/CORD2S)"),
            )
        })
    }

    /// Origin and axes of a rectangular system: users whose directions are fixed (mass offsets
    /// and inertia, element axes) cannot take a curvilinear system, whose axes depend on the
    /// point.
    fn rectangular(
        &self,
        id: u32,
        line: &Loc,
        user: &str,
    ) -> Result<(Vector3<f64>, Matrix3<f64>), FeError> {
        let s = self.get(id, line, user)?;
        if s.kind != SystemKind::Rectangular {
            return Err(mesh_error(
                line,
                format!(
                    "{user}: coordinate system {id} is a {}; only rectangular (CORD2R) systems \
                     are supported here",
                    s.kind.card()
                ),
            ));
        }
        Ok((s.origin, s.axes))
    }
}

fn material_named(c: &Cards, mid: u32, line: &Loc, user: &str) -> Result<cards::Mat1, FeError> {
    c.materials
        .get(&mid)
        .cloned()
        .ok_or_else(|| mesh_error(line, format!("{user}: material MAT1 {mid} not found")))
}

/// E and G of a MAT1 by Nastran's rule for the missing one (E = 2 (1 + ν) G).
fn moduli(m: &cards::Mat1, user: &str) -> Result<(f64, f64, f64), FeError> {
    let fail = |why: &str| mesh_error(&m.line, format!("MAT1 {} (used by {user}): {why}", m.id));
    let (e, g, nu) = match (m.e, m.g, m.nu) {
        (Some(e), Some(g), Some(nu)) => (e, g, nu),
        (Some(e), Some(g), None) => (e, g, e / (2.0 * g) - 1.0),
        (Some(e), None, Some(nu)) => (e, e / (2.0 * (1.0 + nu)), nu),
        (None, Some(g), Some(nu)) => (2.0 * (1.0 + nu) * g, g, nu),
        _ => {
            return Err(fail(
                "give two of E, G, NU (with only one, Nastran sets the others to zero, which \
                 leaves shear or extension without stiffness)",
            ))
        }
    };
    if !(e > 0.0 && g > 0.0 && e.is_finite() && g.is_finite()) {
        return Err(fail(&format!("E = {e} and G = {g} must be > 0")));
    }
    if !(nu > -1.0 && nu < 0.5) {
        return Err(fail(&format!("NU = {nu} must lie in (-1, 0.5)")));
    }
    Ok((e, g, nu))
}

fn node_of(body: &NastranBody, grid: u32, line: &Loc, user: &str) -> Result<usize, FeError> {
    body.grid_index
        .get(&grid)
        .copied()
        .ok_or_else(|| mesh_error(line, format!("{user}: GRID {grid} not found")))
}

fn mask_nodes(mask: [bool; 6]) -> impl Iterator<Item = usize> {
    (0..6).filter(move |&d| mask[d])
}

/// Collects the cards of a deck as they are read.
pub(crate) struct Collector(Cards);

impl Collector {
    pub(crate) fn new() -> Self {
        Self(Cards::new())
    }
}

impl CardSink for Collector {
    fn card(&mut self, card: RawCard) -> Result<(), FeError> {
        card_table::read_card(&mut self.0, &card)
    }

    fn reset(&mut self) {
        self.0 = Cards::new();
    }
}

/// Builds the body from the cards read and the SPC set and the damping table the case control
/// selects.
pub(crate) fn build(cards: Collector, info: &DeckInfo) -> Result<NastranBody, FeError> {
    let spc_selection = info.spc_selection;
    let mut c = cards.0;
    let systems = Systems::new(&c.systems)?;
    let mut body = NastranBody {
        mesh: Mesh::default(),
        grid_index: BTreeMap::new(),
        element_ids: Default::default(),
        spc_set: None,
        element_cards: BTreeMap::new(),
        unused_grids: Vec::new(),
        notes: Vec::new(),
        damping: None,
    };
    if let Some((id, at)) = &info.sdamping {
        let table = c.damping_tables.remove(id).ok_or_else(|| {
            let tables: Vec<String> = c.damping_tables.keys().map(u32::to_string).collect();
            mesh_error(
                at,
                format!(
                    "SDAMPING = {id} names no TABDMP1 (the deck's TABDMP1 ids: {})",
                    if tables.is_empty() {
                        "none".to_string()
                    } else {
                        tables.join(", ")
                    }
                ),
            )
        })?;
        body.damping = Some(table);
    }
    for (&id, g) in &c.grids {
        let x = Vector3::from(g.x);
        let p = match g.cp {
            None => x,
            Some(cp) => systems
                .get(cp, &g.line, &format!("GRID {id} CP"))?
                .to_basic(g.x),
        };
        let node = body.mesh.add_node(p);
        body.grid_index.insert(id, node);
        if let Some(cd) = g.cd {
            let frame = systems
                .get(cd, &g.line, &format!("GRID {id} CD"))?
                .axes_at(&p);
            body.mesh.displacement_frames.insert(node, frame);
        }
        body.mesh
            .constraints
            .extend(mask_nodes(g.ps).map(|d| (node, d)));
    }
    shells::add_shells(&c, &systems, &mut body)?;
    add_beams(&c, &mut body)?;
    add_solids(&c, &systems, &mut body)?;
    add_masses(&c, &systems, &mut body)?;
    add_scalars(&c, &mut body)?;
    add_bushes(&c, &systems, &mut body)?;
    add_links(&c, &mut body)?;
    add_supports(&c, spc_selection, &mut body)?;
    check_dependents(&c, &body)?;
    drop_unused_grids(&mut body);
    // One order whatever the cards' order: a body written and read back is the same mesh.
    body.mesh.constraints.sort_unstable();
    body.element_cards = std::mem::take(&mut c.element_lines);
    Ok(body)
}

/// How many dropped GRID ids a note lists.
const LISTED_UNUSED: usize = 10;

/// GRIDs that no element, spring, damper, bush, mass or link references (coordinate-definition
/// grids, leftovers of meshing) get no DOFs: all six are constrained, as Nastran's AUTOSPC
/// constrains them. Their ids go to [`NastranBody::unused_grids`] and a note.
fn drop_unused_grids(body: &mut NastranBody) {
    let mesh = &body.mesh;
    let mut used = vec![false; mesh.nodes.len()];
    let referenced = all_nodes(mesh).flat_map(|(_, _, nodes)| nodes);
    for k in referenced {
        if let Some(u) = used.get_mut(k) {
            *u = true;
        }
    }
    let unused: Vec<(u32, usize)> = body
        .grid_index
        .iter()
        .filter(|(_, &node)| !used[node])
        .map(|(&g, &node)| (g, node))
        .collect();
    if unused.is_empty() {
        return;
    }
    let held: BTreeSet<(usize, usize)> = body.mesh.constraints.iter().copied().collect();
    for &(_, node) in &unused {
        for d in 0..6 {
            if !held.contains(&(node, d)) {
                body.mesh.constraints.push((node, d));
            }
        }
    }
    let listed: Vec<String> = unused
        .iter()
        .take(LISTED_UNUSED)
        .map(|(g, _)| g.to_string())
        .collect();
    body.notes.push(format!(
        "{} GRID(s) not referenced by any element, spring, damper, bush, mass or link were \
         dropped (no DOFs, as Nastran's AUTOSPC): GRID {}{}",
        unused.len(),
        listed.join(", "),
        if unused.len() > LISTED_UNUSED {
            ", …"
        } else {
            ""
        }
    ));
    body.unused_grids = unused.into_iter().map(|(g, _)| g).collect();
}

/// Solids take an isotropic MAT1 (E, G, NU consistent within 1 %, as shells need).
fn add_solids(c: &Cards, systems: &Systems, body: &mut NastranBody) -> Result<(), FeError> {
    let material = |mid: u32, line: &Loc, user: &str| -> Result<Material, FeError> {
        let m = material_named(c, mid, line, user)?;
        let (e, g, nu) = moduli(&m, user)?;
        if (g / (e / (2.0 * (1.0 + nu))) - 1.0).abs() > 0.01 {
            return Err(mesh_error(
                &m.line,
                format!("MAT1 {mid} (used by {user}): G = {g} differs from E / 2(1 + NU) by more than 1 %"),
            ));
        }
        Ok(Material {
            youngs_modulus: e,
            poisson_ratio: nu,
            density: m.rho * c.mass_scale,
        })
    };
    let system = |cid: u32, line: &Loc, user: &str| systems.get(cid, line, user).map(|_| ());
    solids::add_solids(&c.solids, &c.solid_properties, &material, &system, body)
}

fn add_beams(c: &Cards, body: &mut NastranBody) -> Result<(), FeError> {
    for (&id, bar) in &c.bars {
        let user = format!("{} {id}", c.element_lines[&id].1);
        let line = &bar.line;
        let (p, kind) = c.beam_properties.get(&bar.pid).ok_or_else(|| {
            mesh_error(
                line,
                format!("{user}: property PBAR/PBEAM {} not found", bar.pid),
            )
        })?;
        if (c.element_lines[&id].1 == "CBAR") != (*kind == "PBAR") {
            return Err(mesh_error(
                line,
                format!("{user}: property {} is a {kind}", bar.pid),
            ));
        }
        let m = material_named(c, p.mid, &p.line, &format!("{kind} {}", p.id))?;
        let (e, g, _) = moduli(&m, &user)?;
        // The beam takes G through ν = E/2G − 1, so a MAT1 with all three values keeps its G.
        let nu_for_g = e / (2.0 * g) - 1.0;
        if !(nu_for_g > -1.0 && nu_for_g < 0.5) {
            return Err(mesh_error(
                &m.line,
                format!(
                    "MAT1 {} (used by {user}): E/2G − 1 = {nu_for_g} outside (-1, 0.5)",
                    m.id
                ),
            ));
        }
        let a = node_of(body, bar.ga, line, &user)?;
        let b = node_of(body, bar.gb, line, &user)?;
        let (orientation, ends) = beam_geometry(body, bar, a, b, &user)?;
        if ends != BeamEnds::default() {
            body.mesh.beam_ends.insert(body.mesh.beams.len(), ends);
        }
        body.mesh.beams.push(Beam {
            nodes: [a, b],
            material: Material {
                youngs_modulus: e,
                poisson_ratio: nu_for_g,
                density: m.rho * c.mass_scale,
            },
            // Nastran's plane 1 (element x-y) bends about z with I1 and shears along y with K1;
            // plane 2 about y with I2, along z with K2.
            section: BeamSection {
                area: p.a,
                iy: p.i2,
                iz: p.i1,
                j: p.j,
                shear_factor_y: p.k[0],
                shear_factor_z: p.k[1],
            },
            orientation,
            extra_mass_per_length: p.nsm * c.mass_scale,
        });
        body.element_ids.push(Entity::Beam, id);
    }
    Ok(())
}

/// Orientation vector and end conditions of a CBAR/CBEAM in basic, by OFFT: a G vector is in
/// the displacement system (GRID CD) of its grid, B in basic, an O offset in the offset system
/// (x from GA to GB, y in the plane of x and the orientation vector: Nastran's rule).
fn beam_geometry(
    body: &NastranBody,
    bar: &cards::Bar,
    a: usize,
    b: usize,
    user: &str,
) -> Result<(Vector3<f64>, BeamEnds), FeError> {
    let line = &bar.line;
    let frame = |node: usize| {
        body.mesh
            .displacement_frames
            .get(&node)
            .copied()
            .unwrap_or_else(Matrix3::identity)
    };
    let [v_system, a_system, b_system] = bar.offt;
    let orientation = match bar.orientation {
        Orientation::Vector(v) if v_system == cards::VectorSystem::Grid => {
            frame(a) * Vector3::from(v)
        }
        Orientation::Vector(v) => Vector3::from(v),
        Orientation::Node(g0) => {
            body.mesh.nodes[node_of(body, g0, line, &format!("{user} G0"))?] - body.mesh.nodes[a]
        }
    };
    let mut offsets = [Vector3::zeros(); 2];
    for (end, (node, system)) in [(a, a_system), (b, b_system)].into_iter().enumerate() {
        let w = Vector3::from(bar.offsets[end]);
        offsets[end] = match system {
            cards::VectorSystem::Element => {
                let (rows, _) = crate::fe::beam::local_frame(
                    0,
                    &body.mesh.nodes[a],
                    &body.mesh.nodes[b],
                    &orientation,
                )
                .map_err(|e| {
                    mesh_error(
                        line,
                        format!(
                            "{user}: offsets in the element system (OFFT {:?}) need GA and GB \
                             apart and an orientation vector off the line GA-GB: {e}",
                            bar.offt
                        ),
                    )
                })?;
                rows.transpose() * w
            }
            _ => frame(node) * w,
        };
    }
    Ok((
        orientation,
        BeamEnds {
            offsets,
            pins: bar.pins,
        },
    ))
}

fn add_masses(c: &Cards, systems: &Systems, body: &mut NastranBody) -> Result<(), FeError> {
    for (&id, m) in &c.masses {
        let user = format!("CONM2 {id}");
        let node = node_of(body, m.grid, &m.line, &user)?;
        let [i11, i21, i22, i31, i32, i33] = m.inertia;
        // Nastran enters the products of inertia as I21 = ∫ x1 x2 dm etc. and supplies the
        // minus signs itself (MSC/NX QRG, CONM2 remark): the tensor is
        // [I11 −I21 −I31; −I21 I22 −I32; −I31 −I32 I33].
        let local = Matrix3::new(i11, -i21, -i31, -i21, i22, -i32, -i31, -i32, i33);
        let (offset, inertia) = match m.cid {
            -1 => (Vector3::from(m.x) - body.mesh.nodes[node], local),
            0 => (Vector3::from(m.x), local),
            cid => {
                let (_, r) = systems.rectangular(cid as u32, &m.line, &user)?;
                (r * Vector3::from(m.x), r * local * r.transpose())
            }
        };
        place_mass(body, id, node, m.mass, offset, inertia, c.mass_scale);
    }
    for (&id, m) in &c.general_masses {
        let user = format!("CONM1 {id}");
        let node = node_of(body, m.grid, &m.line, &user)?;
        let mut local = nalgebra::Matrix6::<f64>::zeros();
        for i in 0..6 {
            for j in 0..6 {
                local[(i, j)] = m.matrix[i][j];
            }
        }
        let basic = match m.cid {
            None => local,
            Some(cid) => {
                let (_, r) = systems.rectangular(cid, &m.line, &user)?;
                let mut t = nalgebra::Matrix6::<f64>::zeros();
                t.fixed_view_mut::<3, 3>(0, 0).copy_from(&r);
                t.fixed_view_mut::<3, 3>(3, 3).copy_from(&r);
                t * local * t.transpose()
            }
        };
        let (mass, offset, inertia) = rigid_body_form(&basic).map_err(|why| {
            mesh_error(
                &m.line,
                format!(
                    "{user}: {why}; only the mass matrix of a rigid body is supported (M11 = M22 \
                     = M33 = m, no coupling between translations, translation-rotation block \
                     m[r]× for a centre of gravity at r)"
                ),
            )
        })?;
        place_mass(body, id, node, mass, offset, inertia, c.mass_scale);
    }
    Ok(())
}

/// Mass m, centre-of-gravity offset r and inertia about the centre of gravity of a 6 × 6 mass
/// matrix at a node, which must be the matrix of a rigid body: m I for translations, m [r]×
/// between rotations and translations (from u(r) = u + θ × r), J + m (|r|² I − r rᵀ) for
/// rotations.
fn rigid_body_form(
    m6: &nalgebra::Matrix6<f64>,
) -> Result<(f64, Vector3<f64>, Matrix3<f64>), String> {
    let tol = 1e-9 * m6.abs().max();
    if (m6 - m6.transpose()).abs().max() > tol || m6.iter().any(|v| !v.is_finite()) {
        return Err("the matrix is not symmetric and finite".into());
    }
    let m = m6[(0, 0)];
    let tt: Matrix3<f64> = m6.fixed_view::<3, 3>(0, 0).into();
    if (tt - Matrix3::identity() * m).abs().max() > tol {
        return Err(format!(
            "the translational block is not m I (M11 = {m}, M22 = {}, M33 = {}, M21 = {}, \
             M31 = {}, M32 = {})",
            tt[(1, 1)],
            tt[(2, 2)],
            tt[(1, 0)],
            tt[(2, 0)],
            tt[(2, 1)]
        ));
    }
    let coupling: Matrix3<f64> = m6.fixed_view::<3, 3>(3, 0).into();
    let r = if m > 0.0 {
        Vector3::new(coupling[(2, 1)], coupling[(0, 2)], coupling[(1, 0)]) / m
    } else {
        Vector3::zeros()
    };
    if (coupling - r.cross_matrix() * m).abs().max() > tol {
        return Err(format!(
            "the rotation-translation block (M41 … M63) {:?} is not m [r]× for any r",
            coupling.as_slice()
        ));
    }
    let rot: Matrix3<f64> = m6.fixed_view::<3, 3>(3, 3).into();
    let inertia = rot - m * (r.norm_squared() * Matrix3::identity() - r * r.transpose());
    Ok((m, r, inertia))
}

/// Puts a mass with inertia about its centre of gravity at `offset` from `node`.
fn place_mass(
    body: &mut NastranBody,
    id: u32,
    node: usize,
    mass: f64,
    offset: Vector3<f64>,
    inertia: Matrix3<f64>,
    scale: f64,
) {
    let mass_node = if offset.norm() == 0.0 {
        node
    } else {
        // The offset mass sits on its own node carried rigidly by the grid: exact coupling
        // of translation and rotation, no lumping approximation.
        let cg = body.mesh.add_node(body.mesh.nodes[node] + offset);
        body.mesh.rigid_links.push(RigidLink {
            independent: node,
            dependent: vec![cg],
            components: [true; 6],
        });
        body.element_ids.push(Entity::RigidLink, id);
        cg
    };
    body.mesh.masses.push(PointMass {
        node: mass_node,
        mass: mass * scale,
        inertia: inertia * scale,
    });
    body.element_ids.push(Entity::Mass, id);
}

fn add_bushes(c: &Cards, systems: &Systems, body: &mut NastranBody) -> Result<(), FeError> {
    for (&id, e) in &c.bushes {
        let user = format!("CBUSH {id}");
        let line = &e.line;
        let p = c.bush_properties.get(&e.pid).ok_or_else(|| {
            mesh_error(line, format!("{user}: property PBUSH {} not found", e.pid))
        })?;
        let a = node_of(body, e.ga, line, &user)?;
        let b = match e.gb {
            Some(g) => Some(node_of(body, g, line, &format!("{user} GB"))?),
            None => None,
        };
        let xa = body.mesh.nodes[a];
        let along = b.map_or_else(Vector3::zeros, |b| body.mesh.nodes[b] - xa);
        let frame = match e.axes {
            cards::BushAxes::System(0) => Matrix3::identity(),
            cards::BushAxes::System(cid) => systems.rectangular(cid, line, &user)?.1,
            // Coincident ends (or ground) and no CID: the element axes are basic.
            cards::BushAxes::Line(_) if along.norm() == 0.0 => Matrix3::identity(),
            cards::BushAxes::Line(None) => {
                return Err(mesh_error(
                    line,
                    format!(
                        "{user}: GA and GB are apart, so the element axes need an orientation \
                         vector X1..X3, a grid GO or a CID"
                    ),
                ))
            }
            cards::BushAxes::Line(Some(o)) => {
                let v = match o {
                    // X1..X3 are components in GA's displacement system (GRID CD).
                    Orientation::Vector(v) => body
                        .mesh
                        .displacement_frames
                        .get(&a)
                        .map_or(Vector3::from(v), |r| r * Vector3::from(v)),
                    Orientation::Node(g0) => {
                        body.mesh.nodes[node_of(body, g0, line, &format!("{user} GO"))?] - xa
                    }
                };
                let ex = along.normalize();
                let y = v - ex * ex.dot(&v);
                if !(y.norm() > 1e-9 * v.norm() && y.norm().is_finite()) {
                    return Err(mesh_error(
                        line,
                        format!("{user}: the orientation vector is parallel to GA-GB"),
                    ));
                }
                let ey = y.normalize();
                Matrix3::from_columns(&[ex, ey, ex.cross(&ey)])
            }
        };
        body.mesh.bushes.push(Bush {
            a,
            b,
            frame,
            point: xa + along * e.s,
            stiffness: p.k,
            damping: p.b,
        });
        body.element_ids.push(Entity::Bush, id);
    }
    Ok(())
}

/// Long on purpose: one arm per scalar spring and damper card.
fn add_scalars(c: &Cards, body: &mut NastranBody) -> Result<(), FeError> {
    // Per node (ground) or node pair: (stiffness, damping) per DOF, summed over cards.
    let mut ground: BTreeMap<usize, ([f64; 6], [f64; 6])> = BTreeMap::new();
    let mut pairs: BTreeMap<(usize, usize), ([f64; 6], [f64; 6])> = BTreeMap::new();
    for (is_damper, list) in [(false, &c.springs), (true, &c.dampers)] {
        for (&id, s) in list {
            let user = format!("{} {id}", c.element_lines[&id].1);
            let value = match s.value {
                ScalarValue::Value(v) => v,
                ScalarValue::Property(pid) => {
                    let table = if is_damper {
                        &c.damper_properties
                    } else {
                        &c.spring_properties
                    };
                    table.get(&pid).map(|(v, _)| *v).ok_or_else(|| {
                        mesh_error(
                            &s.line,
                            format!(
                                "{user}: property {} {pid} not found",
                                if is_damper { "PDAMP" } else { "PELAS" }
                            ),
                        )
                    })?
                }
            };
            let slot = usize::from(is_damper);
            match s.ends.as_slice() {
                [(g, comp)] => {
                    let n = node_of(body, *g, &s.line, &user)?;
                    let e = ground.entry(n).or_insert(([0.0; 6], [0.0; 6]));
                    [&mut e.0, &mut e.1][slot][*comp] += value;
                }
                [(g1, c1), (g2, c2)] => {
                    if c1 != c2 {
                        return Err(mesh_error(
                            &s.line,
                            format!(
                                "{user}: components C1 = {} and C2 = {} differ; only springs \
                                 and dampers acting along one direction are supported",
                                c1 + 1,
                                c2 + 1
                            ),
                        ));
                    }
                    let (n1, n2) = (
                        node_of(body, *g1, &s.line, &user)?,
                        node_of(body, *g2, &s.line, &user)?,
                    );
                    if n1 == n2 {
                        return Err(mesh_error(
                            &s.line,
                            format!("{user}: both ends on GRID {g1}"),
                        ));
                    }
                    let e = pairs
                        .entry((n1.min(n2), n1.max(n2)))
                        .or_insert(([0.0; 6], [0.0; 6]));
                    [&mut e.0, &mut e.1][slot][*c1] += value;
                }
                _ => {
                    return Err(mesh_error(
                        &s.line,
                        format!("{user}: needs one or two grids"),
                    ))
                }
            }
        }
    }
    for (node, (stiffness, damping)) in ground {
        body.mesh.ground_springs.push(GroundSpring {
            node,
            stiffness,
            damping,
        });
    }
    for ((a, b), (stiffness, damping)) in pairs {
        body.mesh.springs.push(Spring {
            nodes: [a, b],
            stiffness,
            damping,
        });
    }
    Ok(())
}

fn add_links(c: &Cards, body: &mut NastranBody) -> Result<(), FeError> {
    for (&id, e) in &c.rigid {
        let user = format!("RBE2 {id}");
        let independent = node_of(body, e.independent, &e.line, &user)?;
        let dependent = e
            .dependent
            .iter()
            .map(|&g| node_of(body, g, &e.line, &user))
            .collect::<Result<Vec<_>, _>>()?;
        body.mesh.rigid_links.push(RigidLink {
            independent,
            dependent,
            components: e.components,
        });
        body.element_ids.push(Entity::RigidLink, id);
    }
    for (&id, e) in &c.interpolation {
        let user = format!("RBE3 {id}");
        let reference = node_of(body, e.reference, &e.line, &user)?;
        let mut sources = Vec::new();
        for (weight, components, grids) in &e.groups {
            if weight.is_nan() || *weight <= 0.0 {
                return Err(mesh_error(
                    &e.line,
                    format!("{user}: weight {weight} must be > 0"),
                ));
            }
            sources.push(InterpolationSource {
                nodes: grids
                    .iter()
                    .map(|&g| node_of(body, g, &e.line, &user))
                    .collect::<Result<Vec<_>, _>>()?,
                weight: *weight,
                components: *components,
            });
        }
        body.mesh.interpolation_links.push(InterpolationLink {
            reference,
            reference_components: e.reference_components,
            sources,
        });
        body.element_ids.push(Entity::InterpolationLink, id);
    }
    Ok(())
}

/// A DOF may be dependent in one RBE only and not also supported (Nastran's rule; assembly
/// enforces it too, but here the message can name the cards).
fn check_dependents(c: &Cards, body: &NastranBody) -> Result<(), FeError> {
    let names = ["1", "2", "3", "4", "5", "6"];
    let mut owner: BTreeMap<(u32, usize), (String, &Loc)> = BTreeMap::new();
    let dependents = c
        .rigid
        .iter()
        .flat_map(|(id, e)| {
            e.dependent.iter().flat_map(move |&g| {
                mask_nodes(e.components).map(move |d| (g, d, format!("RBE2 {id}"), &e.line))
            })
        })
        .chain(c.interpolation.iter().flat_map(|(id, e)| {
            mask_nodes(e.reference_components)
                .map(move |d| (e.reference, d, format!("RBE3 {id}"), &e.line))
        }));
    for (grid, d, card, line) in dependents {
        if let Some((first, _)) = owner.get(&(grid, d)) {
            return Err(mesh_error(
                line,
                format!(
                    "GRID {grid} component {} is dependent in both {first} and {card}",
                    names[d]
                ),
            ));
        }
        owner.insert((grid, d), (card, line));
    }
    let grid_of: BTreeMap<usize, u32> = body.grid_index.iter().map(|(g, n)| (*n, *g)).collect();
    for &(node, d) in &body.mesh.constraints {
        let Some(grid) = grid_of.get(&node) else {
            continue;
        };
        if let Some((card, line)) = owner.get(&(*grid, d)) {
            return Err(mesh_error(
                *line,
                format!(
                    "GRID {grid} component {} is dependent in {card} and also constrained \
                     (SPC or GRID PS); constrain the independent grid instead",
                    names[d]
                ),
            ));
        }
    }
    Ok(())
}

fn add_supports(c: &Cards, selected: Option<u32>, body: &mut NastranBody) -> Result<(), FeError> {
    let sets: BTreeSet<u32> = c.supports.iter().map(|s| s.0 .0).collect();
    let set = match (selected, sets.len()) {
        (Some(s), _) => {
            if !sets.is_empty() && !sets.contains(&s) {
                return Err(FeError::InvalidInput(format!(
                    "Nastran case control selects SPC = {s}, but the bulk data defines SPC sets {sets:?}"
                )));
            }
            Some(s)
        }
        (None, 0) => None,
        (None, 1) => sets.first().copied(),
        (None, _) => {
            return Err(FeError::InvalidInput(format!(
                "the bulk data defines several SPC sets {sets:?} and no case control selects one \
                 (add 'SPC = <id>' before BEGIN BULK)"
            )))
        }
    };
    body.spc_set = set;
    let mut seen = BTreeSet::new();
    for ((sid, grids, mask), line) in &c.supports {
        let (sid, grids, mask) = (*sid, *grids, *mask);
        if Some(sid) != set {
            continue;
        }
        let nodes: Vec<usize> = match grids {
            cards::Grids::One(grid) => vec![node_of(body, grid, line, &format!("SPC set {sid}"))?],
            cards::Grids::Range(from, to) => {
                body.grid_index.range(from..=to).map(|(_, &n)| n).collect()
            }
        };
        for node in nodes {
            for d in mask_nodes(mask) {
                if seen.insert((node, d)) {
                    body.mesh.constraints.push((node, d));
                }
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every listed card reaches an arm of the dispatch (a card with blank fields fails in its
    /// own parser, never as unsupported), and any other name is refused listing them all.
    #[test]
    fn the_supported_card_table_is_the_dispatch() {
        for card in card_table::supported_cards() {
            let mut collector = Collector::new();
            let raw = crate::nastran::lex(&format!("{card},1\n"))
                .unwrap()
                .cards
                .remove(0);
            if let Err(e) = collector.card(raw) {
                assert!(
                    !e.to_string().contains("is not supported (supported"),
                    "{card}: {e}"
                );
            }
        }
        let raw = crate::nastran::lex("CTRIA6,1\n").unwrap().cards.remove(0);
        let err = Collector::new().card(raw).err().unwrap().to_string();
        assert!(err.contains(&card_table::supported_list()), "{err}");
    }

    /// The cards the table lists as refused are refused by the dispatch, as unsupported.
    #[test]
    fn the_cards_listed_as_refused_are_refused() {
        for (cards, _) in card_table::REFUSED_CARDS {
            for card in cards.split(", ") {
                let raw = crate::nastran::lex(&format!("{card},1\n"))
                    .unwrap()
                    .cards
                    .remove(0);
                let err = Collector::new().card(raw).err().unwrap().to_string();
                assert!(
                    err.contains(&format!("card {card} is not supported")),
                    "{card}: {err}"
                );
            }
        }
    }
}
