//! Mesh checks: degenerate or warped elements, unconnected nodes, DOFs without mass or stiffness.
//! Every problem found is named (element index, node id, DOF); all are reported together.

use nalgebra::Vector3;

use super::assembly::Assembled;
use super::error::FeError;
use super::mesh::Mesh;
use super::{shell, shell3};

/// Limits of the geometric checks.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CheckLimits {
    /// Largest corner offset from the mean plane / √area of a shell.
    pub max_warp: f64,
    /// Smallest ratio of corner Jacobians of a shell (1 = parallelogram, ≤ 0 = inverted).
    pub min_jacobian_ratio: f64,
    /// Smallest beam length (m).
    pub min_beam_length: f64,
    /// Smallest shell area (m²).
    pub min_shell_area: f64,
    /// Accept structures made of several parts that share no element.
    pub allow_disconnected_parts: bool,
}

impl Default for CheckLimits {
    fn default() -> Self {
        Self {
            max_warp: 0.01,
            min_jacobian_ratio: 0.2,
            min_beam_length: 1e-6,
            min_shell_area: 1e-10,
            allow_disconnected_parts: false,
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

fn node(mesh: &Mesh, id: usize) -> Option<Vector3<f64>> {
    mesh.nodes.get(id).copied()
}

/// Geometric and topological checks of `mesh` before assembly.
///
/// Long on purpose: one list of short checks per entity kind that share the node lookup and the limits; read as a table.
pub fn check_mesh(mesh: &Mesh, limits: &CheckLimits) -> Result<(), FeError> {
    let mut problems = Vec::new();
    let n = mesh.nodes.len();
    let mut connected = vec![false; n];
    let mut has_stiffness = vec![false; n];
    for (i, p) in mesh.nodes.iter().enumerate() {
        if p.iter().any(|c| !c.is_finite()) {
            problems.push(format!("node {i}: non-finite coordinates"));
        }
    }
    for (i, b) in mesh.beams.iter().enumerate() {
        let (Some(p1), Some(p2)) = (node(mesh, b.nodes[0]), node(mesh, b.nodes[1])) else {
            problems.push(format!("beam {i}: node {:?} does not exist", b.nodes));
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
                "beam {i}: degenerate (length {:.3e} m)",
                (p2 - p1).norm()
            ));
        } else if (p2 - p1).normalize().cross(&b.orientation).norm()
            < 1e-6 * b.orientation.norm().max(1e-300)
        {
            problems.push(format!(
                "beam {i}: orientation vector parallel to the axis or zero"
            ));
        }
        for &k in &b.nodes {
            connected[k] = true;
            has_stiffness[k] = true;
        }
    }
    for (i, s) in mesh.shells.iter().enumerate() {
        let pts: Option<Vec<Vector3<f64>>> = s.nodes.iter().map(|&k| node(mesh, k)).collect();
        let Some(pts) = pts else {
            problems.push(format!("shell {i}: node {:?} does not exist", s.nodes));
            continue;
        };
        let mut distinct = s.nodes.to_vec();
        distinct.sort_unstable();
        distinct.dedup();
        if distinct.len() < 4 {
            problems.push(format!("shell {i}: repeated node in {:?}", s.nodes));
            continue;
        }
        match shell::geometry(i, &[pts[0], pts[1], pts[2], pts[3]]) {
            Err(e) => problems.push(e.to_string()),
            Ok(g) => {
                if g.area < limits.min_shell_area {
                    problems.push(format!("shell {i}: degenerate (area {:.3e} m²)", g.area));
                }
                if g.warp > limits.max_warp {
                    problems.push(format!(
                        "shell {i}: warped (warp ratio {:.4} > {})",
                        g.warp, limits.max_warp
                    ));
                }
                if g.jacobian_ratio < limits.min_jacobian_ratio {
                    problems.push(format!(
                        "shell {i}: distorted or inverted (Jacobian ratio {:.3} < {})",
                        g.jacobian_ratio, limits.min_jacobian_ratio
                    ));
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
            problems.push(format!("triangle {i}: node {:?} does not exist", t.nodes));
            continue;
        };
        match shell3::geometry(i, &[pts[0], pts[1], pts[2]]) {
            Err(e) => problems.push(e.to_string()),
            Ok(g) if g.area < limits.min_shell_area => {
                problems.push(format!("triangle {i}: degenerate (area {:.3e} m²)", g.area))
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
            problems.push(format!("solid {i}: node {:?} does not exist", s.nodes));
            continue;
        };
        if let Err(why) = super::solid::check_geometry(&pts) {
            problems.push(format!("solid {i}: {why}"));
        }
        for &k in &s.nodes {
            connected[k] = true;
            has_stiffness[k] = true;
        }
    }
    for (i, m) in mesh.masses.iter().enumerate() {
        match connected.get_mut(m.node) {
            Some(c) => *c = true,
            None => problems.push(format!("point mass {i}: node {} does not exist", m.node)),
        }
    }
    for (i, s) in mesh.ground_springs.iter().enumerate() {
        match connected.get_mut(s.node) {
            Some(c) => *c = true,
            None => problems.push(format!("ground spring {i}: node {} does not exist", s.node)),
        }
    }
    for (i, s) in mesh.springs.iter().enumerate() {
        for &k in &s.nodes {
            match connected.get_mut(k) {
                Some(c) => *c = true,
                None => problems.push(format!("spring {i}: node {k} does not exist")),
            }
        }
    }
    for (i, b) in mesh.bushes.iter().enumerate() {
        for k in std::iter::once(b.a).chain(b.b) {
            match connected.get_mut(k) {
                Some(c) => *c = true,
                None => problems.push(format!("bush {i}: node {k} does not exist")),
            }
        }
    }
    // A node tied by a rigid or interpolation link is held by the link (or holds it): count it
    // as structurally connected; a link on a node without any real stiffness shows up as a
    // singular DOF in `check_assembled`.
    for (what, nodes) in link_node_sets(mesh) {
        for k in nodes {
            match connected.get_mut(k) {
                Some(c) => {
                    *c = true;
                    has_stiffness[k] = true;
                }
                None => problems.push(format!("{what}: node {k} does not exist")),
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
            problems.push(format!("node {k}: not connected to any element"));
        } else if connected[k] && !has_stiffness[k] && !fully_constrained(k) {
            problems.push(format!(
                "node {k}: carries only masses/springs, no structural element"
            ));
        }
    }
    if !limits.allow_disconnected_parts {
        problems.extend(disconnected_parts(mesh, &connected, &fully_constrained));
    }
    for (name, &k) in &mesh.named_nodes {
        if k >= n {
            problems.push(format!("named node '{name}': node {k} does not exist"));
        }
    }
    report(problems)
}

/// The nodes of every rigid and interpolation link, named for messages.
fn link_node_sets(mesh: &Mesh) -> Vec<(String, Vec<usize>)> {
    let rigid = mesh.rigid_links.iter().enumerate().map(|(i, l)| {
        let mut nodes = vec![l.independent];
        nodes.extend(&l.dependent);
        (format!("rigid link {i}"), nodes)
    });
    let interpolation = mesh.interpolation_links.iter().enumerate().map(|(i, l)| {
        let mut nodes = vec![l.reference];
        nodes.extend(l.sources.iter().flat_map(|s| s.nodes.iter().copied()));
        (format!("interpolation link {i}"), nodes)
    });
    rigid.chain(interpolation).collect()
}

fn find(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

/// Parts of the structure (connected through elements and two-node springs) other than the
/// largest one, each described by its size and first node.
fn disconnected_parts(
    mesh: &Mesh,
    connected: &[bool],
    fully_constrained: &dyn Fn(usize) -> bool,
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
        .chain(link_node_sets(mesh).into_iter().map(|(_, nodes)| nodes));
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
    let largest = parts.values().map(Vec::len).max().unwrap_or(0);
    let mut skipped_largest = false;
    let mut out = Vec::new();
    for nodes in parts.values() {
        if nodes.len() == largest && !skipped_largest {
            skipped_largest = true;
            continue;
        }
        let p = mesh.nodes[nodes[0]];
        out.push(format!(
            "node {} at ({:.4}, {:.4}, {:.4}) and {} other node(s) form a part not connected to \
             the main structure",
            nodes[0],
            p.x,
            p.y,
            p.z,
            nodes.len() - 1
        ));
    }
    out
}

/// Checks every free DOF of the assembled system has positive stiffness and mass on the diagonal.
pub fn check_assembled(asm: &Assembled) -> Result<(), FeError> {
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
    let names = ["ux", "uy", "uz", "rx", "ry", "rz"];
    let mut problems = Vec::new();
    for (g, &(node, dof)) in asm.dofs.owners().iter().enumerate() {
        if kd[g].is_nan() || kd[g] <= 0.0 {
            problems.push(format!("node {node} dof {}: no stiffness", names[dof]));
        }
        if md[g].is_nan() || md[g] <= 0.0 {
            problems.push(format!("node {node} dof {}: no mass", names[dof]));
        }
    }
    report(problems)
}

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
            err.contains(&format!("node {hanging}: carries only masses")),
            "{err}"
        );
    }
}
