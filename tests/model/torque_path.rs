//! The torque path (issue 18): the engine's mean indicated torque goes to friction and through
//! the gearbox inside the powertrain, so on average the mounts carry only the drivetrain's
//! reaction — the load torque input — and nothing at idle in neutral.

use engine_mount_chassis::model::{CoupledModel, VehicleConfig};
use engine_mount_chassis::ode::{Bdf, BdfOptions};
use nalgebra::Vector3;
use std::f64::consts::PI;

/// Moment about the crank axis (y) of the mount forces on the ground, about the powertrain CG.
fn roll_moment(cfg: &VehicleConfig, forces: &[[f64; 3]]) -> f64 {
    let cg = Vector3::from(engine_mount_chassis::model::POWERTRAIN_CG);
    cfg.mounts
        .iter()
        .zip(forces)
        .map(|(m, f)| (Vector3::from(m.bracket) - cg).cross(&Vector3::from(*f)).y)
        .sum()
}

/// (static roll moment, mean roll moment over whole cycles after settling) at `rpm`, engine load
/// `load` (0 idle … 1 full) and drivetrain reaction `reaction` (N m).
fn moments(rpm: f64, load: f64, reaction: f64) -> (f64, f64, f64) {
    let mut cfg = VehicleConfig::default();
    cfg.engine.gas.load = load;
    let mut model = CoupledModel::on_ground(&cfg).expect("model");
    let w = rpm * PI / 30.0;
    model.set_crank_speed(0.0, w, 0.0).unwrap();
    model.set_load_torque(0.0, reaction, 0.0).unwrap();
    let y0 = model.static_equilibrium(0.0).expect("statics");
    let at_rest = roll_moment(&cfg, &model.outputs(0.0, &y0).unwrap().mount_forces);
    let mut bdf = Bdf::new(&mut model, 0.0, &y0, BdfOptions::default()).expect("bdf");
    let cycle = 4.0 * PI / w;
    let settle = (1.0 / cycle).ceil() * cycle;
    bdf.advance_to(&mut model, settle).unwrap();
    let samples = 4 * 360;
    let mut sum = 0.0;
    for k in 1..=samples {
        let t = settle + 4.0 * cycle * k as f64 / samples as f64;
        bdf.advance_to(&mut model, t).unwrap();
        sum += roll_moment(&cfg, &model.outputs(t, bdf.y()).unwrap().mount_forces);
    }
    (
        at_rest,
        sum / samples as f64,
        model.powertrain().mean_indicated_torque(),
    )
}

#[test]
fn at_idle_the_mounts_carry_no_mean_torque_and_under_load_the_drivetrain_reaction() {
    let (rest, idle, indicated) = moments(800.0, 0.0, 0.0);
    assert!(indicated > 20.0, "indicated torque at idle {indicated} N m");
    assert!(
        (idle - rest).abs() < 1.0,
        "idle: mean {idle} vs static {rest} N m"
    );
    let reaction = 150.0;
    let (rest_loaded, loaded, indicated) = moments(2000.0, 1.0, reaction);
    assert!(
        indicated > 150.0,
        "indicated torque at full load {indicated} N m"
    );
    assert!(
        (loaded - rest_loaded).abs() < 1.0,
        "under load: mean {loaded} vs static {rest_loaded} N m"
    );
    // and what the mounts carry beyond gravity is the reaction itself
    assert!(
        ((loaded - rest).abs() - reaction).abs() < 1.0,
        "{loaded} - {rest} vs {reaction} N m"
    );
}
