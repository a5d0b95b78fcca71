//! A user's body from a Nastran bulk data deck, against independent truth: a mass on a spring,
//! Euler-Bernoulli cantilever beams, Leissa's cantilever plate, and the procedural chassis
//! written as a deck and read back.

use std::f64::consts::PI;
use std::fmt::Write as _;

use engine_mount_chassis::fe::assembly::assemble;
use engine_mount_chassis::fe::chassis::Chassis;
use engine_mount_chassis::fe::chassis_config::ChassisConfig;
use engine_mount_chassis::fe::eigen::lowest_modes;
use engine_mount_chassis::fe::mesh::Mesh;
use engine_mount_chassis::fe::nastran::{parse_str, read_bulk_deck, write_bulk_deck};

/// The `n` lowest natural frequencies (Hz) of a mesh.
fn frequencies(mesh: &Mesh, n: usize) -> Vec<f64> {
    let asm = assemble(mesh).expect("assembly");
    let modes = lowest_modes(&asm.k, &asm.m, n, -1.0).expect("modes");
    modes
        .eigenvalues
        .iter()
        .map(|l| l.max(0.0).sqrt() / (2.0 * PI))
        .collect()
}

#[test]
fn a_mass_on_a_spring_in_small_and_free_field() {
    let (k, m): (f64, f64) = (4.0e5, 12.5);
    let small = format!(
        "BEGIN BULK\nGRID    1               0.      0.      0.\nCONM2   2       1               {m:<8.1}\n\
         +       1.      0.      1.      0.      0.      1.\nCELAS2  3       {k:<8.1e}1       3\n\
         SPC1    1       12456   1\nENDDATA\n"
    );
    let free = format!("GRID,1,,0.,0.,0.\nCONM2,2,1,,{m:.1},,,,\n+,1.,,1.,,,1.\nCELAS2,3,{k:.1},1,3\nSPC1,1,12456,1\n");
    for deck in [small, free] {
        let body = parse_str(&deck).expect("deck");
        let f = frequencies(&body.mesh, 1)[0];
        let expected = (k / m).sqrt() / (2.0 * PI);
        assert!((f / expected - 1.0).abs() < 1e-10, "{f} vs {expected} Hz");
    }
}

/// A steel cantilever of `n` CBAR elements along x, clamped at x = 0.
fn cantilever_beam(n: usize, length: f64) -> String {
    let mut d =
        String::from("MAT1,1,2.1+11,,0.3,7850.\nPBAR,1,1,1.-4,8.333333333-10,2.083333333-9,1.-9\n");
    for i in 0..=n {
        let _ = writeln!(
            d,
            "GRID,{},,{:?},0.,0.",
            i + 1,
            length * i as f64 / n as f64
        );
    }
    for i in 0..n {
        let _ = writeln!(d, "CBAR,{},1,{},{},0.,1.,0.", i + 1, i + 1, i + 2);
    }
    d.push_str("SPC1,1,123456,1\n");
    d
}

#[test]
fn a_cantilever_beam_has_the_euler_bernoulli_frequencies() {
    let (length, e, rho, area) = (1.0, 2.1e11, 7850.0, 1.0e-4);
    // I1 (bending in the plane of x and the orientation vector y) and I2 (in the x-z plane)
    let (i1, i2) = (8.333333333e-10, 2.083333333e-9);
    let body = parse_str(&cantilever_beam(40, length)).expect("deck");
    let f = frequencies(&body.mesh, 4);
    let beta = 1.875_104_068_711_96_f64;
    let analytic =
        |i: f64| beta * beta / (2.0 * PI) * (e * i / (rho * area * length.powi(4))).sqrt();
    let (fy, fz) = (analytic(i1), analytic(i2));
    // the two lowest modes are the first bending modes in the two planes
    let (lo, hi) = (f[0].min(f[1]), f[0].max(f[1]));
    println!("cantilever beam: {lo} vs {fy} Hz, {hi} vs {fz} Hz");
    assert!((lo / fy - 1.0).abs() < 2e-3, "{lo} vs {fy} Hz");
    assert!((hi / fz - 1.0).abs() < 2e-3, "{hi} vs {fz} Hz");
}

