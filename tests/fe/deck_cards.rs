//! Bulk data cards CORD2C/CORD2S, CONM1 and CBUSH/PBUSH against closed forms: grid positions
//! in curvilinear systems, rigid-body mass properties, rotated bush stiffness, oscillators.

use std::f64::consts::PI;
use std::fmt::Write;

use engine_mount_chassis::eigen::lowest_modes;
use engine_mount_chassis::fe::assembly::{assemble, Assembled};
use engine_mount_chassis::nastran::{parse_str, NastranBody};
use nalgebra::{DMatrix, Matrix3, Vector3};

fn error_of(deck: &str) -> String {
    parse_str(deck).unwrap_err().to_string()
}

fn node_at(body: &NastranBody, grid: u32) -> Vector3<f64> {
    body.mesh.nodes[body.node(grid).unwrap()]
}

fn close(a: Vector3<f64>, b: Vector3<f64>, tol: f64) -> bool {
    (a - b).norm() <= tol
}

// ---------------------------------------------------------------------------------------------
// CORD2C / CORD2S.

#[test]
fn grids_in_cylindrical_and_spherical_systems_land_at_the_cartesian_closed_form() {
    // CORD2C 5: origin (1, 2, 3), z along basic y, x along basic x, so y = z × x = −basic z.
    // CORD2S 6 is defined in CORD2C 5: A at its origin, B at (r 0, z 1) → basic (1, 3, 3),
    // C at (r 1, θ 90°) → basic (1, 2, 2): z6 = basic y, x6 = −basic z, y6 = −basic x.
    let deck = "BEGIN BULK\n\
        CORD2C,5,,1.,2.,3.,1.,3.,3.\n,2.,2.,3.\n\
        CORD2S,6,5,0.,0.,0.,0.,0.,1.\n,1.,90.,0.\n\
        GRID,1,5,2.,30.,0.5\n\
        GRID,2,6,2.,60.,45.\n\
        GRID,3,5,0.,77.,-1.\n\
        GRID,4,6,3.,0.,123.\n\
        ENDDATA\n";
    let body = parse_str(deck).unwrap();
    let s3 = 3f64.sqrt();
    let s6 = 6f64.sqrt();
    // (r cos θ) x5 + (r sin θ) y5 + z z5 = (√3, 0, 0) + (0, 0, −1) + (0, 0.5, 0).
    let cases = [
        (1, Vector3::new(1.0 + s3, 2.5, 2.0)),
        // r (sin θ cos φ, sin θ sin φ, cos θ) = (√6/2, √6/2, 1) in x6, y6, z6.
        (2, Vector3::new(1.0 - s6 / 2.0, 3.0, 3.0 - s6 / 2.0)),
        // On the axis the angle does not matter.
        (3, Vector3::new(1.0, 1.0, 3.0)),
        // θ = 0: on the z6 axis whatever φ.
        (4, Vector3::new(1.0, 5.0, 3.0)),
    ];
    for (grid, expected) in cases {
        let p = node_at(&body, grid);
        println!("GRID {grid}: {p:?}, closed form {expected:?}");
        assert!(close(p, expected, 1e-12), "GRID {grid}: {p} vs {expected}");
    }
}

/// A cantilever of CBARs along a radial line, given in cylindrical coordinates (r, θ = 30°,
/// z) of a system rotated about basic x, or the same grids given in basic.
fn radial_cantilever(cylindrical: bool) -> String {
    let mut deck =
        String::from("BEGIN BULK\nMAT1,1,2.1+11,,0.3,7850.\nPBAR,5,1,3.-4,4.-8,1.-8,5.-8\n");
    // CORD2C 9: origin (0.1, 0.2, 0.3), z along (0, −sin 20°, cos 20°), x along basic x.
    let (s, c) = 20f64.to_radians().sin_cos();
    let o = Vector3::new(0.1, 0.2, 0.3);
    let ez = Vector3::new(0.0, -s, c);
    let ex = Vector3::x();
    let ey = ez.cross(&ex);
    let b = o + ez;
    let cc = o + ex;
    let _ = writeln!(
        deck,
        "CORD2C,9,,{:e},{:e},{:e},{:e},{:e},{:e}\n,{:e},{:e},{:e}",
        o.x, o.y, o.z, b.x, b.y, b.z, cc.x, cc.y, cc.z
    );
    let (st, ct) = 30f64.to_radians().sin_cos();
    let n = 12;
    for k in 0..=n {
        let r = 0.2 + 1.2 * k as f64 / n as f64;
        let z = 0.05;
        if cylindrical {
            let _ = writeln!(deck, "GRID,{},9,{r:e},30.,{z:e}", k + 1);
        } else {
            let p = o + ex * (r * ct) + ey * (r * st) + ez * z;
            let _ = writeln!(deck, "GRID,{},,{:e},{:e},{:e}", k + 1, p.x, p.y, p.z);
        }
        if k > 0 {
            // Orientation along z9 (perpendicular to the radial line), in basic.
            let _ = writeln!(
                deck,
                "CBAR,{},5,{},{},{:e},{:e},{:e}",
                k,
                k,
                k + 1,
                ez.x,
                ez.y,
                ez.z
            );
        }
    }
    deck.push_str("SPC1,1,123456,1\nENDDATA\n");
    deck
}

