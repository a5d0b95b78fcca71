//! Production shell cards against closed forms: CQUAD4/CTRIA3 ZOFFS (parallel-axis bending
//! stiffness, stacked layers, frequency), PSHELL MID2 and MID3 (bending material, Timoshenko
//! shear deflection), MAT8 orthotropic strips along both material axes and THETA, MAT2 with
//! the isotropic matrix against MAT1, and the errors that name card and line.

use std::f64::consts::PI;
use std::fmt::Write;

use engine_mount_chassis::eigen::lowest_modes;
use engine_mount_chassis::fe::assembly::assemble;
use engine_mount_chassis::fe::mesh::{Material, Mesh, Shell};
use engine_mount_chassis::nastran::{parse_str, write_bulk_deck, NastranBody};
use faer::prelude::Solve;
use faer::Mat;
use nalgebra::Vector3;

const E: f64 = 2.1e11;
const RHO: f64 = 7850.0;

/// A cantilever strip along x: `n` cells of length/n, one cell across the width, grids
/// 2i+1 (y = 0) and 2i+2 (y = width), clamped at x = 0.
struct Strip {
    n: usize,
    length: f64,
    width: f64,
    triangles: bool,
    /// Start each quadrilateral at a y = 0 corner after the root (side G1 → G2 along +x), or
    /// at a corner so that G1 → G2 runs across the strip (+y).
    across: bool,
    /// (PID, THETA°, ZOFFS) of each layer of elements on the same grids.
    layers: Vec<(u32, f64, f64)>,
    /// MCID in place of THETA.
    mcid: Option<u32>,
}

impl Strip {
    fn new(n: usize, length: f64, width: f64) -> Self {
        Self {
            n,
            length,
            width,
            triangles: false,
            across: false,
            layers: vec![(1, 0.0, 0.0)],
            mcid: None,
        }
    }

    /// Free-field deck: grids, elements, root clamp, `cards` (properties and materials),
    /// `extra` (further constraints).
    fn deck(&self, cards: &str, extra: &str) -> String {
        let mut d = String::from("BEGIN BULK\n");
        for i in 0..=self.n {
            let x = self.length * i as f64 / self.n as f64;
            writeln!(d, "GRID,{},,{x:?},0.,0.", 2 * i + 1).unwrap();
            writeln!(d, "GRID,{},,{x:?},{:?},0.", 2 * i + 2, self.width).unwrap();
        }
        let mut eid = 1;
        for &(pid, theta, zoffs) in &self.layers {
            let theta = match self.mcid {
                Some(id) => id.to_string(),
                None => format!("{theta:?}"),
            };
            for i in 0..self.n {
                let (a, b, c, e) = (2 * i + 1, 2 * i + 3, 2 * i + 4, 2 * i + 2);
                if self.triangles {
                    // Both triangles have G1 → G2 along the strip (+x and −x): THETA means the
                    // same material axes in both.
                    for [g1, g2, g3] in [[a, b, c], [c, e, a]] {
                        writeln!(d, "CTRIA3,{eid},{pid},{g1},{g2},{g3},{theta},{zoffs:?}").unwrap();
                        eid += 1;
                    }
                } else {
                    let g = if self.across {
                        [b, c, e, a]
                    } else {
                        [a, b, c, e]
                    };
                    writeln!(
                        d,
                        "CQUAD4,{eid},{pid},{},{},{},{},{theta},{zoffs:?}",
                        g[0], g[1], g[2], g[3]
                    )
                    .unwrap();
                    eid += 1;
                }
            }
        }
        d.push_str("SPC1,1,123456,1,2\n");
        d.push_str(cards);
        d.push_str(extra);
        d.push_str("ENDDATA\n");
        d
    }

    /// Tip displacement along `dof` under `force` along `dof` shared by the two tip grids.
    fn tip(&self, body: &NastranBody, dof: usize, force: f64) -> f64 {
        let a = assemble(&body.mesh).unwrap();
        let tips = [2 * self.n as u32 + 1, 2 * self.n as u32 + 2];
        let mut f = Mat::<f64>::zeros(a.dofs.n_free(), 1);
        for g in tips {
            f[(a.dofs.global(body.node(g).unwrap(), dof).unwrap(), 0)] = force / 2.0;
        }
        let u = a.k.to_dense().full_piv_lu().solve(&f);
        tips.iter()
            .map(|&g| u[(a.dofs.global(body.node(g).unwrap(), dof).unwrap(), 0)])
            .sum::<f64>()
            / 2.0
    }
}

