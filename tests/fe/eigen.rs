//! The sparse shift-invert block Lanczos solver against a second method: a dense generalized
//! symmetric eigen solve with nalgebra (Cholesky of M, symmetric eigen of L⁻¹ K L⁻ᵀ).

use engine_mount_chassis::eigen::lowest_modes;
use engine_mount_chassis::fe::assembly::{assemble, mat_vec, Assembled};
use engine_mount_chassis::fe::mesh::{
    Beam, BeamSection, GroundSpring, Material, Mesh, PointMass, Shell,
};
use nalgebra::{DMatrix, Matrix3, Vector3};

/// A small mixed model: a folded shell strip, a beam outrigger with a tip mass, optional springs.
fn model(grounded: bool) -> Mesh {
    let mut mesh = Mesh::default();
    let (nx, ny) = (6, 3);
    let mut id = vec![vec![0; ny + 1]; nx + 1];
    for (i, row) in id.iter_mut().enumerate() {
        for (j, slot) in row.iter_mut().enumerate() {
            let x = 0.1 * i as f64;
            // Fold along j = 2: the last strip rises at 60°.
            let (y, z) = if j <= 2 {
                (0.08 * j as f64, 0.0)
            } else {
                (0.16 + 0.04, 0.07)
            };
            *slot = mesh.add_node(Vector3::new(x, y, z));
        }
    }
    for i in 0..nx {
        for j in 0..ny {
            mesh.shells.push(Shell {
                nodes: [id[i][j], id[i + 1][j], id[i + 1][j + 1], id[i][j + 1]],
                material: Material::STEEL,
                thickness: 0.0015,
                bending_thickness: 0.0015,
                extra_mass_per_area: 2.0,
                section: None,
            });
        }
    }
    let tip = mesh.add_node(Vector3::new(0.3, -0.3, 0.1));
    mesh.beams.push(Beam {
        nodes: [id[3][0], tip],
        material: Material::STEEL,
        section: BeamSection::box_tube(0.02, 0.03, 0.002),
        orientation: Vector3::z(),
        extra_mass_per_length: 0.0,
    });
    mesh.masses.push(PointMass {
        node: tip,
        mass: 0.5,
        inertia: Matrix3::new(2e-3, 1e-4, 0.0, 1e-4, 3e-3, 0.0, 0.0, 0.0, 1e-3),
    });
    if grounded {
        for corner in [id[0][0], id[nx][0], id[0][ny], id[nx][ny]] {
            mesh.ground_springs.push(GroundSpring {
                node: corner,
                stiffness: [2e4, 3e4, 5e4, 0.0, 0.0, 0.0],
                damping: [0.0; 6],
            });
        }
    }
    mesh
}

fn dense(a: &engine_mount_chassis::fe::assembly::SparseMat) -> DMatrix<f64> {
    let d = a.to_dense();
    DMatrix::from_fn(d.nrows(), d.ncols(), |i, j| d[(i, j)])
}

fn reference(asm: &Assembled) -> Vec<f64> {
    let k = dense(&asm.k);
    let m = dense(&asm.m);
    let l = m.cholesky().expect("lumped M is positive definite").l();
    let l_inv = l.clone().try_inverse().unwrap();
    let a = &l_inv * k * l_inv.transpose();
    let a = (&a + a.transpose()) * 0.5;
    let mut ev: Vec<f64> = a.symmetric_eigen().eigenvalues.iter().copied().collect();
    ev.sort_by(f64::total_cmp);
    ev
}

fn compare(grounded: bool, n_modes: usize) {
    let asm = assemble(&model(grounded)).unwrap();
    let want = reference(&asm);
    let scale = want[n_modes - 1].abs();
    compare_with(&asm, &want, n_modes, -10.0, &|_, expected| {
        1e-8 * scale.max(expected.abs())
    });
}

/// Lanczos at `shift` against the dense eigenvalues `want`, each within `tolerance(mode,
/// expected)`; shapes checked for backward error and M-orthonormality.
fn compare_with(
    asm: &Assembled,
    want: &[f64],
    n_modes: usize,
    shift: f64,
    tolerance: &dyn Fn(usize, f64) -> f64,
) {
    let modes = lowest_modes(&asm.k, &asm.m, n_modes, shift).unwrap();
    for (i, (&got, &expected)) in modes.eigenvalues.iter().zip(want).enumerate() {
        assert!(
            (got - expected).abs() <= tolerance(i, expected),
            "shift {shift}, mode {i}: Lanczos {got}, dense {expected}"
        );
    }
    // Shapes: M-orthonormal, and a small normwise backward error
    // ‖Kφ − λMφ‖∞ / ((‖K‖∞ + |λ| ‖M‖∞) ‖φ‖∞).
    let inf_norm = |a: &DMatrix<f64>| {
        (0..a.nrows())
            .map(|i| a.row(i).abs().sum())
            .fold(0.0, f64::max)
    };
    let (k_norm, m_norm) = (inf_norm(&dense(&asm.k)), inf_norm(&dense(&asm.m)));
    for i in 0..n_modes {
        let phi: Vec<f64> = modes.shapes.col(i).iter().copied().collect();
        let kphi = mat_vec(&asm.k, &phi);
        let mphi = mat_vec(&asm.m, &phi);
        let lam = modes.eigenvalues[i];
        let res = kphi
            .iter()
            .zip(&mphi)
            .map(|(a, b)| (a - lam * b).abs())
            .fold(0.0, f64::max);
        let phi_norm = phi.iter().map(|a| a.abs()).fold(0.0, f64::max);
        let backward = res / ((k_norm + lam.abs() * m_norm) * phi_norm);
        assert!(backward < 1e-10, "mode {i}: backward error {backward:e}");
        for j in 0..n_modes {
            let psi: Vec<f64> = modes.shapes.col(j).iter().copied().collect();
            let dot: f64 = psi.iter().zip(&mphi).map(|(a, b)| a * b).sum();
            let expected = if i == j { 1.0 } else { 0.0 };
            assert!(
                (dot - expected).abs() < 1e-8,
                "M-orthonormality ({i},{j}) = {dot}"
            );
        }
    }
}