#[test]
fn a_beam_given_in_cylindrical_coordinates_has_the_frequencies_of_the_same_beam_in_basic() {
    let f = |cyl: bool| {
        let body = parse_str(&radial_cantilever(cyl)).unwrap();
        let asm = assemble(&body.mesh).unwrap();
        lowest_modes(&asm.k, &asm.m, 6, -1.0)
            .unwrap()
            .frequencies_hz()
    };
    let (cyl, basic) = (f(true), f(false));
    for (a, b) in cyl.iter().zip(&basic) {
        println!("cylindrical {a:.9} Hz, basic {b:.9} Hz");
        assert!((a / b - 1.0).abs() < 1e-9, "{a} vs {b}");
    }
}

#[test]
fn a_missing_displacement_system_is_refused_naming_the_grid_and_line() {
    let err = error_of(
        "BEGIN BULK\nCORD2C,5,,0.,0.,0.,0.,0.,1.\n,1.,0.,0.\nGRID,1,,0.,0.,0.\nGRID,17,,1.,0.,0.,6\n",
    );
    assert!(
        err.contains("GRID 17") && err.contains("line 5") && err.contains("CD"),
        "{err}"
    );
    // A curvilinear system cannot orient a mass offset.
    let err = error_of(
        "BEGIN BULK\nCORD2S,5,,0.,0.,0.,0.,0.,1.\n,1.,0.,0.\nGRID,1,,0.,0.,0.\nCONM2,3,1,5,1.,0.1\n",
    );
    assert!(
        err.contains("CONM2 3") && err.contains("CORD2S") && err.contains("line 5"),
        "{err}"
    );
}

// ---------------------------------------------------------------------------------------------
// CONM1.

/// The 6 × 6 matrix of a rigid body of mass m, centre of gravity r and inertia jc about it,
/// at the reference point: u(r) = u + θ × r.
fn rigid_matrix(m: f64, r: Vector3<f64>, jc: Matrix3<f64>) -> DMatrix<f64> {
    let rx = r.cross_matrix();
    let mut out = DMatrix::zeros(6, 6);
    for i in 0..3 {
        out[(i, i)] = m;
        for j in 0..3 {
            out[(3 + i, j)] = m * rx[(i, j)];
            out[(j, 3 + i)] = m * rx[(i, j)];
            out[(3 + i, 3 + j)] =
                jc[(i, j)] + m * (r.norm_squared() * f64::from(u8::from(i == j)) - r[i] * r[j]);
        }
    }
    out
}

fn conm1_card(id: u32, grid: u32, cid: u32, m: &DMatrix<f64>) -> String {
    let mut fields = vec![format!("CONM1,{id},{grid},{cid}")];
    for i in 0..6 {
        for j in 0..=i {
            fields.push(format!("{:e}", m[(i, j)]));
        }
    }
    // Free field: 8 data fields on the first line, then continuation lines of 8.
    // fields[0] holds the name and 3 data fields.
    let mut out = fields[..6].join(",");
    for chunk in fields[6..].chunks(8) {
        out.push_str("\n,");
        out.push_str(&chunk.join(","));
    }
    out.push('\n');
    out
}

