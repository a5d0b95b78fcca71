//! What accuracy costs in time: a work-precision report for one scene.
//!
//! Two cases, both through the co-simulation runtime the FMU uses (`cosim::Simulation`):
//! - a stationary window at constant speed (fade-in, settling, then `--window` revolutions),
//! - a run-up 800 → 2500 rpm, where the inputs change at every communication point.
//!
//! Knobs: solver tolerance, maximum order, communication step with and without input
//! interpolation (first derivatives, as `fmi2SetRealInputDerivatives` supplies them). Each run is
//! compared with a tight-tolerance reference of the same case at the same sample points:
//! relative L2 error of the mount forces over the window, and the error of the main order
//! amplitudes (orders 1.5, 2, 3 of mount 1 vertical). Cost: CPU time and integrator counters.
//!
//! The integrator's absolute tolerance follows the relative one, as in the FMU by default.
//!
//! Usage: `cargo run --release --example accuracy_cost -- [--scene N] [--csv FILE]
//! [--tolerances-only]`
//! (scripts/bench-accuracy.sh adds the log-log plot).

use std::time::Instant;

use engine_mount_chassis::cosim::{
    BodyOptions, Counters, EffectSwitch, Inputs, RampInput, SceneKind, Settings, Simulation,
    RPM_TO_RAD_PER_S,
};

/// One run's samples: every mount force component at each communication point in the window.
struct Run {
    times: Vec<f64>,
    samples: Vec<Vec<f64>>,
    cpu: f64,
    counters: Counters,
}

#[derive(Clone)]
struct Case {
    name: &'static str,
    /// Engine speed at time t (rpm).
    rpm: fn(f64) -> f64,
    /// Speed derivative (rpm/s).
    rpm_rate: fn(f64) -> f64,
    t_end: f64,
    /// Samples are taken from here on, at every communication point.
    t_window: f64,
}

fn inputs_at(case: &Case, t: f64, interpolate: bool) -> Inputs {
    let rate = if interpolate { (case.rpm_rate)(t) } else { 0.0 };
    let mut inputs = Inputs::steady(0.0);
    inputs.model.crank_speed = RampInput {
        value: (case.rpm)(t) * RPM_TO_RAD_PER_S,
        rate: rate * RPM_TO_RAD_PER_S,
        since: t,
    };
    inputs
}

/// Runs a case with communication step `h`, recording every communication point in the window.
fn run(case: &Case, settings: &Settings, h: f64, interpolate: bool) -> Result<Run, String> {
    let mut sim = Simulation::new(settings, 0.0, &inputs_at(case, 0.0, interpolate))?;
    // The clock starts after set-up: instantiation may reduce the chassis (cached afterwards).
    let started = Instant::now();
    let n = (case.t_end / h).round() as usize;
    let mut times = Vec::new();
    let mut samples = Vec::new();
    for k in 0..n {
        let t = k as f64 * h;
        sim.set_inputs(&inputs_at(case, t, interpolate))?;
        let t_next = (k + 1) as f64 * h;
        sim.advance_to(t_next).map_err(|e| e.to_string())?;
        if t_next > case.t_window + 1e-9 {
            let o = sim.outputs()?;
            times.push(t_next);
            let mut row: Vec<f64> = o.mount_force.iter().flatten().copied().collect();
            row.extend(o.steering_wheel_acceleration);
            samples.push(row);
        }
    }
    Ok(Run {
        times,
        samples,
        cpu: started.elapsed().as_secs_f64(),
        counters: sim.counters(),
    })
}

/// Columns of a sample row: the 12 mount-force components, then the steering-wheel acceleration.
const FORCES: std::ops::Range<usize> = 0..12;
const STEERING_WHEEL: std::ops::Range<usize> = 12..15;

/// Relative L2 error of `run` against `reference` in the columns `cols`, at the run's sample
/// times (which are reference sample times too: the reference step divides every communication
/// step).
fn relative_l2(run: &Run, reference: &Run, cols: std::ops::Range<usize>) -> f64 {
    let h_ref = reference.times[1] - reference.times[0];
    let pairs: Vec<(&Vec<f64>, &Vec<f64>)> = run
        .times
        .iter()
        .zip(&run.samples)
        .filter_map(|(t, a)| {
            let k = ((t - reference.times[0]) / h_ref).round();
            let b = reference.samples.get(k as usize)?;
            ((reference.times[k as usize] - t).abs() < 1e-9).then_some((a, b))
        })
        .collect();
    let n = pairs.len().max(1);
    let mean: Vec<f64> = cols
        .clone()
        .map(|j| pairs.iter().map(|(_, b)| b[j]).sum::<f64>() / n as f64)
        .collect();
    let (mut num, mut den) = (0.0, 0.0);
    for (a, b) in pairs {
        for (k, j) in cols.clone().enumerate() {
            num += (a[j] - b[j]).powi(2);
            den += (b[j] - mean[k]).powi(2);
        }
    }
    if den == 0.0 {
        return f64::NAN; // scene 1 has no steering wheel
    }
    (num / den).sqrt()
}

