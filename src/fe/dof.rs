//! Map from (node, local DOF 0..5) to the global equation index, with constrained DOFs removed
//! and the dependent DOFs of rigid/interpolation links eliminated (u = T q, q the equations).
//!
//! Local DOF order at every node: ux, uy, uz, rx, ry, rz (vehicle/global axes, or the node's
//! displacement frame where the mesh gives one: [`crate::fe::nodal_frames`]).

use std::collections::BTreeMap;

use faer::sparse::{SparseColMat, Triplet};
use nalgebra::Matrix3;

use super::error::FeError;
use super::links::LinkEquation;

pub use super::mesh::DOF_PER_NODE;

/// Global numbering of the free DOFs. Constrained and dependent DOFs have no equation index;
/// a dependent DOF is a fixed linear combination of equations ([`DofMap::motion_row`]).
#[derive(Debug, Clone, PartialEq)]
pub struct DofMap {
    index: Vec<Option<usize>>,
    n_free: usize,
    /// Row of T for each dependent slot `node * 6 + dof`: `(equation, coefficient)`.
    dependent: BTreeMap<usize, Vec<(usize, f64)>>,
    /// Displacement frames of nodes (columns: axes in global coordinates).
    frames: BTreeMap<usize, Matrix3<f64>>,
    /// Global-axes motion of the slots of framed nodes: `(equation, coefficient)`.
    global_rows: BTreeMap<usize, Vec<(usize, f64)>>,
}

/// How one (node, dof) enters the equations: its own equation, nothing (fixed), or a
/// combination of equations (dependent).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Expansion<'a> {
    Equation(usize),
    Fixed,
    Combination(&'a [(usize, f64)]),
}

const DOF_NAMES: [&str; 6] = ["ux", "uy", "uz", "rx", "ry", "rz"];

#[derive(Clone, Copy, PartialEq)]
enum Visit {
    New,
    Open,
    Done,
}

impl DofMap {
    /// Numbers all DOFs of `n_nodes` nodes node by node, skipping the `(node, dof)` pairs in
    /// `constrained`.
    pub fn new(n_nodes: usize, constrained: &[(usize, usize)]) -> Result<Self, FeError> {
        Self::with_links(n_nodes, constrained, &[])
    }

    /// Like [`DofMap::new`], and eliminates the dependent DOF of every link equation. Chains
    /// (a dependent DOF referring to another dependent DOF) are resolved; cycles, a DOF made
    /// dependent twice, and a dependent DOF that is also constrained are errors, as in Nastran.
    pub fn with_links(
        n_nodes: usize,
        constrained: &[(usize, usize)],
        links: &[LinkEquation],
    ) -> Result<Self, FeError> {
        Self::with_frames(n_nodes, constrained, links, &BTreeMap::new())
    }

