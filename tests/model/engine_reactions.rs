//! Facts 1–5 of DESIGN §7 from the crank drive's reaction on a monoblock held on rigid ground,
//! order amplitudes by a DFT over whole cycles. The truth is the analytic order formulas of the
//! inline-3 crank drive; the model computes the reactions from the composite-body kinematics.

use crate::wrench_orders::{amp, sample, vamp, SPR};
use engine_mount_chassis::model::{Powertrain, VehicleConfig};

struct Setup {
    scene: Powertrain,
    m: f64,
    r: f64,
    a: f64,
    lambda: f64,
}

fn setup(gas: bool, mass: bool, balance: bool) -> Setup {
    let mut cfg = VehicleConfig::default();
    // The ideal crank drive of the analytic order formulas: no residual unbalance, identical
    // cylinders (both are checked on their own in tests/model/engine_imperfections.rs).
    cfg.engine.residual_unbalance.clear();
    cfg.engine.gas.cylinder_heat_spread.clear();
    cfg.effects.gas_forces = gas;
    cfg.effects.mass_forces = mass;
    cfg.effects.balance_shaft = balance;
    let c = &cfg.engine.crank_drive;
    let (m, r, a, lambda) = (
        c.oscillating_mass,
        c.crank_radius,
        c.cylinders[2].y_offset - c.cylinders[1].y_offset,
        c.crank_radius / c.conrod_length,
    );
    Setup {
        scene: Powertrain::new(cfg.engine, cfg.effects, cfg.gravity).expect("powertrain"),
        m,
        r,
        a,
        lambda,
    }
}

#[test]
fn fact1_free_forces_of_orders_1_2_4_vanish() {
    let s = setup(false, true, true);
    let w = 2000.0 * std::f64::consts::PI / 30.0;
    let x = sample(&s.scene, w, 1);
    let unit = s.m * s.r * w * w;
    for order in [1.0, 2.0, 4.0] {
        let f = vamp(&x, &[0, 1, 2], order);
        assert!(
            f < 1e-6 * unit,
            "order {order}: free force {f} N vs unit {unit}"
        );
    }
    // First non-zero free force: 6th order, 3 (9/128) λ⁵ m r ω² to leading order in λ.
    let f6 = vamp(&x, &[0, 1, 2], 6.0) / unit;
    let expect = 3.0 * 9.0 / 128.0 * s.lambda.powi(5);
    assert!(
        (f6 / expect - 1.0).abs() < 0.15,
        "6th order {f6} vs {expect}"
    );
}

#[test]
fn fact2_rocking_moments_without_balance_shaft() {
    let s = setup(false, true, false);
    let w1 = 1000.0 * std::f64::consts::PI / 30.0;
    let w2 = 2.5 * w1;
    let x1 = sample(&s.scene, w1, 1);
    let x2 = sample(&s.scene, w2, 1);
    let unit = s.m * s.r * w1 * w1 * s.a;
    let m1 = vamp(&x1, &[3, 5], 1.0);
    let m2 = vamp(&x1, &[3, 5], 2.0);
    // Exact: the 1st harmonic of the slider-crank acceleration is exactly r ω² cos ψ.
    assert!(
        (m1 / (3f64.sqrt() * unit) - 1.0).abs() < 1e-6,
        "1st order {m1} vs {}",
        3f64.sqrt() * unit
    );
    // 2nd order √3 λ m r ω² a (1 + λ²/4 + …).
    let expect2 = 3f64.sqrt() * s.lambda * (1.0 + s.lambda * s.lambda / 4.0) * unit;
    assert!(
        (m2 / expect2 - 1.0).abs() < 0.01,
        "2nd order {m2} vs {expect2}"
    );
    // Both scale with ω².
    let ratio = (w2 / w1).powi(2);
    assert!((vamp(&x2, &[3, 5], 1.0) / m1 / ratio - 1.0).abs() < 1e-9);
    assert!((vamp(&x2, &[3, 5], 2.0) / m2 / ratio - 1.0).abs() < 1e-9);
}