/// Φᵀ M Φ with Φ the six rigid-body motions about the basic origin (translations, rotations).
fn rigid_body_mass(body: &NastranBody, asm: &Assembled) -> DMatrix<f64> {
    let owners = asm.dofs.owners();
    let mut phi = DMatrix::zeros(owners.len(), 6);
    for (g, &(node, d)) in owners.iter().enumerate() {
        let x = body.mesh.nodes[node];
        if d < 3 {
            phi[(g, d)] = 1.0;
            // u = θ × x: component d of θ × x is −[x]× θ.
            let xm = -x.cross_matrix();
            for k in 0..3 {
                phi[(g, 3 + k)] = xm[(d, k)];
            }
        } else {
            phi[(g, d)] = 1.0;
        }
    }
    let m = asm.m.to_dense();
    let md = DMatrix::from_fn(m.nrows(), m.ncols(), |i, j| m[(i, j)]);
    phi.transpose() * md * phi
}

/// Rotation of CORD2R 7 used below: about basic z by 90°, then the frame origin elsewhere
/// (irrelevant to directions): x7 = basic y, y7 = −basic x, z7 = basic z.
const CORD2R_7: &str = "CORD2R,7,,5.,6.,7.,5.,6.,8.\n,5.,7.,7.\n";

fn cord7() -> Matrix3<f64> {
    Matrix3::new(0.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0)
}

#[test]
fn a_free_body_of_conm1_masses_has_the_hand_summed_rigid_body_mass_properties() {
    let grids = [
        (1, Vector3::new(0.0, 0.0, 0.0)),
        (2, Vector3::new(1.5, -0.5, 0.25)),
        (3, Vector3::new(-0.7, 2.0, 1.0)),
    ];
    // Per grid: mass, offset of the centre of gravity (in the CONM1's system), inertia about it.
    let jc = |a: f64, b: f64, c: f64, p: f64| Matrix3::new(a, p, 0.0, p, b, -p, 0.0, -p, c);
    let bodies = [
        (
            1,
            0,
            12.0,
            Vector3::new(0.1, -0.2, 0.3),
            jc(2.0, 3.0, 4.0, 0.1),
        ),
        (
            2,
            7,
            3.5,
            Vector3::new(-0.4, 0.0, 0.2),
            jc(0.5, 0.7, 0.9, -0.05),
        ),
        (3, 0, 0.0, Vector3::zeros(), jc(1.0, 1.0, 2.0, 0.0)),
    ];
    let mut deck = String::from("BEGIN BULK\n");
    deck.push_str(CORD2R_7);
    for (g, x) in grids {
        let _ = writeln!(deck, "GRID,{g},,{:e},{:e},{:e}", x.x, x.y, x.z);
    }
    // Hand sum: each matrix turned to basic (T = diag(R, R)), then moved to the origin by
    // Φ_g = [I −[x_g]×; 0 I].
    let mut expected = DMatrix::zeros(6, 6);
    for (k, &(g, cid, m, r, j)) in bodies.iter().enumerate() {
        let local = rigid_matrix(m, r, j);
        deck.push_str(&conm1_card(10 + k as u32, g, cid, &local));
        let rot = if cid == 7 {
            cord7()
        } else {
            Matrix3::identity()
        };
        let mut t = DMatrix::zeros(6, 6);
        let mut phi = DMatrix::identity(6, 6);
        let xg = grids[g as usize - 1].1;
        let xm = -xg.cross_matrix();
        for i in 0..3 {
            for jj in 0..3 {
                t[(i, jj)] = rot[(i, jj)];
                t[(3 + i, 3 + jj)] = rot[(i, jj)];
                phi[(i, 3 + jj)] = xm[(i, jj)];
            }
        }
        let basic = &t * local * t.transpose();
        expected += phi.transpose() * basic * phi;
    }
    deck.push_str("ENDDATA\n");
    let body = parse_str(&deck).unwrap();
    let asm = assemble(&body.mesh).unwrap();
    let got = rigid_body_mass(&body, &asm);
    let scale = expected.abs().max();
    println!("rigid-body mass about the origin:\n{got:.6}hand sum:\n{expected:.6}");
    println!(
        "mass {} (hand 15.5), max |difference| / max entry {:e}",
        got[(0, 0)],
        (&got - &expected).abs().max() / scale
    );
    assert!((got[(0, 0)] - 15.5).abs() < 1e-12 * 15.5);
    assert!((&got - &expected).abs().max() <= 1e-12 * scale);
}

