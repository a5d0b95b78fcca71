//! Modal analysis of the chassis body with mode descriptions:
//! `cargo run --release --example fe_modes [config.json] [--export DIR]`.
//! With `--export DIR`, K and M (Matrix Market), the node table and the DOF table are written to
//! DIR for checking with another tool, e.g. with SciPy:
//!
//! ```text
//! K = scipy.io.mmread("DIR/K.mtx").tocsc(); M = scipy.io.mmread("DIR/M.mtx").tocsc()
//! lam = scipy.sparse.linalg.eigsh(K, k=12, M=M, sigma=-1.0, return_eigenvectors=False)
//! print(numpy.sort(numpy.sqrt(abs(lam)) / (2 * numpy.pi)))
//! ```

use engine_mount_chassis::chassis::config::ChassisConfig;
use engine_mount_chassis::chassis::modal::describe;
use engine_mount_chassis::chassis::Chassis;
use engine_mount_chassis::eigen::lowest_modes;
use engine_mount_chassis::fe::assembly::{assemble, translational_mass};
use engine_mount_chassis::fe::export::write_all;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let export = args
        .iter()
        .position(|a| a == "--export")
        .map(|i| args.get(i + 1).cloned());
    let config_path = args.iter().take_while(|a| *a != "--export").next();
    let config = match config_path {
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
    match export {
        Some(Some(dir)) => {
            write_all(std::path::Path::new(&dir), mesh, &asm)?;
            println!("wrote K.mtx, M.mtx, nodes.csv, dofs.csv to {dir}");
        }
        Some(None) => return Err("--export needs a directory".into()),
        None => {}
    }
    let modes = lowest_modes(&asm.k, &asm.m, 30, -1.0)?;
    for d in describe(mesh, &asm, &modes)? {
        println!("{}", d.summary());
    }
    Ok(())
}
