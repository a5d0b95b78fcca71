//! Sparse assembly of K, M and C from the element matrices (triplets → faer `SparseColMat`).

use faer::sparse::{SparseColMat, Triplet};
use nalgebra::{DMatrix, Dim, Matrix, RawStorage};

use super::dof::{DofMap, Expansion, DOF_PER_NODE};
use super::element::LinkEquation;
use super::elements::Entity;
use super::error::FeError;
use super::mesh::Mesh;
use super::solid;

/// Sparse symmetric matrix type of the FE model (both triangles stored).
pub type SparseMat = SparseColMat<usize, f64>;

/// The assembled system: stiffness, mass (lumped, consistent for solids) and viscous damping on the free DOFs. With
/// rigid/interpolation links the matrices are Tᵀ K T etc. on the independent DOFs (u = T q).
#[derive(Debug, Clone)]
pub struct Assembled {
    /// Stiffness matrix (N/m, N m/rad).
    pub k: SparseMat,
    /// Mass matrix (kg, kg m²): lumped, consistent for solids.
    pub m: SparseMat,
    /// Viscous damping of the discrete dampers (N s/m) (structural damping is added modally).
    pub c: SparseMat,
    /// Numbering of the free DOFs.
    pub dofs: DofMap,
}

struct TripletSink<'a> {
    dofs: &'a DofMap,
    entries: Vec<Triplet<usize, usize, f64>>,
}

impl TripletSink<'_> {
    fn scatter<R: Dim, C: Dim, S: RawStorage<f64, R, C>>(
        &mut self,
        nodes: &[usize],
        local: &Matrix<f64, R, C, S>,
    ) {
        let dofs = self.dofs;
        if !nodes.iter().any(|&n| dofs.frame(n).is_some()) {
            return self.scatter_on(nodes, local, |n, d| dofs.expansion(n, d));
        }
        // Nodes with a displacement frame: the global-axes matrix turned to their own
        // components first (Bᵀ K B, B = diag(R, R) per such node), then scattered on those like
        // the components of any other node (cheaper than spreading every entry over the frame).
        let mut own = DMatrix::from_fn(local.nrows(), local.ncols(), |i, j| local[(i, j)]);
        for (k, &node) in nodes.iter().enumerate() {
            if let Some(r) = dofs.frame(node) {
                for o in [DOF_PER_NODE * k, DOF_PER_NODE * k + 3] {
                    let rows = r.transpose() * own.fixed_rows::<3>(o);
                    own.fixed_rows_mut::<3>(o).copy_from(&rows);
                    let cols = own.fixed_columns::<3>(o) * r;
                    own.fixed_columns_mut::<3>(o).copy_from(&cols);
                }
            }
        }
        self.scatter_on(nodes, &own, |n, d| dofs.own_expansion(n, d));
    }

    fn scatter_on<'d, R: Dim, C: Dim, S: RawStorage<f64, R, C>>(
        &mut self,
        nodes: &[usize],
        local: &Matrix<f64, R, C, S>,
        expansion: impl Fn(usize, usize) -> Option<Expansion<'d>>,
    ) {
        let index = |k: usize| {
            expansion(nodes[k / DOF_PER_NODE], k % DOF_PER_NODE).unwrap_or(Expansion::Fixed)
        };
        for j in 0..local.ncols() {
            let ej = index(j);
            if ej == Expansion::Fixed {
                continue;
            }
            for i in 0..local.nrows() {
                let v = local[(i, j)];
                if v == 0.0 {
                    continue;
                }
                match (index(i), ej) {
                    (Expansion::Fixed, _) => {}
                    (Expansion::Equation(gi), Expansion::Equation(gj)) => {
                        self.entries.push(Triplet::new(gi, gj, v));
                    }
                    // Dependent DOFs: the entry spreads as (Tᵀ K T)[a, b] += T[i, a] K[i, j] T[j, b].
                    (ei, ej) => {
                        let tj = terms(ej);
                        for (gi, ci) in terms(ei) {
                            for &(gj, cj) in &tj {
                                self.entries.push(Triplet::new(gi, gj, ci * v * cj));
                            }
                        }
                    }
                }
            }
        }
    }
}

/// The `(equation, coefficient)` terms of one DOF (the slow path: only for dependent DOFs).
fn terms(e: Expansion<'_>) -> Vec<(usize, f64)> {
    match e {
        Expansion::Equation(g) => vec![(g, 1.0)],
        Expansion::Fixed => Vec::new(),
        Expansion::Combination(row) => row.to_vec(),
    }
}

/// All constraint equations of the links of `mesh` ([`super::element::Element::equations`] of
/// every entity, in the registry's order).
pub fn link_equations(mesh: &Mesh) -> Result<Vec<LinkEquation>, FeError> {
    let mut out = Vec::new();
    for kind in Entity::ALL {
        let list = kind.of(mesh);
        for i in 0..list.len() {
            out.extend(list.equations(i, mesh)?);
        }
    }
    Ok(out)
}