fn within(what: &str, got: f64, want: f64, tol: f64) {
    let err = (got - want).abs() / want.abs();
    println!(
        "{what}: FE {got:.6e}, closed form {want:.6e}, error {:.3} %",
        100.0 * err
    );
    assert!(err < tol, "{what}: {got} vs {want} (error {err:.2e})");
}

/// MAT1 with ν = 0 (a one-cell strip is then a beam, no plate Poisson stiffening) and PSHELL 1
/// of thickness `t` with MID3 `mid3` ("" = blank).
fn steel_strip_cards(t: f64, mid3: &str) -> String {
    format!("MAT1,1,{E:?},,0.,{RHO:?}\nPSHELL,1,1,{t:?},1,,{mid3}\n")
}

// ---------------------------------------------------------------------------------------------
// ZOFFS.

#[test]
fn offset_strip_bends_with_the_parallel_axis_stiffness_when_its_grid_line_cannot_stretch() {
    // Grids held axially (component 1): the strip bends about the grid line, so its reference
    // plane at z0 stretches and I = b t³/12 + b t z0² (Kirchhoff: MID3 blank).
    let (length, width, t, z0, force): (f64, f64, f64, f64, f64) = (1.0, 0.05, 0.01, 0.02, 10.0);
    // The CST membrane converges more slowly here than the QM6 (1.1 % at 40 cells, 0.35 % at
    // 80): the triangles get twice the cells.
    for (triangles, n, tol) in [(false, 40, 0.002), (true, 80, 0.006)] {
        let held: String = (1..=2 * n + 2).map(|g| format!("SPC1,1,1,{g}\n")).collect();
        let mut strip = Strip::new(n, length, width);
        strip.triangles = triangles;
        let kind = if triangles { "CTRIA3" } else { "CQUAD4" };
        for (offset, inertia) in [
            (0.0, width * t.powi(3) / 12.0),
            (z0, width * t.powi(3) / 12.0 + width * t * z0 * z0),
        ] {
            strip.layers = vec![(1, 0.0, offset)];
            let body = parse_str(&strip.deck(&steel_strip_cards(t, ""), &held)).unwrap();
            let w = strip.tip(&body, 2, force);
            let theory = force * length.powi(3) / (3.0 * E * inertia);
            within(&format!("{kind} ZOFFS {offset}: tip"), w, theory, tol);
        }
    }
}

#[test]
fn two_layers_offset_by_half_their_thickness_are_one_plate_of_twice_the_thickness() {
    // Free axially: layers at ±t/2 on the same grids act as a solid plate of 2t, I = b (2t)³/12
    // (four times the two layers without offset), and vibrate at its frequency.
    let (length, width, t, force): (f64, f64, f64, f64) = (1.0, 0.05, 0.01, 10.0);
    let mut strip = Strip::new(40, length, width);
    for triangles in [false, true] {
        strip.triangles = triangles;
        let kind = if triangles { "CTRIA3" } else { "CQUAD4" };
        strip.layers = vec![(1, 0.0, t / 2.0), (1, 0.0, -t / 2.0)];
        let body = parse_str(&strip.deck(&steel_strip_cards(t, ""), "")).unwrap();
        let inertia = width * (2.0 * t).powi(3) / 12.0;
        let w = strip.tip(&body, 2, force);
        let theory = force * length.powi(3) / (3.0 * E * inertia);
        within(&format!("{kind} stacked ±t/2: tip"), w, theory, 0.01);

        let a = assemble(&body.mesh).unwrap();
        let modes = lowest_modes(&a.k, &a.m, 2, -1.0).unwrap();
        let f = modes.frequencies_hz()[0];
        let mass_per_length = RHO * width * 2.0 * t;
        let theory = 1.875_104_07f64.powi(2) / (2.0 * PI * length * length)
            * (E * inertia / mass_per_length).sqrt();
        within(
            &format!("{kind} stacked ±t/2: first frequency"),
            f,
            theory,
            0.01,
        );
    }
}

