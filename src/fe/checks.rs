//! Mesh checks: degenerate or warped elements, unconnected nodes, DOFs without mass or stiffness.
//! Every problem found is named and all are reported together. Names come from a [`Naming`]:
//! [`MeshIndices`] names the mesh's own indices (`node 14`, `shell 3`), a body read from a
//! Nastran deck names its GRID and element ids ([`crate::nastran::DeckNames`]).
//!
//! Connectivity rule: a node is *connected* when any element, point mass, scalar spring or
//! damper, bush or rigid/interpolation link references it; it is *held* when an element with
//! stiffness does (beam, shell, triangle, solid, scalar spring, bush, link). A connected node
//! that is not held (only a point mass) is refused; a node held only by springs or bushes is
//! accepted, and a DOF the springs leave without stiffness shows up in [`check_assembled`] or
//! as a singular interior in the reduction. A part that shares no element with the largest one
//! is refused unless ground holds it (a spring or bush to ground, an SPC).

use nalgebra::Vector3;

use super::assembly::Assembled;
use super::error::FeError;
use super::mesh::Mesh;
use super::{shell, shell3};

/// Which kind of mesh entity a message names.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Entity {
    /// `mesh.beams[i]`.
    Beam,
    /// `mesh.shells[i]`.
    Shell,
    /// `mesh.triangles[i]`.
    Triangle,
    /// `mesh.solids[i]`.
    Solid,
    /// `mesh.masses[i]`.
    Mass,
    /// `mesh.ground_springs[i]`.
    GroundSpring,
    /// `mesh.springs[i]`.
    Spring,
    /// `mesh.bushes[i]`.
    Bush,
    /// `mesh.rigid_links[i]`.
    RigidLink,
    /// `mesh.interpolation_links[i]`.
    InterpolationLink,
}

impl Entity {
    /// The entity's name in a mesh built in code (`shell`, `ground spring`, …).
    pub fn mesh_name(self) -> &'static str {
        match self {
            Entity::Beam => "beam",
            Entity::Shell => "shell",
            Entity::Triangle => "triangle",
            Entity::Solid => "solid",
            Entity::Mass => "point mass",
            Entity::GroundSpring => "ground spring",
            Entity::Spring => "spring",
            Entity::Bush => "bush",
            Entity::RigidLink => "rigid link",
            Entity::InterpolationLink => "interpolation link",
        }
    }
}

/// How check messages name nodes and elements: the user must find them in their own model.
pub trait Naming {
    /// Name of node `node` (a mesh index), e.g. `node 14` or `GRID 5000`.
    fn node(&self, node: usize) -> String;
    /// Name of entity `index` of `kind`, e.g. `shell 3` or `CQUAD4 1234 (line 12 of b.bdf)`.
    fn entity(&self, kind: Entity, index: usize) -> String;
}

/// Names by mesh index: for meshes built in code (the procedural body).
#[derive(Debug, Clone, Copy, Default)]
pub struct MeshIndices;

impl Naming for MeshIndices {
    fn node(&self, node: usize) -> String {
        format!("node {node}")
    }

    fn entity(&self, kind: Entity, index: usize) -> String {
        format!("{} {index}", kind.mesh_name())
    }
}

/// What to do with elements whose shape is poor but whose matrices are still valid (warp,
/// taper, skew, Jacobian ratio beyond the limits).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PoorShape {
    /// Refuse the mesh (a mesh built in code must be good).
    Refuse,
    /// Accept and report counted warnings, as Nastran's GEOMCHECK does by default.
    Warn,
}

