//! Tunes the chassis description to the paper's targets (body without engine on its suspension):
//! first global torsion, steering wheel vertical 31.5 Hz and lateral 32.07 Hz, 1000 kg.
//!
//! Torsion target 44.5 Hz: the paper reports 43 Hz for the body alone and 46.2 Hz with the engine
//! fitted; in our model the soft mounts barely move the torsion mode (+0.04 Hz), so one body
//! frequency has to serve both. 44.5 Hz lies inside both acceptance bands (43 Hz ± 5 %, and
//! 44–48 Hz coupled).
//!
//! `cargo run --release --example fe_tune [config.json]` prints the tuned parameters; copy them
//! into the defaults in `src/chassis/config.rs` or a JSON description. Fixed-point iteration:
//! each frequency scales with the square root of its own stiffness knob (body stiffness scale,
//! column iy, column iz); the floor trim absorbs the mass error.

use engine_mount_chassis::chassis::config::{ChassisConfig, SectionSpec};
use engine_mount_chassis::chassis::modal::{describe, steering_wheel_pair, ModeKind};
use engine_mount_chassis::chassis::Chassis;
use engine_mount_chassis::eigen::lowest_modes;
use engine_mount_chassis::fe::assembly::{assemble, translational_mass};

const TORSION: f64 = 44.5;
const WHEEL_VERTICAL: f64 = 31.5;
const WHEEL_LATERAL: f64 = 32.07;
const MASS: f64 = 1000.0;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut config = match std::env::args().nth(1) {
        Some(path) => ChassisConfig::from_json(&std::fs::read_to_string(path)?)?,
        None => ChassisConfig::default(),
    };
    for iteration in 0..12 {
        let chassis = Chassis::build(&config)?;
        let asm = assemble(&chassis.mesh)?;
        let mass = translational_mass(&asm, 2);
        let modes = lowest_modes(&asm.k, &asm.m, 30, -1.0)?;
        let descs = describe(&chassis.mesh, &asm, &modes)?;
        let torsion = descs
            .iter()
            .find(|d| d.kind == ModeKind::GlobalTorsion)
            .map(|d| d.frequency_hz);
        let (vertical, lateral) = match steering_wheel_pair(&descs) {
            Some((v, l)) => (Some(descs[v].frequency_hz), Some(descs[l].frequency_hz)),
            None => (None, None),
        };
        println!(
            "iteration {iteration}: mass {mass:.1} kg, torsion {torsion:?} Hz, wheel vertical \
             {vertical:?} Hz, lateral {lateral:?} Hz\n  with scale {:.4}, column {:?}",
            config.body_stiffness_scale, config.steering.column_section
        );
        let (Some(t), Some(v), Some(l)) = (torsion, vertical, lateral) else {
            return Err("a target mode was not identified".into());
        };
        // 1 %: the two steering-wheel modes veer apart (minimum gap ≈ 1.1 Hz through the body
        // coupling), so 31.5 / 32.07 Hz cannot both be met more closely.
        let done = (t / TORSION - 1.0).abs() < 0.01
            && (v / WHEEL_VERTICAL - 1.0).abs() < 0.01
            && (l / WHEEL_LATERAL - 1.0).abs() < 0.01
            && (mass / MASS - 1.0).abs() < 0.001;
        if done {
            break;
        }
        config.body_stiffness_scale *= (TORSION / t).powi(2);
        config.trim.floor += MASS - mass;
        if let SectionSpec::Explicit { iy, iz, .. } = &mut config.steering.column_section {
            *iy *= (WHEEL_VERTICAL / v).powi(2);
            *iz *= (WHEEL_LATERAL / l).powi(2);
        } else {
            return Err("steering.column_section must be explicit for tuning".into());
        }
    }
    println!("body_stiffness_scale = {:.4}", config.body_stiffness_scale);
    println!("trim.floor = {:.1}", config.trim.floor);
    println!(
        "steering.column_section = {:?}",
        config.steering.column_section
    );
    Ok(())
}
