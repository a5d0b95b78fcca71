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
pub use super::element::{CheckLimits, PoorShape};
use super::element::{Finding, ShapeTest};
use super::elements::all_nodes;
pub use super::elements::Entity;
use super::error::FeError;
use super::mesh::Mesh;

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
    refuse: bool,
    max_warp: f64,
    min_jacobian_ratio: f64,
    warp: Tally,
    jacobian: Tally,
    taper: Tally,
    skew: Tally,
}

impl ShapeTallies {
    fn new(limits: &CheckLimits) -> Self {
        Self {
            refuse: limits.poor_shape == PoorShape::Refuse,
            max_warp: limits.max_warp,
            min_jacobian_ratio: limits.min_jacobian_ratio,
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

    /// A failed shape test of element `name`: the problem that refuses it under
    /// [`PoorShape::Refuse`] (warp and Jacobian ratio; taper and skew are only ever counted),
    /// else counted.
    fn add(
        &mut self,
        test: ShapeTest,
        value: f64,
        name: impl FnOnce() -> String,
    ) -> Option<String> {
        if self.refuse {
            return match test {
                ShapeTest::Warp => Some(format!(
                    "{}: warped (warp ratio {value:.4} > {})",
                    name(),
                    self.max_warp
                )),
                ShapeTest::JacobianRatio => Some(format!(
                    "{}: distorted or inverted (Jacobian ratio {value:.3} < {})",
                    name(),
                    self.min_jacobian_ratio
                )),
                ShapeTest::Taper | ShapeTest::Skew => None,
            };
        }
        let tally = match test {
            ShapeTest::Warp => &mut self.warp,
            ShapeTest::JacobianRatio => &mut self.jacobian,
            ShapeTest::Taper => &mut self.taper,
            ShapeTest::Skew => &mut self.skew,
        };
        tally.add(value, name);
        None
    }

    fn notes(&self) -> Vec<String> {
        [&self.warp, &self.jacobian, &self.taper, &self.skew]
            .into_iter()
            .filter_map(Tally::note)
            .map(|n| format!("element shape (warning, as Nastran's GEOMCHECK): {n}"))
            .collect()
    }
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
/// Every entity of the registry ([`Entity::ALL`]) is checked the same way: its nodes must
/// exist, its own shape checks ([`super::element::Element::check_shape`]) refuse or count, and
/// its nodes are connected (and held, unless it is a point mass). Then the nodes: connected,
/// held, in the main part (or held by ground), and the named nodes exist.
///
/// Long on purpose: the per-entity checks and the per-node checks share the connectivity they
/// build (connected, held) and the list of problems reported together.
pub fn check_mesh_named(
    mesh: &Mesh,
    limits: &CheckLimits,
    names: &dyn Naming,
) -> Result<Vec<String>, FeError> {
    let mut problems = Vec::new();
    let mut tallies = ShapeTallies::new(limits);
    let n = mesh.nodes.len();
    let mut connected = vec![false; n];
    let mut has_stiffness = vec![false; n];
    for (i, p) in mesh.nodes.iter().enumerate() {
        if p.iter().any(|c| !c.is_finite()) {
            problems.push(format!("{}: non-finite coordinates", names.node(i)));
        }
    }
    for &kind in Entity::ALL {
        let list = kind.of(mesh);
        for i in 0..list.len() {
            let nodes = list.nodes(i);
            if nodes.iter().any(|&k| k >= n) {
                problems.push(format!(
                    "{}: node index {:?} does not exist",
                    names.entity(kind, i),
                    nodes.iter().filter(|&&k| k >= n).collect::<Vec<_>>()
                ));
                continue;
            }
            let points: Vec<Vector3<f64>> = nodes.iter().map(|&k| mesh.nodes[k]).collect();
            for finding in list.check_shape(i, mesh, &points, limits) {
                let name = || names.entity(kind, i);
                match finding {
                    Finding::Wrong(why) => problems.push(format!("{}: {why}", name())),
                    Finding::RepeatedNode => {
                        let grids: Vec<String> = nodes.iter().map(|&k| names.node(k)).collect();
                        problems.push(format!(
                            "{}: repeated node in [{}]",
                            name(),
                            grids.join(", ")
                        ));
                    }
                    Finding::Poor(test, value) => {
                        if let Some(problem) = tallies.add(test, value, name) {
                            problems.push(problem);
                        }
                    }
                }
            }
            for k in nodes {
                connected[k] = true;
                has_stiffness[k] |= list.holds();
            }
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
    // Every entity that holds its nodes joins them (a point mass does not).
    for (kind, _, nodes) in all_nodes(mesh) {
        if kind.of(mesh).holds() {
            for w in nodes.windows(2) {
                join(w[0], w[1]);
            }
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
    let ground_ends = Entity::ALL
        .iter()
        .flat_map(|&kind| {
            let list = kind.of(mesh);
            (0..list.len())
                .filter(move |&i| list.grounds(i))
                .flat_map(move |i| list.nodes(i))
        })
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
