//! What the periodic start costs: for scenes 1 and 2 at several speeds, the time of a static
//! start (model, static equilibrium), what the periodic initialisation adds to it (linearisation,
//! shooting iterations), and simulating 20 revolutions at the same speed (the old default settle),
//! with the iterations and the orbit's closure (error weights of the run's tolerance).
//!
//! `cargo run --release --example periodic_start -- [--scene N] [--rpm R,R,…] [--rtol R]`

use std::time::Instant;

use engine_mount_chassis::cosim::{Inputs, SceneKind, Settings, Simulation};

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().collect();
    let flag = |name: &str| {
        args.iter()
            .position(|a| a == name)
            .and_then(|i| args.get(i + 1))
            .cloned()
    };
    let scenes: Vec<i32> = match flag("--scene") {
        Some(s) => vec![s.parse().map_err(|_| format!("--scene {s}"))?],
        None => vec![1, 2],
    };
    let speeds: Vec<f64> = flag("--rpm")
        .unwrap_or_else(|| "900,1800,3000".into())
        .split(',')
        .map(|s| s.parse::<f64>().map_err(|_| format!("--rpm {s}")))
        .collect::<Result<_, _>>()?;
    let rtol: Option<f64> = flag("--rtol").map(|s| s.parse().unwrap_or(1e-5));
    println!(
        "{:>5} {:>6} {:>9} {:>11} {:>10} {:>15} {:>10} {:>9}",
        "scene",
        "rpm",
        "static s",
        "+periodic s",
        "20 revs s",
        "+periodic/20rev",
        "iterations",
        "closure"
    );
    for scene in scenes {
        for &rpm in &speeds {
            let base = Settings {
                scene: SceneKind::from_number(scene)?,
                rel_tol: rtol.unwrap_or(Settings::default().rel_tol),
                ..Settings::default()
            };

            let inputs = Inputs::steady(rpm);
            // Warm the reduction cache so neither timing includes the reduction.
            Simulation::new(&base, 0.0, &inputs)?;
            let clock = Instant::now();
            let mut settled = Simulation::new(&base, 0.0, &inputs)?;
            let static_s = clock.elapsed().as_secs_f64();
            let clock = Instant::now();
            let revs = 20.0;
            let end = revs * 60.0 / rpm;
            let steps = (end / 1e-3).ceil() as usize;
            for k in 1..=steps {
                settled
                    .advance_to((k as f64 * 1e-3).min(end))
                    .map_err(|e| e.to_string())?;
            }
            let settle_s = clock.elapsed().as_secs_f64();
            let periodic_settings = Settings {
                periodic_start: true,
                ..base.clone()
            };
            let clock = Instant::now();
            let sim = Simulation::new(&periodic_settings, 0.0, &inputs)?;
            let periodic_s = clock.elapsed().as_secs_f64();
            let note = sim
                .describe()
                .into_iter()
                .find(|l| l.starts_with("periodic start"))
                .unwrap_or_default();
            let iterations = note
                .split(" after ")
                .nth(1)
                .and_then(|s| s.split(' ').next())
                .unwrap_or("?")
                .to_string();
            let closure = note
                .split("closed to ")
                .nth(1)
                .and_then(|s| s.split(' ').next())
                .unwrap_or("?")
                .to_string();
            println!(
                "{scene:>5} {rpm:>6.0} {static_s:>9.3} {:>11.3} {settle_s:>10.3} {:>15.2} {iterations:>10} {closure:>9}",
                periodic_s - static_s,
                (periodic_s - static_s) / settle_s
            );
        }
    }
    Ok(())
}
