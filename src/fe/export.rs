//! Export of K, M (Matrix Market, coordinate real symmetric, lower triangle) and of the node and
//! DOF tables (CSV), so the matrices can be checked with another tool (scipy.io.mmread, Octave).

use std::fmt::Write as _;
use std::path::Path;

use super::assembly::{Assembled, SparseMat};
use super::error::FeError;
use super::mesh::Mesh;

/// Matrix Market text of the lower triangle of the symmetric `a` (1-based indices).
pub fn matrix_market(a: &SparseMat, comment: &str) -> String {
    let (cp, ri, val) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
    let mut entries = Vec::new();
    for j in 0..a.ncols() {
        for p in cp[j]..cp[j + 1] {
            if ri[p] >= j && val[p] != 0.0 {
                entries.push((ri[p], j, val[p]));
            }
        }
    }
    let mut s = String::from("%%MatrixMarket matrix coordinate real symmetric\n");
    for line in comment.lines() {
        let _ = writeln!(s, "% {line}");
    }
    let _ = writeln!(s, "{} {} {}", a.nrows(), a.ncols(), entries.len());
    for (i, j, v) in entries {
        let _ = writeln!(s, "{} {} {:.17e}", i + 1, j + 1, v);
    }
    s
}

/// CSV of the nodes: `node,x,y,z,name` (name of a named node, else empty).
pub fn node_table(mesh: &Mesh) -> String {
    let mut names = vec![String::new(); mesh.nodes.len()];
    for (name, &k) in &mesh.named_nodes {
        if let Some(slot) = names.get_mut(k) {
            *slot = name.clone();
        }
    }
    let mut s = String::from("node,x,y,z,name\n");
    for (k, p) in mesh.nodes.iter().enumerate() {
        let _ = writeln!(s, "{k},{:.6},{:.6},{:.6},{}", p.x, p.y, p.z, names[k]);
    }
    s
}

/// CSV of the DOF map: `index,node,dof` for every free DOF (dof 0..5 = ux uy uz rx ry rz).
pub fn dof_table(asm: &Assembled) -> String {
    let mut s = String::from("index,node,dof\n");
    for (g, (node, dof)) in asm.dofs.owners().into_iter().enumerate() {
        let _ = writeln!(s, "{g},{node},{dof}");
    }
    s
}

/// Writes `K.mtx`, `M.mtx`, `nodes.csv` and `dofs.csv` into `dir` (created if missing).
pub fn write_all(dir: &Path, mesh: &Mesh, asm: &Assembled) -> Result<(), FeError> {
    let io = |e: std::io::Error| FeError::Io(format!("{}: {e}", dir.display()));
    std::fs::create_dir_all(dir).map_err(io)?;
    let files = [
        (
            "K.mtx",
            matrix_market(&asm.k, "stiffness [N/m, N m/rad]; DOF order in dofs.csv"),
        ),
        (
            "M.mtx",
            matrix_market(&asm.m, "lumped mass [kg, kg m^2]; DOF order in dofs.csv"),
        ),
        ("nodes.csv", node_table(mesh)),
        ("dofs.csv", dof_table(asm)),
    ];
    for (name, text) in files {
        let path = dir.join(name);
        std::fs::write(&path, text).map_err(|e| FeError::Io(format!("{}: {e}", path.display())))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::sparse::{SparseColMat, Triplet};

    #[test]
    fn written_files_read_back_to_the_assembled_matrices() {
        use crate::fe::assembly::assemble;
        use crate::fe::mesh::{Beam, BeamSection, GroundSpring, Material};
        use nalgebra::Vector3;
        let mut mesh = Mesh::default();
        for x in [0.0, 0.4, 1.0] {
            mesh.add_node(Vector3::new(x, 0.1 * x, 0.0));
        }
        for nodes in [[0, 1], [1, 2]] {
            mesh.beams.push(Beam {
                nodes,
                material: Material::STEEL,
                section: BeamSection::box_tube(0.03, 0.05, 0.002),
                orientation: Vector3::z(),
                extra_mass_per_length: 1.0,
            });
        }
        mesh.ground_springs.push(GroundSpring {
            node: 0,
            stiffness: [1e5; 6],
            damping: [0.0; 6],
        });
        mesh.named_nodes.insert("tip".into(), 2);
        let asm = assemble(&mesh).unwrap();
        let dir = std::env::temp_dir().join(format!("fe_export_test_{}", std::process::id()));
        write_all(&dir, &mesh, &asm).unwrap();
        for (file, matrix) in [("K.mtx", &asm.k), ("M.mtx", &asm.m)] {
            let text = std::fs::read_to_string(dir.join(file)).unwrap();
            let dense = matrix.to_dense();
            let mut read = faer::Mat::<f64>::zeros(dense.nrows(), dense.ncols());
            for line in text.lines().filter(|l| !l.starts_with('%')).skip(1) {
                let f: Vec<&str> = line.split_whitespace().collect();
                let (i, j): (usize, usize) = (f[0].parse().unwrap(), f[1].parse().unwrap());
                let v: f64 = f[2].parse().unwrap();
                read[(i - 1, j - 1)] = v;
                read[(j - 1, i - 1)] = v;
            }
            for j in 0..dense.ncols() {
                for i in 0..dense.nrows() {
                    let (a, b) = (dense[(i, j)], read[(i, j)]);
                    assert!(
                        (a - b).abs() <= 1e-15 * a.abs().max(1.0),
                        "{file} ({i},{j}): {a} vs {b}"
                    );
                }
            }
        }
        let nodes = std::fs::read_to_string(dir.join("nodes.csv")).unwrap();
        assert!(nodes.lines().nth(3).unwrap().ends_with(",tip"));
        let dofs = std::fs::read_to_string(dir.join("dofs.csv")).unwrap();
        assert_eq!(dofs.lines().count(), 1 + asm.dofs.n_free());
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn matrix_market_lists_the_lower_triangle_one_based() {
        let a = SparseColMat::<usize, f64>::try_new_from_triplets(
            2,
            2,
            &[
                Triplet::new(0, 0, 2.0),
                Triplet::new(1, 0, -1.0),
                Triplet::new(0, 1, -1.0),
                Triplet::new(1, 1, 3.0),
            ],
        )
        .unwrap();
        let text = matrix_market(&a, "test");
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[0], "%%MatrixMarket matrix coordinate real symmetric");
        assert_eq!(lines[2], "2 2 3");
        let parsed: Vec<(usize, usize, f64)> = lines[3..]
            .iter()
            .map(|l| {
                let f: Vec<&str> = l.split_whitespace().collect();
                (
                    f[0].parse().unwrap(),
                    f[1].parse().unwrap(),
                    f[2].parse().unwrap(),
                )
            })
            .collect();
        assert_eq!(parsed, vec![(1, 1, 2.0), (2, 1, -1.0), (2, 2, 3.0)]);
    }
}
