//! CBAR/CBEAM offsets (OFFT, W1A..W3B) and pin flags (PA, PB), GRID CD displacement systems,
//! against closed forms of beam statics and oscillators, and against the same structure
//! described without them (a second model, not earlier output of this code).

use std::f64::consts::PI;
use std::fmt::Write;

use engine_mount_chassis::eigen::lowest_modes;
use engine_mount_chassis::fe::assembly::{assemble, Assembled};
use engine_mount_chassis::nastran::{parse_str, write_bulk_deck, NastranBody};
use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

// The steel section of every beam test (also `beam_shear`).
pub(crate) const E: f64 = 2.1e11;
pub(crate) const NU: f64 = 0.3;
pub(crate) const RHO: f64 = 7850.0;
pub(crate) const A: f64 = 3.0e-4;
pub(crate) const I1: f64 = 4.0e-8;
pub(crate) const I2: f64 = 1.0e-8;
pub(crate) const J: f64 = 5.0e-8;

/// A number as a bulk-data field.
pub(crate) fn r(x: f64) -> String {
    format!("{x:e}")
}

fn vec3(v: Vector3<f64>) -> String {
    format!("{},{},{}", r(v.x), r(v.y), r(v.z))
}

/// MAT1 1 and PBAR 5 (A, I1, I2, J above), beam density `rho`.
fn header(rho: f64) -> String {
    format!(
        "BEGIN BULK\nMAT1,1,{},,{},{}\nPBAR,5,1,{},{},{},{}\n",
        r(E),
        r(NU),
        r(rho),
        r(A),
        r(I1),
        r(I2),
        r(J)
    )
}

fn error_of(deck: &str) -> String {
    parse_str(deck).unwrap_err().to_string()
}

fn dense(m: &engine_mount_chassis::fe::assembly::SparseMat) -> DMatrix<f64> {
    let d = m.to_dense();
    DMatrix::from_fn(d.nrows(), d.ncols(), |i, j| d[(i, j)])
}

/// Static response to forces given in basic components at grids: returns the basic motion
/// (six components) of any grid. The load enters through the same motion rows that recover
/// the motion (virtual work), so grids with a displacement system are loaded in basic too.
struct Static<'a> {
    body: &'a NastranBody,
    asm: Assembled,
    q: DVector<f64>,
}

impl<'a> Static<'a> {
    fn solve(body: &'a NastranBody, loads: &[(u32, usize, f64)]) -> Self {
        let asm = assemble(&body.mesh).unwrap();
        let mut f = DVector::zeros(asm.dofs.n_free());
        for &(grid, d, value) in loads {
            for (g, c) in asm.dofs.motion_row(body.node(grid).unwrap(), d).unwrap() {
                f[g] += c * value;
            }
        }
        let q = dense(&asm.k).lu().solve(&f).expect("K is regular");
        Self { body, asm, q }
    }

    fn motion(&self, grid: u32, d: usize) -> f64 {
        self.asm
            .dofs
            .motion_row(self.body.node(grid).unwrap(), d)
            .unwrap()
            .iter()
            .map(|&(g, c)| c * self.q[g])
            .sum()
    }
}

