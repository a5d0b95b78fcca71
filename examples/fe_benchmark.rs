//! Benchmark of the chassis FE model: generation, assembly, checks and the modal analysis (30
//! lowest modes, sparse Cholesky + shift-invert block Lanczos) of the ~15k-DOF body.
//!
//! `cargo run --release --example fe_benchmark [repetitions]` prints a table of wall times (best
//! and median of the repetitions) and the peak resident memory (VmHWM from /proc/self/status).

use std::time::Instant;

use engine_mount_chassis::fe::assembly::assemble;
use engine_mount_chassis::fe::chassis::Chassis;
use engine_mount_chassis::fe::chassis_config::ChassisConfig;
use engine_mount_chassis::fe::checks::{check_assembled, check_mesh, CheckLimits};
use engine_mount_chassis::fe::eigen::lowest_modes;
use engine_mount_chassis::fe::modal::describe;

fn status_kib(field: &str) -> Option<u64> {
    let text = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = text.lines().find(|l| l.starts_with(field))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let repetitions: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(5)
        .max(1);
    let config = ChassisConfig::default();
    let stages = [
        "generate mesh",
        "mesh checks",
        "assemble K, M, C",
        "DOF checks",
        "modal: 30 modes",
        "describe modes",
    ];
    let mut times = vec![Vec::new(); stages.len()];
    let mut summary = String::new();
    for _ in 0..repetitions {
        let mut lap = Instant::now();
        let mut record = |i: usize, times: &mut Vec<Vec<f64>>| {
            times[i].push(lap.elapsed().as_secs_f64());
            lap = Instant::now();
        };
        let chassis = Chassis::build(&config)?;
        record(0, &mut times);
        check_mesh(&chassis.mesh, &CheckLimits::default())?;
        record(1, &mut times);
        let asm = assemble(&chassis.mesh)?;
        record(2, &mut times);
        check_assembled(&asm)?;
        record(3, &mut times);
        let modes = lowest_modes(&asm.k, &asm.m, 30, -1.0)?;
        record(4, &mut times);
        let descs = describe(&chassis.mesh, &asm, &modes)?;
        record(5, &mut times);
        let f = modes.frequencies_hz();
        summary = format!(
            "model: {} nodes, {} shells, {} beams, {} DOF, nnz(K) = {}, nnz(M) = {}; modes 7..30: {:.1}..{:.1} Hz ({} described)",
            chassis.mesh.nodes.len(),
            chassis.mesh.shells.len(),
            chassis.mesh.beams.len(),
            asm.dofs.n_free(),
            asm.k.compute_nnz(),
            asm.m.compute_nnz(),
            f[6],
            f[29],
            descs.len()
        );
    }
    println!("{summary}");
    println!("{repetitions} repetitions\n");
    println!("| stage | best [ms] | median [ms] |");
    println!("|---|---:|---:|");
    let mut total = (0.0, 0.0);
    for (name, t) in stages.iter().zip(&mut times) {
        t.sort_by(f64::total_cmp);
        let (best, median) = (t[0] * 1e3, t[t.len() / 2] * 1e3);
        total.0 += best;
        total.1 += median;
        println!("| {name} | {best:.1} | {median:.1} |");
    }
    println!("| total | {:.1} | {:.1} |", total.0, total.1);
    match status_kib("VmHWM:") {
        Some(kib) => println!(
            "\npeak resident memory (VmHWM): {:.1} MiB",
            kib as f64 / 1024.0
        ),
        None => println!("\npeak resident memory: /proc/self/status not available"),
    }
    Ok(())
}
