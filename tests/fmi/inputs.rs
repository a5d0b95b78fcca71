//! Input semantics through the C ABI (`src/fmi2/input_track.rs`): what a master's values and
//! derivatives mean between communication points, checked against the analytic crank angle.
//!
//! The crank follows the rpm set-point `s` critically damped with time constant τ and speed
//! feed-forward, `ω'' = (s − ω)/τ² + 2(ṡ − ω')/τ`, whose transfer function is
//! `(1 + 2τp)/(1 + τp)² = 1 − τ²p² + …`: after its transient, the crank angle is `∫ s dt` less
//! `τ²` times the change of the set-point's slope. Starting from a constant speed into a ramp of
//! slope `a`, the lag is `a τ²`. A jump `Δ` of the set-point (no derivative to go with it) is
//! followed through `1/(1 + τp)²` and lags `2τΔ` in angle.

use crate::common::*;
use engine_mount_chassis::fmi2::variables::{boolean, real};
use engine_mount_chassis::model::SpeedFollower;
use std::f64::consts::PI;

const RPM0: f64 = 800.0;
/// Ramp slope, rpm/s.
const SLOPE: f64 = 2000.0;
const H: f64 = 1e-3;
const STEPS: usize = 100;

/// Absolute crank angle (crank angle relative to the block plus the block's roll).
fn absolute_angle(s: &Slave) -> f64 {
    let out = s.reals(&[real::CRANK_ANGLE, real::POWERTRAIN_PHI[1]]);
    out[0] + out[1]
}

fn rigid_instance<'a>(fmu: &'a Fmu, name: &str) -> Slave<'a> {
    let s = fmu.instantiate(name);
    // one rigid powertrain, so its rotation is the monoblock's
    assert_eq!(s.set_boolean(&[boolean::EFFECT_RING_CARRIER], &[false]), OK);
    s.initialize();
    s
}

fn ramp(t: f64) -> f64 {
    RPM0 + SLOPE * t
}

/// `∫₀ᵀ ramp dt` in rad, less the follower's lag `a τ²` (rad).
fn expected_angle(t_end: f64) -> f64 {
    let tau = SpeedFollower::default().time_constant;
    (RPM0 * t_end + 0.5 * SLOPE * t_end * t_end) * PI / 30.0 - SLOPE * PI / 30.0 * tau * tau
}

#[test]
fn values_alone_of_a_ramp_are_extrapolated_after_two_held_steps() {
    let fmu = Fmu::load();
    let s = rigid_instance(&fmu, "values-only");
    for k in 0..STEPS {
        let t = k as f64 * H;
        assert_eq!(s.set_real(&[real::RPM], &[ramp(t)]), OK);
        assert_eq!(s.do_step(t, H), OK, "step {k}");
    }
    // The first two values cannot be told from a step: they are held for one step each, which
    // loses ∫ a t dt over each of them, a H² in all, and the set-point jumps by a H after each,
    // which the crank follows with a lag of 2τ a H each; from the third value on the ramp is
    // exact.
    let tau = SpeedFollower::default().time_constant;
    let a = SLOPE * PI / 30.0;
    let lost = a * H * H + 2.0 * (2.0 * tau * a * H);
    let expected = expected_angle(STEPS as f64 * H) - lost;
    let angle = absolute_angle(&s);
    assert!(
        (angle - expected).abs() < 1e-6 * expected,
        "{angle} vs {expected}"
    );
}

