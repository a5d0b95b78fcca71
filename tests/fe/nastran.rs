//! Nastran bulk data reader and writer against independent results: Leissa's cantilever plate,
//! Euler-Bernoulli cantilever beams, a spring-mass oscillator, rigid-body mass properties
//! through RBE2, the weighted mean of RBE3, the procedural chassis round trip, error messages.

use std::collections::BTreeMap;
use std::f64::consts::PI;
use std::fmt::Write;
use std::path::{Path, PathBuf};

use engine_mount_chassis::chassis::config::ChassisConfig;
use engine_mount_chassis::chassis::Chassis;
use engine_mount_chassis::eigen::{lowest_modes, Modes};
use engine_mount_chassis::fe::assembly::{assemble, mat_vec, Assembled};
use engine_mount_chassis::fe::elements::Entity;
use engine_mount_chassis::nastran::{parse_str, read_bulk_deck, write_bulk_deck, NastranBody};
use nalgebra::{DMatrix, Matrix3, Vector3};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fe/data")
        .join(name)
}

fn modes(body: &NastranBody, n: usize) -> (Assembled, Modes) {
    let asm = assemble(&body.mesh).unwrap();
    let modes = lowest_modes(&asm.k, &asm.m, n, -1.0).unwrap();
    (asm, modes)
}

/// Share of a mode's kinetic energy (lumped diagonal) in local DOF `dof`.
fn dof_share(asm: &Assembled, modes: &Modes, mode: usize, dof: usize) -> f64 {
    let phi: Vec<f64> = (0..asm.dofs.n_free())
        .map(|g| modes.shapes[(g, mode)])
        .collect();
    let mphi = mat_vec(&asm.m, &phi);
    let owners = asm.dofs.owners();
    let total: f64 = phi.iter().zip(&mphi).map(|(a, b)| a * b).sum();
    let part: f64 = (0..phi.len())
        .filter(|&g| owners[g].1 == dof)
        .map(|g| phi[g] * mphi[g])
        .sum();
    part / total
}

const STEEL: &str = "MAT1,1,2.1+11,,0.3,7850.\n";

// ---------------------------------------------------------------------------------------------
// (a) Cantilever plate (CQUAD4, SPC1 clamped edge) against Leissa.

/// Square cantilever plate a × a, thickness h, clamped along x = 0, n × n CQUAD4 or 2 n²
/// CTRIA3 (each square cut along alternating diagonals), free field.
fn cantilever_plate_deck(n: usize, a: f64, h: f64, triangles: bool) -> String {
    let mut deck = String::from("BEGIN BULK\n");
    deck.push_str(STEEL);
    let _ = writeln!(deck, "PSHELL,7,1,{h:e},1,,1");
    let id = |i: usize, j: usize| 1000 + i * (n + 1) + j;
    for i in 0..=n {
        for j in 0..=n {
            let (x, y) = (a * i as f64 / n as f64, a * j as f64 / n as f64);
            let _ = writeln!(deck, "GRID,{},,{x:e},{y:e},0.", id(i, j));
        }
    }
    for i in 0..n {
        for j in 0..n {
            let c = [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)];
            let e = 1 + 2 * (i * n + j);
            if !triangles {
                let _ = writeln!(deck, "CQUAD4,{e},7,{},{},{},{}", c[0], c[1], c[2], c[3]);
            } else if (i + j) % 2 == 0 {
                let _ = writeln!(deck, "CTRIA3,{e},7,{},{},{}", c[0], c[1], c[2]);
                let _ = writeln!(deck, "CTRIA3,{},7,{},{},{}", e + 1, c[0], c[2], c[3]);
            } else {
                let _ = writeln!(deck, "CTRIA3,{e},7,{},{},{}", c[0], c[1], c[3]);
                let _ = writeln!(deck, "CTRIA3,{},7,{},{},{}", e + 1, c[1], c[2], c[3]);
            }
        }
    }
    let _ = writeln!(deck, "SPC1,3,123456,{},THRU,{}", id(0, 0), id(0, n));
    deck.push_str("ENDDATA\n");
    deck
}