/// Limits of the geometric checks.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CheckLimits {
    /// Largest corner offset from the mean plane / √area of a shell.
    pub max_warp: f64,
    /// Smallest ratio of corner Jacobians of a shell (1 = parallelogram, ≤ 0 = inverted).
    pub min_jacobian_ratio: f64,
    /// Largest taper of a CQUAD4: 1 − 2·(smallest corner triangle area)/(element area)
    /// (0 for a parallelogram, 1 when a corner collapses); `None`: not checked.
    pub max_taper: Option<f64>,
    /// Smallest angle (degrees) between the lines joining the midpoints of opposite sides of
    /// a CQUAD4 (90 for a rectangle); `None`: not checked.
    pub min_skew_angle_deg: Option<f64>,
    /// Smallest beam length (m).
    pub min_beam_length: f64,
    /// Smallest shell area (m²).
    pub min_shell_area: f64,
    /// Accept structures made of several parts that share no element.
    pub allow_disconnected_parts: bool,
    /// Poorly shaped but valid elements: refused or reported.
    pub poor_shape: PoorShape,
}

impl Default for CheckLimits {
    fn default() -> Self {
        Self {
            max_warp: 0.01,
            min_jacobian_ratio: 0.2,
            max_taper: None,
            min_skew_angle_deg: None,
            min_beam_length: 1e-6,
            min_shell_area: 1e-10,
            allow_disconnected_parts: false,
            poor_shape: PoorShape::Refuse,
        }
    }
}

impl CheckLimits {
    /// Limits for a body read from a user's Nastran deck: what makes an element's matrices
    /// wrong (zero or negative Jacobian or area, coincident corners, non-finite coordinates)
    /// is refused; poor shapes are warnings at Nastran's GEOMCHECK defaults (Q4_WARP 0.05,
    /// Q4_TAPER 0.5, Q4_SKEW 30°) and a corner Jacobian ratio below 0.2.
    pub fn nastran_deck() -> Self {
        Self {
            max_warp: 0.05,
            min_jacobian_ratio: 0.2,
            max_taper: Some(0.5),
            min_skew_angle_deg: Some(30.0),
            poor_shape: PoorShape::Warn,
            ..Self::default()
        }
    }
}

const MAX_LISTED: usize = 20;

fn report(problems: Vec<String>) -> Result<(), FeError> {
    if problems.is_empty() {
        return Ok(());
    }
    let n = problems.len();
    let mut text: Vec<String> = problems.into_iter().take(MAX_LISTED).collect();
    if n > MAX_LISTED {
        text.push(format!("... and {} more", n - MAX_LISTED));
    }
    Err(FeError::Mesh(format!(
        "{n} problem(s): {}",
        text.join("; ")
    )))
}

/// Count and worst case of one shape test that failed its limit.
struct Tally {
    what: &'static str,
    limit: String,
    count: usize,
    worst: Option<(f64, String)>,
    /// Whether a larger value is worse.
    larger_is_worse: bool,
}

impl Tally {
    fn new(what: &'static str, limit: String, larger_is_worse: bool) -> Self {
        Self {
            what,
            limit,
            count: 0,
            worst: None,
            larger_is_worse,
        }
    }

    fn add(&mut self, value: f64, name: impl FnOnce() -> String) {
        self.count += 1;
        let worse = match &self.worst {
            None => true,
            Some((w, _)) => (value > *w) == self.larger_is_worse && value != *w,
        };
        if worse {
            self.worst = Some((value, name()));
        }
    }

    fn note(&self) -> Option<String> {
        let (value, name) = self.worst.as_ref()?;
        Some(format!(
            "{} element(s) {} ({}; worst {name}: {value:.4})",
            self.count, self.what, self.limit
        ))
    }
}

/// The poor-shape tests of a shell, each failing one counted or refused per the policy.
struct ShapeTallies {
    warp: Tally,
    jacobian: Tally,
    taper: Tally,
    skew: Tally,
}

impl ShapeTallies {
    fn new(limits: &CheckLimits) -> Self {
        Self {
            warp: Tally::new("warped", format!("warp > {}", limits.max_warp), true),
            jacobian: Tally::new(
                "distorted",
                format!("corner Jacobian ratio < {}", limits.min_jacobian_ratio),
                false,
            ),
            taper: Tally::new(
                "tapered",
                format!("taper > {}", limits.max_taper.unwrap_or(f64::INFINITY)),
                true,
            ),
            skew: Tally::new(
                "skewed",
                format!("skew angle < {}°", limits.min_skew_angle_deg.unwrap_or(0.0)),
                false,
            ),
        }
    }

