//! How much faster than real time the FMU's runtime is, at its default accuracy.
//!
//! Runs `cosim::Simulation` (exactly what `fmi2DoStep` drives) at constant speed with a 1 ms
//! communication step: a settling phase, then a measured window. Prints one table row per scene
//! and speed: CPU seconds per simulated second, the real-time factor and the integrator's work
//! per simulated second.
//!
//! With `--breakdown` a second table says where the time of a step goes: the cost of one
//! right-hand side, one Jacobian, one factorisation, one linear solve and one reading of the
//! outputs (once per communication step), timed on their own at
//! the window's last state (1000s of calls), times how often the integrator called them; the rest
//! is the integrator's own work (prediction, error control, history, interpolation).
//! `--repeat N` measures the window N times in a row and prints the range.
//!
//! `cargo run --release --example realtime -- [--window SECONDS] [--repeat N] [--breakdown] [--scene N] [--cutoff HZ] [--rtol R] [--atol A] [--max-order Q]
//! [--without gas,mass,balance,gyro,ring,nonlinear,flex]`

use std::time::Instant;

use engine_mount_chassis::cosim::{
    scene, Counters, EffectSwitch, Inputs, SceneKind, Settings, Simulation,
};
use engine_mount_chassis::model::CoupledModel;
use engine_mount_chassis::ode::{
    BlockLowRankJacobian, BlockLowRankLu, DenseLu, OdeProblem, ProblemError,
};
use faer::Mat;

/// Seconds per call of `f`: the fastest of three runs of about 0.1 s each (the least disturbed
/// by the machine).
fn time_per_call(mut f: impl FnMut()) -> f64 {
    let mut calls = 1usize;
    loop {
        let started = Instant::now();
        for _ in 0..calls {
            f();
        }
        if started.elapsed().as_secs_f64() > 0.1 {
            break;
        }
        calls *= 4;
    }
    (0..3)
        .map(|_| {
            let started = Instant::now();
            for _ in 0..calls {
                f();
            }
            started.elapsed().as_secs_f64() / calls as f64
        })
        .fold(f64::INFINITY, f64::min)
}

/// Cost of one right-hand side, Jacobian, factorisation and solve (seconds) at `(t, y)`, with
/// the linear algebra the integrator uses for this model.
fn unit_costs(model: &CoupledModel, t: f64, y: &[f64]) -> Result<[f64; 5], ProblemError> {
    let mut m = model.clone();
    let n = y.len();
    let mut f = vec![0.0; n];
    m.rhs(t, y, &mut f)?;
    let rhs = time_per_call(|| {
        m.rhs(t, y, &mut f).expect("rhs");
    });
    let outputs = time_per_call(|| {
        std::hint::black_box(
            scene::outputs(model, scene::ComfortPoints::of(model), t, y).expect("outputs"),
        );
    });
    let gamma = 1e-5;
    let mut b: Vec<f64> = f.iter().map(|v| v * 1e-6).collect();
    if let Some(shape) = m.jacobian_structure() {
        let mut j = BlockLowRankJacobian::new(shape.clone());
        let jac = time_per_call(|| {
            j.clear();
            m.structured_jacobian(t, y, &mut j).expect("jacobian");
        });
        let mut lu = BlockLowRankLu::new(&shape);
        let factor = time_per_call(|| {
            assert!(lu.factor(&j, gamma));
        });
        let solve = time_per_call(|| lu.solve_in_place(&mut b));
        Ok([rhs, jac, factor, solve, outputs])
    } else {
        let mut j = Mat::zeros(n, n);
        let jac = time_per_call(|| {
            m.jacobian(t, y, j.as_mut()).expect("jacobian");
        });
        let mut lu = DenseLu::new(n);
        let factor = time_per_call(|| {
            let a = lu.matrix_mut();
            for c in 0..n {
                for r in 0..n {
                    a[(r, c)] = -gamma * j[(r, c)] + if r == c { 1.0 } else { 0.0 };
                }
            }
            assert!(lu.factor());
        });
        let solve = time_per_call(|| lu.solve_in_place(&mut b));
        Ok([rhs, jac, factor, solve, outputs])
    }
}

/// One row of the breakdown: per step, microseconds in each kind of work.
fn print_breakdown(scene: i32, rpm: f64, cpu_per_step: f64, per_step: [f64; 5], unit: [f64; 5]) {
    let us = |x: f64| x * 1e6;
    let parts: Vec<f64> = per_step.iter().zip(&unit).map(|(n, c)| n * c).collect();
    let rest = cpu_per_step - parts.iter().sum::<f64>();
    println!(
        "{:>5} {:>6.0} {:>8.2} | {:>5.2} × {:>6.2} = {:>6.2} | {:>5.3} × {:>7.1} = {:>5.2} | {:>5.3} × {:>6.2} = {:>5.2} | {:>5.2} × {:>5.2} = {:>5.2} | {:>5.3} × {:>5.2} = {:>5.2} | {:>6.2}",
        scene,
        rpm,
        us(cpu_per_step),
        per_step[0],
        us(unit[0]),
        us(parts[0]),
        per_step[1],
        us(unit[1]),
        us(parts[1]),
        per_step[2],
        us(unit[2]),
        us(parts[2]),
        per_step[3],
        us(unit[3]),
        us(parts[3]),
        per_step[4],
        us(unit[4]),
        us(parts[4]),
        us(rest),
    );
}