    /// Like [`DofMap::with_links`] for a mesh whose nodes in `frames` have displacement frames:
    /// their slots (in `constrained` and in the link equations) are components in the frame,
    /// and [`DofMap::motion_row`] (and assembly) see their motion in global axes.
    ///
    /// Long on purpose: the constraints, the link equations (each dependent slot checked once,
    /// chains resolved) and the frames' global rows are built on one slot table, in this order,
    /// each refusal naming the link.
    pub fn with_frames(
        n_nodes: usize,
        constrained: &[(usize, usize)],
        links: &[LinkEquation],
        frames: &BTreeMap<usize, Matrix3<f64>>,
    ) -> Result<Self, FeError> {
        super::nodal_frames::validate(frames, n_nodes)?;
        let n_slots = n_nodes * DOF_PER_NODE;
        let mut fixed = vec![false; n_slots];
        for &(node, dof) in constrained {
            if node >= n_nodes || dof >= DOF_PER_NODE {
                return Err(FeError::InvalidInput(format!(
                    "constraint on node {node} dof {dof}: mesh has {n_nodes} nodes, dofs 0..5"
                )));
            }
            fixed[node * DOF_PER_NODE + dof] = true;
        }
        let slot_name = |s: usize| format!("node {} dof {}", s / DOF_PER_NODE, DOF_NAMES[s % 6]);
        let mut equation_of: Vec<Option<usize>> = vec![None; n_slots];
        for (k, eq) in links.iter().enumerate() {
            if let Some(&(bad, _)) = eq.terms.iter().find(|(s, _)| *s >= n_slots) {
                return Err(FeError::Mesh(format!(
                    "{}: refers to DOF slot {bad}, mesh has {n_nodes} nodes",
                    eq.origin
                )));
            }
            let Some(slot) = equation_of.get_mut(eq.dependent) else {
                return Err(FeError::Mesh(format!(
                    "{}: dependent DOF slot {} beyond the {n_nodes} nodes",
                    eq.origin, eq.dependent
                )));
            };
            if let Some(previous) = *slot {
                return Err(FeError::Mesh(format!(
                    "{} is dependent in both {} and {}",
                    slot_name(eq.dependent),
                    links[previous].origin,
                    eq.origin
                )));
            }
            if fixed[eq.dependent] {
                return Err(FeError::Mesh(format!(
                    "{} is dependent in {} and also constrained (SPC)",
                    slot_name(eq.dependent),
                    eq.origin
                )));
            }
            *slot = Some(k);
        }
        let mut n_free = 0;
        let index: Vec<Option<usize>> = (0..n_slots)
            .map(|s| {
                if fixed[s] || equation_of[s].is_some() {
                    None
                } else {
                    n_free += 1;
                    Some(n_free - 1)
                }
            })
            .collect();
        let dependent = resolve_chains(links, &equation_of, &index, &slot_name)?;
        let mut global_rows = BTreeMap::new();
        for (&node, r) in frames {
            let own = |slot: usize| -> Vec<(usize, f64)> {
                match index[slot] {
                    Some(g) => vec![(g, 1.0)],
                    None => dependent.get(&slot).cloned().unwrap_or_default(),
                }
            };
            for block in [0, 3] {
                let base = node * DOF_PER_NODE + block;
                for i in 0..3 {
                    let mut row: BTreeMap<usize, f64> = BTreeMap::new();
                    for j in 0..3 {
                        for (g, c) in own(base + j) {
                            *row.entry(g).or_insert(0.0) += r[(i, j)] * c;
                        }
                    }
                    global_rows.insert(
                        base + i,
                        row.into_iter().filter(|(_, c)| *c != 0.0).collect(),
                    );
                }
            }
        }
        Ok(Self {
            index,
            n_free,
            dependent,
            frames: frames.clone(),
            global_rows,
        })
    }

    /// Displacement frame of `node` (columns: axes in global coordinates), if it has one.
    pub fn frame(&self, node: usize) -> Option<&Matrix3<f64>> {
        self.frames.get(&node)
    }

    /// Global equation index of `(node, dof)` (a component in the node's displacement frame if
    /// it has one), `None` if constrained or out of range.
    pub fn global(&self, node: usize, dof: usize) -> Option<usize> {
        if dof >= DOF_PER_NODE {
            return None;
        }
        self.index.get(node * DOF_PER_NODE + dof).copied().flatten()
    }

    /// Whether `(node, dof)` is constrained (true also for out-of-range pairs; false for a
    /// dependent DOF, which moves).
    pub fn is_constrained(&self, node: usize, dof: usize) -> bool {
        self.global(node, dof).is_none() && !self.is_dependent(node, dof)
    }

    /// Whether `(node, dof)` is a dependent DOF of a rigid or interpolation link.
    pub fn is_dependent(&self, node: usize, dof: usize) -> bool {
        dof < DOF_PER_NODE && self.dependent.contains_key(&(node * DOF_PER_NODE + dof))
    }

    /// The motion of `(node, dof)` in global axes as `(equation, coefficient)` pairs,
    /// `u = Σ c q[equation]`: one pair with coefficient 1 for a free DOF, none for a constrained
    /// DOF, the row of T for a dependent DOF, the frame's mix of the node's own components for a
    /// node with a displacement frame. Use it to recover output points and mount points on
    /// RBE2/RBE3 nodes.
    pub fn motion_row(&self, node: usize, dof: usize) -> Result<Vec<(usize, f64)>, FeError> {
        match self.expansion(node, dof) {
            Some(Expansion::Equation(g)) => Ok(vec![(g, 1.0)]),
            Some(Expansion::Fixed) => Ok(Vec::new()),
            Some(Expansion::Combination(row)) => Ok(row.to_vec()),
            None => Err(FeError::InvalidInput(format!(
                "node {node} dof {dof} does not exist (map has {} nodes, dofs 0..5)",
                self.n_nodes()
            ))),
        }
    }

