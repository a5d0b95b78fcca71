//! Element verification against analytic theory: Euler-Bernoulli / Saint-Venant cantilever,
//! Kirchhoff simply supported plate, membrane patch test, rigid-body mode counts.

use std::f64::consts::PI;

use engine_mount_chassis::eigen::{lowest_modes, Modes};
use engine_mount_chassis::fe::assembly::{assemble, Assembled};
use engine_mount_chassis::fe::mesh::{Beam, BeamSection, Material, Mesh, Shell};
use faer::prelude::Solve;
use faer::Mat;
use nalgebra::Vector3;

const STEEL: Material = Material::STEEL;

/// Fraction of the mode's kinetic energy in local DOF `dof` (diagonal of M, good for lumped M).
fn dof_fraction(a: &Assembled, modes: &Modes, mode: usize, dofs: &[usize]) -> f64 {
    let owners = a.dofs.owners();
    let diag = diagonal(a);
    let mut part = 0.0;
    let mut total = 0.0;
    for (g, &(_, d)) in owners.iter().enumerate() {
        let e = diag[g] * modes.shapes[(g, mode)].powi(2);
        total += e;
        if dofs.contains(&d) {
            part += e;
        }
    }
    part / total
}

fn diagonal(a: &Assembled) -> Vec<f64> {
    let m = &a.m;
    let (cp, ri, val) = (m.symbolic().col_ptr(), m.symbolic().row_idx(), m.val());
    let mut d = vec![0.0; m.nrows()];
    for j in 0..m.ncols() {
        for p in cp[j]..cp[j + 1] {
            if ri[p] == j {
                d[j] += val[p];
            }
        }
    }
    d
}

#[test]
fn cantilever_bending_and_torsion_frequencies_match_theory_within_one_percent() {
    let (length, n_el) = (1.0, 20);
    // Deliberately unequal: iy (z-bending) ≪ iz so the bending families separate.
    let section = BeamSection::rigid_in_shear(4.0e-4, 2.0e-9, 8.0e-8, 6.0e-9);
    let mut mesh = Mesh::default();
    for i in 0..=n_el {
        mesh.add_node(Vector3::new(length * i as f64 / n_el as f64, 0.0, 0.0));
    }
    for i in 0..n_el {
        mesh.beams.push(Beam {
            nodes: [i, i + 1],
            material: STEEL,
            section,
            orientation: Vector3::new(0.0, 1.0, 0.0),
            extra_mass_per_length: 0.0,
        });
    }
    mesh.clamp(0);
    let a = assemble(&mesh).unwrap();
    let modes = lowest_modes(&a.k, &a.m, 12, -1.0).unwrap();
    let f = modes.frequencies_hz();

    let rho_a = STEEL.density * section.area;
    let bending = |beta_l: f64| {
        beta_l * beta_l / (2.0 * PI * length * length)
            * (STEEL.youngs_modulus * section.iy / rho_a).sqrt()
    };
    let expected_bending = [1.875_104_1, 4.694_091_1, 7.854_757_4].map(bending);
    let polar = section.iy + section.iz;
    let expected_torsion =
        1.0 / (4.0 * length) * (STEEL.shear_modulus() * section.j / (STEEL.density * polar)).sqrt();

    let z_bending: Vec<f64> = (0..modes.len())
        .filter(|&i| dof_fraction(&a, &modes, i, &[2, 4]) > 0.9)
        .map(|i| f[i])
        .collect();
    let torsion: Vec<f64> = (0..modes.len())
        .filter(|&i| dof_fraction(&a, &modes, i, &[3]) > 0.9)
        .map(|i| f[i])
        .collect();
    assert!(
        z_bending.len() >= 3 && !torsion.is_empty(),
        "modes found: {f:?}"
    );
    for (got, want) in z_bending.iter().zip(&expected_bending) {
        let err = (got - want).abs() / want;
        println!(
            "bending: FE {got:.4} Hz, theory {want:.4} Hz, error {:.3} %",
            100.0 * err
        );
        assert!(err < 0.01, "bending FE {got} vs theory {want}");
    }
    let err = (torsion[0] - expected_torsion).abs() / expected_torsion;
    println!(
        "torsion: FE {:.3} Hz, theory {expected_torsion:.3} Hz, error {:.3} %",
        torsion[0],
        100.0 * err
    );
    assert!(err < 0.01);
}

