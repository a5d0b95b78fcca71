//! Inputs and outputs of the engine model as the FMI layer uses them.

use engine_mount_chassis::model::{CoupledModel, VehicleConfig};
use engine_mount_chassis::ode::{Bdf, BdfOptions, OdeProblem, Tolerance};

#[test]
fn bad_inputs_are_rejected_and_leave_the_inputs_unchanged() {
    let mut scene = CoupledModel::on_ground(&VehicleConfig::default()).expect("scene");
    let before = scene.inputs().clone();
    assert!(scene.set_crank_speed(0.0, f64::NAN, 0.0).is_err());
    assert!(scene.set_load_torque(0.0, 1.0, f64::INFINITY).is_err());
    assert!(scene.set_mount_scales(7, 1.0, 1.0).is_err());
    assert!(scene.set_mount_scales(0, -0.1, 1.0).is_err());
    assert!(scene.set_mount_scales(0, 1.0, -1.0).is_err());
    assert!(scene.set_mount_scales(0, f64::NAN, 1.0).is_err());
    assert_eq!(scene.inputs(), &before);
    // A stiffness scale of 0 (the mount switched off at run time) is allowed (issue 13).
    assert!(scene.set_mount_scales(0, 0.0, 1.0).is_ok());
}

#[test]
fn output_accelerations_match_the_integrated_velocity_derivative() {
    // The outputs solve M v' = f once; the integrator's interpolated derivative of v is an
    // independent estimate of the same quantity.
    let mut cfg = VehicleConfig::default();
    cfg.engine.gas.load = 0.5;
    cfg.engine.excitation_fade_in = 0.02;
    let mut scene = CoupledModel::on_ground(&cfg).expect("scene");
    // The speed set before the statics: the speed follower starts on it.
    scene
        .set_crank_speed(0.0, 1500.0 * std::f64::consts::PI / 30.0, 50.0)
        .expect("speed");
    let y0 = scene.static_equilibrium(0.0).expect("equilibrium");
    scene.set_load_torque(0.0, 20.0, 10.0).expect("torque");
    let opts = BdfOptions {
        rtol: 1e-8,
        atol: Tolerance::Scalar(1e-11),
        ..Default::default()
    };
    let mut bdf = Bdf::new(&mut scene, 0.0, &y0, opts).expect("bdf");
    let t = 0.1;
    bdf.advance_to(&mut scene, t).expect("integrate");
    let mut yd = vec![0.0; scene.dim()];
    bdf.interpolate(t, 1, &mut yd).expect("derivative");
    let out = scene.outputs(t, bdf.y()).expect("outputs");
    let nb = scene.layout().bodies();
    let acc = |b: usize| -> Vec<f64> {
        let m = if b == 0 { &out.monoblock } else { &out.housing };
        m.acceleration
            .iter()
            .chain(m.angular_acceleration.iter())
            .cloned()
            .collect()
    };
    for b in 0..nb {
        let a = acc(b);
        let scale = a.iter().fold(0.0f64, |s, v| s.max(v.abs()));
        for i in 0..6 {
            let d = yd[scene.layout().v(b).start + i];
            assert!(
                (d - a[i]).abs() < 1e-3 * scale,
                "body {b} component {i}: output {} vs integrator {d}",
                a[i]
            );
        }
    }
    // The crank spins at the ramped speed in inertial space; relative to the block it lags by
    // the block's roll (small angles: the Cardan angle about y).
    let w0 = 1500.0 * std::f64::consts::PI / 30.0;
    let roll = out.monoblock.rotation[1] - y0[4];
    let expected = w0 * t + 0.5 * 50.0 * t * t - roll;
    assert!(
        roll.abs() > 1e-4,
        "the block should roll under the gas and load torque"
    );
    assert!(
        (out.crank_angle - expected).abs() < 1e-2 * roll.abs(),
        "{} vs {expected}",
        out.crank_angle
    );
    assert_eq!(out.mount_forces.len(), 4);
}

#[test]
fn switched_off_effects_remove_states_and_terms() {
    // 12 states per powertrain body, the crank angle, and the speed follower's two.
    let mut cfg = VehicleConfig::default();
    assert_eq!(CoupledModel::on_ground(&cfg).expect("scene").dim(), 25 + 2);
    cfg.effects.ring_carrier_elasticity = false;
    assert_eq!(CoupledModel::on_ground(&cfg).expect("scene").dim(), 13 + 2);
    // Gas, mass forces and gyroscopic terms off, crank turning: nothing excites the engine.
    cfg.effects.gas_forces = false;
    cfg.effects.mass_forces = false;
    cfg.effects.gyroscopic = false;
    let mut scene = CoupledModel::on_ground(&cfg).expect("scene");
    let y0 = scene.static_equilibrium(0.0).expect("equilibrium");
    scene.set_crank_speed(0.0, 300.0, 0.0).expect("speed");
    let mut f = vec![0.0; scene.dim()];
    scene.rhs(0.05, &y0, &mut f).expect("rhs");
    let generalised = scene.evaluate(0.05, &y0).dynamics[0].force;
    assert!(
        generalised.iter().all(|v| v.abs() < 1e-6),
        "{generalised:?}"
    );
}

#[test]
fn linearised_mounts_share_the_operating_point_but_not_the_large_motion() {
    // Mount nonlinearity off: same static state and tangent; under a large load torque the
    // progressive curves carry it with less deflection than the tangent would.
    let base = VehicleConfig::default();
    let mut lin = base.clone();
    lin.effects.mount_nonlinearity = false;
    let mut a = CoupledModel::on_ground(&base).expect("scene");
    let mut b = CoupledModel::on_ground(&lin).expect("scene");
    let ya = a.static_equilibrium(0.0).expect("eq");
    let yb = b.static_equilibrium(0.0).expect("eq");
    for (x, y) in ya.iter().zip(&yb) {
        assert!((x - y).abs() < 1e-12);
    }
    let torque = 400.0;
    for s in [&mut a, &mut b] {
        s.set_load_torque(0.0, torque, 0.0).expect("torque");
    }
    // The housing's generalised moment about y (its rolling coordinate is state 10).
    let moment = |s: &CoupledModel, y: &[f64]| s.evaluate(0.0, y).dynamics[1].force[4];
    // Same small rotation of the housing: identical restoring moments (tangent), but a larger
    // rotation bends the progressive curve.
    let mut small = ya.clone();
    small[10] += 1e-4;
    let (fa, fb) = (moment(&a, &small), moment(&b, &small));
    assert!((fa - fb).abs() < 1e-3 * fa.abs().max(1.0));
    let mut large = ya.clone();
    large[10] += 0.03;
    let (fa, fb) = (moment(&a, &large), moment(&b, &large));
    assert!(fa < fb - 100.0, "progressive {fa} vs linear {fb}");
}

#[test]
fn gas_load_can_change_at_run_time() {
    let mut cfg = VehicleConfig::default();
    cfg.engine.gas.load = 1.0;
    let full = CoupledModel::on_ground(&cfg).expect("scene");
    cfg.engine.gas.load = 0.0;
    let mut scene = CoupledModel::on_ground(&cfg).expect("scene");
    let tdc = 8f64.to_radians();
    let pressure = |s: &CoupledModel| s.powertrain().cylinder_pressure(0, tdc).expect("gas");
    let idle_p = pressure(&scene);
    scene.set_gas_load(1.0).expect("load");
    let p = pressure(&scene);
    assert_eq!(p, pressure(&full));
    assert!(p > 1.5 * idle_p);
    assert!(scene.set_gas_load(1.2).is_err());
}
