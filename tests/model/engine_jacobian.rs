//! The Jacobian of the engine on rigid ground agrees with a central finite difference of the full
//! nonlinear right-hand side.

use engine_mount_chassis::model::{CoupledModel, VehicleConfig};
use engine_mount_chassis::ode::OdeProblem;
use faer::Mat;

fn check(cfg: VehicleConfig) {
    let mut scene = CoupledModel::on_ground(&cfg).expect("scene");
    let mut y = scene.static_equilibrium(0.0).expect("equilibrium");
    scene
        .set_crank_speed(0.0, 2000.0 * std::f64::consts::PI / 30.0, 150.0)
        .expect("speed");
    scene.set_load_torque(0.0, 80.0, -20.0).expect("torque");
    scene.set_mount_scales(2, 1.4, 0.6).expect("scales");
    let n = scene.dim();
    let l = *scene.layout();
    // A state away from equilibrium: displaced, rotating, crank at 37°.
    for (i, v) in y.iter_mut().enumerate().take(l.crank_angle()) {
        let scale = if i >= l.positions().end { 20.0 } else { 1.0 };
        *v += 1e-3 * (((i * 7919) % 13) as f64 / 13.0 - 0.4) * scale;
    }
    y[l.crank_angle()] = 37f64.to_radians();
    let t = 0.3;
    let mut j = Mat::<f64>::zeros(n, n);
    assert!(scene.jacobian(t, &y, j.as_mut()).expect("jacobian"));
    let mut fp = vec![0.0; n];
    let mut fm = vec![0.0; n];
    let scale = (0..n)
        .flat_map(|r| (0..n).map(move |c| (r, c)))
        .map(|(r, c)| j[(r, c)].abs())
        .fold(0.0, f64::max);
    for c in 0..n {
        let h = 1e-6;
        let mut yp = y.clone();
        yp[c] += h;
        let mut ym = y.clone();
        ym[c] -= h;
        scene.rhs(t, &yp, &mut fp).expect("rhs");
        scene.rhs(t, &ym, &mut fm).expect("rhs");
        for r in 0..n {
            let fd = (fp[r] - fm[r]) / (2.0 * h);
            let err = (fd - j[(r, c)]).abs();
            assert!(
                err < 1e-7 * scale + 1e-4 * fd.abs().max(1.0),
                "J[{r},{c}] = {} vs FD {fd}",
                j[(r, c)]
            );
        }
    }
}

#[test]
fn assembled_jacobian_matches_finite_differences_two_bodies() {
    let mut cfg = VehicleConfig::default();
    cfg.engine.gas.load = 1.0;
    // No preload: mounts sit in their progressive range, where the curves bend.
    for m in &mut cfg.mounts {
        m.preload = [0.0; 3];
    }
    check(cfg);
}

#[test]
fn assembled_jacobian_matches_finite_differences_rigid_powertrain_linear_mounts() {
    let mut cfg = VehicleConfig::default();
    cfg.effects.ring_carrier_elasticity = false;
    cfg.effects.mount_nonlinearity = false;
    let rot = nalgebra::Rotation3::from_euler_angles(0.1, 0.2, -0.3).into_inner();
    cfg.mounts[0].axes = [
        [rot[(0, 0)], rot[(0, 1)], rot[(0, 2)]],
        [rot[(1, 0)], rot[(1, 1)], rot[(1, 2)]],
        [rot[(2, 0)], rot[(2, 1)], rot[(2, 2)]],
    ];
    check(cfg);
}