/// λ1 (first bending), λ2 (first torsion) of the cantilever plate on n × n meshes.
fn cantilever_plate_history(triangles: bool) -> Vec<(f64, f64)> {
    let (a, h): (f64, f64) = (0.5, 0.002);
    let d = 2.1e11 * h.powi(3) / (12.0 * (1.0 - 0.09));
    let scale = (7850.0 * h / d).sqrt() * a * a;
    let mut history = Vec::new();
    for n in [4, 8, 16] {
        let body = parse_str(&cantilever_plate_deck(n, a, h, triangles)).unwrap();
        assert_eq!(body.spc_set, Some(3));
        let (asm, m) = modes(&body, 3);
        let lambda: Vec<f64> = m.eigenvalues.iter().map(|l| l.sqrt() * scale).collect();
        for mode in 0..2 {
            assert!(
                dof_share(&asm, &m, mode, 2) > 0.9,
                "mode {mode} is not transverse"
            );
        }
        let kind = if triangles { "CTRIA3" } else { "CQUAD4" };
        println!(
            "cantilever plate {kind} {n}×{n}: λ1 = {:.4}, λ2 = {:.4}",
            lambda[0], lambda[1]
        );
        history.push((lambda[0], lambda[1]));
    }
    history
}

/// Leissa (1969), square cantilever plate, ν = 0.3: λ = ω a² √(ρh/D) = 3.492 (first bending),
/// 8.525 (first torsion). These Ritz values are upper bounds; converged values are about 0.6 %
/// lower (3.471, 8.507), so the finest mesh must lie within 1.5 % of Leissa, and each
/// refinement must at least halve the change (an O(h²) element converging).
fn assert_converges_to_leissa(history: &[(f64, f64)]) {
    let (l1, l2) = history[2];
    assert!((l1 / 3.492 - 1.0).abs() < 0.015, "λ1 = {l1}");
    assert!((l2 / 8.525 - 1.0).abs() < 0.015, "λ2 = {l2}");
    for k in [0, 1] {
        let pick = |s: (f64, f64)| if k == 0 { s.0 } else { s.1 };
        let d1 = (pick(history[1]) - pick(history[0])).abs();
        let d2 = (pick(history[2]) - pick(history[1])).abs();
        assert!(d2 < 0.5 * d1, "mode {k}: changes {d1} then {d2}");
    }
}

#[test]
fn cantilever_plate_of_cquad4_converges_to_leissa_bending_and_torsion() {
    assert_converges_to_leissa(&cantilever_plate_history(false));
}

#[test]
fn cantilever_plate_of_ctria3_converges_to_leissa_bending_and_torsion() {
    assert_converges_to_leissa(&cantilever_plate_history(true));
}

// ---------------------------------------------------------------------------------------------
// (b) Cantilever beams of CBEAM / CBAR against Euler-Bernoulli.