// ---------------------------------------------------------------------------------------------
// PSHELL MID2, MID3.

#[test]
fn a_bending_material_other_than_the_membrane_material_changes_bending_only() {
    let (length, width, t, force): (f64, f64, f64, f64) = (1.0, 0.05, 0.01, 10.0);
    let strip = Strip::new(40, length, width);
    let cards = |mid2: u32| {
        format!(
            "MAT1,1,{E:?},,0.,{RHO:?}\nMAT1,2,{:?},,0.,{RHO:?}\nPSHELL,1,1,{t:?},{mid2}\n",
            2.5 * E
        )
    };
    for (mid2, e_bending) in [(1, E), (2, 2.5 * E)] {
        let body = parse_str(&strip.deck(&cards(mid2), "")).unwrap();
        let stretch = strip.tip(&body, 0, force);
        within(
            &format!("MID2 = {mid2}: stretching"),
            stretch,
            force * length / (E * width * t),
            1e-6,
        );
        let w = strip.tip(&body, 2, force);
        let theory = force * length.powi(3) / (3.0 * e_bending * width * t.powi(3) / 12.0);
        within(&format!("MID2 = {mid2}: bending"), w, theory, 0.01);
    }
}

#[test]
fn transverse_shear_material_adds_the_timoshenko_shear_deflection_and_blank_mid3_removes_it() {
    // A thick strip (span 4 t): δ = P L³/3EI + P L/(k G b t) with k = TS/T = 5/6 when MID3 is
    // given; MID3 blank: no transverse shear flexibility, δ = P L³/3EI.
    let (length, width, t, force): (f64, f64, f64, f64) = (1.0, 0.05, 0.25, 1000.0);
    let strip = Strip::new(40, length, width);
    let g = E / 2.0;
    let bending = force * length.powi(3) / (3.0 * E * width * t.powi(3) / 12.0);
    let shear = force * length / (5.0 / 6.0 * g * width * t);
    let blank = strip.tip(
        &parse_str(&strip.deck(&steel_strip_cards(t, ""), "")).unwrap(),
        2,
        force,
    );
    let given = strip.tip(
        &parse_str(&strip.deck(&steel_strip_cards(t, "1"), "")).unwrap(),
        2,
        force,
    );
    within("MID3 blank: tip", blank, bending, 0.005);
    within("MID3 given: tip", given, bending + shear, 0.005);
    within(
        "MID3 given − blank: shear deflection",
        given - blank,
        shear,
        0.03,
    );
    // TS/T scales the shear stiffness: half the shear thickness, twice the shear deflection.
    let cards = format!("MAT1,1,{E:?},,0.,{RHO:?}\nPSHELL,1,1,{t:?},1,,1,0.4166667\n");
    let half = strip.tip(&parse_str(&strip.deck(&cards, "")).unwrap(), 2, force);
    within(
        "TS/T = 5/12: shear deflection",
        half - blank,
        2.0 * shear,
        0.03,
    );
}

// ---------------------------------------------------------------------------------------------
// MAT8, THETA.

