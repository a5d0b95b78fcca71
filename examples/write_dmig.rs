//! Writes our own Craig-Bampton reduction of the default (procedural) body as a Nastran DMIG
//! body, the way an engineer hands over a body reduced in their own solver:
//! - `body.pch`: `KAAX`, `MAAX` (symmetric), `PHIOUT` (recovery rows of the outputs) and the
//!   named points' `GRID` cards,
//! - `vehicle.json`: the default vehicle with `"body": {"kind": "dmig", ...}` naming that file,
//! - `matrices.json`: the same matrices as triplets `[GJ, CJ, Gi, Ci, value]` (column, row), for
//!   a second reader to compare against (`python/tests/test_dmig.py` reads `body.pch` with
//!   pyNastran),
//! - `modes.json`: the frequencies (Hz) of the same body reduced in process, for a check of the
//!   matrices by an eigen solve of the second reader's.
//!
//! The fixed-interface modes are those the FMU's scene 2 keeps by default (automatic cut-off,
//! 225 Hz), so the same vehicle with the procedural body and with this file run alike.
//!
//! `cargo run --release --example write_dmig -- <folder> [cut-off Hz]`

use engine_mount_chassis::cms::dmig_of_reduction;
use engine_mount_chassis::cms::CacheSetting;
use engine_mount_chassis::model::scene::{body as reduced_body, reduction_spec, BodyOptions};
use engine_mount_chassis::model::VehicleConfig;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let dir = std::path::PathBuf::from(args.next().ok_or("usage: write_dmig <folder> [Hz]")?);
    let mut options = BodyOptions::default();
    if let Some(hz) = args.next() {
        options.mode_cutoff_hz = hz.parse()?;
    }
    std::fs::create_dir_all(&dir)?;
    let vehicle = VehicleConfig::default();
    let (spec, origin) = reduction_spec(&vehicle, &options)?;
    let body = dmig_of_reduction(&spec)?;
    std::fs::write(dir.join("body.pch"), body.text())?;
    let config = serde_json::json!({
        "extends": "default",
        "body": {
            "kind": "dmig",
            "path": "body.pch",
            "stiffness": "KAAX",
            "mass": "MAAX",
            "recovery": "PHIOUT",
            "points": body.points,
        }
    });
    std::fs::write(
        dir.join("vehicle.json"),
        serde_json::to_string_pretty(&config)?,
    )?;
    let matrices: serde_json::Map<String, serde_json::Value> = body
        .file
        .matrices
        .iter()
        .map(|(name, m)| {
            let triplets: Vec<serde_json::Value> = m
                .entries
                .iter()
                .map(|(&(c, r), &v)| serde_json::json!([c.0, c.1, r.0, r.1, v]))
                .collect();
            (
                name.clone(),
                serde_json::json!({"form": m.form, "entries": triplets}),
            )
        })
        .collect();
    std::fs::write(dir.join("matrices.json"), serde_json::to_string(&matrices)?)?;
    let ours = BodyOptions {
        cache: CacheSetting::Disabled,
        ..options.clone()
    };
    let (reduced, _) = reduced_body(&vehicle, &ours)?;
    let hz: Vec<f64> = reduced
        .omega
        .iter()
        .map(|w| w / (2.0 * std::f64::consts::PI))
        .collect();
    std::fs::write(
        dir.join("modes.json"),
        serde_json::to_string(&serde_json::json!({ "hz": hz }))?,
    )?;
    let k = &body.file.matrices["KAAX"];
    println!(
        "{}: {} Craig-Bampton coordinates ({origin}), points {:?}",
        dir.join("body.pch").display(),
        k.ncol.unwrap_or(0),
        body.points
    );
    Ok(())
}