    /// Motion rows of the local DOFs `local` of each node in `nodes` (node by node): the sparse
    /// matrix R with u_points = R q. For a Craig-Bampton interface or an output point on a
    /// dependent node (RBE2 dependent, RBE3 reference) R replaces the missing equation indices.
    pub fn motion_rows(
        &self,
        nodes: &[usize],
        local: &[usize],
    ) -> Result<SparseColMat<usize, f64>, FeError> {
        let mut entries = Vec::new();
        for (n, &node) in nodes.iter().enumerate() {
            for (k, &dof) in local.iter().enumerate() {
                let row = n * local.len() + k;
                for (g, c) in self.motion_row(node, dof)? {
                    entries.push(Triplet::new(row, g, c));
                }
            }
        }
        SparseColMat::try_new_from_triplets(nodes.len() * local.len(), self.n_free, &entries)
            .map_err(|e| FeError::Numerical(format!("building motion rows: {e:?}")))
    }

    /// The transformation T (6·n_nodes × n_free) from the equations to all node DOFs in global
    /// axes, row `node * 6 + dof`; rows of constrained DOFs are empty.
    pub fn transformation(&self) -> Result<SparseColMat<usize, f64>, FeError> {
        let mut entries = Vec::with_capacity(self.n_free + self.dependent.len());
        let framed = |slot: &usize| self.frames.contains_key(&(slot / DOF_PER_NODE));
        for (slot, g) in self.index.iter().enumerate() {
            if let (Some(g), false) = (g, framed(&slot)) {
                entries.push(Triplet::new(slot, *g, 1.0));
            }
        }
        for (slot, row) in self.dependent.iter().filter(|(s, _)| !framed(s)) {
            entries.extend(row.iter().map(|&(g, c)| Triplet::new(*slot, g, c)));
        }
        for (slot, row) in &self.global_rows {
            entries.extend(row.iter().map(|&(g, c)| Triplet::new(*slot, g, c)));
        }
        SparseColMat::try_new_from_triplets(self.index.len(), self.n_free, &entries)
            .map_err(|e| FeError::Numerical(format!("building the transformation T: {e:?}")))
    }

    pub(crate) fn expansion(&self, node: usize, dof: usize) -> Option<Expansion<'_>> {
        if dof >= DOF_PER_NODE {
            return None;
        }
        if let Some(row) = self.global_rows.get(&(node * DOF_PER_NODE + dof)) {
            return Some(Expansion::Combination(row));
        }
        self.own_expansion(node, dof)
    }

    /// Like [`DofMap::expansion`] for component `dof` of the node in its own displacement
    /// frame (the same for a node without one).
    pub(crate) fn own_expansion(&self, node: usize, dof: usize) -> Option<Expansion<'_>> {
        if dof >= DOF_PER_NODE {
            return None;
        }
        let slot = node * DOF_PER_NODE + dof;
        match self.index.get(slot)? {
            Some(g) => Some(Expansion::Equation(*g)),
            None => Some(match self.dependent.get(&slot) {
                Some(row) => Expansion::Combination(row),
                None => Expansion::Fixed,
            }),
        }
    }

    /// Number of free DOFs (size of K and M).
    pub fn n_free(&self) -> usize {
        self.n_free
    }

    /// Number of nodes covered by the map.
    pub fn n_nodes(&self) -> usize {
        self.index.len() / DOF_PER_NODE
    }

    /// Global indices of the local DOFs `local` of each node in `nodes`, node by node (e.g. the
    /// interface DOFs of the engine-mount nodes for a Craig-Bampton reduction).
    pub fn indices_of(&self, nodes: &[usize], local: &[usize]) -> Result<Vec<usize>, FeError> {
        let mut out = Vec::with_capacity(nodes.len() * local.len());
        for &node in nodes {
            for &dof in local {
                if self.is_dependent(node, dof) {
                    return Err(FeError::InvalidInput(format!(
                        "node {node} dof {dof} is a dependent DOF of a rigid/interpolation link \
                         (RBE2/RBE3) and has no equation of its own: use the link's independent \
                         node, or DofMap::motion_row to recover its motion"
                    )));
                }
                out.push(self.global(node, dof).ok_or_else(|| {
                    FeError::InvalidInput(format!(
                        "node {node} dof {dof} is constrained or does not exist"
                    ))
                })?);
            }
        }
        Ok(out)
    }

    /// Inverse map: (node, dof) of every global index, in order.
    pub fn owners(&self) -> Vec<(usize, usize)> {
        let mut out = Vec::with_capacity(self.n_free);
        for (k, g) in self.index.iter().enumerate() {
            if g.is_some() {
                out.push((k / DOF_PER_NODE, k % DOF_PER_NODE));
            }
        }
        out
    }
}

