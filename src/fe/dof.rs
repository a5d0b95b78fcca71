//! Map from (node, local DOF 0..5) to the global equation index, with constrained DOFs removed.
//!
//! Local DOF order at every node: ux, uy, uz, rx, ry, rz (vehicle/global axes).

use super::error::FeError;

/// Degrees of freedom per node (three translations, three rotations).
pub const DOF_PER_NODE: usize = 6;

/// Global numbering of the free DOFs. Constrained DOFs have no equation index.
#[derive(Debug, Clone, PartialEq)]
pub struct DofMap {
    index: Vec<Option<usize>>,
    n_free: usize,
}

impl DofMap {
    /// Numbers all DOFs of `n_nodes` nodes node by node, skipping the `(node, dof)` pairs in
    /// `constrained`.
    pub fn new(n_nodes: usize, constrained: &[(usize, usize)]) -> Result<Self, FeError> {
        let mut fixed = vec![false; n_nodes * DOF_PER_NODE];
        for &(node, dof) in constrained {
            if node >= n_nodes || dof >= DOF_PER_NODE {
                return Err(FeError::InvalidInput(format!(
                    "constraint on node {node} dof {dof}: mesh has {n_nodes} nodes, dofs 0..5"
                )));
            }
            fixed[node * DOF_PER_NODE + dof] = true;
        }
        let mut n_free = 0;
        let index = fixed
            .iter()
            .map(|&f| {
                if f {
                    None
                } else {
                    n_free += 1;
                    Some(n_free - 1)
                }
            })
            .collect();
        Ok(Self { index, n_free })
    }

    /// Global equation index of `(node, dof)`, `None` if constrained or out of range.
    pub fn global(&self, node: usize, dof: usize) -> Option<usize> {
        if dof >= DOF_PER_NODE {
            return None;
        }
        self.index.get(node * DOF_PER_NODE + dof).copied().flatten()
    }

    /// Whether `(node, dof)` is constrained (true also for out-of-range pairs).
    pub fn is_constrained(&self, node: usize, dof: usize) -> bool {
        self.global(node, dof).is_none()
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

    #[test]
    fn out_of_range_constraint_is_an_error() {
        let err = DofMap::new(2, &[(2, 0)]).unwrap_err();
        assert!(err.to_string().contains("node 2"));
    }
}