#[test]
fn orthotropic_strip_bends_with_e1_along_axis_1_and_e2_along_axis_2() {
    // A narrow strip is a beam with free lateral curvature (M₂ = 0), so its bending stiffness
    // is 1/S₁₁ = E1 along axis 1 and E2 along axis 2, whatever NU12 and G12.
    let (length, width, t, force): (f64, f64, f64, f64) = (1.0, 0.05, 0.01, 10.0);
    let (e1, e2) = (1.4e11, 1.0e10);
    let cards = format!("MAT8,8,{e1:?},{e2:?},0.3,5.0e9,,,1600.\nPSHELL,1,8,{t:?},8,,8\n");
    let inertia = width * t.powi(3) / 12.0;
    for (triangles, across, theta, modulus, case) in [
        (false, false, 0.0, e1, "CQUAD4 THETA 0"),
        (false, false, 90.0, e2, "CQUAD4 THETA 90"),
        (false, true, 0.0, e2, "CQUAD4 G1→G2 across, THETA 0"),
        (false, true, -90.0, e1, "CQUAD4 G1→G2 across, THETA −90"),
        (true, false, 0.0, e1, "CTRIA3 THETA 0"),
        (true, false, 90.0, e2, "CTRIA3 THETA 90"),
    ] {
        let mut strip = Strip::new(40, length, width);
        strip.triangles = triangles;
        strip.across = across;
        strip.layers = vec![(1, theta, 0.0)];
        let body = parse_str(&strip.deck(&cards, "")).unwrap();
        let w = strip.tip(&body, 2, force);
        let theory = force * length.powi(3) / (3.0 * modulus * inertia);
        within(&format!("MAT8 {case}: tip"), w, theory, 0.015);
    }
    // MCID: the x axis of the system projected onto the element: basic x (MCID 0), and a
    // CORD2R with x along (0, 1, 1)/√2, which projects onto basic y.
    let tilted = "CORD2R,5,,0.,0.,0.,0.,-1.,1.\n,0.,1.,1.\n";
    for (mcid, triangles, modulus) in [(0, false, e1), (5, false, e2), (5, true, e2)] {
        let mut strip = Strip::new(40, length, width);
        strip.triangles = triangles;
        strip.mcid = Some(mcid);
        let body = parse_str(&strip.deck(&cards, tilted)).unwrap();
        let w = strip.tip(&body, 2, force);
        let theory = force * length.powi(3) / (3.0 * modulus * inertia);
        within(
            &format!("MAT8 MCID {mcid} (triangles: {triangles}): tip"),
            w,
            theory,
            0.015,
        );
    }
    // Stretching sees the same moduli: axial compliance S₁₁ = 1/E1 at THETA 0, 1/E2 at 90°.
    for (theta, modulus) in [(0.0, e1), (90.0, e2)] {
        let mut strip = Strip::new(40, length, width);
        strip.layers = vec![(1, theta, 0.0)];
        let body = parse_str(&strip.deck(&cards, "")).unwrap();
        let u = strip.tip(&body, 0, force);
        within(
            &format!("MAT8 THETA {theta}: stretching"),
            u,
            force * length / (modulus * width * t),
            0.005,
        );
    }
}

// ---------------------------------------------------------------------------------------------
// MAT2.

#[test]
fn mat2_with_the_isotropic_matrix_reproduces_mat1_in_any_orientation() {
    // A clamped, distorted 4 × 3 plate of CQUAD4 and CTRIA3: K and M from MAT1 (E, ν) against
    // MAT2 with G = E/(1−ν²) [1 ν 0; ν 1 0; 0 0 (1−ν)/2] for membrane and bending and a MAT2
    // [G 0; 0 G] for transverse shear, THETA 37° (an isotropic sheet has no orientation).
    let (e, nu, t) = (7.0e10, 0.33, 0.003);
    let g = e / (2.0 * (1.0 + nu));
    let f = e / (1.0 - nu * nu);
    let mut mesh = String::from("BEGIN BULK\n");
    for j in 0..4 {
        for i in 0..5 {
            let (x, y) = (
                0.1 * i as f64 + 0.013 * ((i * j) as f64).sin(),
                0.1 * j as f64 + 0.011 * ((i + 2 * j) as f64).cos(),
            );
            writeln!(
                mesh,
                "GRID,{},,{x:?},{y:?},{:?}",
                5 * j + i + 1,
                0.02 * x * y
            )
            .unwrap();
        }
    }
    let mut eid = 1;
    for j in 0..3 {
        for i in 0..4 {
            let a = 5 * j + i + 1;
            if (i + j) % 3 == 0 {
                writeln!(mesh, "CTRIA3,{eid},1,{a},{},{},THETA", a + 1, a + 6).unwrap();
                writeln!(mesh, "CTRIA3,{},1,{},{},{a},THETA", eid + 1, a + 6, a + 5).unwrap();
                eid += 2;
            } else {
                writeln!(
                    mesh,
                    "CQUAD4,{eid},1,{a},{},{},{},THETA",
                    a + 1,
                    a + 6,
                    a + 5
                )
                .unwrap();
                eid += 1;
            }
        }
    }
    mesh.push_str("SPC1,1,123456,1,6,11,16\n");
    let ts = 5.0 / 6.0;
    let mat1 = format!(
        "{}MAT1,1,{e:?},,{nu:?},2700.\nPSHELL,1,1,{t:?},1,,1,{ts:?},0.5\nENDDATA\n",
        mesh.replace("THETA", "")
    );
    let mat2 = format!(
        "{}MAT2,1,{:?},{:?},0.,{:?},0.,{g:?},2700.\nMAT2,3,{g:?},0.,,{g:?},,,2700.\n\
         PSHELL,1,1,{t:?},1,,3,{ts:?},0.5\nENDDATA\n",
        mesh.replace("THETA", "37."),
        f,
        nu * f,
        f
    );
    let (b1, b2) = (parse_str(&mat1).unwrap(), parse_str(&mat2).unwrap());
    assert!(b1.mesh.shells.iter().all(|s| s.section.is_none()));
    assert!(b2.mesh.shells.iter().all(|s| s.section.is_some()));
    let (a1, a2) = (assemble(&b1.mesh).unwrap(), assemble(&b2.mesh).unwrap());
    for (what, x, y) in [("K", &a1.k, &a2.k), ("M", &a1.m, &a2.m)] {
        let (x, y) = (x.to_dense(), y.to_dense());
        let rel = (&x - &y).norm_max() / x.norm_max();
        println!("{what}: MAT2 vs MAT1 largest difference / largest entry = {rel:.2e}");
        assert!(rel < 1e-12, "{what} differs by {rel:e}");
    }
}

