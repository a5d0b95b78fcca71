//! Sine inputs over a grid of tolerances, frequencies and amplitudes: does every run finish?
//!
//! Drives `cosim::Simulation` (what `fmi2DoStep` drives) the way a master excites the FMU with a
//! sine (`emc frf --verify`, `emc.frf.sine_response`): at every communication step (50 per
//! period) the input's value and its derivative, the amplitude rising smoothly over the first
//! `--ramp` seconds. Cases:
//! - `torque@rest`: a sine on the load torque with the engine at rest, gas and mass forces off
//!   (the operating point of the linearised model);
//! - `torque@2000`: a sine on the load torque at 2000 rpm, excitation on;
//! - `rpm@2000`: a sine on the speed set-point around 2000 rpm, excitation on.
//!
//! Prints one row per run: whether it reached the end, where it failed and why, the
//! integrator's work and the wall time; then the failures per relative tolerance. Runs are
//! spread over the machine's cores (`--jobs`).
//!
//! `cargo run --release --example sine_sweep -- [--scenes 1,2] [--rtols 1e-5,...] [--freqs 5,...]
//! [--cases torque@rest,torque@2000,rpm@2000] [--duration S] [--ramp S] [--jobs N]`

use std::sync::{Arc, Mutex};
use std::time::Instant;

use engine_mount_chassis::cosim::{
    EffectSwitch, Inputs, RampInput, SceneKind, Settings, Simulation, VehicleOverrides,
    RPM_TO_RAD_PER_S,
};

#[derive(Clone, Copy, Debug)]
enum Input {
    Torque,
    Rpm,
}

#[derive(Clone, Debug)]
struct Case {
    scene: SceneKind,
    name: &'static str,
    input: Input,
    rpm: f64,
    amplitude: f64,
    frequency: f64,
    rtol: f64,
}

#[derive(Debug)]
struct Outcome {
    case: Case,
    failure: Option<(f64, String)>,
    steps: u64,
    rhs: u64,
    wall: f64,
}

fn run(case: &Case, duration: f64, ramp: f64) -> Outcome {
    let started = Instant::now();
    let mut vehicle = VehicleOverrides::default();
    if case.rpm == 0.0 {
        vehicle.effects.set(EffectSwitch::GasForces, false);
        vehicle.effects.set(EffectSwitch::MassForces, false);
    }
    let settings = Settings {
        scene: case.scene,
        rel_tol: case.rtol,
        vehicle,
        ..Settings::default()
    };
    let base = Inputs::steady(case.rpm);
    let done = |failure, sim: Option<&Simulation>| {
        let counters = sim.map(|s| s.counters());
        Outcome {
            case: case.clone(),
            failure,
            steps: counters.as_ref().map_or(0, |c| c.steps),
            rhs: counters.as_ref().map_or(0, |c| c.rhs_evaluations),
            wall: started.elapsed().as_secs_f64(),
        }
    };
    let mut sim = match Simulation::new(&settings, 0.0, &base) {
        Ok(s) => s,
        Err(e) => return done(Some((0.0, format!("initialisation: {e}"))), None),
    };
    let w = 2.0 * std::f64::consts::PI * case.frequency;
    let h = 1.0 / (50.0 * case.frequency);
    let n = (duration / h).round() as usize;
    // Smoothstep envelope and its derivative.
    let envelope = |t: f64| {
        let x = (t / ramp).clamp(0.0, 1.0);
        let de = if t > 0.0 && t < ramp {
            6.0 * x * (1.0 - x) / ramp
        } else {
            0.0
        };
        (x * x * (3.0 - 2.0 * x), de)
    };
    for k in 0..n {
        let t = k as f64 * h;
        let (e, de) = envelope(t);
        let u = case.amplitude * e * (w * t).sin();
        let du = case.amplitude * (de * (w * t).sin() + e * w * (w * t).cos());
        let mut inputs = base.clone();
        match case.input {
            Input::Torque => {
                inputs.model.load_torque = RampInput {
                    value: u,
                    rate: du,
                    since: t,
                }
            }
            Input::Rpm => {
                inputs.model.crank_speed = RampInput {
                    value: (case.rpm + u) * RPM_TO_RAD_PER_S,
                    rate: du * RPM_TO_RAD_PER_S,
                    since: t,
                }
            }
        }
        if let Err(e) = sim.set_inputs(&inputs) {
            return done(Some((t, format!("inputs: {e}"))), Some(&sim));
        }
        if let Err(e) = sim.advance_to((k + 1) as f64 * h) {
            return done(Some((e.reached, e.error.to_string())), Some(&sim));
        }
    }
    done(None, Some(&sim))
}

/// One table row.
fn row(o: &Outcome) -> String {
    let c = &o.case;
    let result = match &o.failure {
        None => "ok".to_string(),
        Some((t, why)) => format!("FAILED at {t:.4e} s: {why}"),
    };
    format!(
        "| {} | {} | {} | {} | {:.0e} | {result} | {} | {} | {:.1} |",
        if matches!(c.scene, SceneKind::Ground) {
            1
        } else {
            2
        },
        c.name,
        c.amplitude,
        c.frequency,
        c.rtol,
        o.steps,
        o.rhs,
        o.wall
    )
}

