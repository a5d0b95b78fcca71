//! Prints the eigenmodes of the engine supported by ground next to the paper's Table 1.
//!
//! `cargo run --release --example engine_modes [vehicle.json]`

use engine_mount_chassis::model::{mode_table, CoupledModel, VehicleConfig};
use engine_mount_chassis::paper::{TABLE1_RIGID, TABLE1_RING_CARRIER};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let cfg = match std::env::args().nth(1) {
        Some(path) => VehicleConfig::from_file(path.as_ref())?,
        None => VehicleConfig::default(),
    };
    let mut scene = CoupledModel::on_ground(&cfg)?;
    let y = scene.static_equilibrium(0.0)?;
    let modes = scene.modes(&y)?;
    println!("Engine supported by ground, linearised at the static equilibrium");
    println!("(axial = along crank axis y, lateral = x, rolling = about crank axis y, pitching = about x, yawing = about z)\n");
    print!("{}", mode_table(&modes));
    println!("\nPaper Table 1, engine supported by ground:");
    for (f, d) in TABLE1_RIGID.iter().chain(TABLE1_RING_CARRIER.iter()) {
        let nearest = modes.iter().min_by(|a, b| {
            (a.frequency_hz - f)
                .abs()
                .total_cmp(&(b.frequency_hz - f).abs())
        });
        if let Some(m) = nearest {
            println!(
                "{f:8.2}  {d:<40}  model {:8.2} Hz ({:+5.1} %)  {}",
                m.frequency_hz,
                100.0 * (m.frequency_hz / f - 1.0),
                m.description
            );
        }
    }
    Ok(())
}
