//! Benchmark of scene 2 (engine in the elastic chassis): for several chassis mode sets, the time
//! to reduce the chassis, and for a run at constant speed the integrator's work, the CPU time and
//! the steering-wheel acceleration orders; scene 1 (rigid ground) as the reference line.
//!
//! `cargo run --release --example hybrid_run -- [rpm=1800] [revolutions=30] [rtol=1e-6]`

use std::time::Instant;

use engine_mount_chassis::cms::{reduce, ModeSelection};
use engine_mount_chassis::model::orders::order_amplitude;
use engine_mount_chassis::model::scene::{reduction_spec, BodyOptions};
use engine_mount_chassis::model::{CoupledModel, VehicleConfig};
use engine_mount_chassis::ode::{Bdf, BdfOptions, OdeProblem, Tolerance};

fn arg(i: usize, default: f64) -> f64 {
    std::env::args()
        .nth(i)
        .and_then(|s| s.parse().ok())
        .unwrap_or(default)
}

const SAMPLES_PER_REV: usize = 72;
const ORDERS: [f64; 5] = [1.0, 1.5, 2.0, 3.0, 4.5];

/// CPU seconds, [steps, rhs, jacobians, factorisations], samples.
type RunResult = Result<(f64, [u64; 4], Vec<f64>), Box<dyn std::error::Error>>;

/// Runs `scene` for `revs` revolutions, sampling `sample` over the second half.
fn run<P: OdeProblem>(
    scene: &mut P,
    y0: &[f64],
    rpm: f64,
    revs: usize,
    rtol: f64,
    mut sample: impl FnMut(&P, f64, &[f64]) -> f64,
) -> RunResult {
    let opts = BdfOptions {
        rtol,
        atol: Tolerance::Scalar(rtol * 1e-3),
        ..Default::default()
    };
    let start = Instant::now();
    let mut bdf = Bdf::new(scene, 0.0, y0, opts)?;
    let t_rev = 60.0 / rpm;
    let window = (revs / 2).max(2) & !1;
    bdf.advance_to(scene, (revs - window) as f64 * t_rev)?;
    let mut samples = Vec::new();
    for k in 1..=window * SAMPLES_PER_REV {
        let t = (revs - window) as f64 * t_rev + t_rev * k as f64 / SAMPLES_PER_REV as f64;
        bdf.advance_to(scene, t)?;
        samples.push(sample(scene, t, bdf.y()));
    }
    let cpu = start.elapsed().as_secs_f64();
    let s = bdf.stats();
    Ok((
        cpu,
        [s.steps, s.rhs_evals, s.jac_evals, s.factorizations],
        samples,
    ))
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let (rpm, revs, rtol) = (arg(1, 1800.0), arg(2, 30.0) as usize, arg(3, 1e-6));
    let w = rpm * std::f64::consts::PI / 30.0;
    let sim_time = revs as f64 * 60.0 / rpm;
    println!("{rpm} rpm, {revs} revolutions ({sim_time:.3} s simulated), rtol {rtol:e}\n");
    println!(
        "{:<34} {:>6} {:>9} {:>7} {:>8} {:>6} {:>6} {:>9} {:>10}   steering wheel a_z order amplitudes [m/s²] {ORDERS:?}",
        "scene", "states", "reduce s", "cpu s", "cpu/sim", "steps", "rhs", "jacobians", "factoris."
    );

    let cfg = VehicleConfig::default();
    let mut ground = CoupledModel::on_ground(&cfg)?;
    ground.set_crank_speed(0.0, w, 0.0)?;
    let y0 = ground.static_equilibrium(0.0)?;
    let (cpu, n, _) = run(&mut ground, &y0, rpm, revs, rtol, |_, _, _| 0.0)?;
    println!(
        "{:<34} {:>6} {:>9} {:>7.3} {:>8.2} {:>6} {:>6} {:>9} {:>10}",
        "1: engine on rigid ground",
        ground.dim(),
        "-",
        cpu,
        cpu / sim_time,
        n[0],
        n[1],
        n[2],
        n[3]
    );

    for cutoff_hz in [60.0, 200.0, 400.0] {
        let options = BodyOptions {
            mode_cutoff_hz: cutoff_hz,
            ..BodyOptions::default()
        };
        let (spec, _) = reduction_spec(&cfg, &options)?;
        let started = Instant::now();
        let chassis = reduce(&spec)?;
        let reduce_s = started.elapsed().as_secs_f64();
        let ModeSelection::CutoffHz(cut) = spec.selection else {
            unreachable!("selected by cut-off");
        };
        let label = format!("2: CB < {cut:.0} Hz: {} modes", chassis.n_modes());
        let mut hybrid = CoupledModel::with_body(&cfg, chassis)?;
        hybrid.set_crank_speed(0.0, w, 0.0)?;
        let y0 = hybrid.static_equilibrium(0.0)?;
        let (cpu, n, samples) = run(&mut hybrid, &y0, rpm, revs, rtol, |h, t, y| {
            h.outputs(t, y)
                .ok()
                .and_then(|o| o.point("steering_wheel").map(|p| p.acceleration[2]))
                .unwrap_or(f64::NAN)
        })?;
        let orders: Vec<String> = ORDERS
            .iter()
            .map(|o| {
                format!(
                    "{:.4}",
                    order_amplitude(&samples, SAMPLES_PER_REV, *o).unwrap_or(f64::NAN)
                )
            })
            .collect();
        println!(
            "{:<34} {:>6} {:>9.2} {:>7.3} {:>8.2} {:>6} {:>6} {:>9} {:>10}   {}",
            label,
            hybrid.dim(),
            reduce_s,
            cpu,
            cpu / sim_time,
            n[0],
            n[1],
            n[2],
            n[3],
            orders.join(" ")
        );
    }
    Ok(())
}