fn list(args: &[String], flag: &str, default: &str) -> Vec<String> {
    let value = args
        .iter()
        .position(|a| a == flag)
        .map(|i| args[i + 1].clone())
        .unwrap_or_else(|| default.to_string());
    value.split(',').map(str::to_string).collect()
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let number = |s: &String| -> f64 { s.parse().unwrap_or_else(|_| panic!("not a number: {s}")) };
    let scenes = list(&args, "--scenes", "1,2");
    let rtols: Vec<f64> = list(&args, "--rtols", "1e-5,1e-6,1e-7,1e-8,1e-9")
        .iter()
        .map(number)
        .collect();
    let freqs: Vec<f64> = list(&args, "--freqs", "5,20,45,100,200")
        .iter()
        .map(number)
        .collect();
    let cases = list(&args, "--cases", "torque@rest,torque@2000,rpm@2000");
    let duration = number(&list(&args, "--duration", "0.4")[0]);
    let ramp = number(&list(&args, "--ramp", "0.1")[0]);
    let jobs: usize = list(&args, "--jobs", "0")[0].parse().unwrap();
    let jobs = if jobs == 0 {
        std::thread::available_parallelism().map_or(1, |n| n.get())
    } else {
        jobs
    };
    let mut grid = Vec::new();
    for scene in &scenes {
        let scene = if scene == "1" {
            SceneKind::Ground
        } else {
            SceneKind::Body
        };
        for case in &cases {
            let (name, input, rpm, amplitudes): (&'static str, Input, f64, &[f64]) =
                match case.as_str() {
                    "torque@rest" => ("torque@rest", Input::Torque, 0.0, &[20.0, 200.0]),
                    "torque@2000" => ("torque@2000", Input::Torque, 2000.0, &[200.0]),
                    "rpm@2000" => ("rpm@2000", Input::Rpm, 2000.0, &[20.0, 200.0]),
                    other => panic!("unknown case {other}"),
                };
            for &amplitude in amplitudes {
                for &frequency in &freqs {
                    for &rtol in &rtols {
                        grid.push(Case {
                            scene,
                            name,
                            input,
                            rpm,
                            amplitude,
                            frequency,
                            rtol,
                        });
                    }
                }
            }
        }
    }
    // Workers take runs from the end: the slowest (tightest tolerances) first, so that they
    // finish together.
    grid.sort_by(|a, b| b.rtol.total_cmp(&a.rtol));
    let total = grid.len();
    let queue = Arc::new(Mutex::new(grid.into_iter().enumerate().collect::<Vec<_>>()));
    let results = Arc::new(Mutex::new(Vec::new()));
    let started = Instant::now();
    let workers: Vec<_> = (0..jobs)
        .map(|_| {
            let queue = Arc::clone(&queue);
            let results = Arc::clone(&results);
            std::thread::spawn(move || loop {
                let next = queue.lock().unwrap().pop();
                let Some((i, case)) = next else { break };
                let outcome = run(&case, duration, ramp);
                // As they finish, for a sweep cut short.
                eprintln!("{}", row(&outcome));
                results.lock().unwrap().push((i, outcome));
            })
        })
        .collect();
    for w in workers {
        w.join().unwrap();
    }
    let mut results = Arc::try_unwrap(results).unwrap().into_inner().unwrap();
    results.sort_by_key(|(i, _)| *i);
    println!(
        "{total} runs of {duration} s (sine rising over {ramp} s, 50 communication steps per \
         period), {jobs} jobs, {:.0} s",
        started.elapsed().as_secs_f64()
    );
    println!("| scene | case | amplitude | Hz | rtol | result | steps | RHS | wall s |");
    println!("|---:|---|---:|---:|---:|---|---:|---:|---:|");
    let mut sorted: Vec<&Outcome> = results.iter().map(|(_, o)| o).collect();
    sorted.sort_by(|a, b| {
        let key = |o: &Outcome| {
            (
                o.case.scene as u8,
                o.case.name,
                (o.case.amplitude * 1e3) as i64,
                (o.case.frequency * 1e3) as i64,
            )
        };
        key(a)
            .cmp(&key(b))
            .then(b.case.rtol.total_cmp(&a.case.rtol))
    });
    for o in &sorted {
        println!("{}", row(o));
    }
    println!();
    println!("| rtol | runs | failed | wall s (sum) |");
    println!("|---:|---:|---:|---:|");
    for &rtol in &rtols {
        let of: Vec<_> = sorted.iter().filter(|o| o.case.rtol == rtol).collect();
        let failed = of.iter().filter(|o| o.failure.is_some()).count();
        let wall: f64 = of.iter().map(|o| o.wall).sum();
        println!("| {rtol:.0e} | {} | {failed} | {wall:.1} |", of.len());
    }
}
