//! Reads a DMIG file with this crate's reader and prints its matrices and grids as JSON
//! (`{"matrices": {NAME: {"form": IFO, "entries": [[GJ, CJ, Gi, Ci, value], ...]}}, "grids":
//! {id: [x, y, z]}}`), so a file another program wrote (`python/tests/test_dmig.py`: pyNastran's
//! large-field punch) can be compared with what that program meant to write.
//!
//! `cargo run --release --example read_dmig -- <file>`

use engine_mount_chassis::nastran::{read_dmig_file, DeckOptions};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args().nth(1).ok_or("usage: read_dmig <file>")?;
    let (file, _) = read_dmig_file(std::path::Path::new(&path), &DeckOptions::default())?;
    let matrices: serde_json::Map<String, serde_json::Value> = file
        .matrices
        .iter()
        .map(|(name, m)| {
            let entries: Vec<serde_json::Value> = m
                .entries
                .iter()
                .map(|(&(c, r), &v)| serde_json::json!([c.0, c.1, r.0, r.1, v]))
                .collect();
            (
                name.clone(),
                serde_json::json!({"form": m.form, "entries": entries}),
            )
        })
        .collect();
    let grids: serde_json::Map<String, serde_json::Value> = file
        .grids
        .iter()
        .map(|(id, x)| (id.to_string(), serde_json::json!(x)))
        .collect();
    println!(
        "{}",
        serde_json::json!({"matrices": matrices, "grids": grids})
    );
    Ok(())
}