/// Square plate a × a of `n` × `n` shells in the x-y plane, hard simple support on all edges.
/// `distortion` moves interior nodes by up to that fraction of the element size (deterministic
/// pattern), so the elements become general quadrilaterals.
fn simply_supported_plate_frequency(thickness: f64, n: usize, distortion: f64) -> (f64, f64) {
    let a = 1.0;
    let mut mesh = Mesh::default();
    let id = |i: usize, j: usize| i * (n + 1) + j;
    let h = a / n as f64;
    for i in 0..=n {
        for j in 0..=n {
            let interior = i > 0 && i < n && j > 0 && j < n;
            let (dx, dy) = if interior {
                let s = (i * 7 + j * 13) as f64;
                (distortion * h * s.sin(), distortion * h * (1.7 * s).cos())
            } else {
                (0.0, 0.0)
            };
            mesh.add_node(Vector3::new(h * i as f64 + dx, h * j as f64 + dy, 0.0));
        }
    }
    for i in 0..n {
        for j in 0..n {
            mesh.shells.push(Shell {
                nodes: [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)],
                material: STEEL,
                thickness,
                bending_thickness: thickness,
                extra_mass_per_area: 0.0,
                section: None,
            });
        }
    }
    for i in 0..=n {
        for j in 0..=n {
            let node = id(i, j);
            // In-plane DOFs play no role in bending; fix them at the boundary to remove the
            // membrane rigid-body modes.
            let on_x_edge = i == 0 || i == n;
            let on_y_edge = j == 0 || j == n;
            if on_x_edge || on_y_edge {
                mesh.constraints.extend([(node, 0), (node, 1), (node, 2)]);
            }
            if on_x_edge {
                mesh.constraints.push((node, 3)); // tangential rotation along an x = const edge
            }
            if on_y_edge {
                mesh.constraints.push((node, 4));
            }
        }
    }
    mesh.constraints.sort();
    mesh.constraints.dedup();
    let asm = assemble(&mesh).unwrap();
    let modes = lowest_modes(&asm.k, &asm.m, 1, -1.0).unwrap();
    let d = STEEL.youngs_modulus * thickness.powi(3) / (12.0 * (1.0 - STEEL.poisson_ratio.powi(2)));
    let omega = 2.0 * PI * PI / (a * a) * (d / (STEEL.density * thickness)).sqrt();
    (modes.frequencies_hz()[0], omega / (2.0 * PI))
}

#[test]
fn simply_supported_plate_first_frequency_within_two_percent_thick_and_very_thin() {
    for thickness in [1.0e-2, 1.0e-3] {
        let (fe, theory) = simply_supported_plate_frequency(thickness, 16, 0.0);
        let err = (fe - theory).abs() / theory;
        println!(
            "t/a = {thickness}: FE {fe:.4} Hz, Kirchhoff {theory:.4} Hz, error {:.3} %",
            100.0 * err
        );
        assert!(err < 0.02, "t = {thickness}: FE {fe} vs Kirchhoff {theory}");
    }
}

#[test]
fn distorted_thin_plate_does_not_lock() {
    for thickness in [1.0e-2, 1.0e-3] {
        let (fe, theory) = simply_supported_plate_frequency(thickness, 16, 0.2);
        let err = (fe - theory).abs() / theory;
        println!(
            "distorted mesh, t/a = {thickness}: FE {fe:.4} Hz, Kirchhoff {theory:.4} Hz, error {:.3} %",
            100.0 * err
        );
        assert!(err < 0.02, "t = {thickness}: FE {fe} vs Kirchhoff {theory}");
    }
}