#[test]
fn lanczos_matches_a_dense_solve_on_a_supported_model() {
    compare(true, 20);
}

#[test]
fn lanczos_matches_a_dense_solve_with_six_rigid_body_modes() {
    compare(false, 16);
}

#[test]
fn a_shift_above_the_lowest_eigenvalue_is_reported() {
    let asm = assemble(&model(true)).unwrap();
    let err = lowest_modes(&asm.k, &asm.m, 4, 1e12)
        .unwrap_err()
        .to_string();
    assert!(err.contains("shift"), "{err}");
    let err = lowest_modes(&asm.k, &asm.m, 0, -1.0)
        .unwrap_err()
        .to_string();
    assert!(err.contains("n_modes"), "{err}");
}

/// Fixed-fixed chain of `n` unit masses and unit springs: λ_j = 2 (1 − cos(jπ/(n+1))).
fn chain(
    n: usize,
) -> (
    engine_mount_chassis::fe::assembly::SparseMat,
    engine_mount_chassis::fe::assembly::SparseMat,
) {
    use faer::sparse::{SparseColMat, Triplet};
    let mut k = Vec::new();
    let mut m = Vec::new();
    for i in 0..n {
        k.push(Triplet::new(i, i, 2.0));
        m.push(Triplet::new(i, i, 1.0));
        if i + 1 < n {
            k.push(Triplet::new(i, i + 1, -1.0));
            k.push(Triplet::new(i + 1, i, -1.0));
        }
    }
    (
        SparseColMat::try_new_from_triplets(n, n, &k).unwrap(),
        SparseColMat::try_new_from_triplets(n, n, &m).unwrap(),
    )
}

#[test]
fn small_systems_and_all_of_their_modes() {
    // Fewer DOFs than two Lanczos blocks, and sizes that are no multiple of the block width.
    for (n, wanted) in [(5, 5), (12, 12), (13, 4), (21, 21)] {
        let (k, m) = chain(n);
        let modes = lowest_modes(&k, &m, wanted, -0.1)
            .unwrap_or_else(|e| panic!("n = {n}, {wanted} modes: {e}"));
        assert_eq!(modes.eigenvalues.len(), wanted);
        for (j, lambda) in modes.eigenvalues.iter().enumerate() {
            let exact =
                2.0 * (1.0 - ((j + 1) as f64 * std::f64::consts::PI / (n + 1) as f64).cos());
            assert!(
                (lambda - exact).abs() < 1e-10 * exact.max(1.0),
                "n = {n}, mode {j}: {lambda} vs {exact}"
            );
        }
    }
}

/// A free straight steel bar, 0.2 m long and 20 mm square, of 16 beam elements: six rigid-body
/// modes and a first bending mode near 2.6 kHz, so that at σ = −1 the shift-inverted
/// rigid-body θ = 1 stand 3e8 times above the elastic ones (rotary inertia and short elements
/// make the top of the spectrum, and the conditioning of K − σM, worse still).
fn free_bar() -> Mesh {
    let mut mesh = Mesh::default();
    let n = 16;
    let ids: Vec<usize> = (0..=n)
        .map(|i| mesh.add_node(Vector3::new(0.2 * i as f64 / n as f64, 0.0, 0.0)))
        .collect();
    for pair in ids.windows(2) {
        mesh.beams.push(Beam {
            nodes: [pair[0], pair[1]],
            material: Material::STEEL,
            section: BeamSection::box_tube(0.02, 0.02, 0.01),
            orientation: Vector3::z(),
            extra_mass_per_length: 0.0,
        });
    }
    mesh
}

#[test]
fn a_free_stiff_bar_at_shift_minus_one_matches_a_dense_solve() {
    let asm = assemble(&free_bar()).unwrap();
    let want = reference(&asm);
    let first_elastic = want[6];
    println!(
        "first elastic {first_elastic:e}, largest {:e}",
        want[want.len() - 1]
    );
    // Rigid-body modes near zero on the scale of the first elastic one, elastic ones to 1e-8.
    compare_with(&asm, &want, 16, -1.0, &|i, expected| {
        if i < 6 {
            1e-9 * first_elastic
        } else {
            1e-8 * expected
        }
    });
}