#[test]
fn a_beaded_sheet_written_as_a_deck_reads_back_as_the_same_sheet() {
    // The mesh's sheet with bending thickness 1.7 t shears over 5/6 of it; the writer gives
    // 12I/T³ = 1.7³ and TS/T = 5/6 · 1.7, which the reader recognises as that sheet again.
    let mut mesh = Mesh::default();
    for p in [
        [0.0, 0.0, 0.0],
        [0.3, 0.0, 0.0],
        [0.3, 0.2, 0.01],
        [0.0, 0.2, 0.0],
    ] {
        mesh.add_node(Vector3::from(p));
    }
    mesh.shells.push(Shell {
        nodes: [0, 1, 2, 3],
        material: Material::STEEL,
        thickness: 0.001,
        bending_thickness: 0.0017,
        extra_mass_per_area: 0.3,
        section: None,
    });
    let body = parse_str(&write_bulk_deck(&mesh).unwrap()).unwrap();
    let read = &body.mesh.shells[0];
    assert!(read.section.is_none(), "{read:?}");
    assert!(
        (read.bending_thickness / 0.0017 - 1.0).abs() < 1e-9,
        "{read:?}"
    );
}

#[test]
fn an_offset_sheet_written_as_a_deck_reads_back_with_its_offset_and_stiffness() {
    // Quadrilaterals and triangles offset by ZOFFS and turned by THETA, on an isotropic PSHELL
    // with transverse shear (MID3): the writer puts ZOFFS and THETA on the element cards, and
    // the deck read back assembles to the same stiffness and mass.
    let (length, width, t, z0) = (1.0, 0.05, 0.01, 0.02);
    let cards = format!("MAT1,1,{E:?},,0.,{RHO:?}\nPSHELL,1,1,{t:?},1,,1,0.8333333333333334\n");
    for triangles in [false, true] {
        let mut strip = Strip::new(8, length, width);
        strip.triangles = triangles;
        strip.layers = vec![(1, 30.0, z0)];
        let first = parse_str(&strip.deck(&cards, "")).unwrap();
        let written = write_bulk_deck(&first.mesh).unwrap();
        let again = parse_str(&written).unwrap();
        let sections = |b: &NastranBody| -> Vec<(f64, f64)> {
            let quads = b.mesh.shells.iter().map(|s| s.section.as_deref());
            let tris = b.mesh.triangles.iter().map(|s| s.section.as_deref());
            quads
                .chain(tris)
                .map(|s| s.map_or((0.0, 0.0), |s| (s.offset, s.material_angle)))
                .collect()
        };
        for ((o1, a1), (o2, a2)) in sections(&first).into_iter().zip(sections(&again)) {
            assert_eq!(o1, z0);
            assert!(
                (o2 - o1).abs() < 1e-15 && (a2 - a1).abs() < 1e-15,
                "{o2} {a2}"
            );
        }
        let (a, b) = (
            assemble(&first.mesh).unwrap(),
            assemble(&again.mesh).unwrap(),
        );
        for (x, y) in [(&a.k, &b.k), (&a.m, &b.m)] {
            let (x, y) = (x.to_dense(), y.to_dense());
            let rel = (&x - &y).norm_max() / x.norm_max();
            println!("triangles {triangles}: written and read back, largest difference {rel:.1e}");
            assert!(rel < 1e-12, "{rel:e}");
        }
    }
    // A section the writer cannot express is refused, naming the shell.
    let orthotropic = "MAT8,8,1.4e11,1.0e10,0.3,5.0e9,,,1600.\nPSHELL,1,8,0.01,8,,8\n";
    let body = parse_str(&Strip::new(2, 1.0, 0.1).deck(orthotropic, "")).unwrap();
    let err = write_bulk_deck(&body.mesh).unwrap_err().to_string();
    assert!(
        err.contains("shell 0") && err.contains("general section"),
        "{err}"
    );
}