#[test]
fn in_plane_bending_of_a_one_element_deep_strip_matches_beam_theory() {
    // Pure bending (tip couple) of a 1 × 0.1 strip meshed 10 × 1: the bilinear membrane alone
    // would be several times too stiff (parasitic shear); the incompatible modes make it exact.
    let (length, depth, thickness, n) = (1.0, 0.1, 0.01, 10);
    let mut mesh = Mesh::default();
    for i in 0..=n {
        for y in [-depth / 2.0, depth / 2.0] {
            mesh.add_node(Vector3::new(length * i as f64 / n as f64, y, 0.0));
        }
    }
    for i in 0..n {
        mesh.shells.push(Shell {
            nodes: [2 * i, 2 * i + 2, 2 * i + 3, 2 * i + 1],
            material: STEEL,
            thickness,
            bending_thickness: thickness,
            extra_mass_per_area: 0.0,
            section: None,
        });
    }
    for node in 0..mesh.nodes.len() {
        mesh.constraints.extend([(node, 2), (node, 3), (node, 4)]);
    }
    mesh.constraints.extend([(0, 0), (0, 1), (1, 0), (1, 1)]);
    let asm = assemble(&mesh).unwrap();
    let force = 100.0;
    let (bottom, top) = (2 * n, 2 * n + 1);
    let mut f = Mat::<f64>::zeros(asm.dofs.n_free(), 1);
    f[(asm.dofs.global(top, 0).unwrap(), 0)] = force;
    f[(asm.dofs.global(bottom, 0).unwrap(), 0)] = -force;
    let u = asm.k.to_dense().full_piv_lu().solve(&f);
    let tip = 0.5
        * (u[(asm.dofs.global(top, 1).unwrap(), 0)] + u[(asm.dofs.global(bottom, 1).unwrap(), 0)]);
    let inertia = thickness * depth.powi(3) / 12.0;
    let theory = force * depth * length * length / (2.0 * STEEL.youngs_modulus * inertia);
    let err = (tip.abs() - theory).abs() / theory;
    println!(
        "tip deflection {:.6e} m, beam theory {theory:.6e} m, error {:.3} %",
        tip.abs(),
        100.0 * err
    );
    assert!(err < 0.01, "tip {tip} vs {theory}");
}

#[test]
fn membrane_patch_test_reproduces_a_linear_displacement_field_exactly() {
    // MacNeal-Harder distorted patch: 0.24 × 0.12 with four irregular interior nodes.
    let pts = [
        (0.0, 0.0),
        (0.24, 0.0),
        (0.24, 0.12),
        (0.0, 0.12),
        (0.04, 0.02),
        (0.18, 0.03),
        (0.16, 0.08),
        (0.08, 0.08),
    ];
    let mut mesh = Mesh::default();
    for (x, y) in pts {
        mesh.add_node(Vector3::new(x, y, 0.0));
    }
    for nodes in [
        [0, 1, 5, 4],
        [1, 2, 6, 5],
        [2, 3, 7, 6],
        [3, 0, 4, 7],
        [4, 5, 6, 7],
    ] {
        mesh.shells.push(Shell {
            nodes,
            material: STEEL,
            thickness: 0.001,
            bending_thickness: 0.001,
            extra_mass_per_area: 0.0,
            section: None,
        });
    }
    let asm = assemble(&mesh).unwrap();
    let n = asm.dofs.n_free();
    let k = asm.k.to_dense();
    let exact = |x: f64, y: f64| [1e-3 * (x + 0.5 * y), 1e-3 * (y + 0.5 * x)];
    // Prescribed: u, v at the corners, and every out-of-plane DOF and drill rotation except the
    // interior θz (the exact field has zero rotation).
    let mut prescribed = vec![None; n];
    for (node, &(x, y)) in pts.iter().enumerate() {
        let g = |d| asm.dofs.global(node, d).unwrap();
        for d in [2, 3, 4] {
            prescribed[g(d)] = Some(0.0);
        }
        if node < 4 {
            let u = exact(x, y);
            prescribed[g(0)] = Some(u[0]);
            prescribed[g(1)] = Some(u[1]);
            prescribed[g(5)] = Some(0.0);
        }
    }
    let free: Vec<usize> = (0..n).filter(|&i| prescribed[i].is_none()).collect();
    let mut kff = Mat::<f64>::zeros(free.len(), free.len());
    let mut rhs = Mat::<f64>::zeros(free.len(), 1);
    for (r, &i) in free.iter().enumerate() {
        for (c, &j) in free.iter().enumerate() {
            kff[(r, c)] = k[(i, j)];
        }
        for j in 0..n {
            if let Some(v) = prescribed[j] {
                rhs[(r, 0)] -= k[(i, j)] * v;
            }
        }
    }
    let sol = kff.full_piv_lu().solve(&rhs);
    for (node, &(x, y)) in pts.iter().enumerate().skip(4) {
        let want = exact(x, y);
        for (d, &want_d) in want.iter().enumerate() {
            let r = free
                .iter()
                .position(|&f| f == asm.dofs.global(node, d).unwrap())
                .unwrap();
            assert!(
                (sol[(r, 0)] - want_d).abs() < 1e-12,
                "node {node} dof {d}: {} vs {want_d}",
                sol[(r, 0)]
            );
        }
        let r = free
            .iter()
            .position(|&f| f == asm.dofs.global(node, 5).unwrap())
            .unwrap();
        assert!(
            sol[(r, 0)].abs() < 1e-12,
            "node {node}: drill rotation {}",
            sol[(r, 0)]
        );
    }
}