#[test]
fn a_conm1_equal_to_a_conm2_gives_the_same_mass_matrix() {
    let (m, x) = (7.0, Vector3::new(0.3, -0.1, 0.25));
    let [i11, i21, i22, i31, i32, i33] = [0.9, 0.05, 1.1, -0.02, 0.03, 1.4];
    // CONM2's products of inertia carry Nastran's minus signs.
    let j = Matrix3::new(i11, -i21, -i31, -i21, i22, -i32, -i31, -i32, i33);
    let head = format!("BEGIN BULK\n{CORD2R_7}GRID,4,,1.,2.,3.\n");
    for cid in [0, 7] {
        let conm2 = format!(
            "{head}CONM2,1,4,{cid},{m:e},{:e},{:e},{:e}\n,{i11:e},{i21:e},{i22:e},{i31:e},{i32:e},{i33:e}\n",
            x.x, x.y, x.z
        );
        let conm1 = format!("{head}{}", conm1_card(1, 4, cid, &rigid_matrix(m, x, j)));
        let a = assemble(&parse_str(&conm2).unwrap().mesh)
            .unwrap()
            .m
            .to_dense();
        let b = assemble(&parse_str(&conm1).unwrap().mesh)
            .unwrap()
            .m
            .to_dense();
        let mut worst: f64 = 0.0;
        for r in 0..a.nrows() {
            for c in 0..a.ncols() {
                worst = worst.max((a[(r, c)] - b[(r, c)]).abs());
            }
        }
        println!("CID {cid}: max |M(CONM1) − M(CONM2)| = {worst:e}");
        assert_eq!((a.nrows(), a.ncols()), (6, 6));
        assert!(worst <= 1e-12 * 7.0, "CID {cid}: {worst}");
    }
}

#[test]
fn a_conm1_that_is_not_a_rigid_body_is_refused_naming_card_and_line() {
    let mut m = rigid_matrix(2.0, Vector3::zeros(), Matrix3::identity());
    m[(1, 1)] = 3.0;
    let deck = format!("BEGIN BULK\nGRID,4,,0.,0.,0.\n{}", conm1_card(9, 4, 0, &m));
    let err = error_of(&deck);
    assert!(
        err.contains("CONM1 9") && err.contains("line 3") && err.contains("M22"),
        "{err}"
    );
}

// ---------------------------------------------------------------------------------------------
// CBUSH / PBUSH.

/// Rotation Rz(30°) Rx(20°) (columns: the axes of CORD2R 8 in basic) and its CORD2R card.
fn cord8() -> (Matrix3<f64>, String) {
    let (sz, cz) = 30f64.to_radians().sin_cos();
    let (sx, cx) = 20f64.to_radians().sin_cos();
    let rz = Matrix3::new(cz, -sz, 0.0, sz, cz, 0.0, 0.0, 0.0, 1.0);
    let rx = Matrix3::new(1.0, 0.0, 0.0, 0.0, cx, -sx, 0.0, sx, cx);
    let r = rz * rx;
    let o = Vector3::new(-1.0, 0.5, 2.0);
    let (b, c) = (o + r.column(2), o + r.column(0));
    let card = format!(
        "CORD2R,8,,{:e},{:e},{:e},{:e},{:e},{:e}\n,{:e},{:e},{:e}\n",
        o.x, o.y, o.z, b.x, b.y, b.z, c.x, c.y, c.z
    );
    (r, card)
}

const K: [f64; 6] = [1.0e5, 2.0e5, 3.5e5, 4.0e3, 5.0e3, 7.0e3];
const B: [f64; 6] = [11.0, 12.0, 13.0, 1.4, 1.5, 1.6];

fn pbush_card() -> String {
    let k: Vec<String> = K.iter().map(|v| format!("{v:e}")).collect();
    let b: Vec<String> = B.iter().map(|v| format!("{v:e}")).collect();
    format!("PBUSH,3,K,{}\n,,B,{}\n", k.join(","), b.join(","))
}

/// T diag(v) Tᵀ with T = diag(R, R): a diagonal element matrix turned to basic.
fn rotated(r: &Matrix3<f64>, v: &[f64; 6]) -> DMatrix<f64> {
    let mut t = DMatrix::zeros(6, 6);
    for i in 0..3 {
        for j in 0..3 {
            t[(i, j)] = r[(i, j)];
            t[(3 + i, 3 + j)] = r[(i, j)];
        }
    }
    let d = DMatrix::from_diagonal(&nalgebra::DVector::from_row_slice(v));
    &t * d * t.transpose()
}

