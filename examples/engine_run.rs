//! Runs the engine on rigid ground at constant speed and prints the mount-force orders, the
//! integrator's work and the CPU time (a benchmark command, not a test).
//!
//! `cargo run --release --example engine_run -- [rpm=2000] [load=1.0] [revolutions=40] [rtol=1e-6] [fade_in_s=0.1]`

use std::time::Instant;

use engine_mount_chassis::model::orders::order_amplitude;
use engine_mount_chassis::model::{CoupledModel, VehicleConfig};
use engine_mount_chassis::ode::{Bdf, BdfOptions, Tolerance};

fn arg(i: usize, default: f64) -> f64 {
    std::env::args()
        .nth(i)
        .and_then(|s| s.parse().ok())
        .unwrap_or(default)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let (rpm, load, revs, rtol) = (
        arg(1, 2000.0),
        arg(2, 1.0),
        arg(3, 40.0) as usize,
        arg(4, 1e-6),
    );
    let mut cfg = VehicleConfig::default();
    cfg.engine.gas.load = load;
    cfg.engine.excitation_fade_in = arg(5, 0.1);
    let mut scene = CoupledModel::on_ground(&cfg)?;
    let w = rpm * std::f64::consts::PI / 30.0;
    scene.set_crank_speed(0.0, w, 0.0)?;
    let y0 = scene.static_equilibrium(0.0)?;
    let opts = BdfOptions {
        rtol,
        atol: Tolerance::Scalar(rtol * 1e-3),
        ..Default::default()
    };
    let start = Instant::now();
    let mut bdf = Bdf::new(&mut scene, 0.0, &y0, opts)?;
    let spr = 72;
    let t_rev = 2.0 * std::f64::consts::PI / w;
    let window = (revs / 2).max(2) & !1;
    let settle = (revs - window) as f64 * t_rev;
    bdf.advance_to(&mut scene, settle)?;
    let names: Vec<String> = cfg.mounts.iter().map(|m| m.name.clone()).collect();
    let mut samples = vec![Vec::new(); names.len()];
    for k in 1..=window * spr {
        let t = settle + t_rev * k as f64 / spr as f64;
        bdf.advance_to(&mut scene, t)?;
        let out = scene
            .outputs(t, bdf.y())
            .map_err(|e| format!("outputs at t = {t}: {e:?}"))?;
        for (i, f) in out.mount_forces.iter().enumerate() {
            samples[i].push(f[2]);
        }
    }
    let cpu = start.elapsed().as_secs_f64();
    let st = bdf.stats();
    println!("engine on ground, {rpm} rpm, load {load}, {revs} revolutions ({window} analysed), rtol {rtol:e}");
    println!(
        "cpu {cpu:.3} s, steps {}, rhs {}, jacobians {}, factorizations {}, error-test fails {}, convergence fails {}",
        st.steps, st.rhs_evals, st.jac_evals, st.factorizations, st.err_test_fails, st.conv_fails
    );
    println!("\nvertical mount force (ground side) order amplitudes [N]:");
    print!("{:>14}", "order");
    for n in &names {
        print!("{n:>13}");
    }
    println!();
    for k in 0..=12 {
        let order = 0.5 * k as f64;
        print!("{order:>14.1}");
        for s in &samples {
            print!(
                "{:>13.2}",
                order_amplitude(s, spr, order).unwrap_or(f64::NAN)
            );
        }
        println!();
    }
    Ok(())
}
