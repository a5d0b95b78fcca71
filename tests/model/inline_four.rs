//! The paper's original engine (the M13 replaced an inline-4) from `resources/vehicle_i4.json`,
//! and with two Lanchester shafts from `resources/vehicle_i4_lanchester.json`: free mass forces
//! and moments per order against the analytic crank-drive series, and the firing orders of the gas
//! torque.
//!
//! Truth: a slider-crank piston's acceleration is `−r ω² (cos φ + A₂ cos 2φ − A₄ cos 4φ + …)` with
//! `A₂ = λ + λ³/4 + 15λ⁵/128 + …` and `A₄ = λ³/4 + 3λ⁵/16 + …`. For the 1-3-4-2 crank (throws 0°,
//! 180°, 180°, 0°) the 1st and 3rd orders cancel in force and, by the mirror symmetry of the
//! crank, in moment; the 2nd orders of the four cylinders add: `4 m r ω² A₂` along the bore
//! axis. Two shafts at ±2 ω with `m_e e = m r λ / 2` each cancel the `λ` term of it.

use crate::wrench_orders::{amp, sample, vamp};
use engine_mount_chassis::model::{Powertrain, VehicleConfig};
use std::f64::consts::PI;
use std::path::PathBuf;

fn powertrain(file: &str, gas: bool) -> (Powertrain, f64, f64, f64) {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("resources")
        .join(file);
    let mut cfg = VehicleConfig::from_file(&path).expect("configuration");
    // The ideal crank drive of the analytic order formulas: no residual unbalance, identical
    // cylinders (both are checked on their own in tests/model/engine_imperfections.rs).
    cfg.engine.residual_unbalance.clear();
    cfg.engine.gas.cylinder_heat_spread.clear();
    cfg.effects.gas_forces = gas;
    cfg.effects.mass_forces = !gas;
    let c = &cfg.engine.crank_drive;
    let (m, r, lambda) = (
        c.oscillating_mass,
        c.crank_radius,
        c.crank_radius / c.conrod_length,
    );
    let p = Powertrain::new(cfg.engine, cfg.effects, cfg.gravity).expect("powertrain");
    (p, m, r, lambda)
}

#[test]
fn first_and_third_orders_vanish_and_the_second_adds_up() {
    let (p, m, r, lambda) = powertrain("vehicle_i4.json", false);
    assert_eq!(p.config().crank_drive.cylinders.len(), 4);
    let w = 2000.0 * PI / 30.0;
    let x = sample(&p, w, 1);
    let unit = m * r * w * w;
    let moment_unit = unit * 0.1;
    for order in [1.0, 3.0] {
        let f = vamp(&x, &[0, 1, 2], order);
        let t = vamp(&x, &[3, 4, 5], order);
        assert!(f < 1e-9 * unit, "order {order}: free force {f} N");
        assert!(t < 1e-9 * moment_unit, "order {order}: free moment {t} N m");
    }
    // The crank drive is mirror-symmetric about its middle: no 2nd-order moment either.
    assert!(vamp(&x, &[3, 5], 2.0) < 1e-9 * moment_unit);
    let a2 = lambda + lambda.powi(3) / 4.0 + 15.0 * lambda.powi(5) / 128.0;
    let vertical = amp(&x, 2, 2.0);
    let expected = 4.0 * unit * a2;
    assert!(
        (vertical / expected - 1.0).abs() < 1e-3,
        "2nd order vertical {vertical} N vs 4 m r ω² A₂ = {expected} N"
    );
    assert!(amp(&x, 0, 2.0) < 1e-9 * unit, "no horizontal 2nd order");
    // and to leading order it is the textbook 4 m r ω² λ
    assert!((vertical / (4.0 * unit * lambda) - 1.0).abs() < 0.03);
}

#[test]
fn lanchester_shafts_remove_the_leading_second_order_force() {
    let (p, m, r, lambda) = powertrain("vehicle_i4_lanchester.json", false);
    assert_eq!(p.config().balance_shafts.len(), 2);
    let w = 2000.0 * PI / 30.0;
    let x = sample(&p, w, 1);
    let unit = m * r * w * w;
    // What is left of the 2nd order is its λ³ and λ⁵ terms.
    let rest = 4.0 * unit * (lambda.powi(3) / 4.0 + 15.0 * lambda.powi(5) / 128.0);
    let vertical = amp(&x, 2, 2.0);
    assert!(
        (vertical / rest - 1.0).abs() < 2e-2,
        "2nd order vertical {vertical} N vs the λ³ rest {rest} N"
    );
    let plain = sample(&powertrain("vehicle_i4.json", false).0, w, 1);
    let without = amp(&plain, 2, 2.0);
    assert!(
        vertical < 0.03 * without,
        "{vertical} vs {without} without the shafts"
    );
    // The counter-rotating pair leaves no horizontal force and, placed symmetrically about the
    // crank, no pitch or yaw moment; the 2nd-order roll (inertia torque of the crank drive) is
    // the same as without the shafts (shafts at the same height cannot take it).
    assert!(amp(&x, 0, 2.0) < 1e-9 * unit);
    assert!(vamp(&x, &[3, 5], 2.0) < 1e-9 * unit * 0.1);
    let (roll, roll_plain) = (amp(&x, 4, 2.0), amp(&plain, 4, 2.0));
    assert!(
        (roll / roll_plain - 1.0).abs() < 1e-9,
        "{roll} vs {roll_plain} N m"
    );
    for order in [1.0, 3.0] {
        assert!(vamp(&x, &[0, 1, 2], order) < 1e-9 * unit);
    }
}

#[test]
fn gas_torque_of_the_four_stroke_inline_four_is_of_orders_two_and_multiples() {
    let (p, _, _, _) = powertrain("vehicle_i4.json", true);
    let w = 2000.0 * PI / 30.0;
    let x = sample(&p, w, 2);
    let t2 = amp(&x, 4, 2.0);
    assert!(t2 > 10.0, "2nd order gas torque {t2} N m");
    for order in [0.5, 1.0, 1.5, 2.5, 3.0, 3.5] {
        let t = amp(&x, 4, order);
        assert!(t < 1e-6 * t2, "order {order}: {t} vs 2nd order {t2}");
    }
    assert!(amp(&x, 4, 4.0) > 1e-3 * t2, "4th order present");
}
