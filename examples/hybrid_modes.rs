//! Coupled modal analysis of the engine in the elastic chassis (paper Table 1, middle column),
//! against the engine on rigid ground (left column):
//! `cargo run --release --example hybrid_modes [--modes N | --cutoff HZ] [--bar]` (default: the
//! FMU's, fixed-interface modes below 200 Hz).
//! Chassis modes are named by the FE description of the uncoupled chassis mode that dominates
//! them; engine modes are matched to the ground modes by the direction of their engine motion.

use engine_mount_chassis::cms::reduce_detailed;
use engine_mount_chassis::model::scene::{reduction_spec, BodyOptions};
use engine_mount_chassis::model::{mode_table, CoupledModel, Direction, ModeKind, VehicleConfig};
use engine_mount_chassis::paper::TABLE1_HYBRID;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let value = |flag: &str| {
        args.iter()
            .position(|a| a == flag)
            .and_then(|i| args.get(i + 1))
            .cloned()
    };
    let max_modes: usize = value("--modes")
        .map(|n| n.parse())
        .transpose()?
        .unwrap_or(0);
    let cutoff: f64 = value("--cutoff")
        .map(|f| f.parse())
        .transpose()?
        .unwrap_or(200.0);
    let cfg = VehicleConfig::default();
    let options = BodyOptions {
        mode_cutoff_hz: cutoff,
        max_modes,
        stiffening_bar: args.iter().any(|a| a == "--bar"),
        ..BodyOptions::default()
    };
    let (spec, _) = reduction_spec(&cfg, &options)?;
    let started = std::time::Instant::now();
    let reduction = reduce_detailed(&spec)?;
    let labels = reduction.describe_modes()?;
    let chassis = reduction.reduced;
    println!(
        "chassis (Craig-Bampton, {:?}): {} modes, {:.2}..{:.2} Hz, reduced in {:.2} s",
        spec.selection,
        chassis.n_modes(),
        chassis.omega[0] / std::f64::consts::TAU,
        chassis.omega.last().copied().unwrap_or(0.0) / std::f64::consts::TAU,
        started.elapsed().as_secs_f64()
    );

    let mut ground = CoupledModel::on_ground(&cfg)?;
    let y_ground = ground.static_equilibrium(0.0)?;
    let alone = ground.modes(&y_ground)?;
    println!(
        "\nengine on rigid ground (Table 1 left column):\n{}",
        mode_table(&alone)
    );

    let mut hybrid = CoupledModel::with_body(&cfg, chassis)?;
    let started = std::time::Instant::now();
    let y = hybrid.static_equilibrium(0.0)?;
    let modes = hybrid.modes(&y)?;
    println!(
        "engine in the elastic chassis (statics + modes in {:.2} s):\n{}",
        started.elapsed().as_secs_f64(),
        mode_table(&modes)
    );
    println!("chassis-dominated coupled modes below 60 Hz, by their uncoupled FE mode:");
    for m in &modes {
        if let ModeKind::Body { mode, .. } = &m.kind {
            if m.frequency_hz < 60.0 {
                println!("  {:7.2} Hz  {}", m.frequency_hz, labels[*mode].summary());
            }
        }
    }
    let fz: f64 = hybrid
        .outputs(0.0, &y)
        .map_err(|e| format!("{e:?}"))?
        .mount_forces
        .iter()
        .map(|f| f[2])
        .sum();
    println!(
        "static: sum of vertical mount forces {:.1} N, powertrain weight {:.1} N",
        -fz,
        hybrid.powertrain_weight()
    );

    println!("\nengine modes, rigid ground -> elastic chassis:");
    println!("  kind                                       ground [Hz]  hybrid [Hz]  shift [%]");
    for g in &alone {
        let best = match &g.kind {
            // The coupled mode with the most powertrain kinetic energy in this direction.
            ModeKind::RigidBody(d) => {
                let i = [
                    Direction::Lateral,
                    Direction::Axial,
                    Direction::Vertical,
                    Direction::Pitch,
                    Direction::Roll,
                    Direction::Yaw,
                ]
                .iter()
                .position(|x| x == d)
                .unwrap_or(0);
                modes
                    .iter()
                    .filter(|h| !matches!(&h.kind, ModeKind::RingCarrier { .. }))
                    .max_by(|a, b| {
                        (a.powertrain_fraction * a.powertrain_directions[i])
                            .total_cmp(&(b.powertrain_fraction * b.powertrain_directions[i]))
                    })
            }
            ModeKind::Body { .. } => None,
            ModeKind::RingCarrier { direction, .. } => modes
                .iter()
                .filter(|h| {
                    matches!(&h.kind, ModeKind::RingCarrier { direction: e, .. } if e == direction)
                })
                .min_by(|a, b| {
                    (a.frequency_hz - g.frequency_hz)
                        .abs()
                        .total_cmp(&(b.frequency_hz - g.frequency_hz).abs())
                }),
        };
        let name = match &g.kind {
            ModeKind::RigidBody(d) => d.paper_name().to_string(),
            ModeKind::RingCarrier { bushing, direction } => {
                format!("ring carrier {bushing} {direction:?}")
            }
            ModeKind::Body { .. } => continue,
        };
        match best {
            Some(h) => println!(
                "  {name:<42} {:10.2}  {:11.2}  {:9.1}",
                g.frequency_hz,
                h.frequency_hz,
                100.0 * (h.frequency_hz / g.frequency_hz - 1.0)
            ),
            None => println!(
                "  {name:<42} {:10.2}  (no engine mode of this kind)",
                g.frequency_hz
            ),
        }
    }
    println!("\npaper Table 1 middle column: {TABLE1_HYBRID:?} Hz");
    Ok(())
}
