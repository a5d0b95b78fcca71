//! Cost and accuracy of the chassis reduction: `cargo run --release --example cms_benchmark`.
//!
//! Prints two tables. First, for the default body with 4 mounts × 3 translational interface
//! DOFs and an increasing number of fixed-interface modes (the last: up to 450 Hz, three times the
//! 150 Hz end of the transfer functions): reduction time and the largest error of the first 20
//! elastic frequencies against the full FE model. Second, for the default
//! reduction (40 fixed-interface modes): FE build + assembly, the reduction, the first (storing)
//! and second (cached) `reduce_cached` calls in a fresh temporary cache directory, the entry size
//! and the peak resident memory of the process.

use std::time::Instant;

use engine_mount_chassis::chassis::{config::ChassisConfig, Chassis};
use engine_mount_chassis::cms::{
    reduce_cached, reduce_detailed, CacheSetting, ModeSelection, ReductionSpec,
};
use engine_mount_chassis::eigen::lowest_modes;
use engine_mount_chassis::fe::assembly::assemble;

/// Peak resident set size of this process (VmHWM) in MB, if /proc is readable.
fn peak_rss_mb() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb / 1024.0)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let spec = ReductionSpec::default();

    // The default reduction first, so that the peak memory below belongs to it and the FE model.
    let t0 = Instant::now();
    let chassis = Chassis::build(&ChassisConfig::default())?;
    let asm = assemble(&chassis.mesh)?;
    let t_fe = t0.elapsed().as_secs_f64();
    let n_dof = asm.dofs.n_free();
    let t0 = Instant::now();
    let detailed = reduce_detailed(&spec)?;
    let t_reduce = t0.elapsed().as_secs_f64();
    let peak_after_reduce = peak_rss_mb();
    let n_reduced = detailed.reduced.n_modes();
    drop(detailed);

    let dir = std::env::temp_dir().join(format!("cms-benchmark-{}", std::process::id()));
    let setting = CacheSetting::Dir(dir.clone());
    let t0 = Instant::now();
    let (_, first) = reduce_cached(&spec, &setting)?;
    let t_first = t0.elapsed().as_secs_f64();
    let t0 = Instant::now();
    let (_, second) = reduce_cached(&spec, &setting)?;
    let t_second = t0.elapsed().as_secs_f64();
    let entry_kb = std::fs::read_dir(&dir)?
        .filter_map(|e| e.ok()?.metadata().ok())
        .map(|m| m.len() as f64 / 1024.0)
        .sum::<f64>();
    let _ = std::fs::remove_dir_all(&dir);

    // Accuracy against the full model: 6 rigid-body modes on the suspension + 20 elastic.
    let full = lowest_modes(&asm.k, &asm.m, 26, -1.0)?.frequencies_hz();
    println!(
        "chassis: {n_dof} DOFs; interface 4 mounts x 3 translations; full-model elastic modes \
         7..26 span {:.1}-{:.1} Hz",
        full[6], full[25]
    );
    println!();
    println!("| fixed-interface modes | highest (Hz) | reduced modes | reduce (s) | max error of elastic modes 7..26 |");
    println!("|---|---|---|---|---|");
    for selection in [
        ModeSelection::Count(0),
        ModeSelection::Count(20),
        ModeSelection::Count(40),
        ModeSelection::Count(80),
        ModeSelection::CutoffHz(3.0 * full[25]),
        ModeSelection::CutoffHz(450.0),
    ] {
        let s = ReductionSpec {
            selection,
            ..spec.clone()
        };
        let t0 = Instant::now();
        let detailed = reduce_detailed(&s)?;
        let t = t0.elapsed().as_secs_f64();
        let top = detailed.modes.fixed_interface_hz.last().copied();
        let r = detailed.reduced;
        let hz: Vec<f64> = r
            .omega
            .iter()
            .map(|w| w / (2.0 * std::f64::consts::PI))
            .collect();
        let compared = hz.len().min(26);
        let err = (6..compared)
            .map(|i| hz[i] / full[i] - 1.0)
            .fold(0.0, f64::max);
        let n_fi = r.n_modes() - 12;
        let label = match selection {
            ModeSelection::Count(n) => format!("{n}"),
            ModeSelection::CutoffHz(f) => format!("{n_fi} (cut-off {f:.0} Hz)"),
        };
        let coverage = if compared < 26 {
            format!(" (only {} elastic modes)", compared.saturating_sub(6))
        } else {
            String::new()
        };
        println!(
            "| {label} | {} | {} | {t:.2} | {:.3} %{coverage} |",
            top.map_or("-".to_string(), |f| format!("{f:.1}")),
            r.n_modes(),
            100.0 * err
        );
    }

    println!();
    println!("default reduction ({n_reduced} modes: 40 fixed-interface + 12 constraint)");
    println!("| step | value | note |");
    println!("|---|---|---|");
    println!("| FE build + assembly | {t_fe:.3} s | |");
    println!(
        "| reduce (build, assemble, Craig-Bampton, orthogonalise) | {t_reduce:.3} s | goal < 2 s |"
    );
    println!("| reduce_cached, empty cache | {t_first:.3} s | {first:?} |");
    println!(
        "| reduce_cached, second call | {:.2} ms | goal < 100 ms; {second:?} |",
        1e3 * t_second
    );
    println!("| cache entry size | {entry_kb:.0} kB | |");
    match peak_after_reduce {
        Some(mb) => {
            println!("| peak resident memory after the reduction | {mb:.0} MB | whole process |")
        }
        None => println!("| peak resident memory | n/a | /proc/self/status unreadable |"),
    }
    if let Some(mb) = peak_rss_mb() {
        println!("| peak resident memory after all runs | {mb:.0} MB | incl. the 450 Hz cut-off |");
    }
    Ok(())
}