/// Calls per step of each kind of work between two counter readings.
fn calls_per_step(before: &Counters, after: &Counters, communication_steps: f64) -> [f64; 5] {
    let steps = (after.steps - before.steps).max(1) as f64;
    [
        (after.rhs_evaluations - before.rhs_evaluations) as f64 / steps,
        (after.jacobian_evaluations - before.jacobian_evaluations) as f64 / steps,
        (after.factorizations - before.factorizations) as f64 / steps,
        (after.newton_iterations - before.newton_iterations) as f64 / steps,
        communication_steps / steps,
    ]
}

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().collect();
    let value = |flag: &str| {
        args.iter()
            .position(|a| a == flag)
            .and_then(|i| args.get(i + 1))
            .and_then(|s| s.parse::<f64>().ok())
    };
    let window = value("--window").unwrap_or(1.0);
    let repeat = value("--repeat").unwrap_or(1.0).max(1.0) as usize;
    let breakdown = args.iter().any(|a| a == "--breakdown");
    let mut breakdown_rows = Vec::new();
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
                scene: SceneKind::from_number(scene)?,
                ..Settings::default()
            };
            let without = args
                .iter()
                .position(|a| a == "--without")
                .and_then(|i| args.get(i + 1))
                .cloned()
                .unwrap_or_default();
            for effect in without.split(',').filter(|e| !e.is_empty()) {
                let switch = match effect {
                    "gas" => EffectSwitch::GasForces,
                    "mass" => EffectSwitch::MassForces,
                    "balance" => EffectSwitch::BalanceShaft,
                    "gyro" => EffectSwitch::Gyroscopic,
                    "ring" => EffectSwitch::RingCarrierElasticity,
                    "nonlinear" => EffectSwitch::MountNonlinearity,
                    "flex" => EffectSwitch::ChassisFlexibility,
                    other => return Err(format!("unknown effect {other}")),
                };
                settings.vehicle.effects.set(switch, false);
            }
            if let Some(r) = value("--rtol") {
                // The absolute tolerance follows (as in the FMU) unless --atol is given.
                settings.rel_tol = r;
            }
            if let Some(q) = value("--max-order") {
                settings.max_order = q as usize;
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
                sim.advance_to(k as f64 * h).map_err(|e| e.to_string())?;
            }
            let mut factors = Vec::new();
            let (mut first, mut last) = (sim.counters(), sim.counters());
            let mut cpu_total = 0.0;
            let mut k0 = n_settle;
            for r in 0..repeat {
                let before = sim.counters();
                let started = Instant::now();
                for k in 1..=n_window {
                    sim.advance_to((k0 + k) as f64 * h)
                        .map_err(|e| e.to_string())?;
                    sim.outputs()?;
                }
                let cpu = started.elapsed().as_secs_f64();
                k0 += n_window;
                cpu_total += cpu;
                factors.push(window / cpu);
                if r == 0 {
                    first = before;
                }
                last = sim.counters();
            }
            let simulated = window * repeat as f64;
            let per_s = |a: u64, b: u64| (a - b) as f64 / simulated;
            let lo = factors.iter().cloned().fold(f64::INFINITY, f64::min);
            let hi = factors.iter().cloned().fold(0.0, f64::max);
            let factor = if repeat > 1 {
                format!("{lo:.1}–{hi:.1}")
            } else {
                format!("{lo:.1}")
            };
            println!(
                "{:>5} {:>6.0} {:>7} {:>8.4} {:>10} {:>9.0} {:>9.0} {:>8.0} {:>8.0}",
                scene,
                rpm,
                sim.state_count(),
                cpu_total / simulated,
                factor,
                per_s(last.steps, first.steps),
                per_s(last.rhs_evaluations, first.rhs_evaluations),
                per_s(last.jacobian_evaluations, first.jacobian_evaluations),
                per_s(last.factorizations, first.factorizations),
            );
            if breakdown {
                // The fastest window is the one least disturbed by the machine.
                let cpu_per_step =
                    window / hi / ((last.steps - first.steps) as f64 / repeat as f64);
                let unit = unit_costs(sim.model(), sim.time(), sim.state())
                    .map_err(|e| format!("{e:?}"))?;
                breakdown_rows.push((
                    scene,
                    rpm,
                    cpu_per_step,
                    calls_per_step(&first, &last, (n_window * repeat) as f64),
                    unit,
                ));
            }
        }
    }
    if breakdown {
        println!();
        println!("where a step's time goes (µs; calls per step × µs per call = µs per step):");
        println!(
            "{:>5} {:>6} {:>8} | {:^24} | {:^25} | {:^24} | {:^23} | {:^23} | {:>6}",
            "scene",
            "rpm",
            "step",
            "right-hand side",
            "Jacobian",
            "factorisation",
            "solve",
            "outputs",
            "rest"
        );
        for (scene, rpm, cpu, calls, unit) in breakdown_rows {
            print_breakdown(scene, rpm, cpu, calls, unit);
        }
    }
    Ok(())
}