#[test]
fn cantilever_beams_match_euler_bernoulli_in_both_planes() {
    // Section with I1 (plane 1 = element x-y, here global x-y by v = +y) four times I2.
    let (length, n, area, i1, i2) = (1.2, 24, 3.0e-4, 4.0e-8, 1.0e-8);
    let rho = 7850.0;
    for card in ["CBEAM", "CBAR"] {
        let mut deck = String::from("BEGIN BULK\n");
        deck.push_str(STEEL);
        if card == "CBEAM" {
            // K1 = K2 = 0.0: rigid in shear (blank would be Nastran's shear-flexible 1.0).
            let _ = writeln!(
                deck,
                "PBEAM,5,1,{area:e},{i1:e},{i2:e},0.,{:e}\n,,,,,,,,\n,0.,0.",
                i1 + i2
            );
        } else {
            let _ = writeln!(deck, "PBAR,5,1,{area:e},{i1:e},{i2:e},{:e}", i1 + i2);
        }
        for k in 0..=n {
            let _ = writeln!(
                deck,
                "GRID,{},,{:e},0.,0.",
                k + 1,
                length * k as f64 / n as f64
            );
        }
        // An orientation grid far along +y (G0 form) for CBAR, a vector for CBEAM.
        let _ = writeln!(deck, "GRID,999,,0.,5.,0.");
        for k in 0..n {
            if card == "CBEAM" {
                let _ = writeln!(deck, "CBEAM,{},5,{},{},0.,1.,0.", k + 1, k + 1, k + 2);
            } else {
                let _ = writeln!(deck, "CBAR,{},5,{},{},999", k + 1, k + 1, k + 2);
            }
        }
        deck.push_str("SPC1,1,123456,1\nSPC1,1,123456,999\nENDDATA\n");
        let body = parse_str(&deck).unwrap();
        let (asm, m) = modes(&body, 4);
        let f = m.frequencies_hz();
        let eb = |beta_l: f64, i: f64| {
            beta_l * beta_l / (2.0 * PI) * (2.1e11 * i / (rho * area * length.powi(4))).sqrt()
        };
        // Lowest four: z-bending (I2) 1st, y-bending (I1) 1st, z 2nd, y 2nd.
        let expected = [
            (eb(1.875104, i2), 2),
            (eb(1.875104, i1), 1),
            (eb(4.694091, i2), 2),
            (eb(4.694091, i1), 1),
        ];
        for (mode, (target, dof)) in expected.iter().enumerate() {
            println!(
                "{card} mode {mode}: {:.3} Hz, Euler-Bernoulli {target:.3} Hz",
                f[mode]
            );
            assert!((f[mode] / target - 1.0).abs() < 0.005, "{card} mode {mode}");
            assert!(
                dof_share(&asm, &m, mode, *dof) > 0.9,
                "{card} mode {mode} direction"
            );
        }
    }
}

// ---------------------------------------------------------------------------------------------
// (c) CONM2 on CELAS springs.

#[test]
fn spring_mass_file_gives_the_exact_oscillator_frequencies() {
    let body = read_bulk_deck(&data("spring_mass.bdf")).unwrap();
    let (asm, m) = modes(&body, 2);
    let f = m.frequencies_hz();
    for (k, fk) in [1.0e4, 4.0e4].iter().zip(&f) {
        let exact = (k / 2.5_f64).sqrt() / (2.0 * PI);
        assert!((fk / exact - 1.0).abs() < 1e-12, "{fk} vs {exact}");
    }
    // The CDAMP2 lands on ux.
    let c = asm.c.to_dense();
    let g = asm.dofs.global(0, 0).unwrap();
    assert_eq!(c[(g, g)], 15.5);
}

// ---------------------------------------------------------------------------------------------
// (d) RBE2 and RBE3.

/// A rigid body (mass `m`, inertia `jcg` about its centre at `r` from grid 1) carried by grid 1
/// on six grounded springs; the mass sits on grid 2, tied to grid 1 by an RBE2.
fn rigid_body_deck(m: f64, jcg: [f64; 6], r: [f64; 3], springs: [f64; 6], pinned: bool) -> String {
    let mut deck = String::from("BEGIN BULK\n");
    let _ = writeln!(
        deck,
        "GRID,1,,0.1,0.2,0.3{}",
        if pinned { ",,123" } else { "" }
    );
    let _ = writeln!(
        deck,
        "GRID,2,,{:e},{:e},{:e}",
        0.1 + r[0],
        0.2 + r[1],
        0.3 + r[2]
    );
    let _ = writeln!(deck, "RBE2,50,1,123456,2");
    let _ = writeln!(
        deck,
        "CONM2,60,2,,{m:e},,,,,\n,{:e},{:e},{:e},{:e},{:e},{:e}",
        jcg[0], jcg[1], jcg[2], jcg[3], jcg[4], jcg[5]
    );
    for (c, k) in springs.iter().enumerate() {
        if *k > 0.0 {
            let _ = writeln!(deck, "CELAS2,{},{k:e},1,{}", 70 + c, c + 1);
        }
    }
    deck.push_str("ENDDATA\n");
    deck
}