// ---------------------------------------------------------------------------------------------
// Errors.

fn error_of(deck: &str) -> String {
    parse_str(deck).unwrap_err().to_string()
}

#[test]
fn unknown_material_mid4_bad_mcid_and_half_given_mat8_shear_name_card_and_line() {
    let strip = Strip::new(2, 1.0, 0.1);
    // PSHELL is on line 12 (BEGIN BULK, 6 grids, 2 quads, SPC1, MAT1).
    let missing = strip.deck("MAT1,1,2.1e11,,0.3,7850.\nPSHELL,1,1,0.01,99,,1\n", "");
    let err = error_of(&missing);
    println!("{err}");
    assert!(
        err.contains("line 12") && err.contains("PSHELL 1") && err.contains("MID2"),
        "{err}"
    );
    assert!(err.contains("material 99 not found"), "{err}");

    let mid4 = strip.deck("MAT1,1,2.1e11,,0.3,7850.\nPSHELL,1,1,0.01,1,,1\n,,,5\n", "");
    let err = error_of(&mid4);
    println!("{err}");
    assert!(
        err.contains("PSHELL") && err.contains("MID4") && err.contains("line 13"),
        "{err}"
    );

    // MCID names a missing system, then a cylindrical one (material axes need a fixed x).
    let mut with_mcid = strip.deck("MAT8,8,1.4e11,1.0e10,0.3,5.0e9\nPSHELL,1,8,0.01,8\n", "");
    with_mcid = with_mcid.replace("CQUAD4,2,1,3,5,6,4,0.0,", "CQUAD4,2,1,3,5,6,4,7,");
    let err = error_of(&with_mcid);
    println!("{err}");
    assert!(
        err.contains("line 9") && err.contains("CQUAD4 2 MCID") && err.contains("system 7"),
        "{err}"
    );
    let err =
        error_of(&with_mcid.replace("ENDDATA", "CORD2C,7,,0.,0.,0.,0.,0.,1.\n,1.,0.,0.\nENDDATA"));
    println!("{err}");
    assert!(
        err.contains("line 9") && err.contains("CQUAD4 2 MCID") && err.contains("rectangular"),
        "{err}"
    );
    // With an isotropic material the orientation is irrelevant and MCID is accepted.
    let iso = strip
        .deck("MAT1,1,2.1e11,,0.3,7850.\nPSHELL,1,1,0.01,1,,1\n", "")
        .replace("CQUAD4,2,1,3,5,6,4,0.0,", "CQUAD4,2,1,3,5,6,4,7,");
    parse_str(&iso).unwrap();

    let mat8_half_shear = strip.deck(
        "MAT8,8,1.4e11,1.0e10,0.3,5.0e9,3.0e9\nPSHELL,1,8,0.01,8,,8\n",
        "",
    );
    let err = error_of(&mat8_half_shear);
    println!("{err}");
    assert!(
        err.contains("line 11") && err.contains("MAT8 8") && err.contains("G2Z"),
        "{err}"
    );
}
