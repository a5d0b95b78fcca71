//! Time-domain behaviour of the engine on ground, integrated with the BDF solver.

use engine_mount_chassis::model::orders::order_amplitude;
use engine_mount_chassis::model::{CoupledModel, VehicleConfig};
use engine_mount_chassis::ode::{Bdf, BdfOptions, Tolerance};

fn undamped_config() -> VehicleConfig {
    let mut cfg = VehicleConfig::default();
    cfg.effects.gas_forces = false;
    for rc in &mut cfg.engine.ring_carriers {
        rc.damping = [0.0; 6];
    }
    for m in &mut cfg.mounts {
        m.damping = [0.0; 3];
    }
    cfg
}

/// Largest relative energy change over 0.2 s of free vibration at tolerance `rtol`.
fn energy_drift(rtol: f64, rigid_ring_carriers: bool) -> f64 {
    let mut cfg = undamped_config();
    cfg.effects.ring_carrier_elasticity = !rigid_ring_carriers;
    let mut scene = CoupledModel::on_ground(&cfg).expect("scene");
    let y_eq = scene.static_equilibrium(0.0).expect("equilibrium");
    let e_eq = scene.energy(0.0, &y_eq).expect("energy");
    // Kick: housing displaced 2 mm / 10 mrad (against the monoblock when elastic), the
    // monoblock rotating; crank at rest, so the pistons move only with the block.
    let nb = scene.layout().bodies();
    let hb = 6 * (nb - 1);
    let mut y0 = y_eq.clone();
    y0[hb] += 0.002;
    y0[hb + 2] -= 0.0015;
    y0[hb + 4] += 0.01;
    y0[6 * nb + 3] += 0.05;
    y0[6 * nb + 1] -= 0.01;
    let e0 = scene.energy(0.0, &y0).expect("energy");
    let vibration = e0 - e_eq;
    assert!(vibration > 0.01, "vibration energy {vibration} J");
    let opts = BdfOptions {
        rtol,
        atol: Tolerance::Scalar(rtol * 1e-3),
        ..Default::default()
    };
    let mut bdf = Bdf::new(&mut scene, 0.0, &y0, opts).expect("bdf");
    let mut worst: f64 = 0.0;
    for k in 1..=20 {
        let t = 0.01 * k as f64;
        bdf.advance_to(&mut scene, t).expect("integrate");
        worst = worst.max((scene.energy(t, bdf.y()).expect("energy") - e0).abs() / vibration);
    }
    let moved: f64 = (0..6 * nb).map(|i| (bdf.y()[i] - y0[i]).abs()).sum();
    assert!(moved > 1e-4, "the state should oscillate");
    worst
}

#[test]
fn free_vibration_without_damping_keeps_the_energy() {
    // Gravity, preloaded nonlinear mounts, ring carriers, pistons moving with the block: the
    // model is conservative, so the only energy change is the integrator's numerical
    // dissipation, which shrinks with the tolerance.
    for rigid in [false, true] {
        let loose = energy_drift(1e-8, rigid);
        let tight = energy_drift(1e-10, rigid);
        assert!(loose < 1e-4, "rigid={rigid}: drift {loose} at rtol 1e-8");
        assert!(
            tight < 0.5 * loose + 1e-8,
            "rigid={rigid}: drift {tight} at 1e-10 vs {loose} at 1e-8"
        );
    }
}

/// Mount force samples over `revs` revolutions after `settle` seconds at `rpm`.
fn run(cfg: VehicleConfig, rpm: f64, settle: f64, revs: usize, spr: usize) -> Vec<[f64; 3]> {
    let mut scene = CoupledModel::on_ground(&cfg).expect("scene");
    let y0 = scene.static_equilibrium(0.0).expect("equilibrium");
    let w = rpm * std::f64::consts::PI / 30.0;
    scene.set_crank_speed(0.0, w, 0.0).expect("speed");
    let opts = BdfOptions {
        rtol: 1e-6,
        atol: Tolerance::Scalar(1e-9),
        ..Default::default()
    };
    let mut bdf = Bdf::new(&mut scene, 0.0, &y0, opts).expect("bdf");
    bdf.advance_to(&mut scene, settle).expect("settle");
    let dt = 2.0 * std::f64::consts::PI / w / spr as f64;
    let mut out = Vec::new();
    for k in 1..=revs * spr {
        let t = settle + dt * k as f64;
        bdf.advance_to(&mut scene, t).expect("integrate");
        let o = scene.outputs(t, bdf.y()).expect("outputs");
        out.push(o.mount_forces[0]);
    }
    out
}

#[test]
fn gas_forces_make_order_one_and_a_half_dominant_in_the_mount_forces() {
    // Fact 4 in the mount forces: full load, 2000 rpm, stationary window of 4 revolutions.
    let mut cfg = VehicleConfig::default();
    cfg.engine.gas.load = 1.0;
    cfg.engine.excitation_fade_in = 0.05;
    let spr = 90;
    let f = run(cfg, 2000.0, 0.6, 4, spr);
    let vertical: Vec<f64> = f.iter().map(|v| v[2]).collect();
    let amp = |o: f64| order_amplitude(&vertical, spr, o).expect("whole periods");
    let a15 = amp(1.5);
    for order in [0.5, 1.0, 2.0, 2.5, 3.0, 4.5] {
        assert!(
            amp(order) < a15,
            "order {order}: {} N vs 1.5 order {a15} N",
            amp(order)
        );
    }
    assert!(a15 > 1.0, "1.5 order {a15} N");
}
