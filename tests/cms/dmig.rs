//! A body reduced elsewhere, handed over as Craig-Bampton matrices in Nastran DMIG form:
//! our own reduction of the default body written as DMIG and read back through the vehicle JSON
//! gives the same body modes (a round trip of the format); three spring–mass chains whose
//! Craig-Bampton matrices are written here in closed form give the analytic chain frequencies
//! (an independent truth); malformed files are refused naming card and line or matrix.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::PathBuf;

use engine_mount_chassis::cms::{
    dmig_of_reduction, reduce_external, CacheSetting, DampingTable, ExternalBody, ModeSelection,
    ReducedChassis,
};
use engine_mount_chassis::model::scene::{body, reduction_spec, BodyOptions};
use engine_mount_chassis::model::VehicleConfig;
use engine_mount_chassis::nastran::{parse_dmig_str, read_dmig_file, DeckOptions};

fn temp_dir(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("emc-dmig-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn options() -> BodyOptions {
    BodyOptions {
        mode_cutoff_hz: 100.0,
        cache: CacheSetting::Disabled,
        ..BodyOptions::default()
    }
}

/// The default vehicle with its body written as DMIG to `dir`, read through a vehicle JSON file.
fn dmig_vehicle(
    dir: &std::path::Path,
    patch: impl FnOnce(&mut serde_json::Value),
) -> VehicleConfig {
    let (spec, _) = reduction_spec(&VehicleConfig::default(), &options()).unwrap();
    let written = dmig_of_reduction(&spec).unwrap();
    std::fs::write(dir.join("body.pch"), written.text()).unwrap();
    let mut config = serde_json::json!({
        "extends": "default",
        "body": {"kind": "dmig", "path": "body.pch", "stiffness": "KAAX", "mass": "MAAX",
                 "recovery": "PHIOUT", "points": written.points}
    });
    patch(&mut config);
    std::fs::write(dir.join("vehicle.json"), config.to_string()).unwrap();
    VehicleConfig::from_file(&dir.join("vehicle.json")).unwrap()
}

/// Largest |entry| of a point's shape over all modes (the scale of its rows).
fn scale(shape: &[[f64; 6]]) -> f64 {
    shape.iter().flatten().fold(0.0, |a, b| a.max(b.abs()))
}

#[test]
fn our_reduction_written_as_dmig_and_read_back_gives_the_same_body_modes() {
    let dir = temp_dir("round-trip");
    let vehicle = dmig_vehicle(&dir, |_| {});
    let (ours, _) = body(&VehicleConfig::default(), &options()).unwrap();
    let (read, notes) = body(&vehicle, &options()).unwrap();
    assert!(notes[0].contains("DMIG body"), "{notes:?}");
    assert_eq!(ours.n_modes(), read.n_modes());
    assert!(ours.n_modes() > 20, "{} modes", ours.n_modes());
    for (k, (a, b)) in ours.omega.iter().zip(&read.omega).enumerate() {
        assert!((a - b).abs() <= 1e-9 * a, "mode {k}: {a} vs {b} rad/s");
    }
    let worst_frequency = ours
        .omega
        .iter()
        .zip(&read.omega)
        .map(|(a, b)| (a - b).abs() / a)
        .fold(0.0, f64::max);
    let worst_shape = ours
        .points
        .iter()
        .zip(&read.points)
        .map(|(p, q)| {
            let s = scale(&p.shape);
            p.shape
                .iter()
                .flatten()
                .zip(q.shape.iter().flatten())
                .map(|(x, y)| (x - y).abs() / s)
                .fold(0.0, f64::max)
        })
        .fold(0.0, f64::max);
    eprintln!(
        "{} modes: frequencies within {worst_frequency:.1e}, point shapes within {worst_shape:.1e} \
         of each point's largest entry",
        ours.n_modes()
    );
    assert_eq!(ours.zeta, read.zeta);
    assert_eq!(ours.points.len(), read.points.len());
    for (p, q) in ours.points.iter().zip(&read.points) {
        assert_eq!(p.name, q.name);
        assert_eq!(p.position, q.position);
        let s = scale(&p.shape);
        for k in 0..ours.n_modes() {
            for d in 0..6 {
                let (x, y) = (p.shape[k][d], q.shape[k][d]);
                assert!(
                    (x - y).abs() <= 1e-9 * s,
                    "{} mode {k} dof {d}: {x} vs {y} (scale {s})",
                    p.name
                );
            }
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

const CHAIN_MASSES: usize = 6;
const MASS: f64 = 2.0;
const AXIS_STIFFNESS: [f64; 3] = [1.0e4, 2.0e4, 3.0e4];

/// Three chains of [`CHAIN_MASSES`] masses on springs, grounded at one end and sharing their last
/// mass, the tip GRID 1: component 1, 2, 3 of the tip ends the chain of stiffness
/// `AXIS_STIFFNESS[0, 1, 2]`. Their Craig-Bampton matrices in closed form, as DMIG text: the tip is
/// the boundary grid, the fixed-interface modes of each chain (the fixed–fixed chain of the
/// N − 1 inner masses) are scalar points `100 × axis + i`.
///
/// Inner chain, fixed at both ends: `λ_i = 4k/m sin²(iπ/2N)`, mass-normalised
/// `φ_i(j) = √(2/(mN)) sin(ijπ/N)`; constraint mode: `u_j = j/N` (unit tip, straight line);
/// so `K_qq = diag(λ)`, `K_qb = 0`, `K_bb = k/N` (N springs in series), `M_qq = I`,
/// `M_qb,i = Σ_j m φ_i(j) j/N`, `M_bb = m Σ_j (j/N)²` (tip included).
fn chains_dmig() -> String {
    let n = CHAIN_MASSES;
    let nf = n as f64;
    let mut k = String::from("DMIG,KAAX,0,6,2,0\n");
    let mut m = String::from("DMIG,MAAX,0,6,2,0\n");
    for (axis, &stiffness) in AXIS_STIFFNESS.iter().enumerate() {
        let c = axis + 1;
        let mbb: f64 = (1..=n).map(|j| MASS * (j as f64 / nf).powi(2)).sum();
        writeln!(k, "DMIG,KAAX,1,{c},,1,{c},{:e},", stiffness / nf).unwrap();
        writeln!(m, "DMIG,MAAX,1,{c},,1,{c},{:e},", mbb).unwrap();
        for i in 1..n {
            let q = 100 * c + i;
            let theta = i as f64 * std::f64::consts::PI / nf;
            let lambda = 4.0 * stiffness / MASS * (theta / 2.0).sin().powi(2);
            let mqb: f64 = (1..n)
                .map(|j| {
                    let phi = (2.0 / (MASS * nf)).sqrt() * (j as f64 * theta).sin();
                    MASS * phi * j as f64 / nf
                })
                .sum();
            writeln!(k, "DMIG,KAAX,{q},0,,{q},0,{lambda:e},").unwrap();
            // Both triangles of the coupling, as some solvers write them.
            writeln!(m, "DMIG,MAAX,{q},0,,{q},0,1.0,,\n,1,{c},{mqb:e},").unwrap();
            writeln!(m, "DMIG,MAAX,1,{c},,{q},0,{mqb:e},").unwrap();
        }
    }
    format!("GRID,1,,0.,0.,0.\n{k}{m}")
}

/// The analytic frequencies (rad/s) of the three chains (fixed–free, N masses), ascending.
fn chain_frequencies() -> Vec<f64> {
    let n = CHAIN_MASSES;
    let mut w: Vec<f64> = AXIS_STIFFNESS
        .iter()
        .flat_map(|&k| {
            (1..=n).map(move |j| {
                let s =
                    ((2 * j - 1) as f64 * std::f64::consts::PI / (2.0 * (2 * n + 1) as f64)).sin();
                (4.0 * k / MASS).sqrt() * s
            })
        })
        .collect();
    w.sort_by(f64::total_cmp);
    w
}

fn chains_body(
    file: &engine_mount_chassis::nastran::DmigFile,
    selection: ModeSelection,
) -> ReducedChassis {
    let points = BTreeMap::from([("tip".to_string(), 1)]);
    reduce_external(&ExternalBody {
        file,
        stiffness: "KAAX",
        mass: "MAAX",
        recovery: None,
        points: &points,
        interface: &["tip".to_string()],
        outputs: &[],
        selection,
        damping: &DampingTable::default(),
    })
    .unwrap()
}

#[test]
fn spring_mass_chains_from_closed_form_matrices_give_the_analytic_frequencies() {
    let file = parse_dmig_str(&chains_dmig()).unwrap();
    let exact = chain_frequencies();
    let all = chains_body(&file, ModeSelection::Count(3 * (CHAIN_MASSES - 1)));
    assert_eq!(all.n_modes(), exact.len());
    for (w, e) in all.omega.iter().zip(&exact) {
        assert!((w / e - 1.0).abs() < 1e-10, "{w} vs {e} rad/s");
    }
    // The tip's modal participation: Σ_k φ_tip,k² / ω_k² is the static compliance N/k per axis.
    let tip = &all.points[0];
    for (axis, &k) in AXIS_STIFFNESS.iter().enumerate() {
        let compliance: f64 = (0..all.n_modes())
            .map(|mode| tip.shape[mode][axis].powi(2) / all.omega[mode].powi(2))
            .sum();
        let expected = CHAIN_MASSES as f64 / k;
        assert!(
            (compliance / expected - 1.0).abs() < 1e-10,
            "{compliance} vs {expected}"
        );
    }
    // A cut-off keeps the fixed-interface modes below it; a truncated basis bounds from above.
    let cutoff_hz = 20.0;
    let truncated = chains_body(&file, ModeSelection::CutoffHz(cutoff_hz));
    assert!(truncated.n_modes() > 3 && truncated.n_modes() < exact.len());
    for (w, e) in truncated.omega.iter().zip(&exact) {
        assert!(*w >= e * (1.0 - 1e-12), "{w} < {e}");
    }
}

fn error_of(text: &str) -> String {
    parse_dmig_str(text).unwrap_err().to_string()
}

#[test]
fn malformed_dmig_is_refused_naming_card_and_line_or_matrix() {
    // Both triangles of a symmetric matrix, inconsistent.
    let e = error_of("DMIG,KAAX,0,6,2,0\nDMIG,KAAX,1,1,,2,1,5.,\nDMIG,KAAX,2,1,,1,1,4.,\n");
    assert!(
        e.contains("DMIG KAAX card at line 3") && e.contains("mirror") && e.contains("line 2"),
        "{e}"
    );
    // A non-finite value.
    let e = error_of("DMIG,MAAX,0,6,2,0\nDMIG,MAAX,1,1,,1,1,1.0E+999,\n");
    assert!(
        e.contains("DMIG MAAX card at line 2") && e.contains("A1"),
        "{e}"
    );
    let e = error_of("DMIG,MAAX,0,6,2,0\nDMIG,MAAX,1,1,,1,1,NAN,\n");
    assert!(e.contains("line 2") && e.contains("finite"), "{e}");

    // A missing matrix, named with what the file has.
    let file = parse_dmig_str(&chains_dmig()).unwrap();
    let points = BTreeMap::from([("tip".to_string(), 1)]);
    let mut external = ExternalBody {
        file: &file,
        stiffness: "KAAX",
        mass: "MGG",
        recovery: None,
        points: &points,
        interface: &["tip".to_string()],
        outputs: &[],
        selection: ModeSelection::CutoffHz(100.0),
        damping: &DampingTable::default(),
    };
    let e = reduce_external(&external).unwrap_err().to_string();
    assert!(
        e.contains("MGG is not in the file") && e.contains("KAAX, MAAX"),
        "{e}"
    );
    external.mass = "MAAX";
    external.recovery = Some("PHIOUT");
    let e = reduce_external(&external).unwrap_err().to_string();
    assert!(e.contains("PHIOUT is not in the file"), "{e}");

    // A boundary grid the mounts need that the file lacks; and from a file, the path is named.
    let dir = temp_dir("errors");
    let vehicle = dmig_vehicle(&dir, |c| c["body"]["points"]["mount_rear_left"] = 7.into());
    let e = body(&vehicle, &options()).unwrap_err().to_string();
    assert!(
        e.contains("mount body node 'mount_rear_left' is GRID 7")
            && e.contains("not a boundary DOF of KAAX")
            && e.contains("body.pch"),
        "{e}"
    );
    // The vehicle JSON's body is strict: a misspelt field, a missing matrix name, a point no
    // mount or output uses are refused by their path.
    let points = r#"{"mount_front_left": 1, "mount_front_right": 2, "mount_rear_left": 3,
                     "mount_rear_right": 4, "steering_wheel": 5, "seat_rail": 6}"#;
    for (body, field) in [
        (
            format!(r#"{{"kind": "dmig", "path": "b.pch", "stifness": "KAAX", "mass": "MAAX", "points": {points}}}"#),
            "stifness",
        ),
        (
            format!(r#"{{"kind": "dmig", "path": "b.pch", "stiffness": "KAAX", "points": {points}}}"#),
            "mass",
        ),
        (
            r#"{"kind": "dmig", "path": "b.pch", "stiffness": "KAAX", "mass": "MAAX", "points": {"wheel": 5}}"#
                .to_string(),
            "body.points.wheel",
        ),
    ] {
        let e = VehicleConfig::from_json(&format!(r#"{{"extends": "default", "body": {body}}}"#))
            .unwrap_err()
            .to_string();
        assert!(e.contains(field), "{field}: {e}");
    }

    let bad = dir.join("bad.pch");
    std::fs::write(&bad, "$ header\nDMIG,KAAX,0,6,2,0\nDMIG,KAAX,1,1,,1,1,1,\n").unwrap();
    let e = read_dmig_file(&bad, &DeckOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("bad.pch") && e.contains("DMIG KAAX card at line 3") && e.contains("A1"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// The gaps a trial found: a recovery matrix whose header's `NCOL` is not the a-set size, the
/// stiffness matrix named as recovery matrix, two mounts on one GRID — each refused before any
/// computation, naming the matrix or the mounts (they failed as a Newton or positive-definiteness
/// error far downstream).
#[test]
fn recovery_and_mount_grid_mistakes_are_refused_up_front() {
    let dir = temp_dir("gaps");
    let vehicle = dmig_vehicle(&dir, |_| {});
    let text = std::fs::read_to_string(dir.join("body.pch")).unwrap();
    let header = text
        .lines()
        .find(|l| l.starts_with("DMIG,PHIOUT,"))
        .expect("recovery header")
        .to_string();
    let a_set = header.rsplit(',').next().unwrap().to_string();
    for ncol in ["7", "1000000000"] {
        let wrong = header.replace(&format!(",,,{a_set}"), &format!(",,,{ncol}"));
        std::fs::write(dir.join("body.pch"), text.replace(&header, &wrong)).unwrap();
        let e = body(&vehicle, &options()).unwrap_err().to_string();
        assert!(
            e.contains(&format!("PHIOUT declares NCOL = {ncol}"))
                && e.contains(&format!("KAAX has {a_set} DOFs")),
            "{e}"
        );
    }
    std::fs::write(dir.join("body.pch"), &text).unwrap();

    let kaax = dmig_vehicle(&dir, |c| c["body"]["recovery"] = "KAAX".into());
    let e = body(&kaax, &options()).unwrap_err().to_string();
    assert!(
        e.contains("recovery matrix KAAX is also the stiffness matrix"),
        "{e}"
    );

    let file = dir.join("vehicle.json");
    let mut config: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&file).unwrap()).unwrap();
    let front_left = config["body"]["points"]["mount_front_left"].clone();
    config["body"]["points"]["mount_front_right"] = front_left.clone();
    std::fs::write(&file, config.to_string()).unwrap();
    let e = VehicleConfig::from_file(&file).unwrap_err().to_string();
    assert!(
        e.contains("mounts[1].body_node")
            && e.contains("mounts 'front_left' and 'front_right' both attach to GRID")
            && e.contains(&front_left.to_string()),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
