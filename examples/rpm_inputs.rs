//! What a master's way of setting rpm costs and changes: a run-up 800 → 2500 rpm in 10 s through
//! the FMU's instance (the code behind the C ABI), with rpm set at every communication step
//! with its derivative (the reference), or without it (what most masters do), at 0.1, 1 and 10 ms.
//! Prints CPU time, integrator work, integrator restarts and the relative L2 difference of the
//! mount forces from the derivative run at common communication points (every 10 ms).
//!
//! `cargo run --release --example rpm_inputs -- [--scene N] [--seconds S]`

use std::path::PathBuf;
use std::time::Instant;

use engine_mount_chassis::cosim::FmuKind;
use engine_mount_chassis::fmi2::variables::{integer, real};
use engine_mount_chassis::fmu::instance::{Instance, Outcome, Status};
use engine_mount_chassis::fmu::logger::Logger;

struct Run {
    cpu: f64,
    steps: u64,
    restarts: u64,
    /// Mount forces every 10 ms.
    forces: Vec<[f64; 12]>,
}

fn run(scene: i32, seconds: f64, h: f64, derivatives: bool) -> Result<Run, String> {
    let resources = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("resources");
    let logger = Logger::new(None, std::ptr::null_mut(), "rpm", false);
    let abi = &engine_mount_chassis::fmi2::abi::ABI;
    let mut fmu = Instance::new("rpm", FmuKind::Engine, abi, logger, Some(resources));
    let ok = |s: Outcome, what: &str| match s {
        Ok(Status::Ok | Status::Warning) => Ok(()),
        Ok(other) => Err(format!("{what}: {other:?}")),
        Err(m) => Err(format!("{what}: {m}")),
    };
    ok(
        fmu.set::<i32>(&[integer::SCENE as usize], &[scene]),
        "scene",
    )?;
    ok(fmu.setup_experiment(0.0, None, None), "setup")?;
    ok(fmu.enter_initialization(), "initialisation")?;
    ok(fmu.exit_initialization(), "initialisation")?;
    let (rpm0, rpm1) = (800.0, 2500.0);
    let rate = (rpm1 - rpm0) / seconds;
    let n = (seconds / h).round() as usize;
    let every = ((1e-2 / h).round() as usize).max(1);
    let mut forces = Vec::new();
    let started = Instant::now();
    for k in 0..n {
        let t = k as f64 * h;
        ok(
            fmu.set::<f64>(&[real::RPM as usize], &[rpm0 + rate * t]),
            "set rpm",
        )?;
        if derivatives {
            ok(
                fmu.set_real_input_derivatives(&[real::RPM as usize], &[1], &[rate]),
                "set derivative",
            )?;
        }
        ok(fmu.do_step(t, h), "step")?;
        if (k + 1) % every == 0 {
            let r = &fmu.core.values.reals;
            let mut f = [0.0; 12];
            for (i, mount) in real::MOUNT_F.iter().enumerate() {
                for (j, index) in mount.iter().enumerate() {
                    f[3 * i + j] = *r.get(*index);
                }
            }
            forces.push(f);
        }
    }
    let cpu = started.elapsed().as_secs_f64();
    let counters = fmu
        .core
        .simulation
        .as_ref()
        .ok_or("no simulation")?
        .counters();
    Ok(Run {
        cpu,
        steps: counters.steps,
        restarts: counters.restarts,
        forces,
    })
}

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().collect();
    let value = |flag: &str| {
        args.iter()
            .position(|a| a == flag)
            .and_then(|i| args.get(i + 1))
            .and_then(|s| s.parse::<f64>().ok())
    };
    let scene = value("--scene").unwrap_or(1.0) as i32;
    let seconds = value("--seconds").unwrap_or(10.0);
    println!(
        "scene {scene}: run-up 800 -> 2500 rpm in {seconds} s, rpm set at every communication step"
    );
    println!(
        "{:>8} {:>12} {:>8} {:>9} {:>9} {:>11} {:>16}",
        "step", "derivatives", "cpu s", "cpu ratio", "steps", "restarts", "L2 forces"
    );
    for h in [1e-4, 1e-3, 1e-2] {
        let with = run(scene, seconds, h, true)?;
        let without = run(scene, seconds, h, false)?;
        // Relative L2 of the mount forces, the measure of the accuracy table (user guide, Evidence).
        let (mut num, mut den) = (0.0, 0.0);
        for (a, b) in with.forces.iter().zip(&without.forces) {
            for (x, y) in a.iter().zip(b) {
                num += (x - y) * (x - y);
                den += x * x;
            }
        }
        let diff = (num / den).sqrt();
        for (label, r, d) in [("yes", &with, 0.0), ("no", &without, diff)] {
            println!(
                "{:>6.1}ms {:>12} {:>8.2} {:>9.2} {:>9} {:>11} {:>16.1e}",
                h * 1e3,
                label,
                r.cpu,
                r.cpu / with.cpu,
                r.steps,
                r.restarts,
                d
            );
        }
    }
    Ok(())
}
