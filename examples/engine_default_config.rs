//! Writes the default engine configuration to `resources/engine.json`.
//!
//! `cargo run --release --example engine_default_config`

fn main() -> std::io::Result<()> {
    let cfg = engine_mount_chassis::model::EngineConfig::default();
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/resources/engine.json");
    std::fs::create_dir_all(concat!(env!("CARGO_MANIFEST_DIR"), "/resources"))?;
    std::fs::write(path, cfg.to_json() + "\n")?;
    println!("wrote {path}");
    Ok(())
}
