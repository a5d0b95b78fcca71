//! Transverse shear flexibility of CBAR/CBEAM (PBAR/PBEAM K1, K2): static deflections against
//! the closed forms of Timoshenko beam statics (bending plus shear, each plane with its own I
//! and K), the simply supported frequency against the root of the Timoshenko frequency
//! equation, Nastran's defaults (PBAR blank: rigid in shear; PBEAM blank: K = 1.0, 0.0: rigid),
//! and shear flexibility composed with offsets and pin flags.

use std::f64::consts::PI;
use std::fmt::Write;

use engine_mount_chassis::eigen::lowest_modes;
use engine_mount_chassis::fe::assembly::assemble;
use engine_mount_chassis::nastran::{parse_str, write_bulk_deck, NastranBody};
use nalgebra::{DMatrix, DVector};

// The steel section of `beam_cards` (A = 3e-4 m², I1 = 4e-8 m⁴, I2 = 1e-8 m⁴): with the short
// spans below, shear deformation is 0.4–2 % of the deflections.
use super::beam_cards::{r, A, E, I1, I2, J, NU, RHO};

/// Different factors per plane, so swapping K1 and K2 (or I1 and I2) shows.
const K1: f64 = 0.5;
const K2: f64 = 0.8;

fn g() -> f64 {
    E / (2.0 * (1.0 + NU))
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// Property 5 of the section, `card` PBAR or PBEAM (constant section), with K1, K2 on the line
/// after the stress points (blank fields for `None`: the card's default).
fn property(card: &str, k: [Option<f64>; 2]) -> String {
    let f = |k: Option<f64>| k.map(r).unwrap_or_default();
    // PBEAM has the product of inertia I12 before J; PBAR has it after, on its second line.
    let i12 = if card == "PBEAM" { "0.," } else { "" };
    format!(
        "{card},5,1,{},{},{},{i12}{}\n,,,,,,,,\n,{},{}\n",
        r(A),
        r(I1),
        r(I2),
        r(J),
        f(k[0]),
        f(k[1])
    )
}

fn pbar(k: [Option<f64>; 2]) -> String {
    property("PBAR", k)
}

fn pbeam(k: [Option<f64>; 2]) -> String {
    property("PBEAM", k)
}

/// A straight line of `n` elements `card` (CBAR or CBEAM, property 5, element y = basic y)
/// along basic x from 0 to `l`, grids 1..=n+1, then `tail` (supports) and ENDDATA.
fn line(property: &str, card: &str, n: usize, l: f64, tail: &str) -> NastranBody {
    let mut deck = format!("BEGIN BULK\nMAT1,1,{},,{},{}\n", r(E), r(NU), r(RHO));
    deck.push_str(property);
    for k in 0..=n {
        let _ = writeln!(deck, "GRID,{},,{},0.,0.", k + 1, r(l * k as f64 / n as f64));
    }
    for k in 1..=n {
        let _ = writeln!(deck, "{card},{k},5,{},{},0.,1.,0.", k, k + 1);
    }
    deck.push_str(tail);
    deck.push_str("ENDDATA\n");
    parse_str(&deck).unwrap()
}

fn stiffness(body: &NastranBody) -> DMatrix<f64> {
    let d = assemble(&body.mesh).unwrap().k.to_dense();
    DMatrix::from_fn(d.nrows(), d.ncols(), |i, j| d[(i, j)])
}

/// Basic motion component `d` of grid `at` under the forces `loads` (grid, component, value).
fn deflection(body: &NastranBody, loads: &[(u32, usize, f64)], at: u32, d: usize) -> f64 {
    let asm = assemble(&body.mesh).unwrap();
    let row = |grid: u32, d: usize| asm.dofs.motion_row(body.node(grid).unwrap(), d).unwrap();
    let mut f = DVector::zeros(asm.dofs.n_free());
    for &(grid, c, value) in loads {
        for (g, w) in row(grid, c) {
            f[g] += w * value;
        }
    }
    let k = asm.k.to_dense();
    let k = DMatrix::from_fn(k.nrows(), k.ncols(), |i, j| k[(i, j)]);
    let q = k.lu().solve(&f).expect("K is regular");
    row(at, d).iter().map(|&(g, w)| w * q[g]).sum()
}

/// Tip deflection of a cantilever: bending plus shear, P L³/(3 E I) + P L/(k A G).
fn cantilever_tip(p: f64, l: f64, i: f64, k: Option<f64>) -> f64 {
    p * l.powi(3) / (3.0 * E * i) + k.map_or(0.0, |k| p * l / (k * A * g()))
}

#[test]
fn a_cantilever_tip_deflects_by_bending_plus_shear_in_each_plane_at_any_mesh() {
    let (l, p) = (0.3, 400.0);
    for (card, property) in [
        ("CBAR", pbar([Some(K1), Some(K2)])),
        ("CBEAM", pbeam([Some(K1), Some(K2)])),
    ] {
        for n in [1, 3, 7] {
            let body = line(&property, card, n, l, "SPC1,1,123456,1\n");
            let tip = n as u32 + 1;
            // Plane 1 (element x-y): I1 with K1; plane 2 (x-z): I2 with K2.
            for (d, i, k) in [(1, I1, K1), (2, I2, K2)] {
                let w = deflection(&body, &[(tip, d, p)], tip, d);
                let exact = cantilever_tip(p, l, i, Some(k));
                let shear_share = 1.0 - cantilever_tip(p, l, i, None) / exact;
                println!(
                    "{card} n = {n}, plane {d}: tip {w:.12e} m, closed form {exact:.12e} m \
                     (shear {:.2} %)",
                    100.0 * shear_share
                );
                assert!(shear_share > 3e-3, "the test must see shear");
                assert!(
                    rel(w, exact) < 1e-9,
                    "{card} n = {n} plane {d}: {w} vs {exact}"
                );
                // The other plane's factor would be a different beam: K1 belongs to plane 1.
                let swapped = cantilever_tip(p, l, i, Some(K1 + K2 - k));
                assert!(rel(w, swapped) > 100.0 * rel(w, exact).max(1e-12));
            }
        }
    }
}

#[test]
fn nastran_defaults_pbar_blank_is_rigid_pbeam_blank_is_one_and_zero_is_rigid() {
    let (n, l, p) = (4, 0.3, 400.0);
    let clamp = "SPC1,1,123456,1\n";
    let bar_blank = line(&pbar([None, None]), "CBAR", n, l, clamp);
    let section = bar_blank.mesh.beams[0].section;
    assert_eq!(
        (section.shear_factor_y, section.shear_factor_z),
        (None, None)
    );
    // PBAR without K: Euler-Bernoulli, the tip at P L³/(3 E I) exactly.
    let tip = n as u32 + 1;
    for (d, i) in [(1, I1), (2, I2)] {
        let w = deflection(&bar_blank, &[(tip, d, p)], tip, d);
        assert!(
            rel(w, cantilever_tip(p, l, i, None)) < 1e-9,
            "plane {d}: {w}"
        );
    }
    // PBAR K = 0.0 is rigid too (the value is read as infinite).
    let bar_zero = line(&pbar([Some(0.0), Some(0.0)]), "CBAR", n, l, clamp);
    assert_eq!(stiffness(&bar_zero), stiffness(&bar_blank));
    // PBEAM K = 0.0: today's Euler-Bernoulli element.
    let beam_zero = line(&pbeam([Some(0.0), Some(0.0)]), "CBEAM", n, l, clamp);
    let (kz, kb) = (stiffness(&beam_zero), stiffness(&bar_blank));
    assert!((&kz - &kb).abs().max() <= 1e-12 * kb.abs().max());
    // PBEAM blank: K1 = K2 = 1.0, shear flexible, the same element as PBAR K1 = K2 = 1.0.
    let beam_blank = line(&pbeam([None, None]), "CBEAM", n, l, clamp);
    let s = beam_blank.mesh.beams[0].section;
    assert_eq!((s.shear_factor_y, s.shear_factor_z), (Some(1.0), Some(1.0)));
    let bar_one = line(&pbar([Some(1.0), Some(1.0)]), "CBAR", n, l, clamp);
    assert_eq!(stiffness(&beam_blank), stiffness(&bar_one));
    for (d, i) in [(1, I1), (2, I2)] {
        let w = deflection(&beam_blank, &[(tip, d, p)], tip, d);
        assert!(
            rel(w, cantilever_tip(p, l, i, Some(1.0))) < 1e-9,
            "plane {d}: {w}"
        );
        assert!(rel(w, cantilever_tip(p, l, i, None)) > 1e-3);
    }
    // Only one plane given on the PBAR: the other stays rigid.
    let one = line(&pbar([Some(K1), None]), "CBAR", n, l, clamp);
    let w = deflection(&one, &[(tip, 2, p)], tip, 2);
    assert!(rel(w, cantilever_tip(p, l, I2, None)) < 1e-9);
    // Negative factors are refused, naming the field.
    let mut deck = format!("BEGIN BULK\nMAT1,1,{},,{}\n", r(E), r(NU));
    deck.push_str(&pbar([Some(-1.0), None]));
    deck.push_str("ENDDATA\n");
    let err = parse_str(&deck).unwrap_err().to_string();
    assert!(err.contains("K1") && err.contains("PBAR"), "{err}");
}

#[test]
fn a_written_deck_reads_back_with_the_same_shear_factors() {
    for k in [[Some(K1), Some(K2)], [None, Some(K2)], [None, None]] {
        let body = line(&pbar(k), "CBAR", 3, 0.3, "SPC1,1,123456,1\n");
        let text = write_bulk_deck(&body.mesh).unwrap();
        let back = parse_str(&text).unwrap();
        assert_eq!(back.mesh.beams.len(), 3);
        for (a, b) in body.mesh.beams.iter().zip(&back.mesh.beams) {
            assert_eq!(a.section, b.section, "{k:?}");
        }
    }
}

#[test]
fn a_hinged_gerber_beam_and_offset_grids_compose_with_shear_flexibility() {
    // Gerber beam: cantilever 1–2 (length a), hinge at 2 (PA = 6 on the next element: moment
    // about element z released), span 2–4 (length b, grid 3 at mid-span) on a roller at 4.
    // P at 3: the span is simply supported on the cantilever tip, which carries P/2.
    let (a, b, p) = (0.25, 0.4, 300.0);
    for (card, property) in [
        ("CBAR", pbar([Some(K1), Some(K2)])),
        ("CBEAM", pbeam([Some(K1), Some(K2)])),
    ] {
        let mut deck = format!("BEGIN BULK\nMAT1,1,{},,{},{}\n", r(E), r(NU), r(RHO));
        deck.push_str(&property);
        for (k, x) in [0.0, a, a + b / 2.0, a + b].iter().enumerate() {
            let _ = writeln!(deck, "GRID,{},,{},0.,0.", k + 1, r(*x));
        }
        let _ = writeln!(deck, "{card},1,5,1,2,0.,1.,0.");
        let _ = writeln!(deck, "{card},2,5,2,3,0.,1.,0.\n,6");
        let _ = writeln!(deck, "{card},3,5,3,4,0.,1.,0.");
        deck.push_str("SPC1,1,123456,1\nSPC1,1,123,4\nENDDATA\n");
        let body = parse_str(&deck).unwrap();
        let w = deflection(&body, &[(3, 1, p)], 3, 1);
        let tip = cantilever_tip(p / 2.0, a, I1, Some(K1));
        let span = p * b.powi(3) / (48.0 * E * I1) + p * b / (4.0 * K1 * A * g());
        let exact = tip / 2.0 + span;
        println!("{card} Gerber beam: {w:.12e} m, closed form {exact:.12e} m");
        assert!(rel(w, exact) < 1e-9, "{card}: {w} vs {exact}");
        let rigid = cantilever_tip(p / 2.0, a, I1, None) / 2.0 + p * b.powi(3) / (48.0 * E * I1);
        assert!(rel(w, rigid) > 0.01);
    }

    // Cantilever on grids e beside its axis (basic y), brought back by offsets W = (0, −e, 0):
    // a y load at the tip grid bends plane 1 only; a z load also twists the beam by the arm,
    // T = e P, which moves the grid by e θx = e² P L/(G J).
    let (n, l, e, p) = (5, 0.3, 0.04, 400.0);
    let mut deck = format!("BEGIN BULK\nMAT1,1,{},,{},{}\n", r(E), r(NU), r(RHO));
    deck.push_str(&pbar([Some(K1), Some(K2)]));
    for k in 0..=n {
        let x = l * k as f64 / n as f64;
        let _ = writeln!(deck, "GRID,{},,{},{},0.", k + 1, r(x), r(e));
    }
    for k in 1..=n {
        let w = format!("0.,{},0.", r(-e));
        let _ = writeln!(deck, "CBAR,{k},5,{},{},0.,1.,0.,,GGG\n,,,{w},{w}", k, k + 1);
    }
    deck.push_str("SPC1,1,123456,1\nENDDATA\n");
    let body = parse_str(&deck).unwrap();
    let tip = n as u32 + 1;
    let wy = deflection(&body, &[(tip, 1, p)], tip, 1);
    let exact_y = cantilever_tip(p, l, I1, Some(K1));
    let wz = deflection(&body, &[(tip, 2, p)], tip, 2);
    let exact_z = cantilever_tip(p, l, I2, Some(K2)) + e * e * p * l / (g() * J);
    println!("offset cantilever: y {wy:.12e} ({exact_y:.12e}), z {wz:.12e} ({exact_z:.12e})");
    assert!(rel(wy, exact_y) < 1e-9, "{wy} vs {exact_y}");
    assert!(rel(wz, exact_z) < 1e-9, "{wz} vs {exact_z}");
}

/// Lowest root ω² of the Timoshenko frequency equation of a simply supported uniform beam, mode
/// 1 (wave number α = π/L), from w = W sin αx, ψ = Ψ cos αx in
/// k A G (w'' − ψ') + ρ A ω² w = 0 and E I ψ'' + k A G (w' − ψ) + ρ I ω² ψ = 0:
/// (ρ A ω² − k A G α²)(ρ I ω² − E I α² − k A G) − (k A G α)² = 0. `rotary` = false drops the
/// ρ I ω² term (shear deformation only).
fn timoshenko_omega2(l: f64, i: f64, k: f64, rotary: bool) -> f64 {
    let alpha = PI / l;
    let kag = k * A * g();
    let ri = if rotary { RHO * i } else { 0.0 };
    // a ω⁴ + b ω² + c = 0
    let qa = RHO * A * ri;
    let qb = -RHO * A * (E * i * alpha * alpha + kag) - ri * kag * alpha * alpha;
    let qc = kag * alpha * alpha * (E * i * alpha * alpha + kag) - (kag * alpha).powi(2);
    if qa == 0.0 {
        -qc / qb
    } else {
        (-qb - (qb * qb - 4.0 * qa * qc).sqrt()) / (2.0 * qa)
    }
}

#[test]
fn a_deep_simply_supported_beam_converges_to_the_timoshenko_frequency() {
    // L = 0.15 m with I/A = (0.0115 m)²: slenderness L/r ≈ 13, a deep beam.
    let l = 0.15;
    // Plane 1 alone (v, rz free; every other DOF held) with I1/K1, then plane 2 with I2/K2.
    for (plane, i, k, held, ends) in [(1, I1, K1, "1345", "2"), (2, I2, K2, "1246", "3")] {
        let mut history = Vec::new();
        for n in [4, 8, 16, 32] {
            let tail = format!(
                "SPC1,1,{held},1,THRU,{}\nSPC1,1,{ends},1,{}\n",
                n + 1,
                n + 1
            );
            let body = line(&pbar([Some(K1), Some(K2)]), "CBAR", n, l, &tail);
            let asm = assemble(&body.mesh).unwrap();
            let f = lowest_modes(&asm.k, &asm.m, 1, -1.0)
                .unwrap()
                .frequencies_hz()[0];
            history.push(f);
        }
        let hz = |w2: f64| w2.sqrt() / (2.0 * PI);
        let shear_only = hz(timoshenko_omega2(l, i, k, false));
        let full = hz(timoshenko_omega2(l, i, k, true));
        let euler = hz(E * i * (PI / l).powi(4) / (RHO * A));
        println!(
            "plane {plane}: {history:.3?} Hz; Timoshenko {full:.3} Hz (shear only {shear_only:.3}), \
             Euler-Bernoulli {euler:.3} Hz"
        );
        // The Euler-Bernoulli formula is far off for this beam: the test sees shear.
        assert!(euler / shear_only > 1.02, "{euler} vs {shear_only}");
        // The lumped mass carries no section rotary inertia for bending (its HRZ rotation terms
        // vanish with the element length), so the mesh converges to the Timoshenko root without
        // the ρ I ω² term, at O(h²): each halving quarters the error.
        let errors: Vec<f64> = history.iter().map(|f| rel(*f, shear_only)).collect();
        assert!(errors[3] < 2e-3, "plane {plane}: {errors:?}");
        for w in errors.windows(2) {
            assert!(w[1] < 0.35 * w[0], "plane {plane}: {errors:?}");
        }
        // Rotary inertia lowers the full Timoshenko root below that.
        assert!(full < shear_only && rel(history[3], full) < 0.05);
    }
}
