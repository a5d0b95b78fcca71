//! How much faster than real time the FMU's runtime is, at its default accuracy.
//!
//! Runs `cosim::Simulation` (exactly what `fmi2DoStep` drives) at constant speed with a 1 ms
//! communication step: a settling phase, then a measured window. Prints one table row per scene
//! and speed: CPU seconds per simulated second, the real-time factor and the integrator's work
//! per simulated second.
//!
//! `cargo run --release --example realtime -- [--window SECONDS] [--scene N] [--cutoff HZ] [--rtol R] [--atol A] [--max-order Q]
//! [--without gas,mass,balance,gyro,ring,nonlinear,flex]`

use std::time::Instant;

use engine_mount_chassis::cosim::{Inputs, Settings, Simulation};

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().collect();
    let value = |flag: &str| {
        args.iter()
            .position(|a| a == flag)
            .and_then(|i| args.get(i + 1))
            .and_then(|s| s.parse::<f64>().ok())
    };
    let window = value("--window").unwrap_or(1.0);
    let scenes: Vec<i32> = match value("--scene") {
        Some(s) => vec![s as i32],
        None => vec![1, 2],
    };
    let h: f64 = 1e-3;
    let settle: f64 = 0.2;
    println!(
        "{:>5} {:>6} {:>7} {:>8} {:>10} {:>9} {:>9} {:>8} {:>8}",
        "scene", "rpm", "states", "cpu/sim", "× realtime", "steps/s", "rhs/s", "jac/s", "LU/s"
    );
    for scene in scenes {
        for rpm in [800.0, 2000.0, 4000.0] {
            let mut settings = Settings {
                scene,
                ..Settings::default()
            };
            let without = args
                .iter()
                .position(|a| a == "--without")
                .and_then(|i| args.get(i + 1))
                .cloned()
                .unwrap_or_default();
            for effect in without.split(',').filter(|e| !e.is_empty()) {
                let e = &mut settings.effects;
                match effect {
                    "gas" => e.gas_forces = false,
                    "mass" => e.mass_forces = false,
                    "balance" => e.balance_shaft = false,
                    "gyro" => e.gyroscopic = false,
                    "ring" => e.ring_carrier_elasticity = false,
                    "nonlinear" => e.mount_nonlinearity = false,
                    "flex" => e.chassis_flexibility = false,
                    other => return Err(format!("unknown effect {other}")),
                }
            }
            if let Some(r) = value("--rtol") {
                settings.rel_tol = r;
                settings.abs_tol = r * 1e-3;
            }
            if let Some(q) = value("--max-order") {
                settings.max_order = q as i32;
            }
            if let Some(a) = value("--atol") {
                settings.abs_tol = a;
            }
            if let Some(c) = value("--cutoff") {
                settings.chassis.mode_cutoff_hz = c;
            }
            let mut sim = Simulation::new(&settings, 0.0, &Inputs::steady(rpm))?;
            let n_settle = (settle / h).round() as usize;
            let n_window = (window / h).round() as usize;
            for k in 1..=n_settle {
                sim.advance_to(k as f64 * h).map_err(|e| e.message)?;
            }
            let before = sim.counters();
            let started = Instant::now();
            for k in 1..=n_window {
                sim.advance_to((n_settle + k) as f64 * h)
                    .map_err(|e| e.message)?;
                sim.outputs()?;
            }
            let cpu = started.elapsed().as_secs_f64();
            let after = sim.counters();
            let per_s = |a: u64, b: u64| (a - b) as f64 / window;
            println!(
                "{:>5} {:>6.0} {:>7} {:>8.4} {:>10.1} {:>9.0} {:>9.0} {:>8.0} {:>8.0}",
                scene,
                rpm,
                sim.state_count(),
                cpu / window,
                window / cpu,
                per_s(after.steps, before.steps),
                per_s(after.rhs_evaluations, before.rhs_evaluations),
                per_s(after.jacobian_evaluations, before.jacobian_evaluations),
                per_s(after.factorizations, before.factorizations),
            );
        }
    }
    Ok(())
}