    fn notes(&self) -> Vec<String> {
        [&self.warp, &self.jacobian, &self.taper, &self.skew]
            .into_iter()
            .filter_map(Tally::note)
            .map(|n| format!("element shape (warning, as Nastran's GEOMCHECK): {n}"))
            .collect()
    }
}

/// Taper (1 − 2·smallest corner triangle / area) and skew angle (degrees, between the lines
/// joining midpoints of opposite sides) of a quadrilateral.
fn taper_and_skew(p: &[Vector3<f64>; 4]) -> (f64, f64) {
    let area = 0.5 * (p[2] - p[0]).cross(&(p[3] - p[1])).norm();
    let corner = |i: usize| {
        let (a, b, c) = (p[(i + 3) % 4], p[i], p[(i + 1) % 4]);
        0.5 * (a - b).cross(&(c - b)).norm()
    };
    let smallest = (0..4).map(corner).fold(f64::INFINITY, f64::min);
    let taper = 1.0 - 2.0 * smallest / area;
    let m = |i: usize| (p[i] + p[(i + 1) % 4]) / 2.0;
    let (u, v) = (m(2) - m(0), m(3) - m(1));
    let cos = (u.dot(&v) / (u.norm() * v.norm())).abs().min(1.0);
    (taper, cos.acos().to_degrees())
}

fn node(mesh: &Mesh, id: usize) -> Option<Vector3<f64>> {
    mesh.nodes.get(id).copied()
}

/// Geometric and topological checks of `mesh` before assembly, named by mesh index; poor
/// shapes are refused or (with [`PoorShape::Warn`]) dropped: [`check_mesh_named`] returns them.
pub fn check_mesh(mesh: &Mesh, limits: &CheckLimits) -> Result<(), FeError> {
    check_mesh_named(mesh, limits, &MeshIndices).map(|_| ())
}