#[test]
fn rbe2_mass_equals_the_parallel_axis_inertia_at_the_independent_node() {
    // Pinned grid 1, torsion springs; mass 3 kg at height 0.4 m above it: rotary inertia about
    // x and y gains m h² (parallel axes), about z not. Exact closed form per axis.
    let (m, h) = (3.0, 0.4);
    let jcg = [0.02, 0.0, 0.03, 0.0, 0.0, 0.05];
    let k = [0.0, 0.0, 0.0, 500.0, 700.0, 900.0];
    let body = parse_str(&rigid_body_deck(m, jcg, [0.0, 0.0, h], k, true)).unwrap();
    let (_, modes_) = modes(&body, 3);
    let mut expected = [
        (500.0 / (0.02 + m * h * h)).sqrt(),
        (700.0 / (0.03 + m * h * h)).sqrt(),
        (900.0_f64 / 0.05).sqrt(),
    ];
    expected.sort_by(f64::total_cmp);
    for (f, w) in modes_.frequencies_hz().iter().zip(expected) {
        assert!(
            (f / (w / (2.0 * PI)) - 1.0).abs() < 1e-10,
            "{f} vs {}",
            w / (2.0 * PI)
        );
    }
}

#[test]
fn rbe2_spider_with_products_of_inertia_matches_a_dense_rigid_body_solution() {
    // Free grid 1 on six springs; the mass is offset in all directions and has products of
    // inertia (Nastran sign convention: the tensor holds −I21 etc.). Reference: the 6 × 6
    // rigid-body mass matrix about grid 1 written out by hand, dense generalized eigen solve.
    let m = 2.0;
    let (i11, i21, i22, i31, i32, i33) = (0.05, 0.01, 0.07, -0.005, 0.008, 0.09);
    let r = Vector3::new(0.3, -0.2, 0.25);
    let k = [4.0e4, 5.0e4, 6.0e4, 900.0, 1100.0, 1300.0];
    let body = parse_str(&rigid_body_deck(
        m,
        [i11, i21, i22, i31, i32, i33],
        [r.x, r.y, r.z],
        k,
        false,
    ))
    .unwrap();
    let (_, fe) = modes(&body, 6);

    let jcg = Matrix3::new(i11, -i21, -i31, -i21, i22, -i32, -i31, -i32, i33);
    let skew = Matrix3::new(0.0, -r.z, r.y, r.z, 0.0, -r.x, -r.y, r.x, 0.0);
    let mut mass = DMatrix::<f64>::zeros(6, 6);
    // u_cg = u + θ × r = u − [r]× θ: kinetic energy ½ m |u − [r]×θ|² + ½ θᵀ J θ.
    for i in 0..3 {
        mass[(i, i)] = m;
        for j in 0..3 {
            mass[(i, 3 + j)] = -m * skew[(i, j)];
            mass[(3 + j, i)] = -m * skew[(i, j)];
        }
    }
    let rot = jcg + m * skew.transpose() * skew;
    for i in 0..3 {
        for j in 0..3 {
            mass[(3 + i, 3 + j)] = rot[(i, j)];
        }
    }
    let stiffness = DMatrix::from_diagonal(&nalgebra::DVector::from_row_slice(&k));
    let l = mass.clone().cholesky().unwrap().l();
    let li = l.clone().try_inverse().unwrap();
    let mut reference: Vec<f64> = (li.clone() * stiffness * li.transpose())
        .symmetric_eigenvalues()
        .iter()
        .copied()
        .collect();
    reference.sort_by(f64::total_cmp);
    for (a, b) in fe.eigenvalues.iter().zip(&reference) {
        assert!((a / b - 1.0).abs() < 1e-9, "{a} vs {b}");
    }
}