/// Assembles K, M, C of `mesh` on the DOFs left free by `mesh.constraints`: every entity's
/// [`super::element::Element::matrices`], in the registry's order, scattered through the DOF
/// map of the constraints and the links' equations.
pub fn assemble(mesh: &Mesh) -> Result<Assembled, FeError> {
    let equations = link_equations(mesh)?;
    let dofs = DofMap::with_frames(
        mesh.nodes.len(),
        &mesh.constraints,
        &equations,
        &mesh.displacement_frames,
    )?;
    let sink = || TripletSink {
        dofs: &dofs,
        entries: Vec::new(),
    };
    let (mut k, mut m, mut c) = (sink(), sink(), sink());
    for kind in Entity::ALL {
        let list = kind.of(mesh);
        for i in 0..list.len() {
            let matrices = list.matrices(i, mesh)?;
            let nodes = list.nodes(i);
            for (sink, matrix) in [
                (&mut k, &matrices.k),
                (&mut m, &matrices.m),
                (&mut c, &matrices.c),
            ] {
                if let Some(matrix) = matrix {
                    sink.scatter(&nodes, matrix);
                }
            }
        }
    }
    let entries = [k.entries, m.entries, c.entries];
    let (dofs, [k, m, c]) = solid::remove_free_rotations(mesh, dofs, &equations, entries)?;
    let n = dofs.n_free();
    let finish = |entries: Vec<Triplet<usize, usize, f64>>, what: &str| {
        SparseColMat::try_new_from_triplets(n, n, &entries)
            .map_err(|e| FeError::Numerical(format!("building sparse {what}: {e:?}")))
    };
    Ok(Assembled {
        k: finish(k, "K")?,
        m: finish(m, "M")?,
        c: finish(c, "C")?,
        dofs,
    })
}

/// y = A x for a sparse `a` and a dense vector `x` (faer's sparse-dense product).
pub fn mat_vec(a: &SparseMat, x: &[f64]) -> Vec<f64> {
    let y = a.as_ref() * faer::ColRef::from_slice(x);
    y.iter().copied().collect()
}

/// Sum of all entries of the diagonal of `a` belonging to translational DOFs in direction
/// `direction` (0 = x, 1 = y, 2 = z): the total mass seen by a rigid translation.
pub fn translational_mass(a: &Assembled, direction: usize) -> f64 {
    let owners = a.dofs.owners();
    let mut unit = vec![0.0; owners.len()];
    for (g, &(node, d)) in owners.iter().enumerate() {
        unit[g] = match a.dofs.frame(node) {
            // A global translation e seen in a node's frame: Rᵀ e.
            Some(r) if d < 3 => r[(direction, d)],
            _ if d == direction => 1.0,
            _ => 0.0,
        };
    }
    let mu = mat_vec(&a.m, &unit);
    unit.iter().zip(&mu).map(|(u, v)| u * v).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fe::mesh::{GroundSpring, Spring};
    use nalgebra::Vector3;

    fn two_nodes() -> Mesh {
        let mut mesh = Mesh::default();
        mesh.add_node(Vector3::zeros());
        mesh.add_node(Vector3::new(1.0, 0.0, 0.0));
        mesh
    }

    #[test]
    fn contributions_to_one_entry_are_summed_and_constrained_dofs_dropped() {
        let mut mesh = two_nodes();
        for k in [100.0, 23.0] {
            mesh.ground_springs.push(GroundSpring {
                node: 1,
                stiffness: [k; 6],
                damping: [0.5; 6],
            });
        }
        mesh.springs.push(Spring {
            nodes: [0, 1],
            stiffness: [7.0; 6],
            damping: [0.0; 6],
        });
        mesh.clamp(0);
        let a = assemble(&mesh).unwrap();
        assert_eq!(a.dofs.n_free(), 6);
        let k = a.k.to_dense();
        let c = a.c.to_dense();
        for d in 0..6 {
            assert_eq!(k[(d, d)], 130.0);
            assert_eq!(c[(d, d)], 1.0);
        }
    }

    #[test]
    fn a_rigidly_linked_point_mass_moves_to_the_independent_node_with_its_lever_arm() {
        use crate::fe::mesh::{PointMass, RigidLink};
        use nalgebra::Matrix3;
        let mut mesh = two_nodes();
        mesh.nodes[1] = Vector3::new(0.5, -0.2, 0.3);
        mesh.ground_springs.push(GroundSpring {
            node: 0,
            stiffness: [1.0; 6],
            damping: [0.0; 6],
        });
        mesh.masses.push(PointMass {
            node: 1,
            mass: 2.0,
            inertia: Matrix3::from_diagonal(&Vector3::new(0.1, 0.2, 0.3)),
        });
        mesh.rigid_links.push(RigidLink {
            independent: 0,
            dependent: vec![1],
            components: [true; 6],
        });
        let a = assemble(&mesh).unwrap();
        assert_eq!(a.dofs.n_free(), 6);
        let m = a.m.to_dense();
        // Parallel-axis theorem: J + m (|r|² I − r rᵀ); coupling m [r]× between u and θ.
        let r = mesh.nodes[1];
        let j = Matrix3::from_diagonal(&Vector3::new(0.1, 0.2, 0.3))
            + 2.0 * (r.norm_squared() * Matrix3::identity() - r * r.transpose());
        for p in 0..3 {
            assert!((m[(p, p)] - 2.0).abs() < 1e-14);
            for q in 0..3 {
                assert!((m[(3 + p, 3 + q)] - j[(p, q)]).abs() < 1e-14);
            }
        }
        // Translation x couples to rotation y through z-offset: ∂(u + θ × r)_x/∂θ_y = r_z.
        assert!((m[(0, 4)] - 2.0 * r.z).abs() < 1e-14);
    }

    #[test]
    fn bad_node_reference_is_named() {
        let mut mesh = two_nodes();
        mesh.springs.push(Spring {
            nodes: [0, 9],
            stiffness: [1.0; 6],
            damping: [0.0; 6],
        });
        let err = assemble(&mesh).unwrap_err().to_string();
        assert!(err.contains("spring 0") && err.contains("node 9"), "{err}");
    }
}