/// Geometric and topological checks of `mesh` before assembly, every node and element named
/// by `names`. Returns the warnings (counted poor shapes under [`PoorShape::Warn`], one line
/// per test with the worst element); refuses what makes the model wrong.
///
/// Long on purpose: one list of short checks per entity kind that share the node lookup and the limits; read as a table.
pub fn check_mesh_named(
    mesh: &Mesh,
    limits: &CheckLimits,
    names: &dyn Naming,
) -> Result<Vec<String>, FeError> {
    let mut problems = Vec::new();
    let mut tallies = ShapeTallies::new(limits);
    let refuse = limits.poor_shape == PoorShape::Refuse;
    let n = mesh.nodes.len();
    let mut connected = vec![false; n];
    let mut has_stiffness = vec![false; n];
    for (i, p) in mesh.nodes.iter().enumerate() {
        if p.iter().any(|c| !c.is_finite()) {
            problems.push(format!("{}: non-finite coordinates", names.node(i)));
        }
    }
    let missing = |kind: Entity, i: usize, nodes: &[usize]| {
        format!(
            "{}: node index {:?} does not exist",
            names.entity(kind, i),
            nodes.iter().filter(|&&k| k >= n).collect::<Vec<_>>()
        )
    };
    for (i, b) in mesh.beams.iter().enumerate() {
        let (Some(p1), Some(p2)) = (node(mesh, b.nodes[0]), node(mesh, b.nodes[1])) else {
            problems.push(missing(Entity::Beam, i, &b.nodes));
            continue;
        };
        // With offsets the element runs between the offset ends, not the nodes.
        let w = mesh
            .beam_ends
            .get(&i)
            .map_or([Vector3::zeros(); 2], |e| e.offsets);
        let (p1, p2) = (p1 + w[0], p2 + w[1]);
        if b.nodes[0] == b.nodes[1] || (p2 - p1).norm() < limits.min_beam_length {
            problems.push(format!(
                "{}: degenerate (length {:.3e} m)",
                names.entity(Entity::Beam, i),
                (p2 - p1).norm()
            ));
        } else if (p2 - p1).normalize().cross(&b.orientation).norm()
            < 1e-6 * b.orientation.norm().max(1e-300)
        {
            problems.push(format!(
                "{}: orientation vector parallel to the axis or zero",
                names.entity(Entity::Beam, i)
            ));
        }
        for &k in &b.nodes {
            connected[k] = true;
            has_stiffness[k] = true;
        }
    }
    for (i, s) in mesh.shells.iter().enumerate() {
        let name = || names.entity(Entity::Shell, i);
        let pts: Option<Vec<Vector3<f64>>> = s.nodes.iter().map(|&k| node(mesh, k)).collect();
        let Some(pts) = pts else {
            problems.push(missing(Entity::Shell, i, &s.nodes));
            continue;
        };
        let mut distinct = s.nodes.to_vec();
        distinct.sort_unstable();
        distinct.dedup();
        if distinct.len() < 4 {
            let grids: Vec<String> = s.nodes.iter().map(|&k| names.node(k)).collect();
            problems.push(format!(
                "{}: repeated node in [{}]",
                name(),
                grids.join(", ")
            ));
            continue;
        }
        let corners = [pts[0], pts[1], pts[2], pts[3]];
        match shell::geometry(i, &corners) {
            Err(e) => problems.push(format!(
                "{}: {}",
                name(),
                strip_index(&e, &format!("shell {i}: "))
            )),
            Ok(g) => {
                if g.area < limits.min_shell_area {
                    problems.push(format!("{}: degenerate (area {:.3e} m²)", name(), g.area));
                } else if g.jacobian_ratio <= 0.0 {
                    problems.push(format!(
                        "{}: inverted or degenerate (corner Jacobian ratio {:.3} ≤ 0: a corner \
                         angle of 180° or more; check the corner order)",
                        name(),
                        g.jacobian_ratio
                    ));
                } else if refuse {
                    if g.warp > limits.max_warp {
                        problems.push(format!(
                            "{}: warped (warp ratio {:.4} > {})",
                            name(),
                            g.warp,
                            limits.max_warp
                        ));
                    }
                    if g.jacobian_ratio < limits.min_jacobian_ratio {
                        problems.push(format!(
                            "{}: distorted or inverted (Jacobian ratio {:.3} < {})",
                            name(),
                            g.jacobian_ratio,
                            limits.min_jacobian_ratio
                        ));
                    }
                } else {
                    if g.warp > limits.max_warp {
                        tallies.warp.add(g.warp, name);
                    }
                    if g.jacobian_ratio < limits.min_jacobian_ratio {
                        tallies.jacobian.add(g.jacobian_ratio, name);
                    }
                    let (taper, skew) = taper_and_skew(&corners);
                    if limits.max_taper.is_some_and(|t| taper > t) {
                        tallies.taper.add(taper, name);
                    }
                    if limits.min_skew_angle_deg.is_some_and(|s| skew < s) {
                        tallies.skew.add(skew, name);
                    }
                }
            }
        }
        for &k in &s.nodes {
            connected[k] = true;
            has_stiffness[k] = true;
        }
    }
    for (i, t) in mesh.triangles.iter().enumerate() {
        let pts: Option<Vec<Vector3<f64>>> = t.nodes.iter().map(|&k| node(mesh, k)).collect();
        let Some(pts) = pts else {
            problems.push(missing(Entity::Triangle, i, &t.nodes));
            continue;
        };
        let name = names.entity(Entity::Triangle, i);
        match shell3::geometry(i, &[pts[0], pts[1], pts[2]]) {
            Err(e) => problems.push(format!(
                "{name}: {}",
                strip_index(&e, &format!("triangle {i}: "))
            )),
            Ok(g) if g.area < limits.min_shell_area => {
                problems.push(format!("{name}: degenerate (area {:.3e} m²)", g.area))
            }
            Ok(_) => {}
        }
        for &k in &t.nodes {
            connected[k] = true;
            has_stiffness[k] = true;
        }
    }
    for (i, s) in mesh.solids.iter().enumerate() {
        let pts: Option<Vec<Vector3<f64>>> = s.nodes.iter().map(|&k| node(mesh, k)).collect();
        let Some(pts) = pts else {
            problems.push(missing(Entity::Solid, i, &s.nodes));
            continue;
        };
        if let Err(why) = super::solid::check_geometry(&pts) {
            problems.push(format!("{}: {why}", names.entity(Entity::Solid, i)));
        }
        for &k in &s.nodes {
            connected[k] = true;
            has_stiffness[k] = true;
        }
    }
    for (i, m) in mesh.masses.iter().enumerate() {
        match connected.get_mut(m.node) {
            Some(c) => *c = true,
            None => problems.push(missing(Entity::Mass, i, &[m.node])),
        }
    }
    // Springs, dampers and bushes hold their nodes (a wheel-centre grid on a CBUSH, a CELAS2
    // to ground): whether every DOF gets stiffness is for `check_assembled`.
    let spring_like = mesh
        .ground_springs
        .iter()
        .enumerate()
        .map(|(i, s)| (Entity::GroundSpring, i, vec![s.node]))
        .chain(
            mesh.springs
                .iter()
                .enumerate()
                .map(|(i, s)| (Entity::Spring, i, s.nodes.to_vec())),
        )
        .chain(
            mesh.bushes
                .iter()
                .enumerate()
                .map(|(i, b)| (Entity::Bush, i, std::iter::once(b.a).chain(b.b).collect())),
        )
        .chain(link_node_sets(mesh));
    // A node tied by a rigid or interpolation link is held by the link (or holds it); a link
    // on a node without any real stiffness shows up as a singular DOF in `check_assembled`.
    for (kind, i, nodes) in spring_like {
        if nodes.iter().any(|&k| k >= n) {
            problems.push(missing(kind, i, &nodes));
            continue;
        }
        for k in nodes {
            connected[k] = true;
            has_stiffness[k] = true;
        }
    }
    let mut constrained_count = vec![0usize; n];
    let mut seen = std::collections::HashSet::new();
    for &(k, d) in &mesh.constraints {
        if k < n && d < 6 && seen.insert((k, d)) {
            constrained_count[k] += 1;
        }
    }
    let fully_constrained = |k: usize| constrained_count[k] == 6;
    for k in 0..n {
        if !connected[k] && !fully_constrained(k) {
            problems.push(format!("{}: not connected to any element", names.node(k)));
        } else if connected[k] && !has_stiffness[k] && !fully_constrained(k) {
            problems.push(format!(
                "{}: carries only point masses, no element, spring, bush or link with stiffness",
                names.node(k)
            ));
        }
    }
    if !limits.allow_disconnected_parts {
        problems.extend(disconnected_parts(
            mesh,
            &connected,
            &fully_constrained,
            names,
        ));
    }
    for (name, &k) in &mesh.named_nodes {
        if k >= n {
            problems.push(format!(
                "named node '{name}': node index {k} does not exist"
            ));
        }
    }
    report(problems)?;
    Ok(tallies.notes())
}