fn frequencies(body: &NastranBody, n: usize) -> Vec<f64> {
    let asm = assemble(&body.mesh).unwrap();
    lowest_modes(&asm.k, &asm.m, n, -1.0)
        .unwrap()
        .frequencies_hz()
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

// ---------------------------------------------------------------------------------------------
// Offsets.

/// A clamped cantilever of `n` CBARs along basic x, length `l`, orientation (0, 1, 0), its grids
/// at `grid_shift` from the neutral axis and brought back to it by offsets: `None` without
/// offsets, else (OFFT, W at end A = W at end B as written on the card).
fn cantilever(
    n: usize,
    l: f64,
    grid_shift: Vector3<f64>,
    offsets: Option<(&str, Vector3<f64>)>,
) -> String {
    let mut deck = header(RHO);
    for k in 0..=n {
        let p = Vector3::new(l * k as f64 / n as f64, 0.0, 0.0) + grid_shift;
        let _ = writeln!(deck, "GRID,{},,{}", k + 1, vec3(p));
    }
    for k in 1..=n {
        let _ = write!(deck, "CBAR,{k},5,{},{},0.,1.,0.", k, k + 1);
        match offsets {
            None => deck.push('\n'),
            Some((offt, w)) => {
                let _ = writeln!(deck, ",{offt}\n,,,{},{}", vec3(w), vec3(w));
            }
        }
    }
    deck.push_str("SPC1,1,123456,1\nENDDATA\n");
    deck
}

#[test]
fn a_cantilever_on_offset_grids_equals_the_cantilever_on_its_axis() {
    let (n, l, e) = (8, 1.2, 0.05);
    let axis = parse_str(&cantilever(n, l, Vector3::zeros(), None)).unwrap();
    // Grids above the axis, offsets back down in basic (GGG, CD basic); grids beside it with
    // offsets in the element system (x along the bar, y = basic y from the orientation vector).
    let above = parse_str(&cantilever(
        n,
        l,
        Vector3::new(0.0, 0.0, e),
        Some(("GGG", Vector3::new(0.0, 0.0, -e))),
    ))
    .unwrap();
    let beside = parse_str(&cantilever(
        n,
        l,
        Vector3::new(0.0, e, 0.0),
        Some(("GOO", Vector3::new(0.0, -e, 0.0))),
    ))
    .unwrap();
    let tip = (n + 1) as u32;
    let p = 100.0;
    // Tip load along basic y (plane 1, I1) or z (plane 2, I2); EB elements are exact at the
    // nodes: P L³ / 3 E I. A grid beside the axis across the load also twists the beam: the
    // load's moment P e about the axis adds e · (P e L / G J) at the grid.
    let g = E / (2.0 * (1.0 + NU));
    for (body, shift) in [
        (&axis, Vector3::zeros()),
        (&above, Vector3::z() * e),
        (&beside, Vector3::y() * e),
    ] {
        for (d, i) in [(1, I1), (2, I2)] {
            let arm = shift.norm() - shift[d].abs();
            let expected = p * l.powi(3) / (3.0 * E * i) + p * arm * arm * l / (g * J);
            let s = Static::solve(body, &[(tip, d, p)]);
            let w = s.motion(tip, d);
            println!(
                "grids at {shift:?}, tip load along {d}: {w:.9e} m, closed form {expected:.9e} m"
            );
            assert!(rel(w, expected) < 1e-9, "{w} vs {expected}");
        }
    }
    // Written back as bulk data, offsets (in basic) and pin flags survive.
    let mut pinned = above.mesh.clone();
    pinned.beam_ends.get_mut(&2).unwrap().pins =
        [[false, true, false, false, false, true], [false; 6]];
    let again = parse_str(&write_bulk_deck(&pinned).unwrap()).unwrap();
    assert_eq!(again.mesh.beam_ends, pinned.beam_ends);
    let f_axis = frequencies(&axis, 8);
    for body in [&above, &beside] {
        for (a, b) in frequencies(body, 8).iter().zip(&f_axis) {
            println!("offset model {a:.9} Hz, on the axis {b:.9} Hz");
            assert!(rel(*a, *b) < 1e-9, "{a} vs {b}");
        }
    }
}

#[test]
fn an_axial_load_on_an_eccentric_arm_bends_the_beam_by_the_arm_moment() {
    // Beam on the axis, the tip grid sits e above the element end (W3B = −e): an axial force
    // P at the grid is P at the end plus the moment M = e P about y.
    let (n, l, e, p) = (4, 0.9, 0.04, 1.0e4);
    let mut deck = header(RHO);
    for k in 0..=n {
        let z = if k == n { e } else { 0.0 };
        let _ = writeln!(
            deck,
            "GRID,{},,{},0.,{}",
            k + 1,
            r(l * k as f64 / n as f64),
            r(z)
        );
    }
    for k in 1..=n {
        let _ = writeln!(deck, "CBAR,{k},5,{},{},0.,1.,0.", k, k + 1);
        if k == n {
            let _ = writeln!(deck, ",,,0.,0.,0.,0.,0.,{}", r(-e));
        }
    }
    deck.push_str("SPC1,1,123456,1\n");
    let body = parse_str(&deck).unwrap();
    let tip = (n + 1) as u32;
    let s = Static::solve(&body, &[(tip, 0, p)]);
    let m = e * p;
    // End rotation θy = M L / E I2; the grid moves with the end plus θ × (0, 0, e).
    let theta = m * l / (E * I2);
    let ux = p * l / (E * A) + theta * e;
    let uz = -m * l * l / (2.0 * E * I2);
    println!(
        "ux {:.9e} (closed {ux:.9e}), uz {:.9e} (closed {uz:.9e}), θy {:.9e} (closed {theta:.9e})",
        s.motion(tip, 0),
        s.motion(tip, 2),
        s.motion(tip, 4)
    );
    assert!(rel(s.motion(tip, 0), ux) < 1e-9);
    assert!(rel(s.motion(tip, 2), uz) < 1e-9);
    assert!(rel(s.motion(tip, 4), theta) < 1e-9);
}

#[test]
fn a_mass_on_a_rigid_arm_beyond_the_beam_end_has_the_arm_oscillator_frequency() {
    // A light cantilever of length L ends at x = L; its tip grid sits on the axis at L + a
    // (W1B = −a: a rigid arm) and carries a point mass m. Tip flexibility at the mass:
    // (L³/3 + a L² + a² L) / E I per bending plane.
    let (n, l, a, m) = (6, 0.6, 0.5, 4.0);
    let mut deck = header(1e-6);
    for k in 0..=n {
        let x = l * k as f64 / n as f64 + if k == n { a } else { 0.0 };
        let _ = writeln!(deck, "GRID,{},,{},0.,0.", k + 1, r(x));
    }
    for k in 1..=n {
        let _ = writeln!(deck, "CBAR,{k},5,{},{},0.,1.,0.", k, k + 1);
        if k == n {
            let _ = writeln!(deck, ",,,0.,0.,0.,{},0.,0.", r(-a));
        }
    }
    let _ = writeln!(deck, "CONM2,99,{},,{}", n + 1, r(m));
    deck.push_str("SPC1,1,123456,1\n");
    let body = parse_str(&deck).unwrap();
    let f = frequencies(&body, 2);
    let flex = (l.powi(3) / 3.0 + a * l * l + a * a * l) / E;
    // I2 < I1: the z bending (plane 2) is the lower mode.
    let expected = [I2, I1].map(|i| (i / flex / m).sqrt() / (2.0 * PI));
    for (got, want) in f.iter().zip(expected) {
        println!("{got:.9} Hz, closed form {want:.9} Hz");
        assert!(rel(*got, want) < 1e-6, "{got} vs {want}");
    }
    // A flexible extension instead of the rigid arm (a cantilever of length L + a, 3 E I /
    // (L + a)³) would be softer by a³/3 in the flexibility: the arm is really rigid.
    let plain = (3.0 * E * I2 / (l + a).powi(3) / m).sqrt() / (2.0 * PI);
    assert!(rel(plain, expected[0]) > 0.03);
}

// ---------------------------------------------------------------------------------------------
// Pin flags.

/// Beam 1–2–3 along x (two CBARs of length l, element y = basic y), clamped at 1, roller at 3
/// (translations fixed), `pins` = (PB of element 1, PA of element 2).
fn hinged_beam(l: f64, pins: (&str, &str)) -> NastranBody {
    let mut deck = header(RHO);
    for k in 0..3 {
        let _ = writeln!(deck, "GRID,{},,{},0.,0.", k + 1, r(l * k as f64));
    }
    let _ = writeln!(deck, "CBAR,1,5,1,2,0.,1.,0.\n,,{}", pins.0);
    let _ = writeln!(deck, "CBAR,2,5,2,3,0.,1.,0.\n,{}", pins.1);
    deck.push_str("SPC1,1,123456,1\nSPC1,1,123,3\n");
    parse_str(&deck).unwrap()
}

#[test]
fn a_pin_at_the_middle_joint_turns_a_propped_cantilever_into_a_hinged_one() {
    let (l, p) = (0.7, 250.0);
    // Load along basic y = element y at the middle grid: bending about element z (digit 6, I1).
    let deflection = |pins| Static::solve(&hinged_beam(l, pins), &[(2, 1, p)]).motion(2, 1);
    // Continuous: a propped cantilever of span 2l loaded at mid-span, δ = 7 P (2l)³ / 768 E I.
    let continuous = deflection(("", ""));
    let propped = 7.0 * p * (2.0 * l).powi(3) / (768.0 * E * I1);
    println!("continuous {continuous:.9e} m, closed form {propped:.9e} m");
    assert!(rel(continuous, propped) < 1e-9);
    // Hinge (moment release about element z at the joint, on either element): the span 2–3 is
    // a link pinned at both ends and carries no transverse load, so grid 2 is the tip of a
    // cantilever of length l: δ = P l³ / 3 E I.
    let hinge = p * l.powi(3) / (3.0 * E * I1);
    for pins in [("6", ""), ("", "6"), ("56", "")] {
        let w = deflection(pins);
        println!("pins {pins:?}: {w:.9e} m, closed form {hinge:.9e} m");
        assert!(rel(w, hinge) < 1e-9, "{pins:?}: {w} vs {hinge}");
    }
    // A release about element y (digit 5) leaves bending in this plane untouched.
    let w = deflection(("5", ""));
    assert!(rel(w, propped) < 1e-9, "{w} vs {propped}");
}

#[test]
fn bars_with_both_end_moments_released_in_the_plane_act_as_a_truss() {
    // Two bars from clamped grids 1 (0, 0) and 3 (2b, 0) meet at grid 2 (b, h); orientation
    // (0, 0, 1) makes element y = basic z, so the in-plane rotation is element ry (digit 5).
    // Grid 2 is held out of plane and in rotation: a pin joint of a plane truss.
    let (b, h, p) = (0.6, 0.45, 5.0e3);
    let deck = |pins: &str| {
        let mut d = header(RHO);
        let _ = writeln!(
            d,
            "GRID,1,,0.,0.,0.\nGRID,2,,{},{},0.,,3456\nGRID,3,,{},0.,0.",
            r(b),
            r(h),
            r(2.0 * b)
        );
        let _ = writeln!(d, "CBAR,1,5,1,2,0.,0.,1.\n,{pins},{pins}");
        let _ = writeln!(d, "CBAR,2,5,3,2,0.,0.,1.\n,{pins},{pins}");
        d.push_str("SPC1,1,123456,1,3\n");
        parse_str(&d).unwrap()
    };
    let lb = b.hypot(h);
    let (sin, cos) = (h / lb, b / lb);
    // Two-bar truss: k_y = 2 EA/L sin²α, k_x = 2 EA/L cos²α (symmetric, uncoupled).
    let ky = 2.0 * E * A / lb * sin * sin;
    let kx = 2.0 * E * A / lb * cos * cos;
    let truss = deck("5");
    for (d, k) in [(1, ky), (0, kx)] {
        let u = Static::solve(&truss, &[(2, d, p)]).motion(2, d);
        println!("truss along {d}: {u:.9e} m, closed form {:.9e} m", p / k);
        assert!(rel(u, p / k) < 1e-9, "{u} vs {}", p / k);
    }
    // Rigid joints add bending stiffness: a different (smaller) deflection.
    let frame = deck("");
    let u = Static::solve(&frame, &[(2, 1, p)]).motion(2, 1);
    assert!(u < p / ky * (1.0 - 1e-5), "{u} vs {}", p / ky);
}

#[test]
fn a_bar_released_axially_at_both_ends_assembles_and_carries_only_bending() {
    // Two bars between the same grids, one with PA = PB = 1: axial is a mechanism of that
    // element alone, dropped as NASTRAN does; the pair is still stable through the other bar.
    let (l, p) = (0.5, 1.0e3);
    let mut deck = header(RHO);
    deck.push_str("GRID,1,,0.,0.,0.\nGRID,2,,");
    let _ = writeln!(deck, "{},0.,0.", r(l));
    deck.push_str("CBAR,1,5,1,2,0.,1.,0.\n,1,1\nCBAR,2,5,1,2,0.,1.,0.\nSPC1,1,123456,1\n");
    let body = parse_str(&deck).unwrap();
    let axial = Static::solve(&body, &[(2, 0, p)]).motion(2, 0);
    assert!(rel(axial, p * l / (E * A)) < 1e-9, "{axial}");
    let bending = Static::solve(&body, &[(2, 1, p)]).motion(2, 1);
    let closed = p * l.powi(3) / (3.0 * E * 2.0 * I1);
    assert!(rel(bending, closed) < 1e-9, "{bending} vs {closed}");
    assert!(frequencies(&body, 3)
        .iter()
        .all(|f| f.is_finite() && *f > 0.0));
}

// ---------------------------------------------------------------------------------------------
// GRID CD.

/// Axes (columns, basic) of a CORD2R/CORD2C by points A, B, C: z along A→B, x in the plane
/// of A, B, C.
fn axes_of(a: Vector3<f64>, b: Vector3<f64>, c: Vector3<f64>) -> Matrix3<f64> {
    let ez = (b - a).normalize();
    let ex = ((c - a) - ez * ez.dot(&(c - a))).normalize();
    Matrix3::from_columns(&[ex, ez.cross(&ex), ez])
}

#[derive(Clone, Copy)]
enum Cd {
    Basic,
    Rectangular,
    Cylindrical,
}

const SYS_A: [f64; 3] = [0.3, -0.2, 0.1];
const SYS_B: [f64; 3] = [0.5, 0.4, 1.0];
const SYS_C: [f64; 3] = [1.3, 0.1, -0.4];

/// Displacement axes at basic point `p` for each kind of CD used below.
fn cd_axes(cd: Cd, p: Vector3<f64>) -> Matrix3<f64> {
    let (a, b, c) = (
        Vector3::from(SYS_A),
        Vector3::from(SYS_B),
        Vector3::from(SYS_C),
    );
    let r = axes_of(a, b, c);
    match cd {
        Cd::Basic => Matrix3::identity(),
        Cd::Rectangular => r,
        Cd::Cylindrical => {
            let l = r.transpose() * (p - a);
            let t = l.y.atan2(l.x);
            // Radial, tangential, axial at the point.
            let er = r * Vector3::new(t.cos(), t.sin(), 0.0);
            let et = r * Vector3::new(-t.sin(), t.cos(), 0.0);
            Matrix3::from_columns(&[er, et, r.column(2).into_owned()])
        }
    }
}

/// A 3D frame: clamped columns 1–3 and 2–4, a beam 3–4 with offsets, a CONM2 with offset and
/// inertia at 4, an RBE2 from 4 to grid 5 carrying a second mass, an RBE3 reference grid 6 on
/// grids 3, 4, 5 carrying a third.
/// Every vector written in a grid's displacement system (orientation vectors, GGG offsets) is
/// converted to it here, so all three decks describe the same structure.
fn frame_deck(cd: Cd) -> String {
    let mut deck = header(RHO);
    for card in ["CORD2R,10", "CORD2C,11"] {
        let _ = writeln!(
            deck,
            "{card},,{},{}\n,{}",
            vec3(SYS_A.into()),
            vec3(SYS_B.into()),
            vec3(SYS_C.into())
        );
    }
    let id = match cd {
        Cd::Basic => 0,
        Cd::Rectangular => 10,
        Cd::Cylindrical => 11,
    };
    let grids = [
        Vector3::new(0.0, 0.0, 0.0),
        Vector3::new(1.0, 0.1, 0.0),
        Vector3::new(0.05, 0.0, 0.9),
        Vector3::new(1.0, 0.3, 1.1),
        Vector3::new(0.6, 0.5, 1.4),
    ];
    for (k, p) in grids.iter().enumerate() {
        let _ = writeln!(deck, "GRID,{},,{},{id}", k + 1, vec3(*p));
    }
    let local = |grid: usize, v: Vector3<f64>| cd_axes(cd, grids[grid - 1]).transpose() * v;
    let bars = [
        (1, 1, 3, Vector3::new(1.0, 0.2, 0.0)),
        (2, 2, 4, Vector3::new(0.1, 1.0, 0.3)),
    ];
    for (id, a, b, v) in bars {
        let _ = writeln!(deck, "CBAR,{id},5,{a},{b},{}", vec3(local(a, v)));
    }
    // Beam 3–4 with offsets in basic (0, 0, 0.03) at A and (−0.02, 0.01, 0.02) at B, GGG.
    let (wa, wb) = (
        Vector3::new(0.0, 0.0, 0.03),
        Vector3::new(-0.02, 0.01, 0.02),
    );
    let _ = writeln!(
        deck,
        "CBAR,3,5,3,4,{},GGG\n,,,{},{}",
        vec3(local(3, Vector3::new(0.0, 0.2, 1.0))),
        vec3(local(3, wa)),
        vec3(local(4, wb))
    );
    deck.push_str("CONM2,20,4,,3.5,0.1,0.05,-0.02\n,0.02,0.001,0.03,0.,0.002,0.025\n");
    deck.push_str("RBE2,30,4,123456,5\nCONM2,21,5,,1.5\n,0.01,,0.01,,,0.01\n");
    // An RBE3 reference (grid 6) on grids 3, 4, 5 carrying a third mass.
    let _ = writeln!(deck, "GRID,6,,0.5,0.2,1.2,{id}");
    deck.push_str("RBE3,31,,6,123456,1.,123,3,4\n,5\nCONM2,22,6,,0.8\n,0.02,,0.01,,,0.015\n");
    deck.push_str("SPC1,1,123456,1,2\nENDDATA\n");
    deck
}

#[test]
fn a_frame_read_with_rotated_and_cylindrical_displacement_systems_has_the_same_modes() {
    let n = 8;
    let reference = parse_str(&frame_deck(Cd::Basic)).unwrap();
    let asm0 = assemble(&reference.mesh).unwrap();
    let modes0 = lowest_modes(&asm0.k, &asm0.m, n, -1.0).unwrap();
    let f0 = modes0.frequencies_hz();
    assert!(
        f0.windows(2).all(|w| w[1] > w[0] * 1.01),
        "distinct modes: {f0:?}"
    );
    // Basic motion of grids 4 and 5 in mode k.
    let motion = |body: &NastranBody, asm: &Assembled, shapes: &faer::Mat<f64>, k: usize| {
        let mut out = Vec::new();
        for grid in [3, 4, 5] {
            for d in 0..6 {
                let row = asm.dofs.motion_row(body.node(grid).unwrap(), d).unwrap();
                out.push(row.iter().map(|&(g, c)| c * shapes[(g, k)]).sum::<f64>());
            }
        }
        DVector::from_vec(out)
    };
    for cd in [Cd::Rectangular, Cd::Cylindrical] {
        let body = parse_str(&frame_deck(cd)).unwrap();
        assert_eq!(body.mesh.displacement_frames.len(), 6);
        let asm = assemble(&body.mesh).unwrap();
        let modes = lowest_modes(&asm.k, &asm.m, n, -1.0).unwrap();
        for (k, (a, b)) in modes.frequencies_hz().iter().zip(&f0).enumerate() {
            let (u, u0) = (
                motion(&body, &asm, &modes.shapes, k),
                motion(&reference, &asm0, &modes0.shapes, k),
            );
            let sign = u.dot(&u0).signum();
            let diff = (u * sign - &u0).amax() / u0.amax();
            println!("mode {k}: {a:.9} Hz vs {b:.9} Hz, basic motion difference {diff:.2e}");
            assert!(rel(*a, *b) < 1e-9, "{a} vs {b}");
            assert!(diff < 1e-7, "mode {k}: {diff}");
        }
    }
}

/// A point mass m on grid 1 whose CD is system 10 (basic rotated by α about z), on a grounded
/// CBUSH with stiffness k1, k2 along basic x, y; `constraint` holds CD components (SPC1 or PS),
/// `celas` adds a CELAS2 on CD component 2.
fn skewed_oscillator(alpha_deg: f64, ps: bool, celas: Option<f64>) -> NastranBody {
    let (s, c) = alpha_deg.to_radians().sin_cos();
    let mut deck = String::from("BEGIN BULK\n");
    let _ = writeln!(deck, "CORD2R,10,,0.,0.,0.,0.,0.,1.\n,{},{},0.", r(c), r(s));
    deck.push_str(if ps {
        "GRID,1,,0.,0.,0.,10,13456\n"
    } else {
        "GRID,1,,0.,0.,0.,10\nSPC1,1,13456,1\n"
    });
    deck.push_str("CONM2,2,1,,2.\nCBUSH,3,4,1,,,,,0\nPBUSH,4,K,1.+5,3.+5,1.+5,1.,1.,1.\n");
    if let Some(k) = celas {
        let _ = writeln!(deck, "CELAS2,5,{},1,2", r(k));
    }
    parse_str(&deck).unwrap()
}

#[test]
fn a_roller_on_an_inclined_plane_moves_along_the_plane_at_the_closed_form_frequency() {
    // Constraint along CD axis 1 = (cos α, sin α, 0): the mass slides along (−sin α, cos α, 0)
    // against k1 sin²α + k2 cos²α (+ a CELAS2 acting on that CD component).
    let (k1, k2, m) = (1.0e5, 3.0e5, 2.0);
    for (alpha, ps, celas) in [
        (30.0, false, None),
        (30.0, true, None),
        (-55.0, false, Some(4.0e4)),
    ] {
        let body = skewed_oscillator(alpha, ps, celas);
        let asm = assemble(&body.mesh).unwrap();
        assert_eq!(asm.dofs.n_free(), 1);
        let modes = lowest_modes(&asm.k, &asm.m, 1, -1.0).unwrap();
        let (s, c) = f64::to_radians(alpha).sin_cos();
        let k = k1 * s * s + k2 * c * c + celas.unwrap_or(0.0);
        let expected = (k / m).sqrt() / (2.0 * PI);
        let f = modes.frequencies_hz()[0];
        println!("α = {alpha}°: {f:.9} Hz, closed form {expected:.9} Hz");
        assert!(rel(f, expected) < 1e-9, "{f} vs {expected}");
        let u: Vec<f64> = (0..3)
            .map(|d| {
                let row = asm.dofs.motion_row(body.node(1).unwrap(), d).unwrap();
                row.iter().map(|&(g, cf)| cf * modes.shapes[(g, 0)]).sum()
            })
            .collect();
        let along = Vector3::new(-s, c, 0.0);
        let u = Vector3::from_vec(u);
        assert!(
            (u.normalize().dot(&along).abs() - 1.0).abs() < 1e-12,
            "{u:?}"
        );
        // Unit modal mass: m |u|² = 1.
        assert!((m * u.norm_squared() - 1.0).abs() < 1e-12);
    }
}

// ---------------------------------------------------------------------------------------------
// Errors.

#[test]
fn bad_offset_codes_pin_flags_and_displacement_systems_are_refused_naming_card_and_line() {
    let base = "BEGIN BULK\nGRID,1,,0.,0.,0.\nGRID,2,,1.,0.,0.\n";
    for code in ["OGG", "GGB", "GG", "XYZ"] {
        let err = error_of(&format!("{base}CBAR,7,5,1,2,0.,1.,0.,{code}\n"));
        assert!(
            err.contains("CBAR")
                && err.contains("line 4")
                && err.contains("OFFT")
                && err.contains(code),
            "{err}"
        );
    }
    let err = error_of(&format!("{base}CBEAM,7,5,1,2,0.,1.,0.,1.5\n"));
    assert!(err.contains("CBEAM") && err.contains("OFFT"), "{err}");
    for (pins, field) in [
        ("123456,", "PA"),
        (",123456", "PB"),
        ("17,", "PA"),
        (",33", "PB"),
    ] {
        let err = error_of(&format!("{base}CBAR,7,5,1,2,0.,1.,0.\n,{pins}\n"));
        assert!(
            err.contains("CBAR") && err.contains("line 5") && err.contains(field),
            "{pins}: {err}"
        );
    }
    let err = error_of("BEGIN BULK\nGRID,1,,0.,0.,0.\nGRID,17,,1.,0.,0.,5\n");
    assert!(
        err.contains("GRID 17")
            && err.contains("line 3")
            && err.contains("CD")
            && err.contains("5"),
        "{err}"
    );
    // Offsets in the element system need an element system: GA and GB must be apart.
    let err = error_of(
        "BEGIN BULK\nMAT1,1,2.1+11,,0.3\nPBAR,5,1,1.-4,1.-8,1.-8,1.-8\nGRID,1,,0.,0.,0.\n\
         GRID,2,,0.,0.,0.\nCBAR,7,5,1,2,0.,1.,0.,GOO\n,,,0.,0.,0.,1.,0.,0.\n",
    );
    assert!(err.contains("CBAR 7") && err.contains("line 6"), "{err}");
}

#[test]
fn a_reduced_body_with_mount_grids_in_displacement_systems_reports_the_same_basic_motion() {
    use engine_mount_chassis::cms::{
        reduce, BodySource, BulkDeckBody, ModeSelection, ReductionSpec,
    };
    use engine_mount_chassis::nastran::{deck_digest, DeckOptions};
    let dir = std::env::temp_dir().join(format!("emc-beam-cards-cd-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let reduced = |cd: Cd| {
        let path = dir.join(format!("frame-{}.bdf", cd as u8));
        std::fs::write(&path, frame_deck(cd)).unwrap();
        let points = [("mount_a", 3), ("mount_b", 4), ("out", 5)]
            .map(|(n, g)| (n.to_string(), g))
            .into();
        let spec = ReductionSpec {
            body: BodySource::Deck(BulkDeckBody {
                sha256: deck_digest(&path, &DeckOptions::default()).unwrap(),
                path,
                points,
                include_root: None,
            }),
            interface: vec!["mount_a".into(), "mount_b".into()],
            outputs: vec!["out".into()],
            selection: ModeSelection::Count(3),
            ..ReductionSpec::default()
        };
        reduce(&spec).unwrap()
    };
    let basic = reduced(Cd::Basic);
    for cd in [Cd::Rectangular, Cd::Cylindrical] {
        let other = reduced(cd);
        assert_eq!(other.omega.len(), basic.omega.len());
        for (k, (a, b)) in other.omega.iter().zip(&basic.omega).enumerate() {
            assert!(rel(*a, *b) < 1e-9, "mode {k}: {a} vs {b} rad/s");
            // The points' motion per modal coordinate is in basic (vehicle) axes: equal up to
            // the sign of the mode.
            let flat = |r: &engine_mount_chassis::cms::ReducedChassis| -> DVector<f64> {
                DVector::from_iterator(18, r.points.iter().flat_map(|p| p.shape[k]))
            };
            let (u, u0) = (flat(&other), flat(&basic));
            let diff = (u.clone() * u.dot(&u0).signum() - &u0).amax() / u0.amax();
            println!("mode {k}: {a:.6} rad/s, point motion difference {diff:.2e}");
            assert!(diff < 1e-7, "mode {k}: {diff}");
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}