#[test]
fn rbe3_reference_moves_with_the_weighted_mean_of_its_sources() {
    // Sources with weights 1 (grids 1, 2) and 3 (grids 3, 4); the reference (grid 9) sits at
    // the weighted centroid, so its translation is Σ wᵢ uᵢ / Σ wᵢ for any source motion.
    let deck = "BEGIN BULK\n\
                GRID,1,,1.,0.,0.\nGRID,2,,-1.,0.,0.\nGRID,3,,0.,1.,0.2\nGRID,4,,0.,-1.,-0.2\n\
                GRID,9,,0.,0.,0.\n\
                RBE3,40,,9,123,1.,123,1,2\n,3.,123,3,4\n\
                CELAS2,1,1.+3,1,1\nCELAS2,2,1.+3,2,2\nENDDATA\n";
    let body = parse_str(deck).unwrap();
    let asm = assemble(&body.mesh).unwrap();
    let t = asm.dofs.transformation().unwrap();
    let q: Vec<f64> = (0..asm.dofs.n_free())
        .map(|g| ((g * 7919) % 31) as f64 / 7.0 - 2.0)
        .collect();
    let u = mat_vec(&t, &q);
    let node = |grid: u32| body.node(grid).unwrap();
    for d in 0..3 {
        let at = |grid: u32| u[node(grid) * 6 + d];
        let mean = (at(1) + at(2) + 3.0 * at(3) + 3.0 * at(4)) / 8.0;
        assert!((at(9) - mean).abs() < 1e-12, "dof {d}: {} vs {mean}", at(9));
        // The reference has no equation; its motion row reproduces the same value.
        assert!(asm.dofs.global(node(9), d).is_none());
        let row = asm.dofs.motion_row(node(9), d).unwrap();
        let v: f64 = row.iter().map(|&(g, c)| c * q[g]).sum();
        assert!((v - mean).abs() < 1e-12);
    }
}

// ---------------------------------------------------------------------------------------------
// (e) The procedural chassis written and read back.

#[test]
fn chassis_written_as_bulk_data_and_read_back_has_the_same_lowest_20_modes() {
    let chassis = Chassis::build(&ChassisConfig::default()).unwrap();
    let deck = write_bulk_deck(&chassis.mesh).unwrap();
    let mut body = parse_str(&deck).unwrap();
    assert_eq!(body.mesh.nodes.len(), chassis.mesh.nodes.len());
    assert_eq!(body.mesh.shells.len(), chassis.mesh.shells.len());
    assert_eq!(body.mesh.beams.len(), chassis.mesh.beams.len());
    // Points named by GRID id (= node index + 1 in the writer) land on the same nodes.
    let wheel = chassis.node("steering_wheel").unwrap();
    let points = BTreeMap::from([("steering_wheel".to_string(), wheel as u32 + 1)]);
    body.name_points(&points).unwrap();
    assert_eq!(body.mesh.named("steering_wheel"), Some(wheel));
    let missing = BTreeMap::from([("seat".to_string(), 10_000_000)]);
    let err = body.name_points(&missing).unwrap_err().to_string();
    assert!(
        err.contains("'seat'") && err.contains("GRID 10000000"),
        "{err}"
    );
    let floor: Vec<u32> = chassis.mesh.regions["floor"]
        .iter()
        .map(|&n| n as u32 + 1)
        .collect();
    body.name_regions(&BTreeMap::from([("floor".to_string(), floor)]))
        .unwrap();
    assert_eq!(body.mesh.regions["floor"], chassis.mesh.regions["floor"]);

    let original = assemble(&chassis.mesh).unwrap();
    let read = assemble(&body.mesh).unwrap();
    assert_eq!(original.dofs.n_free(), read.dofs.n_free());
    // The matrices agree to the 10–11 significant digits of 16-column fields (compared through
    // products with a fixed vector: entries exactly zero in one may be round-off in the other).
    let x: Vec<f64> = (0..original.dofs.n_free())
        .map(|g| ((g * 7919) % 97) as f64 / 48.0 - 1.0)
        .collect();
    for (p, q) in [(&original.k, &read.k), (&original.m, &read.m)] {
        let scale = p.val().iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let (px, qx) = (mat_vec(p, &x), mat_vec(q, &x));
        let worst = px
            .iter()
            .zip(&qx)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0_f64, f64::max);
        assert!(worst <= 1e-11 * scale, "{worst:e} vs scale {scale:e}");
    }
    let frequencies = |asm: &Assembled| {
        lowest_modes(&asm.k, &asm.m, 20, -1.0)
            .unwrap()
            .frequencies_hz()
    };
    let (a, b) = (frequencies(&original), frequencies(&read));
    // The six body-on-suspension modes (1–4 Hz, λ ≈ 10² against ‖K‖ ≈ 10¹⁰) are only resolved
    // to ~1e-9 by the eigen solve itself: the same mesh with its elements in reverse order
    // (identical physics, other summation order) moves them by as much. The tolerance is
    // 1e-9 or four times that floor, whichever is larger.
    let mut reordered = chassis.mesh.clone();
    reordered.shells.reverse();
    reordered.beams.reverse();
    let floor = a
        .iter()
        .zip(frequencies(&assemble(&reordered).unwrap()))
        .map(|(x, y)| (x / y - 1.0).abs())
        .fold(0.0_f64, f64::max);
    let tolerance = (4.0 * floor).max(1e-9);
    let mut worst: f64 = 0.0;
    for (x, y) in a.iter().zip(&b) {
        worst = worst.max((x / y - 1.0).abs());
    }
    println!(
        "chassis round trip: largest relative frequency difference {worst:.2e} (solver floor \
         {floor:.2e})"
    );
    assert!(worst <= tolerance, "{worst} > {tolerance}");
    // Structural modes (above 10 Hz) are far from the floor: 1e-9 without allowance.
    for (x, y) in a.iter().zip(&b).filter(|(x, _)| **x > 10.0) {
        assert!((x / y - 1.0).abs() < 1e-9, "{x} vs {y}");
    }
    // Damping (suspension dampers as CDAMP2) survives too.
    let (ca, cb) = (original.c.to_dense(), read.c.to_dense());
    for i in 0..ca.nrows() {
        assert!((ca[(i, i)] - cb[(i, i)]).abs() <= 1e-9 * ca[(i, i)].abs());
    }
}