/// `message` without the index prefix the element code puts in front (the caller names the
/// element itself).
fn strip_index(e: &FeError, prefix: &str) -> String {
    let (FeError::Mesh(m) | FeError::InvalidInput(m) | FeError::Numerical(m) | FeError::Io(m)) = e;
    m.strip_prefix(prefix).unwrap_or(m).to_string()
}

/// The nodes of every rigid and interpolation link.
fn link_node_sets(mesh: &Mesh) -> impl Iterator<Item = (Entity, usize, Vec<usize>)> + '_ {
    let rigid = mesh.rigid_links.iter().enumerate().map(|(i, l)| {
        let mut nodes = vec![l.independent];
        nodes.extend(&l.dependent);
        (Entity::RigidLink, i, nodes)
    });
    let interpolation = mesh.interpolation_links.iter().enumerate().map(|(i, l)| {
        let mut nodes = vec![l.reference];
        nodes.extend(l.sources.iter().flat_map(|s| s.nodes.iter().copied()));
        (Entity::InterpolationLink, i, nodes)
    });
    rigid.chain(interpolation)
}

fn find(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

/// Parts of the structure (connected through elements, two-node springs, bushes and links)
/// other than the largest one and not held by ground (a spring or bush to ground, a
/// constrained DOF), each described by its size and first node.
fn disconnected_parts(
    mesh: &Mesh,
    connected: &[bool],
    fully_constrained: &dyn Fn(usize) -> bool,
    names: &dyn Naming,
) -> Vec<String> {
    let n = mesh.nodes.len();
    let mut parent: Vec<usize> = (0..n).collect();
    let mut join = |a: usize, b: usize| {
        if a < n && b < n {
            let (ra, rb) = (find(&mut parent, a), find(&mut parent, b));
            parent[ra] = rb;
        }
    };
    let links = mesh
        .beams
        .iter()
        .map(|b| b.nodes.to_vec())
        .chain(mesh.shells.iter().map(|s| s.nodes.to_vec()))
        .chain(mesh.triangles.iter().map(|t| t.nodes.to_vec()))
        .chain(mesh.solids.iter().map(|s| s.nodes.clone()))
        .chain(mesh.springs.iter().map(|s| s.nodes.to_vec()))
        .chain(
            mesh.bushes
                .iter()
                .map(|b| std::iter::once(b.a).chain(b.b).collect()),
        )
        .chain(link_node_sets(mesh).map(|(_, _, nodes)| nodes));
    for nodes in links {
        for w in nodes.windows(2) {
            join(w[0], w[1]);
        }
    }
    let mut parts: std::collections::BTreeMap<usize, Vec<usize>> = Default::default();
    for (k, &is_connected) in connected.iter().enumerate() {
        if is_connected && !fully_constrained(k) {
            let root = find(&mut parent, k);
            parts.entry(root).or_default().push(k);
        }
    }
    // Ground holds a part too: a spring or bush to ground, or a constrained DOF.
    let mut grounded = vec![false; n];
    let ground_ends = mesh
        .ground_springs
        .iter()
        .map(|s| s.node)
        .chain(mesh.bushes.iter().filter(|b| b.b.is_none()).map(|b| b.a))
        .chain(mesh.constraints.iter().map(|&(k, _)| k));
    for k in ground_ends {
        if let Some(g) = grounded.get_mut(k) {
            *g = true;
        }
    }
    let largest = parts.values().map(Vec::len).max().unwrap_or(0);
    let mut skipped_largest = false;
    let mut out = Vec::new();
    for nodes in parts.values() {
        if nodes.len() == largest && !skipped_largest {
            skipped_largest = true;
            continue;
        }
        if nodes.iter().any(|&k| grounded[k]) {
            continue;
        }
        let p = mesh.nodes[nodes[0]];
        out.push(format!(
            "{} at ({:.4}, {:.4}, {:.4}) and {} other node(s) form a part not connected to \
             the main structure",
            names.node(nodes[0]),
            p.x,
            p.y,
            p.z,
            nodes.len() - 1
        ));
    }
    out
}

/// Checks every free DOF of the assembled system has positive stiffness and mass on the
/// diagonal, naming nodes by mesh index.
pub fn check_assembled(asm: &Assembled) -> Result<(), FeError> {
    check_assembled_named(asm, &MeshIndices)
}

/// [`check_assembled`] with nodes named by `names`.
pub fn check_assembled_named(asm: &Assembled, names: &dyn Naming) -> Result<(), FeError> {
    let diag = |m: &super::assembly::SparseMat| {
        let (cp, ri, val) = (m.symbolic().col_ptr(), m.symbolic().row_idx(), m.val());
        let mut d = vec![0.0; m.ncols()];
        for (j, dj) in d.iter_mut().enumerate() {
            for p in cp[j]..cp[j + 1] {
                if ri[p] == j {
                    *dj += val[p];
                }
            }
        }
        d
    };
    let (kd, md) = (diag(&asm.k), diag(&asm.m));
    let mut problems = Vec::new();
    for (g, &(node, dof)) in asm.dofs.owners().iter().enumerate() {
        if kd[g].is_nan() || kd[g] <= 0.0 {
            problems.push(format!(
                "{} dof {}: no stiffness",
                names.node(node),
                DOF_NAMES[dof]
            ));
        }
        if md[g].is_nan() || md[g] <= 0.0 {
            problems.push(format!(
                "{} dof {}: no mass",
                names.node(node),
                DOF_NAMES[dof]
            ));
        }
    }
    report(problems)
}

/// Names of a node's six DOFs in messages.
pub const DOF_NAMES: [&str; 6] = ["ux", "uy", "uz", "rx", "ry", "rz"];

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fe::assembly::assemble;
    use crate::fe::mesh::{Beam, BeamSection, Material, PointMass, Shell};
    use nalgebra::Matrix3;

    fn square(mesh: &mut Mesh, z3: f64) {
        for p in [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, z3],
            [0.0, 1.0, 0.0],
        ] {
            mesh.add_node(Vector3::from(p));
        }
        mesh.shells.push(Shell {
            nodes: [0, 1, 2, 3],
            material: Material::STEEL,
            thickness: 0.001,
            bending_thickness: 0.001,
            extra_mass_per_area: 0.0,
            section: None,
        });
    }

    #[test]
    fn warped_shell_is_named() {
        let mut mesh = Mesh::default();
        square(&mut mesh, 0.2);
        let err = check_mesh(&mesh, &CheckLimits::default())
            .unwrap_err()
            .to_string();
        assert!(err.contains("shell 0: warped"), "{err}");
        let mut flat = Mesh::default();
        square(&mut flat, 0.0);
        check_mesh(&flat, &CheckLimits::default()).unwrap();
    }

    #[test]
    fn unconnected_node_and_degenerate_beam_are_named() {
        let mut mesh = Mesh::default();
        square(&mut mesh, 0.0);
        let lonely = mesh.add_node(Vector3::new(5.0, 5.0, 5.0));
        mesh.beams.push(Beam {
            nodes: [1, 1],
            material: Material::STEEL,
            section: BeamSection::circular_tube(0.02, 0.002),
            orientation: Vector3::z(),
            extra_mass_per_length: 0.0,
        });
        let err = check_mesh(&mesh, &CheckLimits::default())
            .unwrap_err()
            .to_string();
        assert!(
            err.contains(&format!("node {lonely}: not connected")),
            "{err}"
        );
        assert!(err.contains("beam 0: degenerate"), "{err}");
    }

    #[test]
    fn a_part_not_connected_to_the_main_structure_is_named() {
        let mut mesh = Mesh::default();
        square(&mut mesh, 0.0);
        let a = mesh.add_node(Vector3::new(3.0, 0.0, 0.0));
        let b = mesh.add_node(Vector3::new(4.0, 0.0, 0.0));
        mesh.beams.push(Beam {
            nodes: [a, b],
            material: Material::STEEL,
            section: BeamSection::circular_tube(0.02, 0.002),
            orientation: Vector3::z(),
            extra_mass_per_length: 0.0,
        });
        let err = check_mesh(&mesh, &CheckLimits::default())
            .unwrap_err()
            .to_string();
        assert!(
            err.contains(&format!("node {a} at")) && err.contains("not connected to the main"),
            "{err}"
        );
        let lenient = CheckLimits {
            allow_disconnected_parts: true,
            ..CheckLimits::default()
        };
        check_mesh(&mesh, &lenient).unwrap();
    }

    #[test]
    fn dof_without_stiffness_is_named_after_assembly() {
        let mut mesh = Mesh::default();
        square(&mut mesh, 0.0);
        let hanging = mesh.add_node(Vector3::new(2.0, 0.0, 0.0));
        mesh.masses.push(PointMass {
            node: hanging,
            mass: 1.0,
            inertia: Matrix3::identity(),
        });
        let asm = assemble(&mesh).unwrap();
        let err = check_assembled(&asm).unwrap_err().to_string();
        assert!(
            err.contains(&format!("node {hanging} dof ux: no stiffness")),
            "{err}"
        );
        let err = check_mesh(&mesh, &CheckLimits::default())
            .unwrap_err()
            .to_string();
        assert!(
            err.contains(&format!("node {hanging}: carries only point masses")),
            "{err}"
        );
    }
}
