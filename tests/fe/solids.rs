//! Solid elements (CTETRA 4/10, CPENTA 6, CHEXA 8 with PSOLID/MAT1) against closed forms:
//! constant-strain patch tests on distorted meshes, rigid-body modes, mass = ρV (volumes by the
//! divergence theorem over the faces), consistent mass matrices of the tetrahedra, cantilever
//! deflection and frequencies against Euler-Bernoulli, axial bar frequencies, deck errors.

use std::f64::consts::PI;
use std::fmt::Write;

use engine_mount_chassis::eigen::{lowest_modes, Modes};
use engine_mount_chassis::fe::assembly::{assemble, translational_mass, Assembled};
use engine_mount_chassis::fe::checks::{check_assembled, check_mesh, CheckLimits};
use engine_mount_chassis::fe::elements::Entity;
use engine_mount_chassis::fe::mesh::{Material, Mesh, Solid};
use engine_mount_chassis::fe::solid::{self, SolidKind};
use engine_mount_chassis::nastran::{parse_str, write_bulk_deck};
use faer::linalg::solvers::Solve;
use faer::{Mat, Side};
use nalgebra::{Matrix3, Vector3, Vector6};

const STEEL: Material = Material::STEEL;
const KINDS: [SolidKind; 4] = [
    SolidKind::Tetra4,
    SolidKind::Tetra10,
    SolidKind::Penta6,
    SolidKind::Hexa8,
];

/// Deterministic numbers in [−1, 1].
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }
}

/// A block of (nx × ny × nz) cells of size `size`, split into elements of `kind`: hexahedra,
/// two wedges per cell, or six tetrahedra per cell (Kuhn's split, conforming), with mid-edge
/// nodes at the edge midpoints for the 10-node tetrahedron. Returns the node positions and the
/// element node lists (Nastran order).
struct Block {
    nodes: Vec<Vector3<f64>>,
    elements: Vec<Vec<usize>>,
}

fn block(kind: SolidKind, n: [usize; 3], size: [f64; 3], distortion: f64, seed: u64) -> Block {
    let id = |i: usize, j: usize, k: usize| i + (n[0] + 1) * (j + (n[1] + 1) * k);
    let mut rng = Lcg(seed);
    let h = [
        size[0] / n[0] as f64,
        size[1] / n[1] as f64,
        size[2] / n[2] as f64,
    ];
    let mut nodes = Vec::new();
    for k in 0..=n[2] {
        for j in 0..=n[1] {
            for i in 0..=n[0] {
                let idx = [i, j, k];
                let mut p = Vector3::new(i as f64 * h[0], j as f64 * h[1], k as f64 * h[2]);
                // Interior nodes move in all directions, boundary nodes only within their
                // face or edge: the block keeps its outer shape and volume.
                for d in 0..3 {
                    let r = rng.next();
                    if idx[d] > 0 && idx[d] < n[d] {
                        p[d] += distortion * h[d] * r;
                    }
                }
                nodes.push(p);
            }
        }
    }
    let mut elements = Vec::new();
    for k in 0..n[2] {
        for j in 0..n[1] {
            for i in 0..n[0] {
                let c = |a: usize, b: usize, e: usize| id(i + a, j + b, k + e);
                let hexa = [
                    c(0, 0, 0),
                    c(1, 0, 0),
                    c(1, 1, 0),
                    c(0, 1, 0),
                    c(0, 0, 1),
                    c(1, 0, 1),
                    c(1, 1, 1),
                    c(0, 1, 1),
                ];
                match kind {
                    SolidKind::Hexa8 => elements.push(hexa.to_vec()),
                    SolidKind::Penta6 => {
                        for t in [[0, 1, 2], [0, 2, 3]] {
                            let mut e: Vec<usize> = t.iter().map(|&a| hexa[a]).collect();
                            e.extend(t.iter().map(|&a| hexa[a + 4]));
                            elements.push(e);
                        }
                    }
                    SolidKind::Tetra4 | SolidKind::Tetra10 => {
                        for perm in [
                            [0, 1, 2],
                            [0, 2, 1],
                            [1, 0, 2],
                            [1, 2, 0],
                            [2, 0, 1],
                            [2, 1, 0],
                        ] {
                            let mut v = [0usize; 3];
                            let mut tet = vec![c(0, 0, 0)];
                            for &d in &perm {
                                v[d] = 1;
                                tet.push(c(v[0], v[1], v[2]));
                            }
                            elements.push(tet);
                        }
                    }
                }
            }
        }
    }
    if kind == SolidKind::Tetra10 {
        let mut mid: std::collections::BTreeMap<(usize, usize), usize> = Default::default();
        for e in &mut elements {
            let corners = [e[0], e[1], e[2], e[3]];
            for [a, b] in [[0, 1], [1, 2], [2, 0], [0, 3], [1, 3], [2, 3]] {
                let key = (corners[a].min(corners[b]), corners[a].max(corners[b]));
                let m = *mid.entry(key).or_insert_with(|| {
                    nodes.push((nodes[key.0] + nodes[key.1]) * 0.5);
                    nodes.len() - 1
                });
                e.push(m);
            }
        }
    }
    Block { nodes, elements }
}

fn mesh_of(b: &Block, material: Material) -> Mesh {
    let mut mesh = Mesh::default();
    for p in &b.nodes {
        mesh.add_node(*p);
    }
    for e in &b.elements {
        mesh.solids.push(Solid {
            nodes: e.clone(),
            material,
        });
    }
    mesh
}