#[test]
fn triangles_links_masses_and_springs_survive_a_write_read_cycle_unchanged() {
    let mut deck = cantilever_plate_deck(2, 0.5, 0.002, true);
    deck = deck.replace("ENDDATA\n", "");
    // A rigid body on grid 1 (offset CONM2 with products of inertia), a second offset CONM2,
    // and an RBE3 reference point (grid 3) over two plate grids.
    let rigid = rigid_body_deck(
        2.0,
        [0.05, 0.01, 0.07, -0.005, 0.008, 0.09],
        [0.3, -0.2, 0.25],
        [4.0e4, 5.0e4, 6.0e4, 900.0, 1100.0, 1300.0],
        false,
    );
    let body_part = rigid.replace("BEGIN BULK\n", "")
        + "CONM2,61,1,,1.5,0.1,0.,0.\nGRID,3,,0.1,0.2,0.\nRBE3,41,,3,123,1.,123,1002,1004\n";
    deck.push_str(&body_part);
    let first = parse_str(&deck).unwrap();
    assert_eq!(first.mesh.triangles.len(), 8);
    let second = parse_str(&write_bulk_deck(&first.mesh).unwrap()).unwrap();
    assert_eq!(first.mesh, second.mesh);
    assemble(&second.mesh).unwrap();
}

