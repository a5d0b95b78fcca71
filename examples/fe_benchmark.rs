//! Benchmark of the chassis FE model: generation, assembly, checks and the modal analysis (30
//! lowest modes, sparse Cholesky + shift-invert block Lanczos) of the ~15k-DOF body, plus a
//! 100-mode solve as a size indication for the Craig-Bampton reduction.
//!
//! `cargo run --release --example fe_benchmark [repetitions]` prints a table of wall times (best
//! and median of the repetitions) and the peak resident memory (VmHWM from /proc/self/status).

use std::time::Instant;

use engine_mount_chassis::chassis::config::ChassisConfig;
use engine_mount_chassis::chassis::modal::describe;
use engine_mount_chassis::chassis::Chassis;
use engine_mount_chassis::eigen::lowest_modes;
use engine_mount_chassis::fe::assembly::assemble;
use engine_mount_chassis::fe::checks::{check_assembled, check_mesh, CheckLimits};

fn status_kib(field: &str) -> Option<u64> {
    let text = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = text.lines().find(|l| l.starts_with(field))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

/// Wall time of `f` in seconds, appended to `times`.
fn timed<T>(times: &mut Vec<f64>, f: impl FnOnce() -> T) -> T {
    let start = Instant::now();
    let out = f();
    times.push(start.elapsed().as_secs_f64());
    out
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let repetitions: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(5)
        .max(1);
    let config = ChassisConfig::default();
    let stages = [
        "generate mesh (incl. mesh checks)",
        "mesh checks alone",
        "assemble K, M, C",
        "DOF checks",
        "modal: 30 modes",
        "describe modes",
    ];
    let mut times = vec![Vec::new(); stages.len()];
    let mut times_100 = Vec::new();
    let mut summary = String::new();
    let mut hwm_30 = None;
    for _ in 0..repetitions {
        let chassis = timed(&mut times[0], || Chassis::build(&config))?;
        timed(&mut times[1], || {
            check_mesh(&chassis.mesh, &CheckLimits::default())
        })?;
        let asm = timed(&mut times[2], || assemble(&chassis.mesh))?;
        timed(&mut times[3], || check_assembled(&asm))?;
        let modes = timed(&mut times[4], || lowest_modes(&asm.k, &asm.m, 30, -1.0))?;
        let descs = timed(&mut times[5], || describe(&chassis.mesh, &asm, &modes))?;
        // Peak memory of the 30-mode pipeline, before any 100-mode solve has run.
        hwm_30.get_or_insert(status_kib("VmHWM:"));
        timed(&mut times_100, || lowest_modes(&asm.k, &asm.m, 100, -1.0))?;
        let f = modes.frequencies_hz();
        summary = format!(
            "model: {} nodes, {} shells, {} beams, {} DOF, nnz(K) = {}, nnz(M) = {}; \
             modes 7..30: {:.1}..{:.1} Hz ({} described)",
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
    let stats = |t: &mut Vec<f64>| {
        t.sort_by(f64::total_cmp);
        (t[0] * 1e3, t[t.len() / 2] * 1e3)
    };
    println!("{summary}");
    println!("{repetitions} repetitions\n");
    println!("| stage | best [ms] | median [ms] |");
    println!("|---|---:|---:|");
    let mut total = (0.0, 0.0);
    for (i, (name, t)) in stages.iter().zip(&mut times).enumerate() {
        let (best, median) = stats(t);
        if i != 1 {
            total.0 += best;
            total.1 += median;
        }
        println!("| {name} | {best:.1} | {median:.1} |");
    }
    println!(
        "| total, 30-mode pipeline | {:.1} | {:.1} |",
        total.0, total.1
    );
    let (best, median) = stats(&mut times_100);
    println!("| extra: modal, 100 modes | {best:.1} | {median:.1} |");
    let mib = |kib: Option<u64>| match kib {
        Some(k) => format!("{:.1} MiB", k as f64 / 1024.0),
        None => "n/a (/proc/self/status not available)".into(),
    };
    println!(
        "\npeak resident memory (VmHWM), 30-mode pipeline: {}",
        mib(hwm_30.flatten())
    );
    println!(
        "peak resident memory (VmHWM), including the 100-mode solves: {}",
        mib(status_kib("VmHWM:"))
    );
    Ok(())
}
