//! The two imperfections of a real engine (issue 18): residual unbalance after balancing and
//! cylinder-to-cylinder variation of the heat release, against their analytic consequences.

use crate::wrench_orders::{amp, sample};
use engine_mount_chassis::model::powertrain::config::ResidualUnbalance;
use engine_mount_chassis::model::powertrain::gas::GasModel;
use engine_mount_chassis::model::{Powertrain, VehicleConfig};
use std::f64::consts::PI;

/// The default vehicle with mass forces only and the given residual unbalances.
fn with_unbalance(unbalance: Vec<ResidualUnbalance>) -> (Powertrain, f64) {
    let mut cfg = VehicleConfig::default();
    cfg.effects.gas_forces = false;
    cfg.engine.residual_unbalance = unbalance;
    let crank_mass = cfg.engine.crank_drive.crank_mass;
    let p = Powertrain::new(cfg.engine, cfg.effects, cfg.gravity).expect("powertrain");
    (p, crank_mass)
}

#[test]
fn a_crank_unbalance_of_grade_g_adds_a_first_order_force_u_omega_squared() {
    let (ideal, _) = with_unbalance(Vec::new());
    let grade = 16.0;
    let service_rpm = 4500.0;
    let (unbalanced, crank_mass) = with_unbalance(vec![ResidualUnbalance {
        part: "crank".into(),
        grade_mm_per_s: grade,
        service_rpm,
        y: 0.0,
        phase_deg: 30.0,
    }]);
    // ISO 21940-11: e = G / Ω at the service speed, U = m e.
    let u = crank_mass * grade * 1e-3 / (service_rpm * PI / 30.0);
    for rpm in [1000.0, 2500.0] {
        let w = rpm * PI / 30.0;
        let a = sample(&ideal, w, 1);
        let b = sample(&unbalanced, w, 1);
        let diff: Vec<[f64; 6]> = a
            .iter()
            .zip(&b)
            .map(|(x, y)| std::array::from_fn(|i| y[i] - x[i]))
            .collect();
        // a rotating force of magnitude U ω² in the plane normal to the crank axis
        for comp in [0, 2] {
            let f = amp(&diff, comp, 1.0);
            assert!(
                (f / (u * w * w) - 1.0).abs() < 1e-9,
                "{rpm} rpm, component {comp}: {f} N vs U ω² = {} N",
                u * w * w
            );
        }
        assert!(amp(&diff, 1, 1.0) < 1e-9 * u * w * w);
        for order in [2.0, 3.0] {
            assert!(amp(&diff, 0, order) < 1e-9 * u * w * w);
        }
    }
}

#[test]
fn switching_the_balance_shaft_off_keeps_its_mass() {
    let cfg = VehicleConfig::default();
    let on = Powertrain::new(cfg.engine.clone(), cfg.effects, cfg.gravity).unwrap();
    let mut effects = cfg.effects;
    effects.balance_shaft = false;
    let off = Powertrain::new(cfg.engine, effects, cfg.gravity).unwrap();
    assert!(
        (on.mass() - off.mass()).abs() < 1e-12,
        "{} vs {}",
        on.mass(),
        off.mass()
    );
}

/// Default engine, gas forces only, with the given heat-release spread; `adiabatic` switches
/// the wall heat loss off, which makes the pressure exactly linear in the heat released.
fn with_spread(spread: Vec<f64>, adiabatic: bool) -> Powertrain {
    let mut cfg = VehicleConfig::default();
    cfg.effects.mass_forces = false;
    cfg.engine.gas.load = 1.0;
    cfg.engine.gas.cylinder_heat_spread = spread;
    if adiabatic {
        if let GasModel::Wiebe(w) = &mut cfg.engine.gas.model {
            w.wall_heat = None;
        }
    }
    Powertrain::new(cfg.engine, cfg.effects, cfg.gravity).expect("powertrain")
}

#[test]
fn a_heat_release_spread_brings_the_half_order_by_the_phasor_sum_of_the_spread() {
    for adiabatic in [true, false] {
        half_order_is_the_phasor_sum(adiabatic);
    }
}

/// Exact with adiabatic walls; with Woschni's wall loss (not linear in the pressure) the
/// superposition holds to first order in the spread.
fn half_order_is_the_phasor_sum(adiabatic: bool) {
    let tolerance = if adiabatic { 1e-6 } else { 2e-3 };
    let w = 2000.0 * PI / 30.0;
    let ideal = sample(&with_spread(Vec::new(), adiabatic), w, 2);
    let one = sample(&with_spread(vec![0.02, 0.0, 0.0], adiabatic), w, 2);
    let default = sample(&with_spread(vec![0.02, -0.01, -0.01], adiabatic), w, 2);
    // Identical cylinders firing 240° apart: the 0.5 order cancels (phasors 120° apart).
    let t15 = amp(&ideal, 4, 1.5);
    assert!(amp(&ideal, 4, 0.5) < 1e-9 * t15);
    // The torque is linear in each cylinder's heat: the 0.5 order of a spread δ is
    // |Σ δ_i e^{−i θ_i / 2}| times that of a unit change of one cylinder (θ_i its firing angle).
    let single = amp(&one, 4, 0.5) / 0.02;
    assert!(single > 0.0);
    let firing = [0.0_f64, 240.0, 480.0];
    let spread = [0.02, -0.01, -0.01];
    let (re, im) = firing
        .iter()
        .zip(spread)
        .fold((0.0, 0.0), |(re, im), (th, d)| {
            let a = -0.5 * th.to_radians();
            (re + d * a.cos(), im + d * a.sin())
        });
    let expected = re.hypot(im) * single;
    let got = amp(&default, 4, 0.5);
    assert!(
        (got / expected - 1.0).abs() < tolerance,
        "adiabatic {adiabatic}: 0.5 order {got} N m vs {expected} N m"
    );
    // The spread sums to zero: the mean torque is unchanged (to first order with wall loss).
    let mean = |x: &[[f64; 6]]| x.iter().map(|v| v[4]).sum::<f64>() / x.len() as f64;
    let tolerance = if adiabatic { 1e-9 } else { 1e-3 };
    assert!(
        (mean(&default) / mean(&ideal) - 1.0).abs() < tolerance,
        "adiabatic {adiabatic}: mean {} vs {}",
        mean(&default),
        mean(&ideal)
    );
}