fn strain_of(grad: &Matrix3<f64>) -> Vector6<f64> {
    Vector6::new(
        grad[(0, 0)],
        grad[(1, 1)],
        grad[(2, 2)],
        grad[(0, 1)] + grad[(1, 0)],
        grad[(1, 2)] + grad[(2, 1)],
        grad[(2, 0)] + grad[(0, 2)],
    )
}

fn on_boundary(p: &Vector3<f64>, size: [f64; 3]) -> bool {
    (0..3).any(|d| p[d].abs() < 1e-12 || (p[d] - size[d]).abs() < 1e-12)
}

#[test]
fn constant_strain_patch_test_is_passed_exactly_on_distorted_meshes() {
    let size = [1.0, 0.8, 1.2];
    let material = Material {
        youngs_modulus: 1.0e3,
        poisson_ratio: 0.25,
        density: 1.0,
    };
    // u = a + G x with a general gradient: all six strains plus a rotation.
    let a = Vector3::new(1e-3, -2e-3, 0.5e-3);
    let g = Matrix3::new(
        1.0e-3, 0.4e-3, -0.3e-3, -0.2e-3, -0.7e-3, 0.5e-3, 0.6e-3, 0.1e-3, 0.8e-3,
    );
    let exact = |p: &Vector3<f64>| a + g * p;
    let eps = strain_of(&g);
    let sigma = solid::elasticity(&material) * eps;
    for kind in KINDS {
        let b = block(kind, [3, 3, 3], size, 0.2, 7);
        let mesh = mesh_of(&b, material);
        let asm = assemble(&mesh).unwrap();
        let owners = asm.dofs.owners();
        assert!(owners.iter().all(|&(_, d)| d < 3), "rotations removed");
        let k = asm.k.to_dense();
        let n = owners.len();
        let prescribed: Vec<Option<f64>> = owners
            .iter()
            .map(|&(node, d)| on_boundary(&b.nodes[node], size).then(|| exact(&b.nodes[node])[d]))
            .collect();
        let free: Vec<usize> = (0..n).filter(|&i| prescribed[i].is_none()).collect();
        assert!(free.len() >= 24, "{kind:?}: {} free DOFs", free.len());
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
        let mut u = vec![0.0; n];
        for (i, p) in prescribed.iter().enumerate() {
            u[i] = p.unwrap_or(0.0);
        }
        for (r, &i) in free.iter().enumerate() {
            u[i] = sol[(r, 0)];
        }
        let mut worst = 0.0f64;
        for (i, &(node, d)) in owners.iter().enumerate() {
            worst = worst.max((u[i] - exact(&b.nodes[node])[d]).abs());
        }
        // Strain energy against ½ σ:ε V with V the block's volume.
        let ku: Vec<f64> = (0..n)
            .map(|i| (0..n).map(|j| k[(i, j)] * u[j]).sum())
            .collect();
        let energy = 0.5 * u.iter().zip(&ku).map(|(a, b)| a * b).sum::<f64>();
        let volume = size[0] * size[1] * size[2];
        let energy_exact = 0.5 * sigma.dot(&eps) * volume;
        // Stresses at every integration point of every element.
        let mut worst_stress = 0.0f64;
        for (e, s) in mesh.solids.iter().enumerate() {
            let x: Vec<Vector3<f64>> = s.nodes.iter().map(|&k| b.nodes[k]).collect();
            let ue: Vec<Vector3<f64>> = s
                .nodes
                .iter()
                .map(|&node| Vector3::from_fn(|d, _| u[asm.dofs.global(node, d).unwrap()]))
                .collect();
            for strain in solid::strains(e, s, &x, &ue).unwrap() {
                let st = solid::elasticity(&material) * Vector6::from(strain);
                worst_stress = worst_stress.max((st - sigma).amax());
            }
        }
        println!(
            "{kind:?}: {} elements, {} interior DOFs, max |u − u_exact| = {worst:.2e}, energy \
             {energy:.10e} vs {energy_exact:.10e}, max stress error {worst_stress:.2e} (σ ~ {:.2e})",
            mesh.solids.len(),
            free.len(),
            sigma.amax()
        );
        assert!(worst < 1e-12, "{kind:?}: displacement error {worst}");
        assert!(
            ((energy - energy_exact) / energy_exact).abs() < 1e-10,
            "{kind:?} energy"
        );
        assert!(
            worst_stress < 1e-9 * sigma.amax(),
            "{kind:?} stress {worst_stress}"
        );
    }
}