#[test]
fn fact3_balance_shaft_cancels_first_order_and_keeps_second() {
    let w = 2000.0 * std::f64::consts::PI / 30.0;
    let off = sample(&setup(false, true, false).scene, w, 1);
    let on = sample(&setup(false, true, true).scene, w, 1);
    let (m1_off, m1_on) = (vamp(&off, &[3, 4, 5], 1.0), vamp(&on, &[3, 4, 5], 1.0));
    assert!(
        m1_on < 0.01 * m1_off,
        "1st order with shaft {m1_on} vs without {m1_off}"
    );
    let (m2_off, m2_on) = (vamp(&off, &[3, 4, 5], 2.0), vamp(&on, &[3, 4, 5], 2.0));
    assert!(
        (m2_on / m2_off - 1.0).abs() < 0.01,
        "2nd order {m2_on} vs {m2_off}"
    );
    // The balancing parts are force-free.
    for order in [1.0, 2.0] {
        assert!(vamp(&on, &[0, 1, 2], order) < 1e-6 * m1_off);
    }
}

#[test]
fn fact4_gas_torque_has_only_multiples_of_order_one_and_a_half() {
    let s = setup(true, false, true);
    let w = 2000.0 * std::f64::consts::PI / 30.0;
    let x = sample(&s.scene, w, 2);
    let t15 = amp(&x, 4, 1.5);
    assert!(t15 > 10.0, "1.5 order gas torque {t15} N m");
    for order in [0.5, 1.0, 2.0, 2.5, 3.5, 4.0, 5.0] {
        let t = amp(&x, 4, order);
        assert!(t < 1e-6 * t15, "order {order}: {t} vs 1.5 order {t15}");
    }
    for order in [3.0, 4.5] {
        assert!(
            amp(&x, 4, order) > 1e-3 * t15,
            "order {order} should be present"
        );
    }
    // The 1.5 order dominates the alternating torque; the side-force pairs are force-free.
    for order in [3.0, 4.5, 6.0] {
        assert!(
            amp(&x, 4, order) < t15,
            "order {order} exceeds the 1.5 order"
        );
    }
    for order in [0.5, 1.0, 1.5, 3.0] {
        assert!(vamp(&x, &[0, 1, 2], order) < 1e-9 * t15);
        assert!(vamp(&x, &[3, 5], order) < 1e-9 * t15);
    }
    // Mean torque on the block equals minus the indicated mean torque: −(work per cycle)/(4π)
    // per cylinder, work from ∮ p dV (independent of the side-force construction).
    let c = &s.scene.config().crank_drive;
    let area = std::f64::consts::PI * 0.25 * c.bore * c.bore;
    let n = 4 * SPR;
    let mut work = 0.0;
    for k in 0..n {
        let phi0 = 4.0 * std::f64::consts::PI * k as f64 / n as f64;
        let phi1 = 4.0 * std::f64::consts::PI * (k + 1) as f64 / n as f64;
        let vol = |phi: f64| {
            let (sp, _, _) = engine_mount_chassis::model::powertrain::parts::slider_crank(
                phi,
                c.crank_radius,
                c.conrod_length,
            );
            -area * sp
        };
        let p = 0.5
            * (s.scene.cylinder_pressure(0, phi0).expect("gas")
                + s.scene.cylinder_pressure(0, phi1).expect("gas"));
        work += (p - s.scene.config().gas.crankcase_pressure) * (vol(phi1) - vol(phi0));
    }
    let mean_indicated = 3.0 * work / (4.0 * std::f64::consts::PI);
    assert!(mean_indicated > 0.0);
    // The powertrain's own work integral agrees with this one.
    let model = s.scene.mean_indicated_torque();
    assert!(
        (model / mean_indicated - 1.0).abs() < 0.01,
        "powertrain {model} vs indicated {mean_indicated}"
    );
    // The side-force couple takes −(indicated torque) on average; its mean leaves the crank
    // inside the powertrain (friction, gearbox), so the block carries none of it on average.
    let mean_block = x.iter().map(|v| v[4]).sum::<f64>() / x.len() as f64;
    assert!(
        mean_block.abs() < 1e-3 * mean_indicated,
        "block {mean_block} vs indicated {mean_indicated}"
    );
}

#[test]
fn fact5_third_order_mass_torque() {
    let s = setup(false, true, true);
    let w = 2000.0 * std::f64::consts::PI / 30.0;
    let x = sample(&s.scene, w, 1);
    let t3 = amp(&x, 4, 3.0);
    let expect = 9.0 / 4.0 * s.lambda * s.m * s.r * s.r * w * w;
    assert!(
        (t3 / expect - 1.0).abs() < 0.05,
        "3rd order mass torque {t3} vs {expect}"
    );
    // Orders 1 and 2 of the torque cancel between the cylinders.
    assert!(amp(&x, 4, 1.0) < 1e-6 * expect);
    assert!(amp(&x, 4, 2.0) < 1e-6 * expect);
}
