//! Bulk data cards CORD2C/CORD2S, CONM1 and CBUSH/PBUSH against closed forms: grid positions
//! in curvilinear systems, rigid-body mass properties, rotated bush stiffness, oscillators.

use std::f64::consts::PI;
use std::fmt::Write;

use engine_mount_chassis::fe::assembly::{assemble, Assembled};
use engine_mount_chassis::fe::eigen::lowest_modes;
use engine_mount_chassis::fe::nastran::{parse_str, NastranBody};
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
fn a_non_basic_displacement_system_is_refused_naming_the_grid_and_line() {
    let err = error_of(
        "BEGIN BULK\nCORD2C,5,,0.,0.,0.,0.,0.,1.\n,1.,0.,0.\nGRID,1,,0.,0.,0.\nGRID,17,,1.,0.,0.,5\n",
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