/// A single element of each kind with distorted, non-planar faces (and a mirrored numbering
/// for the wedge, which must be accepted like Nastran does).
fn distorted(kind: SolidKind) -> Vec<Vector3<f64>> {
    let v = |x: f64, y: f64, z: f64| Vector3::new(x, y, z);
    match kind {
        SolidKind::Tetra4 => vec![
            v(0.1, 0.0, -0.1),
            v(1.2, 0.2, 0.1),
            v(0.3, 0.9, 0.0),
            v(0.4, 0.3, 1.1),
        ],
        SolidKind::Tetra10 => {
            let c = distorted(SolidKind::Tetra4);
            let mut x = c.clone();
            for [a, b] in [[0, 1], [1, 2], [2, 0], [0, 3], [1, 3], [2, 3]] {
                x.push((c[a] + c[b]) * 0.5);
            }
            x
        }
        SolidKind::Penta6 => vec![
            // G1..G3 clockwise seen from G4..G6: the mirrored numbering.
            v(0.0, 0.0, 0.0),
            v(0.1, 1.1, 0.1),
            v(1.0, 0.1, -0.1),
            v(0.1, -0.1, 0.9),
            v(0.0, 0.9, 1.2),
            v(1.3, 0.2, 1.0),
        ],
        SolidKind::Hexa8 => vec![
            v(0.0, 0.0, 0.0),
            v(1.1, 0.1, 0.1),
            v(1.2, 0.9, -0.1),
            v(-0.1, 1.0, 0.05),
            v(0.1, -0.1, 1.0),
            v(0.9, 0.0, 1.3),
            v(1.0, 1.1, 0.9),
            v(0.0, 0.8, 1.1),
        ],
    }
}

/// Volume enclosed by the element's faces (bilinear quadrilaterals, flat triangles), by the
/// divergence theorem V = ⅓ ∮ x·n dA; 2 × 2 Gauss points integrate a bilinear face exactly.
fn volume_by_faces(kind: SolidKind, x: &[Vector3<f64>]) -> f64 {
    let triangle =
        |a: usize, b: usize, c: usize| x[a].dot(&(x[b] - x[a]).cross(&(x[c] - x[a]))) / 2.0;
    let quad = |q: [usize; 4]| {
        let g = 0.5 / 3f64.sqrt();
        let mut flux = 0.0;
        for s in [0.5 - g, 0.5 + g] {
            for t in [0.5 - g, 0.5 + g] {
                let p = x[q[0]] * (1.0 - s) * (1.0 - t)
                    + x[q[1]] * s * (1.0 - t)
                    + x[q[2]] * s * t
                    + x[q[3]] * (1.0 - s) * t;
                let ds = (x[q[1]] - x[q[0]]) * (1.0 - t) + (x[q[2]] - x[q[3]]) * t;
                let dt = (x[q[3]] - x[q[0]]) * (1.0 - s) + (x[q[2]] - x[q[1]]) * s;
                flux += 0.25 * p.dot(&ds.cross(&dt));
            }
        }
        flux
    };
    let flux = match kind {
        SolidKind::Tetra4 | SolidKind::Tetra10 => {
            triangle(0, 2, 1) + triangle(0, 1, 3) + triangle(1, 2, 3) + triangle(2, 0, 3)
        }
        SolidKind::Penta6 => {
            triangle(0, 2, 1)
                + triangle(3, 4, 5)
                + quad([0, 1, 4, 3])
                + quad([1, 2, 5, 4])
                + quad([2, 0, 3, 5])
        }
        SolidKind::Hexa8 => {
            quad([0, 3, 2, 1])
                + quad([4, 5, 6, 7])
                + quad([0, 1, 5, 4])
                + quad([1, 2, 6, 5])
                + quad([2, 3, 7, 6])
                + quad([3, 0, 4, 7])
        }
    };
    (flux / 3.0).abs()
}

fn single(kind: SolidKind) -> (Mesh, Vec<Vector3<f64>>) {
    let x = distorted(kind);
    let mut mesh = Mesh::default();
    for p in &x {
        mesh.add_node(*p);
    }
    mesh.solids.push(Solid {
        nodes: (0..x.len()).collect(),
        material: STEEL,
    });
    (mesh, x)
}

#[test]
fn a_free_element_has_exactly_six_rigid_body_modes() {
    for kind in KINDS {
        let (mesh, x) = single(kind);
        let k = solid::stiffness(0, &mesh.solids[0], &x).unwrap();
        let eig = k.clone().symmetric_eigen();
        let mut values: Vec<f64> = eig.eigenvalues.iter().copied().collect();
        values.sort_by(|a, b| a.total_cmp(b));
        let max = values[values.len() - 1];
        println!(
            "{kind:?}: λ/λmax = {:?}",
            values.iter().take(8).map(|v| v / max).collect::<Vec<_>>()
        );
        assert!(
            values[..6].iter().all(|v| v.abs() < 1e-10 * max),
            "{kind:?}"
        );
        assert!(
            values[6] > 1e-4 * max,
            "{kind:?}: a spurious zero-energy mode"
        );
        // The rigid-body motions themselves produce no force.
        for w in [Vector3::x(), Vector3::y(), Vector3::z()] {
            let u = nalgebra::DVector::from_iterator(
                3 * x.len(),
                x.iter()
                    .flat_map(|p| w.cross(p).iter().copied().collect::<Vec<_>>()),
            );
            assert!((&k * u).amax() < 1e-10 * max, "{kind:?} rotation {w}");
        }
    }
}

#[test]
fn a_free_mesh_has_exactly_six_zero_frequency_modes() {
    for kind in KINDS {
        let b = block(kind, [3, 2, 2], [0.3, 0.2, 0.15], 0.15, 11);
        let mesh = mesh_of(&b, STEEL);
        check_mesh(&mesh, &CheckLimits::default()).unwrap();
        let asm = assemble(&mesh).unwrap();
        check_assembled(&asm).unwrap();
        let modes = lowest_modes(&asm.k, &asm.m, 8, -1.0).unwrap();
        let f = modes.frequencies_hz();
        println!("{kind:?}: {:?}", &f[..8]);
        assert!(f[..6].iter().all(|&v| v < 1e-3), "{kind:?}: {f:?}");
        assert!(f[6] > 1000.0, "{kind:?}: {f:?}");
    }
}