#[test]
fn a_derivative_given_once_continues_until_the_master_changes_it() {
    let fmu = Fmu::load();
    let once = rigid_instance(&fmu, "derivative-once");
    let every = rigid_instance(&fmu, "derivative-every-step");
    for k in 0..STEPS {
        let t = k as f64 * H;
        if k == 0 {
            assert_eq!(once.set_real(&[real::RPM], &[ramp(t)]), OK);
            assert_eq!(once.set_input_derivatives(&[real::RPM], &[SLOPE]), OK);
        }
        assert_eq!(every.set_real(&[real::RPM], &[ramp(t)]), OK);
        assert_eq!(every.set_input_derivatives(&[real::RPM], &[SLOPE]), OK);
        assert_eq!(once.do_step(t, H), OK);
        assert_eq!(every.do_step(t, H), OK);
    }
    let expected = expected_angle(STEPS as f64 * H);
    for s in [&once, &every] {
        let angle = absolute_angle(s);
        assert!(
            (angle - expected).abs() < 1e-6 * expected,
            "{angle} vs {expected}"
        );
    }
    // the input reads back as the value the ramp has reached
    let rpm = once.reals(&[real::RPM])[0];
    assert!((rpm - ramp(STEPS as f64 * H)).abs() < 1e-9, "{rpm}");
}

#[test]
fn the_order_of_value_and_derivative_calls_does_not_matter() {
    let fmu = Fmu::load();
    let a = rigid_instance(&fmu, "value-first");
    let b = rigid_instance(&fmu, "derivative-first");
    for k in 0..20 {
        let t = k as f64 * H;
        assert_eq!(a.set_real(&[real::RPM], &[ramp(t)]), OK);
        assert_eq!(a.set_input_derivatives(&[real::RPM], &[SLOPE]), OK);
        assert_eq!(b.set_input_derivatives(&[real::RPM], &[SLOPE]), OK);
        assert_eq!(b.set_real(&[real::RPM], &[ramp(t)]), OK);
        assert_eq!(a.do_step(t, H), OK);
        assert_eq!(b.do_step(t, H), OK);
    }
    let vrs: Vec<u32> = real::MOUNT_F.iter().flatten().copied().collect();
    assert_eq!(a.reals(&vrs), b.reals(&vrs));
    assert_eq!(absolute_angle(&a), absolute_angle(&b));
}

#[test]
fn a_ramp_past_the_declared_maximum_ends_on_it_with_a_warning() {
    let fmu = Fmu::load();
    let s = fmu.instantiate("past-max");
    assert_eq!(s.set_real(&[real::RPM], &[5990.0]), OK);
    s.initialize();
    assert_eq!(s.set_input_derivatives(&[real::RPM], &[1000.0]), OK);
    let status = s.do_step(0.0, 0.1);
    assert_eq!(status, fmi_sys::fmi2::fmi2Status_fmi2Warning);
    assert!(
        s.logs()
            .iter()
            .any(|l| l.contains("rpm") && l.contains("ends on 6000")),
        "{:?}",
        s.logs()
    );
    // the next step starts on the bound and stays there
    assert_eq!(s.do_step(0.1, 0.1), OK);
    assert!((s.reals(&[real::RPM])[0] - 6000.0).abs() < 1e-9);
}

#[test]
fn every_continuous_input_takes_derivatives_and_a_mount_scale_of_zero() {
    let fmu = Fmu::load();
    let s = fmu.instantiate("scales");
    s.initialize();
    let inputs = [
        real::LOAD_TORQUE,
        real::MOUNT_STIFFNESS_SCALE[0],
        real::MOUNT_DAMPING_SCALE[3],
    ];
    assert_eq!(s.set_input_derivatives(&inputs, &[10.0, -0.5, 0.5]), OK);
    assert_eq!(s.do_step(0.0, 0.1), OK, "{:?}", s.logs());
    let now = s.reals(&inputs);
    assert!((now[0] - 1.0).abs() < 1e-12, "{now:?}");
    assert!((now[1] - 0.95).abs() < 1e-12, "{now:?}");
    assert!((now[2] - 1.05).abs() < 1e-12, "{now:?}");
    assert_eq!(s.set_real(&[real::MOUNT_STIFFNESS_SCALE[1]], &[0.0]), OK);
    assert_eq!(s.do_step(0.1, 0.01), OK, "{:?}", s.logs());
    let f = s.reals(&real::MOUNT_F[1]);
    assert!(f.iter().all(|x| x.is_finite()), "{f:?}");
    assert_eq!(
        s.set_real(&[real::MOUNT_STIFFNESS_SCALE[1]], &[-0.1]),
        ERROR
    );
}