#[test]
fn a_cantilever_plate_has_leissas_frequencies() {
    // Square steel plate a × a, thickness h, clamped along x = 0 (Leissa, Vibration of Plates,
    // 1969, Table 4.50, ν = 0.3: ω a² √(ρh/D) = 3.492, 8.525, 21.43 for the first three modes).
    let (a, h, n): (f64, f64, usize) = (0.5, 0.004, 16);
    let (e, nu, rho): (f64, f64, f64) = (2.1e11, 0.3, 7850.0);
    let mut d = format!("MAT1,1,2.1+11,,0.3,7850.\nPSHELL,1,1,{h:?}\n");
    let gid = |i: usize, j: usize| i * (n + 1) + j + 1;
    for i in 0..=n {
        for j in 0..=n {
            let _ = writeln!(
                d,
                "GRID,{},,{:?},{:?},0.",
                gid(i, j),
                a * i as f64 / n as f64,
                a * j as f64 / n as f64
            );
        }
    }
    let mut eid = 0;
    for i in 0..n {
        for j in 0..n {
            eid += 1;
            let _ = writeln!(
                d,
                "CQUAD4,{eid},1,{},{},{},{}",
                gid(i, j),
                gid(i + 1, j),
                gid(i + 1, j + 1),
                gid(i, j + 1)
            );
        }
    }
    for j in 0..=n {
        let _ = writeln!(d, "SPC1,1,123456,{}", gid(0, j));
    }
    let body = parse_str(&d).expect("deck");
    let f = frequencies(&body.mesh, 3);
    let dflex = e * h.powi(3) / (12.0 * (1.0 - nu * nu));
    let unit = (dflex / (rho * h)).sqrt() / (a * a) / (2.0 * PI);
    for (got, leissa) in f.iter().zip([3.492, 8.525, 21.43]) {
        let expected = leissa * unit;
        println!("cantilever plate: {got} vs Leissa {expected} Hz");
        assert!(
            (got / expected - 1.0).abs() < 0.02,
            "{got} vs {expected} Hz"
        );
    }
}

#[test]
fn the_procedural_chassis_written_as_a_deck_reads_back_with_the_same_modes() {
    let chassis = Chassis::build(&ChassisConfig::default()).expect("chassis");
    let deck = write_bulk_deck(&chassis.mesh).expect("deck");
    let body = parse_str(&deck).expect("read back");
    assert_eq!(body.mesh.nodes.len(), chassis.mesh.nodes.len());
    let a = frequencies(&chassis.mesh, 20);
    let b = frequencies(&body.mesh, 20);
    for (x, y) in a.iter().zip(&b) {
        assert!((x - y).abs() <= 1e-9 * x.max(1.0), "{x} vs {y} Hz");
    }
}

#[test]
fn unsupported_and_broken_decks_are_errors_naming_card_and_line() {
    let cases = [
        (
            "GRID,1,,0.,0.,0.\nCTRIA3,1,1,1,1,1\n",
            "CTRIA3 card on line 2",
        ),
        (
            "GRID,1,,0.,0.,0.\nRBE2,1,1,123456,2\n",
            "RBE2 card on line 2",
        ),
        (
            "GRID,1,,0.,0.,0.\nFORCE,1,1,,1.\n",
            "unsupported card FORCE on line 2",
        ),
        ("GRID,1,,0.,zero,0.\n", "GRID card on line 1, field 5"),
        (
            "GRID,1,,0.,0.,0.\nCQUAD4,1,7,1,1,1,1\n",
            "refers to PSHELL 7",
        ),
        (
            "MAT1,1,2.1+11,,0.3,7850.\nPSHELL,1,1,.004\nCQUAD4,1,1,1,2,3,4\n",
            "refers to GRID 1",
        ),
    ];
    for (deck, needle) in cases {
        let e = parse_str(deck).unwrap_err().to_string();
        assert!(e.contains(needle), "{needle}: {e}");
    }
    let dir = std::env::temp_dir().join(format!("emc-nastran-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let e = read_bulk_deck(&dir).unwrap_err().to_string();
    assert!(e.contains("not a regular file"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}
