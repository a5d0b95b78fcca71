//! The right-hand side allocates nothing: counted by this test binary's global allocator
//! (`main.rs`), per thread, so tests running alongside do not disturb the count.

use engine_mount_chassis::model::scene::{build, BodyOptions, SceneKind};
use engine_mount_chassis::model::{CoupledModel, VehicleConfig};
use engine_mount_chassis::ode::OdeProblem;

use crate::allocations_on_this_thread;

/// Allocations made by 50 right-hand sides of the running engine, after one warm-up call.
fn rhs_allocations(model: &mut CoupledModel) -> usize {
    model
        .set_crank_speed(0.0, 2000.0 * std::f64::consts::PI / 30.0, 0.0)
        .unwrap();
    let mut y = model.static_equilibrium(0.0).expect("statics");
    let mut f = vec![0.0; y.len()];
    model.rhs(0.5, &y, &mut f).unwrap();
    let before = allocations_on_this_thread();
    for k in 0..50 {
        let t = 0.5 + k as f64 * 1e-4;
        // A moving state: the crank turns and the body rocks, so every branch is taken.
        y[model.layout().crank_angle()] = 0.3 * k as f64;
        model.rhs(t, &y, &mut f).unwrap();
    }
    let count = allocations_on_this_thread() - before;
    assert!(f.iter().all(|x| x.is_finite()));
    count
}

#[test]
fn right_hand_side_does_not_allocate_on_ground() {
    let mut model = CoupledModel::on_ground(&VehicleConfig::default()).expect("model");
    assert_eq!(rhs_allocations(&mut model), 0);
}

#[test]
fn right_hand_side_does_not_allocate_in_the_elastic_body() {
    let vehicle = VehicleConfig::default();
    let mut model = build(&vehicle, SceneKind::Body, &BodyOptions::default())
        .expect("scene")
        .model;
    assert!(model.modes_count() > 50);
    assert_eq!(rhs_allocations(&mut model), 0);
}

#[test]
fn the_counter_sees_allocations() {
    let before = allocations_on_this_thread();
    let v: Vec<f64> = std::hint::black_box(vec![1.0; 100]);
    assert!(allocations_on_this_thread() > before);
    drop(v);
}
