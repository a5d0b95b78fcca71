//! Timing and memory of the chassis reduction:
//! `cargo run --release --example cms_benchmark [N | cutoff=HZ]` (default N = 40 fixed-interface
//! modes).
//!
//! Prints one table: FE build + assembly, the full reduction with the given number of
//! fixed-interface modes (default 40), the first (storing) and second (cached) `reduce_cached`
//! calls in a fresh temporary cache directory, and the peak resident memory of the process.

use std::time::Instant;

use engine_mount_chassis::cms::{
    reduce_cached, reduce_detailed, CacheSetting, ModeSelection, ReductionSpec,
};
use engine_mount_chassis::fe::assembly::assemble;
use engine_mount_chassis::fe::chassis::Chassis;

/// Peak resident set size of this process (VmHWM, kB) from /proc, if available.
fn peak_rss_mb() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb / 1024.0)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let selection = match std::env::args().nth(1) {
        Some(a) => match a.strip_prefix("cutoff=") {
            Some(hz) => ModeSelection::CutoffHz(hz.parse()?),
            None => ModeSelection::Count(a.parse()?),
        },
        None => ModeSelection::Count(40),
    };
    let spec = ReductionSpec {
        selection,
        ..ReductionSpec::default()
    };

    let t0 = Instant::now();
    let chassis = Chassis::build(&spec.chassis)?;
    let asm = assemble(&chassis.mesh)?;
    let t_fe = t0.elapsed().as_secs_f64();
    let n_dof = asm.dofs.n_free();
    drop((chassis, asm));

    let t0 = Instant::now();
    let detailed = reduce_detailed(&spec)?;
    let t_reduce = t0.elapsed().as_secs_f64();
    let n_reduced = detailed.reduced.n_modes();
    let n_fi = detailed.modes.fixed_interface_hz.len();
    let top_fi = detailed
        .modes
        .fixed_interface_hz
        .last()
        .copied()
        .unwrap_or(0.0);
    drop(detailed);

    let dir = std::env::temp_dir().join(format!("cms-benchmark-{}", std::process::id()));
    let setting = CacheSetting::Dir(dir.clone());
    let t0 = Instant::now();
    let (_, first) = reduce_cached(&spec, &setting)?;
    let t_first = t0.elapsed().as_secs_f64();
    let t0 = Instant::now();
    let (reduced, second) = reduce_cached(&spec, &setting)?;
    let t_second = t0.elapsed().as_secs_f64();
    let entry_kb = std::fs::read_dir(&dir)?
        .filter_map(|e| e.ok()?.metadata().ok())
        .map(|m| m.len() as f64 / 1024.0)
        .sum::<f64>();
    let _ = std::fs::remove_dir_all(&dir);

    println!("chassis: {n_dof} DOFs; interface: 4 mounts x 3 translations");
    println!(
        "reduced: {n_reduced} modes ({n_fi} fixed-interface up to {top_fi:.1} Hz + 12 constraint), \
         {} recovery points",
        reduced.points.len()
    );
    println!("| step | time (s) | note |");
    println!("|---|---|---|");
    println!("| FE build + assembly | {t_fe:.3} | |");
    println!(
        "| reduce (build, assemble, Craig-Bampton, orthogonalise) | {t_reduce:.3} | goal < 2 s |"
    );
    println!("| reduce_cached, empty cache | {t_first:.3} | {first:?} |");
    println!("| reduce_cached, second call | {t_second:.4} | goal < 0.1 s; {second:?} |");
    println!("| cache entry size | {entry_kb:.0} kB | |");
    match peak_rss_mb() {
        Some(mb) => println!("| peak resident memory | {mb:.0} MB | whole process |"),
        None => println!("| peak resident memory | n/a | /proc/self/status unreadable |"),
    }
    Ok(())
}