#[test]
fn grids_and_masses_in_nested_cord2r_systems_land_in_basic() {
    // System 5: origin (1, 2, 3), local z = basic x, local x = basic y (so local y = basic z).
    // System 6 is defined in system 5 and is system 5 moved by 1 along basic x.
    let deck = "BEGIN BULK\n\
                CORD2R,5,,1.,2.,3.,2.,2.,3.\n,1.,3.,3.\n\
                CORD2R,6,5,0.,0.,1.,0.,0.,2.\n,1.,0.,1.\n\
                GRID,1,5,0.5,0.25,2.\nGRID,2,6,0.5,0.25,2.\n\
                CONM2,9,1,5,4.,0.1,0.,0.\n,1.,,2.,,,3.\nENDDATA\n";
    let body = parse_str(deck).unwrap();
    let at = |g: u32| body.mesh.nodes[body.node(g).unwrap()];
    assert!(
        (at(1) - Vector3::new(3.0, 2.5, 3.25)).norm() < 1e-14,
        "{}",
        at(1)
    );
    assert!(
        (at(2) - Vector3::new(4.0, 2.5, 3.25)).norm() < 1e-14,
        "{}",
        at(2)
    );
    // The CONM2 offset (0.1 along local x = basic y) puts the mass on its own node, rigidly
    // tied to grid 1; its inertia about local x, y, z is about basic y, z, x.
    let mass = &body.mesh.masses[0];
    assert_eq!(mass.mass, 4.0);
    assert!((body.mesh.nodes[mass.node] - Vector3::new(3.0, 2.6, 3.25)).norm() < 1e-14);
    let diagonal = [
        mass.inertia[(0, 0)],
        mass.inertia[(1, 1)],
        mass.inertia[(2, 2)],
    ];
    for (got, want) in diagonal.iter().zip([3.0, 1.0, 2.0]) {
        assert!((got - want).abs() < 1e-14, "{diagonal:?}");
    }
    assert_eq!(body.mesh.rigid_links.len(), 1);
    assert_eq!(body.element_ids.of(Entity::RigidLink), [9]);
}

#[test]
fn spc1_thru_takes_the_grids_that_exist_and_wtmass_scales_all_mass() {
    let deck = "GRID,1,,0.,0.,0.\nGRID,2,,1.,0.,0.\nGRID,5,,2.,0.,0.\nGRID,9,,3.,0.,0.\n\
                SPC1,1,123,2,THRU,8\nPARAM,WTMASS,0.5\nCONM2,3,9,,10.\nPARAM,POST,-1\n";
    // Springs use GRIDs 1, 2, 5 (an unused grid would be dropped, all six DOFs held).
    let deck = format!("{deck}CELAS2,11,1.,1,1\nCELAS2,12,1.,2,1\nCELAS2,13,1.,5,1\n");
    let body = parse_str(&deck).unwrap();
    assert!(body.unused_grids.is_empty());
    let mut fixed: Vec<(usize, usize)> = body.mesh.constraints.clone();
    fixed.sort_unstable();
    assert_eq!(fixed, vec![(1, 0), (1, 1), (1, 2), (2, 0), (2, 1), (2, 2)]);
    assert_eq!(body.mesh.masses[0].mass, 5.0);
}

// ---------------------------------------------------------------------------------------------
// (f) Errors name the card, line and field.

fn error_of(deck: &str) -> String {
    parse_str(deck).unwrap_err().to_string()
}

#[test]
fn unsupported_card_names_card_and_line() {
    let err = error_of("BEGIN BULK\nGRID,1,,0.,0.,0.\nCHEXA,2,3,1,1,1,1,1,1\n+,1,1\n");
    assert!(err.contains("CHEXA") && err.contains("line 3"), "{err}");
    let err = error_of("GRID,1,,0.,0.,0.\nCQUAD8,2,7,1,1,1\n");
    assert!(err.contains("CQUAD8") && err.contains("line 2"), "{err}");
    let err = error_of("PARAM,COUPMASS,1\n");
    assert!(err.contains("COUPMASS") && err.contains("line 1"), "{err}");
}