fn count_zero_modes(mesh: &Mesh) -> (usize, Vec<f64>) {
    let asm = assemble(mesh).unwrap();
    let modes = lowest_modes(&asm.k, &asm.m, 10, -1.0).unwrap();
    let f = modes.frequencies_hz();
    (f.iter().filter(|&&v| v < 1e-3).count(), f)
}

fn grid(
    mesh: &mut Mesh,
    origin: Vector3<f64>,
    du: Vector3<f64>,
    dv: Vector3<f64>,
    n: usize,
) -> Vec<Vec<usize>> {
    let ids: Vec<Vec<usize>> = (0..=n)
        .map(|i| {
            (0..=n)
                .map(|j| mesh.add_node(origin + du * i as f64 + dv * j as f64))
                .collect()
        })
        .collect();
    for i in 0..n {
        for j in 0..n {
            mesh.shells.push(Shell {
                nodes: [ids[i][j], ids[i + 1][j], ids[i + 1][j + 1], ids[i][j + 1]],
                material: STEEL,
                thickness: 0.002,
                bending_thickness: 0.002,
                extra_mass_per_area: 0.0,
                section: None,
            });
        }
    }
    ids
}

#[test]
fn free_flat_and_folded_shells_have_exactly_six_zero_frequency_modes() {
    let mut flat = Mesh::default();
    grid(
        &mut flat,
        Vector3::zeros(),
        Vector3::new(0.1, 0.02, 0.0),
        Vector3::new(-0.01, 0.12, 0.0),
        4,
    );
    let (zeros, f) = count_zero_modes(&flat);
    println!("flat: {f:?}");
    assert_eq!(zeros, 6, "flat plate frequencies {f:?}");
    assert!(f[6] > 1.0);

    // Folded: two panels meeting at a 90° fold, sharing the fold-line nodes.
    let mut folded = Mesh::default();
    let a = grid(
        &mut folded,
        Vector3::zeros(),
        Vector3::new(0.1, 0.0, 0.0),
        Vector3::new(0.0, 0.1, 0.0),
        4,
    );
    let fold: Vec<usize> = a.iter().map(|row| row[4]).collect();
    let b = grid(
        &mut folded,
        Vector3::new(0.0, 0.4, 0.0),
        Vector3::new(0.1, 0.0, 0.0),
        Vector3::new(0.0, 0.0, 0.1),
        4,
    );
    // Merge panel b's first column (on the fold line) into panel a's fold nodes.
    let remap: Vec<(usize, usize)> = b.iter().zip(&fold).map(|(row, &f)| (row[0], f)).collect();
    for s in &mut folded.shells {
        for n in &mut s.nodes {
            if let Some(&(_, f)) = remap.iter().find(|(from, _)| from == n) {
                *n = f;
            }
        }
    }
    // The duplicated nodes are now unused: give them a grounded spring so they stay regular.
    for &(dup, _) in &remap {
        folded.clamp(dup);
    }
    let (zeros, f) = count_zero_modes(&folded);
    println!("folded: {f:?}");
    assert_eq!(zeros, 6, "folded structure frequencies {f:?}");
    assert!(f[6] > 1.0);
}
