//! Modal analysis of the chassis body: `cargo run --release --example fe_modes [config.json]`.

use engine_mount_chassis::fe::assembly::{assemble, translational_mass};
use engine_mount_chassis::fe::chassis::Chassis;
use engine_mount_chassis::fe::chassis_config::ChassisConfig;
use engine_mount_chassis::fe::eigen::lowest_modes;
use engine_mount_chassis::fe::modal::describe;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let config = match std::env::args().nth(1) {
        Some(path) => ChassisConfig::from_json(&std::fs::read_to_string(path)?)?,
        None => ChassisConfig::default(),
    };
    let chassis = Chassis::build(&config)?;
    let mesh = &chassis.mesh;
    let asm = assemble(mesh)?;
    println!(
        "nodes {}, shells {}, beams {}, dofs {}, mass {:.1} kg",
        mesh.nodes.len(),
        mesh.shells.len(),
        mesh.beams.len(),
        asm.dofs.n_free(),
        translational_mass(&asm, 2)
    );
    let modes = lowest_modes(&asm.k, &asm.m, 30, -1.0)?;
    for d in describe(mesh, &asm, &modes)? {
        println!("{}  elastic {:4.2}", d.summary(), d.elastic);
    }
    Ok(())
}