#[test]
fn malformed_field_names_line_and_field() {
    // Integer where a real is required (E), in small field on line 3.
    let deck = "$ comment\nBEGIN BULK\nMAT1           1  210000             0.3\n";
    let err = error_of(deck);
    assert!(
        err.contains("line 3") && err.contains("field 3") && err.contains("(E)"),
        "{err}"
    );
    // Garbage in the continuation of a GRID-referencing card, field 4 of line 3.
    let err = error_of("GRID,1,,0.,0.,0.\nCONM2,1,1,,1.\n,1.,2.x\n");
    assert!(err.contains("line 3") && err.contains("field 3"), "{err}");
    let err = error_of("GRID,1,,0.,0.,0.,7\n");
    assert!(err.contains("CD"), "{err}");
    // Bad offset codes and tapered beams are rejected by name rather than ignored.
    let err = error_of("CBAR,1,2,3,4,0.,0.,1.,GGO\n,,,0.01x\n");
    assert!(err.contains("line 2") && err.contains("W1A"), "{err}");
    let err = error_of("PBEAM,1,1,1.-4,1.-8,1.-8,,2.-8\n,,,,,,,,\n,YES,1.,2.-4\n");
    assert!(err.contains("tapered") && err.contains("line 3"), "{err}");
}

#[test]
fn missing_references_are_named() {
    let base = "GRID,1,,0.,0.,0.\nGRID,2,,1.,0.,0.\nGRID,3,,1.,1.,0.\nGRID,4,,0.,1.,0.\n";
    let err = error_of(&format!("{base}CQUAD4,10,7,1,2,3,4\n"));
    assert!(
        err.contains("CQUAD4 10") && err.contains("PSHELL 7"),
        "{err}"
    );
    let err = error_of(&format!("{base}PSHELL,7,5,0.001,5\nCQUAD4,10,7,1,2,3,4\n"));
    assert!(err.contains("MAT1 5"), "{err}");
    let err = error_of(&format!(
        "{base}{STEEL}PSHELL,7,1,0.001,1\nCQUAD4,10,7,1,2,3,44\n"
    ));
    assert!(err.contains("GRID 44") && err.contains("line 7"), "{err}");
    let err = error_of(&format!(
        "{base}RBE2,3,1,123456,2\nRBE3,4,,2,1,1.,123,3,4\n"
    ));
    assert!(
        err.contains("GRID 2 component 1") && err.contains("RBE2 3 and RBE3 4"),
        "{err}"
    );
    let err = error_of(&format!("{base}RBE2,3,1,123,2\nSPC1,1,3,2\n"));
    assert!(
        err.contains("RBE2 3") && err.contains("also constrained"),
        "{err}"
    );
    let err = error_of(&format!("{base}RBE2,3,1,123456,2,9\n"));
    assert!(err.contains("RBE2 3") && err.contains("GRID 9"), "{err}");
    let err = error_of(&format!("{base}SPC1,1,123,1\nSPC1,2,123,2\n"));
    assert!(err.contains("several SPC sets"), "{err}");
    let err = error_of(&format!("{base}GRID,3,,5.,5.,5.\n"));
    assert!(
        err.contains("GRID 3 is defined twice") && err.contains("line 5"),
        "{err}"
    );
    let err = error_of(
        "CORD2R,1,2,0.,0.,0.,0.,0.,1.\n,1.,0.,0.\nCORD2R,2,1,0.,0.,0.,0.,0.,1.\n,1.,0.,0.\n",
    );
    assert!(err.contains("cycle"), "{err}");
    let err = error_of(&format!("{base}GRID,7,9,0.,0.,0.\n"));
    assert!(
        err.contains("GRID 7 CP") && err.contains("coordinate system 9"),
        "{err}"
    );
}

#[test]
fn directories_and_fifos_are_not_read() {
    let dir = std::env::temp_dir().join(format!("nastran-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let err = read_bulk_deck(&dir).unwrap_err().to_string();
    assert!(err.contains("not a regular file"), "{err}");
    let fifo = dir.join("deck.fifo");
    let made = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap();
    assert!(made.success());
    // Opening a FIFO without a writer would block: the check must come before the open.
    let err = read_bulk_deck(&fifo).unwrap_err().to_string();
    assert!(err.contains("not a regular file"), "{err}");
    let err = read_bulk_deck(&dir.join("missing.bdf"))
        .unwrap_err()
        .to_string();
    assert!(err.contains("missing.bdf"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}