/// Amplitude of order `order` in component `j` of a window of whole revolutions at constant rpm.
fn order_amplitude(samples: &[Vec<f64>], j: usize, order: f64, rpm: f64, dt: f64) -> f64 {
    let n = samples.len() as f64;
    let w = order * rpm * RPM_TO_RAD_PER_S;
    let mean = samples.iter().map(|s| s[j]).sum::<f64>() / n;
    let (mut c, mut s) = (0.0, 0.0);
    for (k, x) in samples.iter().enumerate() {
        let t = k as f64 * dt;
        c += (x[j] - mean) * (w * t).cos();
        s += (x[j] - mean) * (w * t).sin();
    }
    2.0 * (c * c + s * s).sqrt() / n
}

/// Chassis cut-off of the most complete model (scene 2): 1,056 fixed-interface modes, the
/// largest set the shift-invert Lanczos reduces in about two minutes (cached afterwards). Model
/// knobs are measured against its tight reference.
const COMPLETE_CUTOFF_HZ: f64 = 2000.0;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let arg = |name: &str| {
        args.iter()
            .position(|a| a == name)
            .and_then(|i| args.get(i + 1))
            .cloned()
    };
    let scene: i32 = arg("--scene").and_then(|s| s.parse().ok()).unwrap_or(1);
    let csv = arg("--csv");
    // Only the tolerance rows (and 1e-9): the part of the table `emc accuracy` reproduces.
    let tolerances_only = args.iter().any(|a| a == "--tolerances-only");
    let base = Settings {
        scene: SceneKind::from_number(scene).expect("--scene"),
        ..Settings::default()
    };

    // Constant speed: 2000 rpm; fade-in 0.1 s, settle to 0.6 s, then 8 revolutions (0.24 s).
    let stationary = Case {
        name: "2000 rpm stationary",
        rpm: |_| 2000.0,
        rpm_rate: |_| 0.0,
        t_end: 0.6 + 8.0 * 60.0 / 2000.0,
        t_window: 0.6,
    };
    // Run-up 800 → 2500 rpm in 2 s after 0.3 s at idle.
    let runup = Case {
        name: "run-up 800-2500 rpm",
        rpm: |t| {
            if t < 0.3 {
                800.0
            } else {
                (800.0 + 850.0 * (t - 0.3)).min(2500.0)
            }
        },
        rpm_rate: |t| if (0.3..2.3).contains(&t) { 850.0 } else { 0.0 },
        t_end: 2.3,
        t_window: 0.3,
    };

    let mut rows = Vec::new();
    println!(
        "{:<22} {:<26} {:>10} {:>10} {:>9} {:>9} {:>9} {:>6} {:>6} {:>10} {:>10}",
        "case",
        "knob",
        "L2 forces",
        "L2 wheel",
        "ord err",
        "cpu [s]",
        "steps",
        "jac",
        "lu",
        "rhs",
        "x realtime"
    );
    for case in [&stationary, &runup] {
        // The absolute tolerance follows the relative one (`abs_tol` 0, the FMU's default).
        let reference_settings = Settings {
            rel_tol: 1e-10,
            abs_tol: 0.0,
            ..base.clone()
        };
        let reference = match run(case, &reference_settings, 1e-4, true) {
            Ok(r) => r,
            Err(e) => {
                println!("{}: reference failed: {e}", case.name);
                continue;
            }
        };
        // Knobs that change the model (cut-off, effects) are measured against a reference of the
        // most complete model; accuracy knobs against the reference of the default model.
        let complete = if scene == 2 && !tolerances_only {
            let s = Settings {
                chassis: BodyOptions {
                    mode_cutoff_hz: COMPLETE_CUTOFF_HZ,
                    ..base.chassis.clone()
                },
                ..reference_settings.clone()
            };
            match run(case, &s, 1e-4, true) {
                Ok(r) => Some(r),
                Err(e) => {
                    println!(
                        "{}: {COMPLETE_CUTOFF_HZ} Hz reference failed: {e}",
                        case.name
                    );
                    None
                }
            }
        } else {
            None
        };
        let mut knobs: Vec<(String, Settings, f64, bool)> = Vec::new();
        // 0.8e-5 and 1.25e-5 beside the default show how much the error of one run scatters
        // with the step sequence at (almost) the same tolerance.
        for rtol in [1e-2, 1e-3, 1e-4, 1.25e-5, 1e-5, 0.8e-5, 1e-6, 1e-7, 1e-8] {
            let s = Settings {
                rel_tol: rtol,
                ..base.clone()
            };
            let label = if rtol == 1.25e-5 || rtol == 0.8e-5 {
                format!("rtol {rtol:.2e}")
            } else {
                format!("rtol {rtol:.0e}")
            };
            knobs.push((label, s, 1e-3, true));
        }
        if tolerances_only {
            knobs.push((
                "rtol 1e-9".to_owned(),
                Settings {
                    rel_tol: 1e-9,
                    ..base.clone()
                },
                1e-3,
                true,
            ));
        }
        let s = Settings {
            stability_limit_detection: false,
            ..base.clone()
        };
        knobs.push(("stability control off".to_owned(), s, 1e-3, true));
        for order in [2, 3, 4] {
            let s = Settings {
                max_order: order,
                ..base.clone()
            };
            knobs.push((format!("max order {order} (rtol 1e-5)"), s, 1e-3, true));
        }
        for h in [1e-4, 1e-3, 1e-2] {
            for interpolate in [true, false] {
                let label = format!(
                    "comm {h:.0e} s {}",
                    if interpolate { "interp" } else { "hold" }
                );
                knobs.push((label, base.clone(), h, interpolate));
            }
        }
        if tolerances_only {
            knobs.retain(|k| k.0.starts_with("rtol"));
        }
        let mut model_knobs: Vec<(String, Settings)> = vec![
            (
                "without gyroscopic terms".to_owned(),
                Settings {
                    vehicle: base.vehicle.with_effect(EffectSwitch::Gyroscopic, false),
                    ..base.clone()
                },
            ),
            (
                "rigid ring carriers".to_owned(),
                Settings {
                    vehicle: base
                        .vehicle
                        .with_effect(EffectSwitch::RingCarrierElasticity, false),
                    ..base.clone()
                },
            ),
        ];
        if tolerances_only {
            model_knobs.clear();
        } else if scene == 2 {
            for cutoff in [50.0, 100.0, 200.0, 400.0, 1000.0, COMPLETE_CUTOFF_HZ] {
                model_knobs.push((
                    format!("chassis cut-off {cutoff:.0} Hz"),
                    Settings {
                        chassis: BodyOptions {
                            mode_cutoff_hz: cutoff,
                            ..base.chassis.clone()
                        },
                        ..base.clone()
                    },
                ));
            }
            model_knobs.push((
                "rigid chassis".to_owned(),
                Settings {
                    vehicle: base
                        .vehicle
                        .with_effect(EffectSwitch::ChassisFlexibility, false),
                    ..base.clone()
                },
            ));
        }
        let main_orders = [1.5, 2.0, 3.0];
        // The reference's order amplitudes from its samples at the run's sample times, so that
        // both see the same (not quite periodic) window.
        let ref_orders = |h: f64| -> Vec<f64> {
            let stride = (h / 1e-4).round().max(1.0) as usize;
            let decimated: Vec<Vec<f64>> = reference
                .samples
                .iter()
                .skip(stride - 1)
                .step_by(stride)
                .cloned()
                .collect();
            main_orders
                .iter()
                .map(|o| order_amplitude(&decimated, 2, *o, 2000.0, h))
                .collect()
        };
        let all = knobs
            .into_iter()
            .map(|(l, s, h, i)| (l, s, h, i, &reference))
            .chain(
                model_knobs
                    .into_iter()
                    .map(|(l, s)| (l, s, 1e-3, true, complete.as_ref().unwrap_or(&reference))),
            );
        for (label, settings, h, interpolate, against) in all {
            match run(case, &settings, h, interpolate) {
                Ok(r) => {
                    let l2 = relative_l2(&r, against, FORCES);
                    let l2_wheel = relative_l2(&r, against, STEERING_WHEEL);
                    // Order amplitudes need samples well above the 3rd order (100 Hz at 2000 rpm).
                    let order_error = if case.name.contains("stationary") && h <= 1e-3 {
                        main_orders
                            .iter()
                            .zip(&ref_orders(h))
                            .map(|(o, a)| {
                                (order_amplitude(&r.samples, 2, *o, 2000.0, h) - a).abs() / a
                            })
                            .fold(0.0, f64::max)
                    } else {
                        f64::NAN
                    };
                    let realtime = case.t_end / r.cpu;
                    println!(
                        "{:<22} {:<26} {:>10.2e} {:>10.2e} {:>9.1e} {:>9.3} {:>9} {:>6} {:>6} {:>10} {:>10.1}",
                        case.name,
                        label,
                        l2,
                        l2_wheel,
                        order_error,
                        r.cpu,
                        r.counters.steps,
                        r.counters.jacobian_evaluations,
                        r.counters.factorizations,
                        r.counters.rhs_evaluations,
                        realtime
                    );
                    rows.push(format!(
                        "{},{},{},{},{},{},{},{},{},{},{},{}",
                        scene,
                        case.name,
                        label,
                        l2,
                        l2_wheel,
                        order_error,
                        r.cpu,
                        r.counters.steps,
                        r.counters.rhs_evaluations,
                        r.counters.jacobian_evaluations,
                        r.counters.factorizations,
                        realtime
                    ));
                }
                Err(e) => println!("{:<22} {:<26} failed: {e}", case.name, label),
            }
        }
    }
    if let Some(path) = csv {
        let mut text = String::from(
            "scene,case,knob,rel_l2,rel_l2_wheel,order_error,cpu_s,steps,rhs,jacobians,factorizations,realtime_factor\n",
        );
        for r in rows {
            text.push_str(&r);
            text.push('\n');
        }
        if let Err(e) = std::fs::write(&path, text) {
            eprintln!("cannot write {path}: {e}");
        }
    }
}