#[test]
fn mass_is_density_times_volume_for_distorted_elements() {
    for kind in KINDS {
        let (mesh, x) = single(kind);
        let v = volume_by_faces(kind, &x);
        let asm = assemble(&mesh).unwrap();
        for d in 0..3 {
            let m = translational_mass(&asm, d);
            println!("{kind:?}: mass {m} vs ρV {}", STEEL.density * v);
            assert!((m / (STEEL.density * v) - 1.0).abs() < 1e-12, "{kind:?}");
        }
        let vol = solid::volume(0, &mesh.solids[0], &x).unwrap();
        assert!(
            (vol / v - 1.0).abs() < 1e-12,
            "{kind:?} volume {vol} vs {v}"
        );
    }
}

#[test]
fn tetrahedron_consistent_mass_matrices_match_the_closed_forms() {
    // ∫ Nᵢ Nⱼ dV: linear tetrahedron V/20 (1 + δᵢⱼ); quadratic tetrahedron (×V/420): corner
    // with itself 6, two corners 1, corner and mid-edge node on an edge at the corner −4, off
    // it −6, mid-edge node with itself 32, two mid-edge nodes sharing a corner 16, opposite 8.
    let edges = [[0, 1], [1, 2], [2, 0], [0, 3], [1, 3], [2, 3]];
    let table10 = |i: usize, j: usize| -> f64 {
        match (i < 4, j < 4) {
            (true, true) => {
                if i == j {
                    6.0
                } else {
                    1.0
                }
            }
            (true, false) | (false, true) => {
                let (c, m) = if i < 4 { (i, j) } else { (j, i) };
                if edges[m - 4].contains(&c) {
                    -4.0
                } else {
                    -6.0
                }
            }
            (false, false) => {
                if i == j {
                    32.0
                } else if edges[i - 4].iter().any(|c| edges[j - 4].contains(c)) {
                    16.0
                } else {
                    8.0
                }
            }
        }
    };
    for kind in [SolidKind::Tetra4, SolidKind::Tetra10] {
        let (mesh, x) = single(kind);
        let v = volume_by_faces(kind, &x);
        let m = solid::mass(0, &mesh.solids[0], &x).unwrap();
        let rho_v = STEEL.density * v;
        let n = x.len();
        for i in 0..n {
            for j in 0..n {
                let want = if kind == SolidKind::Tetra4 {
                    rho_v / 20.0 * if i == j { 2.0 } else { 1.0 }
                } else {
                    rho_v / 420.0 * table10(i, j)
                };
                for d in 0..3 {
                    let got = m[(3 * i + d, 3 * j + d)];
                    assert!(
                        (got - want).abs() < 1e-12 * rho_v,
                        "{kind:?} ({i},{j}): {got} vs {want}"
                    );
                    let off = m[(3 * i + d, 3 * j + (d + 1) % 3)];
                    assert_eq!(off, 0.0);
                }
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Decks.

/// Bulk data of a block of solids: GRIDs, MAT1 1 (steel), PSOLID 1, the elements, and the
/// root at x = 0 supported like a beam's clamp if `clamped`.
fn deck_of(b: &Block, kind: SolidKind, clamped: bool) -> String {
    let mut deck = String::from("BEGIN BULK\nMAT1,1,2.1+11,,0.3,7850.\nPSOLID,1,1\n");
    for (i, p) in b.nodes.iter().enumerate() {
        let _ = writeln!(deck, "GRID,{},,{:e},{:e},{:e}", i + 1, p.x, p.y, p.z);
    }
    for (e, nodes) in b.elements.iter().enumerate() {
        let grids: Vec<String> = nodes.iter().map(|n| (n + 1).to_string()).collect();
        // Six grids on the first line, the rest on a continuation.
        let (first, rest) = grids.split_at(grids.len().min(6));
        let _ = write!(deck, "{},{},1,{}", kind.card(), e + 1, first.join(","));
        if !rest.is_empty() {
            let _ = write!(deck, ",+\n+,{}", rest.join(","));
        }
        deck.push('\n');
    }
    if clamped {
        // Beam theory's clamp: the root section stays plane (ux = 0) and its centre lines do
        // not move sideways, while it may contract laterally (Poisson), which a clamp of all
        // translations would prevent, stiffening the bar over the first element.
        let (y_mid, z_mid) = (
            b.nodes.iter().map(|p| p.y).fold(0.0, f64::max) / 2.0,
            b.nodes.iter().map(|p| p.z).fold(0.0, f64::max) / 2.0,
        );
        for (i, p) in b.nodes.iter().enumerate() {
            if p.x.abs() < 1e-12 {
                let mut c = String::from("1");
                if (p.y - y_mid).abs() < 1e-9 {
                    c.push('2');
                }
                if (p.z - z_mid).abs() < 1e-9 {
                    c.push('3');
                }
                let _ = writeln!(deck, "SPC1,1,{c},{}", i + 1);
            }
        }
    }
    deck.push_str("ENDDATA\n");
    deck
}

/// Index of the elastic mode whose shape is most axial (largest share of ux in Σ u²); rigid
/// translation along x, the most axial of all, is left out.
fn most_axial(asm: &Assembled, modes: &Modes) -> usize {
    let owners = asm.dofs.owners();
    (0..modes.len())
        .filter(|&m| modes.eigenvalues[m] > 1.0)
        .max_by(|&a, &b| {
            let share = |m: usize| {
                let (mut ax, mut all) = (0.0, 0.0);
                for (g, &(_, d)) in owners.iter().enumerate() {
                    let v = modes.shapes[(g, m)].powi(2);
                    all += v;
                    if d == 0 {
                        ax += v;
                    }
                }
                ax / all
            };
            share(a).total_cmp(&share(b))
        })
        .unwrap_or(0)
}

struct Cantilever {
    tip_deflection: f64,
    bending_hz: [f64; 2],
    axial_hz: f64,
}

const LENGTH: f64 = 1.0;
const WIDTH: f64 = 0.06;
const HEIGHT: f64 = 0.04;

/// A steel cantilever along x clamped at x = 0, read from a deck: tip deflection under its
/// own weight (uniform load q = ρ A g, consistent load M·g), the first bending frequencies
/// in z and y and the first axial frequency.
fn cantilever(kind: SolidKind, n: [usize; 3]) -> Cantilever {
    let b = block(kind, n, [LENGTH, WIDTH, HEIGHT], 0.0, 1);
    let body = parse_str(&deck_of(&b, kind, true)).unwrap();
    assert_eq!(body.mesh.solids.len(), b.elements.len());
    check_mesh(&body.mesh, &CheckLimits::default()).unwrap();
    let asm = assemble(&body.mesh).unwrap();
    check_assembled(&asm).unwrap();
    let owners = asm.dofs.owners();
    let n_eq = owners.len();
    let g = 9.81;
    let unit: Vec<f64> = owners
        .iter()
        .map(|&(_, d)| if d == 2 { g } else { 0.0 })
        .collect();
    let load = engine_mount_chassis::fe::assembly::mat_vec(&asm.m, &unit);
    let mut f = Mat::<f64>::zeros(n_eq, 1);
    for (i, v) in load.iter().enumerate() {
        f[(i, 0)] = *v;
    }
    let llt = asm.k.sp_cholesky(Side::Lower).unwrap();
    llt.solve_in_place(f.as_mut());
    let tip: Vec<f64> = owners
        .iter()
        .enumerate()
        .filter(|(_, &(node, d))| d == 2 && (body.mesh.nodes[node].x - LENGTH).abs() < 1e-12)
        .map(|(i, _)| f[(i, 0)])
        .collect();
    let tip_deflection = tip.iter().sum::<f64>() / tip.len() as f64;
    let modes = lowest_modes(&asm.k, &asm.m, 14, -1.0).unwrap();
    let hz = modes.frequencies_hz();
    Cantilever {
        tip_deflection,
        bending_hz: [hz[0], hz[1]],
        axial_hz: hz[most_axial(&asm, &modes)],
    }
}

fn euler_bernoulli() -> Cantilever {
    let (e, rho) = (2.1e11, 7850.0);
    let area = WIDTH * HEIGHT;
    let iy = WIDTH * HEIGHT.powi(3) / 12.0;
    let iz = HEIGHT * WIDTH.powi(3) / 12.0;
    let beta = 1.875_104_068_711_961;
    let f = |i: f64| beta * beta / (2.0 * PI * LENGTH * LENGTH) * (e * i / (rho * area)).sqrt();
    Cantilever {
        tip_deflection: rho * area * 9.81 * LENGTH.powi(4) / (8.0 * e * iy),
        bending_hz: [f(iy), f(iz)],
        axial_hz: (e / rho).sqrt() / (4.0 * LENGTH),
    }
}

fn report(kind: SolidKind, n: [usize; 3], c: &Cantilever, t: &Cantilever) -> [f64; 4] {
    let err = [
        c.tip_deflection / t.tip_deflection - 1.0,
        c.bending_hz[0] / t.bending_hz[0] - 1.0,
        c.bending_hz[1] / t.bending_hz[1] - 1.0,
        c.axial_hz / t.axial_hz - 1.0,
    ];
    println!(
        "{kind:?} {n:?}: tip {:.5e} m ({:+.3} %), f_z {:.3} Hz ({:+.3} %), f_y {:.3} Hz ({:+.3} %), \
         axial {:.2} Hz ({:+.3} %)",
        c.tip_deflection,
        100.0 * err[0],
        c.bending_hz[0],
        100.0 * err[1],
        c.bending_hz[1],
        100.0 * err[2],
        c.axial_hz,
        100.0 * err[3]
    );
    err
}

#[test]
fn hexa_cantilever_converges_to_euler_bernoulli() {
    // L/h = 25: shear deformation and rotary inertia change the first bending frequency by
    // well under 0.5 %, so a converged solid agrees with Euler-Bernoulli within 1 %.
    let theory = euler_bernoulli();
    println!(
        "Euler-Bernoulli: tip {:.5e} m, f_z {:.3} Hz, f_y {:.3} Hz, axial {:.2} Hz",
        theory.tip_deflection, theory.bending_hz[0], theory.bending_hz[1], theory.axial_hz
    );
    let mut previous = f64::INFINITY;
    for nx in [5, 10, 20] {
        let n = [nx, 2, 2];
        let c = cantilever(SolidKind::Hexa8, n);
        let err = report(SolidKind::Hexa8, n, &c, &theory);
        let worst = err.iter().fold(0.0f64, |a, e| a.max(e.abs()));
        assert!(
            worst <= previous * 1.05,
            "refinement must not move away: {err:?}"
        );
        previous = worst;
        if nx == 20 {
            assert!(err.iter().all(|e| e.abs() < 0.01), "{err:?}");
        }
    }
}

#[test]
fn tetra10_cantilever_converges_to_euler_bernoulli() {
    let theory = euler_bernoulli();
    let mut errors = Vec::new();
    for nx in [5, 10, 20] {
        let n = [nx, 2, 2];
        let c = cantilever(SolidKind::Tetra10, n);
        errors.push(report(SolidKind::Tetra10, n, &c, &theory));
    }
    let last = errors[errors.len() - 1];
    assert!(last.iter().all(|e| e.abs() < 0.01), "{last:?}");
    assert!(
        errors[0][1].abs() > last[1].abs(),
        "f_z converges: {errors:?}"
    );
}

#[test]
fn axial_frequency_of_tetra4_and_penta6_bars_matches_the_closed_form() {
    // Bending locks in these low-order elements; axial deformation is a constant-strain state
    // they represent exactly, so the axial frequency converges like that of rod elements.
    let theory = euler_bernoulli();
    for kind in [SolidKind::Tetra4, SolidKind::Penta6] {
        let n = [40, 2, 2];
        let c = cantilever(kind, n);
        let err = report(kind, n, &c, &theory);
        assert!(err[3].abs() < 0.01, "{kind:?} axial {err:?}");
        assert!(
            err[0] < 0.0,
            "{kind:?}: low-order solids are stiff in bending"
        );
    }
}

#[test]
fn a_deck_with_all_four_solid_types_reads_assembles_and_gives_free_free_modes() {
    // A free bar of four segments along x (CTETRA 10-node, CTETRA 4-node, CHEXA, CPENTA)
    // sharing the corner grids at the segment joints; a CONM2 on a solid grid keeps the
    // assembly free of rotations without stiffness.
    let (seg, w, h) = (0.5, 0.06, 0.04);
    let mut deck =
        String::from("BEGIN BULK\nMAT1,7,2.1+11,,0.3,7850.\nPSOLID,3,7,0,BUBBLE,GRID,,SMECH\n");
    let mut grid = 0;
    let mut eid = 0;
    let mut grids_at: std::collections::BTreeMap<(i64, i64, i64), usize> = Default::default();
    // The 10-node tetrahedra sit at a free end: their mid-edge grids on the joint with the
    // 4-node tetrahedra are used by one side only (a non-conforming joint), best placed where
    // the axial mode strains little.
    let order = [
        SolidKind::Tetra10,
        SolidKind::Tetra4,
        SolidKind::Hexa8,
        SolidKind::Penta6,
    ];
    for (s, kind) in order.into_iter().enumerate() {
        let b = block(kind, [6, 2, 2], [seg, w, h], 0.0, 1);
        let mut ids = Vec::new();
        for p in &b.nodes {
            let q = p + Vector3::new(seg * s as f64, 0.0, 0.0);
            let key = (
                (q.x * 1e6).round() as i64,
                (q.y * 1e6).round() as i64,
                (q.z * 1e6).round() as i64,
            );
            let id = *grids_at.entry(key).or_insert_with(|| {
                grid += 1;
                let _ = writeln!(deck, "GRID,{grid},,{:e},{:e},{:e}", q.x, q.y, q.z);
                grid
            });
            ids.push(id);
        }
        for e in &b.elements {
            eid += 1;
            let g: Vec<String> = e.iter().map(|&k| ids[k].to_string()).collect();
            let (first, rest) = g.split_at(g.len().min(6));
            let _ = write!(deck, "{},{eid},3,{}", kind.card(), first.join(","));
            if !rest.is_empty() {
                let _ = write!(deck, "\n,{}", rest.join(","));
            }
            deck.push('\n');
        }
    }
    let _ = writeln!(deck, "CONM2,{},{},,1.-6\nENDDATA", eid + 1, 1);
    let body = parse_str(&deck).unwrap();
    assert_eq!(body.mesh.solids.len(), eid);
    let mut counts = [0usize; 4];
    for s in &body.mesh.solids {
        counts[KINDS
            .iter()
            .position(|&k| Some(k) == SolidKind::from_node_count(s.nodes.len()))
            .unwrap()] += 1;
    }
    assert_eq!(counts, [24 * 6, 24 * 6, 24 * 2, 24]);
    check_mesh(&body.mesh, &CheckLimits::default()).unwrap();
    let asm = assemble(&body.mesh).unwrap();
    check_assembled(&asm).unwrap();
    let length = 4.0 * seg;
    let mass = translational_mass(&asm, 0);
    let want = 7850.0 * length * w * h + 1e-6;
    assert!((mass / want - 1.0).abs() < 1e-12, "{mass} vs {want}");
    let modes = lowest_modes(&asm.k, &asm.m, 24, -1.0).unwrap();
    let f = modes.frequencies_hz();
    let axial = f[most_axial(&asm, &modes)];
    let theory = (2.1e11f64 / 7850.0).sqrt() / (2.0 * length);
    println!("free-free: {f:?}; axial {axial:.2} Hz vs {theory:.2} Hz");
    assert!(f[..6].iter().all(|&v| v < 1e-2), "{f:?}");
    assert!(f[6] > 5.0, "{f:?}");
    assert!((axial / theory - 1.0).abs() < 0.01, "{axial} vs {theory}");
}

#[test]
fn solids_written_to_bulk_data_read_back_unchanged() {
    let mut mesh = Mesh::default();
    for kind in KINDS {
        let (single_mesh, x) = single(kind);
        let base = mesh.nodes.len();
        for p in x {
            mesh.add_node(p + Vector3::new(3.0 * base as f64, 0.0, 0.0));
        }
        mesh.solids.push(Solid {
            nodes: single_mesh.solids[0]
                .nodes
                .iter()
                .map(|k| k + base)
                .collect(),
            material: STEEL,
        });
    }
    let deck = write_bulk_deck(&mesh).unwrap();
    for card in ["CTETRA*", "CPENTA*", "CHEXA*", "PSOLID*"] {
        assert!(deck.contains(card), "{card} missing in\n{deck}");
    }
    let body = parse_str(&deck).unwrap();
    assert_eq!(body.mesh.solids, mesh.solids);
    assert_eq!(body.element_ids.of(Entity::Solid).len(), 4);
}

// ---------------------------------------------------------------------------------------------
// Deck errors name the card and the line.

fn error_of(deck: &str) -> String {
    parse_str(deck).unwrap_err().to_string()
}

const CUBE: &str = "BEGIN BULK\nMAT1,1,2.1+11,,0.3,7850.\nPSOLID,1,1\n\
    GRID,1,,0.,0.,0.\nGRID,2,,1.,0.,0.\nGRID,3,,1.,1.,0.\nGRID,4,,0.,1.,0.\n\
    GRID,5,,0.,0.,1.\nGRID,6,,1.,0.,1.\nGRID,7,,1.,1.,1.\nGRID,8,,0.,1.,1.\n";

#[test]
fn a_solid_with_a_missing_grid_is_named_with_its_line() {
    let err = error_of(&format!("{CUBE}CHEXA,12,1,1,2,3,4,5,6\n,7,99\nENDDATA\n"));
    assert!(
        err.contains("line 12") && err.contains("CHEXA 12") && err.contains("GRID 99 not found"),
        "{err}"
    );
    let err = error_of(&format!("{CUBE}CTETRA,4,1,1,2,4,5,6\n,7,8\nENDDATA\n"));
    assert!(
        err.contains("line 12") && err.contains("CTETRA") && err.contains("mid-edge"),
        "{err}"
    );
    let err = error_of(&format!("{CUBE}CTETRA,5,2,1,2,4,5\nENDDATA\n"));
    assert!(
        err.contains("line 12") && err.contains("PSOLID 2 not found"),
        "{err}"
    );
}

#[test]
fn psolid_options_that_are_not_implemented_are_refused_naming_the_field() {
    for (card, field) in [
        ("PSOLID,1,1,,,,FULL", "ISOP"),
        ("PSOLID,1,1,,THREE", "IN"),
        ("PSOLID,1,1,,,,,PFLUID", "FCTN"),
        ("PSOLID,1,1,,2", "IN"),
    ] {
        let deck = CUBE.replace("PSOLID,1,1", card) + "CHEXA,1,1,1,2,3,4,5,6\n,7,8\nENDDATA\n";
        let err = error_of(&deck);
        assert!(
            err.contains("line 3") && err.contains("PSOLID") && err.contains(field),
            "{card}: {err}"
        );
    }
    // CORDM must name an existing system (isotropic MAT1: its axes do not matter).
    let deck =
        CUBE.replace("PSOLID,1,1", "PSOLID,1,1,5") + "CHEXA,1,1,1,2,3,4,5,6\n,7,8\nENDDATA\n";
    let err = error_of(&deck);
    assert!(
        err.contains("line 3") && err.contains("coordinate system 5"),
        "{err}"
    );
    let deck = CUBE.replace("PSOLID,1,1", "PSOLID,1,1,5")
        + "CORD2R,5,,0.,0.,0.,0.,0.,1.\n,1.,0.,0.\nCHEXA,1,1,1,2,3,4,5,6\n,7,8\nENDDATA\n";
    parse_str(&deck).unwrap();
}

#[test]
fn zero_volume_and_inverted_solids_are_named_with_their_line() {
    let cases = [
        // Four coplanar grids.
        ("CTETRA,3,1,1,2,3,4\n", "CTETRA 3"),
        // The top face numbered against the bottom one: the element is folded.
        ("CHEXA,8,1,1,2,3,4,6,5\n,8,7\n", "CHEXA 8"),
        // A corner of the top face pushed through the bottom face.
        ("CPENTA,9,1,1,2,3,5,6,10\n", "CPENTA 9"),
        // Repeated grid.
        ("CHEXA,10,1,1,2,3,4,5,6\n,7,7\n", "CHEXA"),
    ];
    for (card, name) in cases {
        let deck = format!("{CUBE}GRID,10,,1.,1.,-0.5\n{card}ENDDATA\n");
        let err = error_of(&deck);
        println!("{err}");
        assert!(
            err.contains("line 13") && err.contains(name),
            "{card}: {err}"
        );
        assert!(
            err.contains("inverted") || err.contains("appears twice"),
            "{card}: {err}"
        );
    }
    // The mirrored numbering of a valid element is accepted, as Nastran does.
    parse_str(&format!("{CUBE}CHEXA,1,1,1,4,3,2,5,8\n,7,6\nENDDATA\n")).unwrap();
}

#[test]
fn rotations_of_grids_with_shells_or_beams_stay_and_others_are_removed() {
    // A hexahedron with a CONM2 (rotary inertia) on grid 1 and a CBAR from grid 7 to an extra
    // grid: grid 7 keeps its rotations (the bar holds them), grid 1 loses them (AUTOSPC).
    let deck = format!(
        "{CUBE}GRID,9,,2.,1.,1.\nPBAR,2,1,1.-4,1.-9,1.-9,2.-9\nCBAR,20,2,7,9,0.,0.,1.\n\
         CONM2,30,1,,5.,,,,,+\n+,1.,,1.,,,1.\nCHEXA,1,1,1,2,3,4,5,6\n,7,8\nENDDATA\n"
    );
    let body = parse_str(&deck).unwrap();
    let asm = assemble(&body.mesh).unwrap();
    let (g1, g7, g9) = (
        body.node(1).unwrap(),
        body.node(7).unwrap(),
        body.node(9).unwrap(),
    );
    for d in 3..6 {
        assert!(asm.dofs.global(g1, d).is_none());
        assert!(asm.dofs.global(g7, d).is_some());
        assert!(asm.dofs.global(g9, d).is_some());
    }
    // Eight translations per hexahedron grid, the rotations of grid 7, six DOFs of grid 9.
    assert_eq!(asm.dofs.n_free(), 8 * 3 + 3 + 6);
    check_assembled(&asm).unwrap();
}

/// All eigenvalues of (K, M) by a dense solve (nalgebra): Cholesky of M, symmetric eigen of
/// L⁻¹ K L⁻ᵀ; ascending.
fn dense_eigenvalues(asm: &Assembled) -> Vec<f64> {
    let (kd, md) = (asm.k.to_dense(), asm.m.to_dense());
    let n = kd.nrows();
    let k = nalgebra::DMatrix::from_fn(n, n, |i, j| kd[(i, j)]);
    let m = nalgebra::DMatrix::from_fn(n, n, |i, j| md[(i, j)]);
    let l_inv = m.cholesky().unwrap().l().try_inverse().unwrap();
    let a = &l_inv * k * l_inv.transpose();
    let a = (&a + a.transpose()) * 0.5;
    let mut ev: Vec<f64> = a.symmetric_eigen().eigenvalues.iter().copied().collect();
    ev.sort_by(f64::total_cmp);
    ev
}

#[test]
fn a_free_stiff_block_at_shift_minus_one_matches_a_dense_solve() {
    // At σ = −1 the six rigid-body modes have θ = 1/(λ − σ) = 1 and the elastic ones (kHz)
    // θ ≈ 1e-9 (0.3 m block) or 1e-12 (the same block at 1 cm). The solver used to lose the
    // M-orthogonality of its basis here and return negative eigenvalues, and with the basis
    // repaired the projected eigenproblem still held θ = 1 next to θ = 1e-9 and gave the
    // elastic eigenvalues to 1e-7 (1e-4 at 1 cm) only.
    for (size, label) in [(1.0, "0.3 m"), (1.0 / 30.0, "1 cm")] {
        for kind in KINDS {
            let b = block(
                kind,
                [3, 2, 2],
                [0.3 * size, 0.2 * size, 0.15 * size],
                0.15,
                11,
            );
            let asm = assemble(&mesh_of(&b, STEEL)).unwrap();
            let wanted = 14;
            let modes = lowest_modes(&asm.k, &asm.m, wanted, -1.0).unwrap();
            let dense = dense_eigenvalues(&asm);
            let first_elastic = dense[6];
            for (i, (&got, &expected)) in modes.eigenvalues.iter().zip(&dense).enumerate() {
                if i < 6 {
                    assert!(
                        got.abs() < 1e-9 * first_elastic,
                        "{kind:?} {label}: mode {i} = {got:e}, first elastic {first_elastic:e}"
                    );
                } else {
                    assert!(
                        (got / expected - 1.0).abs() < 1e-8,
                        "{kind:?} {label}: mode {i}: Lanczos {got:e}, dense {expected:e}"
                    );
                }
            }
            // The shapes are eigenvectors (small residual against ‖K‖) and M-orthonormal.
            let (kd, md) = (asm.k.to_dense(), asm.m.to_dense());
            let k_norm = kd.norm_l2();
            let (k_phi, m_phi) = (&kd * &modes.shapes, &md * &modes.shapes);
            let mut worst: f64 = 0.0;
            for j in 0..wanted {
                let lambda = modes.eigenvalues[j];
                let r = (0..k_phi.nrows())
                    .map(|i| (k_phi[(i, j)] - lambda * m_phi[(i, j)]).powi(2))
                    .sum::<f64>()
                    .sqrt()
                    / (k_norm * modes.shapes.col(j).norm_l2());
                worst = worst.max(r);
            }
            assert!(
                worst < 1e-10,
                "{kind:?} {label}: relative residual {worst:e}"
            );
            println!("{kind:?} {label}: largest relative residual {worst:e}");
            let gram = modes.shapes.transpose() * &md * &modes.shapes;
            for j in 0..wanted {
                for i in 0..wanted {
                    let e = if i == j { 1.0 } else { 0.0 };
                    assert!(
                        (gram[(i, j)] - e).abs() < 1e-10,
                        "{kind:?} {label}: (ΦᵀMΦ)[{i},{j}] = {}",
                        gram[(i, j)]
                    );
                }
            }
        }
    }
}