/// Dense matrix of `asm` indexed by (node, dof) of the given nodes, in that order.
fn by_nodes(asm: &Assembled, a: &nalgebra::DMatrix<f64>, nodes: &[usize]) -> DMatrix<f64> {
    let owners = asm.dofs.owners();
    let index = |n: usize, d: usize| owners.iter().position(|&o| o == (n, d)).unwrap();
    let size = 6 * nodes.len();
    DMatrix::from_fn(size, size, |i, j| {
        a[(index(nodes[i / 6], i % 6), index(nodes[j / 6], j % 6))]
    })
}

fn dense(m: &engine_mount_chassis::fe::assembly::SparseMat) -> DMatrix<f64> {
    let d = m.to_dense();
    DMatrix::from_fn(d.nrows(), d.ncols(), |i, j| d[(i, j)])
}

#[test]
fn a_two_node_bush_in_a_rotated_system_has_stiffness_and_damping_rotated_from_its_axes() {
    let (r, cord) = cord8();
    let deck = format!(
        "BEGIN BULK\n{cord}{}GRID,1,,0.3,0.2,0.1\nGRID,2,,0.3,0.2,0.1\nCBUSH,5,3,1,2,,,,8\n",
        pbush_card()
    );
    let body = parse_str(&deck).unwrap();
    let asm = assemble(&body.mesh).unwrap();
    let nodes = [body.node(1).unwrap(), body.node(2).unwrap()];
    for (what, got, v) in [
        ("K", by_nodes(&asm, &dense(&asm.k), &nodes), &K),
        ("C", by_nodes(&asm, &dense(&asm.c), &nodes), &B),
    ] {
        let g = rotated(&r, v);
        // Relative motion only: [G −G; −G G].
        let mut expected = DMatrix::zeros(12, 12);
        for i in 0..6 {
            for j in 0..6 {
                expected[(i, j)] = g[(i, j)];
                expected[(6 + i, 6 + j)] = g[(i, j)];
                expected[(i, 6 + j)] = -g[(i, j)];
                expected[(6 + i, j)] = -g[(i, j)];
            }
        }
        let err = (&got - &expected).abs().max() / expected.abs().max();
        println!("{what}: max |assembled − T diag Tᵀ| / max entry = {err:e}");
        assert!(err <= 1e-12, "{what}: {err}");
    }
}

#[test]
fn a_bush_with_apart_ends_resists_no_rigid_motion_and_its_line_axes_equal_the_same_cid() {
    // GA → GB along the x axis of CORD2R 8, orientation vector its y axis: the element axes
    // are those of CORD2R 8, so the CID form must give the same matrix.
    let (r, cord) = cord8();
    let (xa, len) = (Vector3::new(0.3, 0.2, 0.1), 0.4);
    let xb = xa + r.column(0) * len;
    let y = r.column(1);
    let grids = format!(
        "GRID,1,,{:e},{:e},{:e}\nGRID,2,,{:e},{:e},{:e}\n",
        xa.x, xa.y, xa.z, xb.x, xb.y, xb.z
    );
    let head = format!("BEGIN BULK\n{cord}{}{grids}", pbush_card());
    let line = format!("{head}CBUSH,5,3,1,2,{:e},{:e},{:e},\n,0.3\n", y.x, y.y, y.z);
    let cid = format!("{head}CBUSH,5,3,1,2,,,,8\n,0.3\n");
    let k = |deck: &str| {
        let body = parse_str(deck).unwrap();
        let asm = assemble(&body.mesh).unwrap();
        let nodes = [body.node(1).unwrap(), body.node(2).unwrap()];
        by_nodes(&asm, &dense(&asm.k), &nodes)
    };
    let (kl, kc) = (k(&line), k(&cid));
    let scale = kc.abs().max();
    let same = (&kl - &kc).abs().max() / scale;
    // Six rigid-body motions of both ends: u = t + θ × x.
    let mut worst: f64 = 0.0;
    for mode in 0..6 {
        let mut u = DMatrix::zeros(12, 1);
        for (n, x) in [xa, xb].iter().enumerate() {
            if mode < 3 {
                u[(6 * n + mode, 0)] = 1.0;
            } else {
                let mut theta = Vector3::zeros();
                theta[mode - 3] = 1.0;
                let v = theta.cross(x);
                for d in 0..3 {
                    u[(6 * n + d, 0)] = v[d];
                }
                u[(6 * n + mode, 0)] = 1.0;
            }
        }
        worst = worst.max((&kc * u).abs().max() / scale);
    }
    println!("line axes vs CID: {same:e}; max |K u_rigid| / max |K| = {worst:e}");
    assert!(same <= 1e-12, "{same}");
    assert!(worst <= 1e-12, "{worst}");
}