/// Rows of T for the dependent slots, chains substituted (explicit stack: no recursion depth
/// limit on long chains).
fn resolve_chains(
    links: &[LinkEquation],
    equation_of: &[Option<usize>],
    index: &[Option<usize>],
    slot_name: &dyn Fn(usize) -> String,
) -> Result<BTreeMap<usize, Vec<(usize, f64)>>, FeError> {
    let mut rows: BTreeMap<usize, Vec<(usize, f64)>> = BTreeMap::new();
    let mut visit = vec![Visit::New; equation_of.len()];
    for eq in links {
        let mut stack = vec![eq.dependent];
        while let Some(&top) = stack.last() {
            let Some(own) = equation_of[top].map(|k| &links[k]) else {
                stack.pop();
                continue;
            };
            match visit[top] {
                Visit::Done => {
                    stack.pop();
                }
                Visit::New => {
                    visit[top] = Visit::Open;
                    for &(s, _) in &own.terms {
                        if equation_of[s].is_none() {
                            continue;
                        }
                        match visit[s] {
                            Visit::New => stack.push(s),
                            Visit::Open => {
                                return Err(FeError::Mesh(format!(
                                    "rigid/interpolation links form a cycle through {} ({})",
                                    slot_name(s),
                                    own.origin
                                )))
                            }
                            Visit::Done => {}
                        }
                    }
                }
                Visit::Open => {
                    let mut row: BTreeMap<usize, f64> = BTreeMap::new();
                    for &(s, c) in &own.terms {
                        if let Some(g) = index[s] {
                            *row.entry(g).or_insert(0.0) += c;
                        } else if let Some(sub) = rows.get(&s) {
                            for &(g, cs) in sub {
                                *row.entry(g).or_insert(0.0) += c * cs;
                            }
                        }
                    }
                    rows.insert(top, row.into_iter().filter(|(_, c)| *c != 0.0).collect());
                    visit[top] = Visit::Done;
                    stack.pop();
                }
            }
        }
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn constrained_dofs_are_removed_and_numbering_is_dense() {
        let map = DofMap::new(2, &[(0, 2), (1, 5)]).unwrap();
        assert_eq!(map.n_free(), 10);
        assert_eq!(map.global(0, 1), Some(1));
        assert_eq!(map.global(0, 2), None);
        assert_eq!(map.global(0, 3), Some(2));
        assert_eq!(map.global(1, 4), Some(9));
        assert!(map.is_constrained(1, 5));
        assert_eq!(map.owners()[2], (0, 3));
    }

    #[test]
    fn interface_indices_follow_node_then_dof_order() {
        let map = DofMap::new(3, &[(1, 0)]).unwrap();
        assert_eq!(
            map.indices_of(&[2, 0], &[0, 2]).unwrap(),
            vec![11, 13, 0, 2]
        );
        let err = map.indices_of(&[1], &[0]).unwrap_err().to_string();
        assert!(err.contains("node 1 dof 0"), "{err}");
    }

    fn link(dependent: usize, terms: Vec<(usize, f64)>, origin: &str) -> LinkEquation {
        LinkEquation {
            dependent,
            terms,
            origin: origin.to_string(),
        }
    }

    #[test]
    fn chained_dependents_are_substituted_and_fixed_terms_dropped() {
        // Slot 6 (node 1 ux) = 2 × slot 0 + slot 12; slot 12 (node 2 ux) = 3 × slot 1 + slot 2.
        let links = [
            link(6, vec![(0, 2.0), (12, 1.0)], "a"),
            link(12, vec![(1, 3.0), (2, 5.0)], "b"),
        ];
        let map = DofMap::with_links(3, &[(0, 2)], &links).unwrap();
        assert_eq!(map.n_free(), 18 - 3);
        assert!(map.is_dependent(1, 0) && !map.is_constrained(1, 0));
        assert!(map.is_constrained(0, 2));
        assert_eq!(map.motion_row(1, 0).unwrap(), vec![(0, 2.0), (1, 3.0)]);
        assert_eq!(map.motion_row(0, 2).unwrap(), vec![]);
        assert_eq!(map.motion_row(0, 3).unwrap(), vec![(2, 1.0)]);
        let t = map.transformation().unwrap().to_dense();
        assert_eq!((t.nrows(), t.ncols()), (18, 15));
        assert_eq!(t[(6, 0)], 2.0);
        assert_eq!(t[(6, 1)], 3.0);
        let err = map.indices_of(&[1], &[0]).unwrap_err().to_string();
        assert!(err.contains("dependent"), "{err}");
        let r = map.motion_rows(&[1, 0], &[0, 2]).unwrap().to_dense();
        assert_eq!((r.nrows(), r.ncols()), (4, 15));
        assert_eq!((r[(0, 0)], r[(0, 1)]), (2.0, 3.0));
        assert!((0..15).all(|g| r[(3, g)] == 0.0), "node 0 dof 2 is fixed");
    }

    #[test]
    fn cycles_double_dependents_and_constrained_dependents_are_errors() {
        let cycle = [link(6, vec![(12, 1.0)], "a"), link(12, vec![(6, 1.0)], "b")];
        let err = DofMap::with_links(3, &[], &cycle).unwrap_err().to_string();
        assert!(err.contains("cycle"), "{err}");
        let twice = [link(6, vec![(0, 1.0)], "a"), link(6, vec![(12, 1.0)], "b")];
        let err = DofMap::with_links(3, &[], &twice).unwrap_err().to_string();
        assert!(err.contains("both a and b"), "{err}");
        let err = DofMap::with_links(3, &[(1, 0)], &twice[..1])
            .unwrap_err()
            .to_string();
        assert!(err.contains("also constrained"), "{err}");
    }

    #[test]
    fn a_framed_node_numbers_its_own_components_and_moves_in_global_axes() {
        // Node 1 in a frame whose axis 1 is (cos a, sin a, 0): fixing its component 1 leaves
        // motion along axis 2 = (−sin a, cos a, 0) and the global z axis.
        let a = 0.6f64;
        let (s, c) = a.sin_cos();
        let r = Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0);
        let frames = BTreeMap::from([(1, r)]);
        let map = DofMap::with_frames(2, &[(1, 0), (1, 3), (1, 4), (1, 5)], &[], &frames).unwrap();
        assert_eq!(map.n_free(), 8);
        let (gy, gz) = (map.global(1, 1).unwrap(), map.global(1, 2).unwrap());
        assert_eq!(map.motion_row(1, 0).unwrap(), vec![(gy, -s)]);
        assert_eq!(map.motion_row(1, 1).unwrap(), vec![(gy, c)]);
        assert_eq!(map.motion_row(1, 2).unwrap(), vec![(gz, 1.0)]);
        assert!(map.motion_row(1, 4).unwrap().is_empty());
        let t = map.transformation().unwrap().to_dense();
        assert_eq!((t[(6, gy)], t[(7, gy)], t[(8, gz)]), (-s, c, 1.0));
        assert_eq!(map.frame(1), Some(&r));
        assert_eq!(map.frame(0), None);
    }

    #[test]
    fn out_of_range_constraint_is_an_error() {
        let err = DofMap::new(2, &[(2, 0)]).unwrap_err();
        assert!(err.to_string().contains("node 2"));
    }
}