#[test]
fn a_mass_on_a_grounded_bush_oscillates_at_the_square_root_of_k_over_m_per_direction() {
    let (m, j) = (4.0, 0.25);
    let (_, cord) = cord8();
    for cid in ["", "8", "0"] {
        let deck = format!(
            "BEGIN BULK\n{cord}{}GRID,1,,0.3,0.2,0.1\nCONM2,9,1,,{m:e},,,,\n,{j:e},,{j:e},,,{j:e}\nCBUSH,5,3,1,,,,,{cid}\n",
            pbush_card()
        );
        let body = parse_str(&deck).unwrap();
        let asm = assemble(&body.mesh).unwrap();
        let f = lowest_modes(&asm.k, &asm.m, 6, -1.0)
            .unwrap()
            .frequencies_hz();
        let mut expected: Vec<f64> = (0..6)
            .map(|d| (K[d] / if d < 3 { m } else { j }).sqrt() / (2.0 * PI))
            .collect();
        expected.sort_by(f64::total_cmp);
        for (a, b) in f.iter().zip(&expected) {
            println!("CID '{cid}': {a:.9} Hz, sqrt(k/m)/2π = {b:.9} Hz");
            assert!((a / b - 1.0).abs() < 1e-9, "CID '{cid}': {a} vs {b}");
        }
    }
}

#[test]
fn unsupported_bush_features_are_refused_naming_card_field_and_line() {
    let head = format!(
        "BEGIN BULK\n{}GRID,1,,0.,0.,0.\nGRID,2,,1.,0.,0.\n",
        pbush_card()
    );
    // Head: PBUSH on lines 2-3, grids on 4-5; the CBUSH starts on line 6.
    let cases = [
        (
            "CBUSH,5,3,1,2,0.,1.,0.\n,0.5,7\n",
            vec!["CBUSH", "OCID", "line 7"],
        ),
        (
            "CBUSH,5,3,1,2,0.,1.,0.\n,0.5,-1,0.1\n",
            vec!["CBUSH", "S1", "line 7"],
        ),
        ("CBUSH,5,3,1,2\n", vec!["CBUSH 5", "orientation", "line 6"]),
        ("PBUSH,4,K,1.\n,,GE,0.02\n", vec!["PBUSH", "GE1", "line 7"]),
        ("PBUSH,4,K,1.\n,,M,2.\n", vec!["PBUSH", "keyword", "line 7"]),
        (
            "CBUSH,5,4,1,2,0.,1.,0.\n",
            vec!["CBUSH 5", "PBUSH 4", "line 6"],
        ),
    ];
    for (card, words) in cases {
        let err = error_of(&format!("{head}{card}"));
        for w in words {
            assert!(err.contains(w), "{card}: '{w}' missing in {err}");
        }
    }
}

#[test]
fn beams_joined_only_by_a_bush_pass_the_mesh_checks_as_one_part() {
    use engine_mount_chassis::fe::checks::{check_mesh, CheckLimits};
    // Two cantilever segments whose facing ends coincide and are joined by a CBUSH alone.
    let deck = format!(
        "BEGIN BULK\nMAT1,1,2.1+11,,0.3,7850.\nPBAR,5,1,3.-4,4.-8,1.-8,5.-8\n{}\
         GRID,1,,0.,0.,0.\nGRID,2,,0.5,0.,0.\nGRID,3,,0.5,0.,0.\nGRID,4,,1.,0.,0.\n\
         CBAR,1,5,1,2,0.,1.,0.\nCBAR,2,5,3,4,0.,1.,0.\nCBUSH,6,3,2,3\nSPC1,1,123456,1\n",
        pbush_card()
    );
    let body = parse_str(&deck).unwrap();
    check_mesh(&body.mesh, &CheckLimits::default()).unwrap();
}
