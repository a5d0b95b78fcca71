//! The coupling of powertrain and body, checked against independent truth on a body whose answer
//! is known in closed form: a rigid mass on translational springs (three modes, `φ = e_k / √M` at
//! every point).

use engine_mount_chassis::cms::{RecoveryPoint, ReducedChassis};
use engine_mount_chassis::model::{CoupledModel, VehicleConfig};
use engine_mount_chassis::ode::{
    Bdf, BdfOptions, BlockLowRankJacobian, BlockLowRankLu, OdeProblem, Tolerance,
};
use faer::Mat;
use nalgebra::{DMatrix, Matrix3};

const TWO_PI: f64 = 2.0 * std::f64::consts::PI;

/// A rigid chassis of mass `mass` on springs with natural frequencies `hz` along x, y, z, with
/// points at every active mount's bracket (named as its body node) plus a steering wheel and a
/// seat rail.
fn rigid_chassis(cfg: &VehicleConfig, mass: f64, hz: [f64; 3]) -> ReducedChassis {
    let shape: Vec<[f64; 6]> = (0..3)
        .map(|k| {
            let mut s = [0.0; 6];
            s[k] = 1.0 / mass.sqrt();
            s
        })
        .collect();
    let mut points: Vec<RecoveryPoint> = cfg
        .mounts
        .iter()
        .filter(|m| m.active)
        .enumerate()
        .map(|(i, m)| RecoveryPoint {
            name: m.body_node.clone().unwrap(),
            node: i,
            position: m.bracket,
            shape: shape.clone(),
        })
        .collect();
    for (name, position) in [
        ("steering_wheel", [-1.0, 0.37, 0.95]),
        ("seat_rail", [-1.4, 0.35, 0.25]),
    ] {
        points.push(RecoveryPoint {
            name: name.into(),
            node: points.len(),
            position,
            shape: shape.clone(),
        });
    }
    ReducedChassis {
        omega: hz.iter().map(|f| TWO_PI * f).collect(),
        zeta: vec![0.0; 3],
        points,
        cutoff_hz: None,
        own_damping: None,
    }
}

fn weight(cfg: &VehicleConfig, scene: &CoupledModel) -> f64 {
    assert!(cfg.gravity > 0.0);
    scene.powertrain_weight()
}

#[test]
fn static_equilibrium_rides_on_the_sinking_chassis() {
    let cfg = VehicleConfig::default();
    let mut ground = CoupledModel::on_ground(&cfg).unwrap();
    let y_ground = ground.static_equilibrium(0.0).unwrap();
    let (mass, hz) = (1000.0, [2.0, 2.5, 3.0]);
    let chassis = rigid_chassis(&cfg, mass, hz);
    let mut hybrid = CoupledModel::with_body(&cfg, chassis).unwrap();
    let y = hybrid.static_equilibrium(0.0).unwrap();
    let w = weight(&cfg, &hybrid);

    // The chassis carries the powertrain weight on its vertical spring: it sinks by W / k_z and
    // does not move sideways.
    let kz = mass * (TWO_PI * hz[2]).powi(2);
    let out = hybrid.outputs(0.0, &y).unwrap();
    let u = &out.point("steering_wheel").unwrap().displacement;
    assert!(
        (u[2] + w / kz).abs() < 1e-9 + 1e-7 * w / kz,
        "sink {} vs {}",
        u[2],
        -w / kz
    );
    assert!(u[0].abs() < 1e-9 && u[1].abs() < 1e-9, "{u:?}");

    // A uniformly translated support translates the engine's equilibrium by the same amount.
    let expected = [y_ground[0], y_ground[1], y_ground[2] - w / kz];
    for i in 0..3 {
        assert!(
            (y[i] - expected[i]).abs() < 1e-8,
            "engine translation {i}: {} vs {}",
            y[i],
            expected[i]
        );
    }
    for i in 3..6 {
        assert!((y[i] - y_ground[i]).abs() < 1e-7, "engine rotation {i}");
    }

    // Fact 6: the vertical mount forces carry the weight.
    let fz: f64 = out.mount_forces.iter().map(|f| f[2]).sum();
    assert!((fz + w).abs() < 1e-6 * w, "sum of Fz {fz} vs weight {w}");
    // At rest the chassis accelerates nowhere.
    for a in out
        .point("steering_wheel")
        .unwrap()
        .acceleration
        .iter()
        .chain(&out.point("seat_rail").unwrap().acceleration)
    {
        assert!(a.abs() < 1e-6, "{a}");
    }
}

/// Stiffness `−∂Q/∂q` and mass of the rigid powertrain on rigid ground at its equilibrium.
fn ground_linearisation(ground: &CoupledModel, y: &[f64]) -> (DMatrix<f64>, DMatrix<f64>) {
    let mut k = DMatrix::zeros(6, 6);
    for j in 0..6 {
        let h = 1e-7;
        let mut yp = y.to_vec();
        yp[j] += h;
        let mut ym = y.to_vec();
        ym[j] -= h;
        let fp = ground.evaluate(0.0, &yp).dynamics[0].force;
        let fm = ground.evaluate(0.0, &ym).dynamics[0].force;
        for i in 0..6 {
            k[(i, j)] = -(fp[i] - fm[i]) / (2.0 * h);
        }
    }
    let m = ground.evaluate(0.0, y).dynamics[0].mass;
    let mass = DMatrix::from_fn(6, 6, |i, j| m[(i, j)]);
    (k, mass)
}

#[test]
fn coupled_modes_match_an_independent_two_body_model() {
    // Rigid powertrain, no gas, undamped mounts: a conservative 9-DOF system.
    let mut cfg = VehicleConfig::default();
    cfg.effects.ring_carrier_elasticity = false;
    cfg.effects.gas_forces = false;
    let mut ground = CoupledModel::on_ground(&cfg).unwrap();
    for i in 0..cfg.mounts.len() {
        ground.set_mount_scales(i, 1.0, 0.0).unwrap();
    }
    let y_ground = ground.static_equilibrium(0.0).unwrap();
    let (k_e, m_e) = ground_linearisation(&ground, &y_ground);

    let (mass, hz) = (250.0, [1.5, 2.0, 2.5]);
    let chassis = rigid_chassis(&cfg, mass, hz);
    let mut hybrid = CoupledModel::with_body(&cfg, chassis).unwrap();
    for i in 0..cfg.mounts.len() {
        hybrid.set_mount_scales(i, 1.0, 0.0).unwrap();
    }
    let y = hybrid.static_equilibrium(0.0).unwrap();
    let modes = hybrid.modes(&y).unwrap();

    // Truth: M ẍ + K x = 0 for x = [engine q, chassis u]. The mounts depend on the bracket motion
    // relative to the support, so a support translation u acts like an engine translation −u.
    let mut kk = DMatrix::<f64>::zeros(9, 9);
    let mut mm = DMatrix::<f64>::zeros(9, 9);
    kk.view_mut((0, 0), (6, 6)).copy_from(&k_e);
    mm.view_mut((0, 0), (6, 6)).copy_from(&m_e);
    let k_et = k_e.columns(0, 3).into_owned(); // K_e T
    let k_te = k_e.rows(0, 3).into_owned(); // Tᵀ K_e
    kk.view_mut((0, 6), (6, 3)).copy_from(&(-&k_et));
    kk.view_mut((6, 0), (3, 6)).copy_from(&(-&k_te));
    let springs = Matrix3::from_diagonal(&nalgebra::Vector3::from_fn(|i, _| {
        mass * (TWO_PI * hz[i]).powi(2)
    }));
    let k_tet = k_e.view((0, 0), (3, 3)).into_owned();
    for i in 0..3 {
        for j in 0..3 {
            kk[(6 + i, 6 + j)] = springs[(i, j)] + k_tet[(i, j)];
        }
        mm[(6 + i, 6 + i)] = mass;
    }
    let a = mm.lu().solve(&kk).unwrap();
    let mut truth: Vec<f64> = a
        .complex_eigenvalues()
        .iter()
        .map(|l| l.re.max(0.0).sqrt() / TWO_PI)
        .collect();
    truth.sort_by(f64::total_cmp);

    let got: Vec<f64> = modes.iter().map(|m| m.frequency_hz).collect();
    assert_eq!(got.len(), 9, "coupled modes {got:?}, truth {truth:?}");
    for (g, t) in got.iter().zip(&truth) {
        assert!(
            (g - t).abs() < 5e-3 * t,
            "coupled {got:?} vs two-body {truth:?}"
        );
    }
    // The coupling matters: the chassis lowers or raises the engine frequencies measurably.
    let alone: Vec<f64> = ground
        .modes(&y_ground)
        .unwrap()
        .iter()
        .map(|m| m.frequency_hz)
        .collect();
    let engine_modes: Vec<f64> = got.iter().copied().filter(|f| *f > 3.0).collect();
    assert!(engine_modes
        .iter()
        .zip(&alone)
        .any(|(h, g)| (h - g).abs() > 0.05 * g));
}

/// The rigid test chassis with damping, at a moving state away from equilibrium, running.
fn moving_scene() -> (CoupledModel, Vec<f64>) {
    let cfg = VehicleConfig::default();
    let mut chassis = rigid_chassis(&cfg, 400.0, [3.0, 4.0, 5.0]);
    chassis.zeta = vec![0.05, 0.1, 0.2];
    let mut hybrid = CoupledModel::with_body(&cfg, chassis).unwrap();
    hybrid
        .set_crank_speed(0.0, 1500.0 * std::f64::consts::PI / 30.0, 0.0)
        .unwrap();
    let mut y = hybrid.static_equilibrium(0.0).unwrap();
    for (i, v) in y.iter_mut().enumerate() {
        *v += 1e-4 * ((i as f64) * 0.7).sin();
    }
    (hybrid, y)
}

#[test]
fn every_column_of_the_block_low_rank_jacobian_matches_finite_differences() {
    let (mut hybrid, y) = moving_scene();
    let n = hybrid.dim();
    let t = 0.2;
    // The dense matrix is the expansion blockdiag + U Vᵀ of the structured one.
    let mut j = Mat::<f64>::zeros(n, n);
    assert!(hybrid.jacobian(t, &y, j.as_mut()).unwrap());
    let (mut fp, mut fm) = (vec![0.0; n], vec![0.0; n]);
    for c in 0..n {
        let h = 1e-6 * y[c].abs().max(1.0);
        let mut yp = y.clone();
        yp[c] += h;
        let mut ym = y.clone();
        ym[c] -= h;
        hybrid.rhs(t, &yp, &mut fp).unwrap();
        hybrid.rhs(t, &ym, &mut fm).unwrap();
        let scale = (0..n).map(|r| j[(r, c)].abs()).fold(1.0, f64::max);
        // Engine columns are differences themselves (at another step): a looser bound.
        let tol = if c < hybrid.layout().eta().start {
            1e-4
        } else {
            1e-6
        };
        for r in 0..n {
            let fd = (fp[r] - fm[r]) / (2.0 * h);
            assert!(
                (fd - j[(r, c)]).abs() < tol * scale,
                "J[{r},{c}] = {} vs finite difference {fd}",
                j[(r, c)]
            );
        }
    }
}

#[test]
fn woodbury_newton_solve_equals_the_dense_lu_solve_on_the_coupled_jacobian() {
    let (hybrid, y) = moving_scene();
    let n = hybrid.dim();
    let mut structured = BlockLowRankJacobian::new(hybrid.jacobian_shape());
    hybrid.structured(0.2, &y, &mut structured).unwrap();
    let mut dense = Mat::<f64>::zeros(n, n);
    structured.to_dense(dense.as_mut());
    let b: Vec<f64> = (0..n).map(|i| ((i * 7) as f64).cos()).collect();
    for gamma in [1e-6, 1e-4, 1e-2] {
        let mut lu = BlockLowRankLu::new(structured.shape());
        assert!(lu.factor(&structured, gamma));
        let mut x = b.clone();
        lu.solve_in_place(&mut x);
        // Residual of the dense system (I − γ J) x = b.
        let worst = (0..n)
            .map(|r| {
                let ax: f64 = (0..n)
                    .map(|c| (if r == c { 1.0 } else { 0.0 } - gamma * dense[(r, c)]) * x[c])
                    .sum();
                (ax - b[r]).abs()
            })
            .fold(0.0, f64::max);
        assert!(worst < 1e-10, "residual {worst:e} at gamma {gamma}");
    }
}

#[test]
fn dense_and_block_low_rank_newton_integrate_the_same_motion() {
    let run = |dense: bool| {
        let (mut hybrid, y) = moving_scene();
        hybrid.set_dense_newton(dense);
        let opts = BdfOptions {
            rtol: 1e-8,
            atol: Tolerance::Scalar(1e-11),
            ..Default::default()
        };
        let mut bdf = Bdf::new(&mut hybrid, 0.0, &y, opts).unwrap();
        bdf.advance_to(&mut hybrid, 0.05).unwrap();
        (bdf.y().to_vec(), bdf.stats().factorizations)
    };
    let (dense, _) = run(true);
    let (structured, factorizations) = run(false);
    assert!(factorizations > 10);
    // The Newton matrix only steers convergence: the two runs differ by the integration error
    // (rtol 1e-8 over some 1000 steps), not by anything the linear solver does.
    for (i, (a, b)) in dense.iter().zip(&structured).enumerate() {
        assert!(
            (a - b).abs() < 1e-5 * a.abs().max(1e-3),
            "state {i}: dense {a} vs block-low-rank {b}"
        );
    }
}

#[test]
fn mounts_must_meet_their_body_nodes_and_removed_mounts_carry_nothing() {
    let cfg = VehicleConfig::default();
    let mut chassis = rigid_chassis(&cfg, 800.0, [2.0, 2.0, 2.0]);
    chassis.points[1].position[2] += 0.002;
    let err = CoupledModel::with_body(&cfg, chassis)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains(&format!("mount 2 ('{}')", cfg.mounts[1].name)) && err.contains("2.0 mm"),
        "{err}"
    );

    let full = VehicleConfig::default();
    let mut cfg = full.clone();
    cfg.mounts[3].active = false;
    let chassis = rigid_chassis(&full, 800.0, [2.0, 2.0, 2.0]);
    let mut hybrid = CoupledModel::with_body(&cfg, chassis).unwrap();
    assert!(hybrid.mounts()[3].is_none());
    let y = hybrid.static_equilibrium(0.0).unwrap();
    let out = hybrid.outputs(0.0, &y).unwrap();
    assert_eq!(out.mount_forces[3], [0.0; 3]);
    let fz: f64 = out.mount_forces.iter().map(|f| f[2]).sum();
    let w = hybrid.powertrain_weight();
    assert!((fz + w).abs() < 1e-6 * w);

    let mut bad = rigid_chassis(&full, 800.0, [2.0, 2.0, 2.0]);
    bad.points.retain(|p| p.name != "seat_rail");
    let err = CoupledModel::with_body(&full, bad).unwrap_err().to_string();
    assert!(err.contains("seat_rail"), "{err}");
    let mut bad = rigid_chassis(&full, 800.0, [2.0, 2.0, 2.0]);
    bad.zeta[1] = f64::NAN;
    let err = CoupledModel::with_body(&full, bad).unwrap_err().to_string();
    assert!(err.contains("body mode 1"), "{err}");
}

#[test]
fn comfort_accelerations_equal_the_derivative_of_the_integrated_velocity() {
    use engine_mount_chassis::ode::{Bdf, BdfOptions, Tolerance};
    let cfg = VehicleConfig::default();
    let mut chassis = rigid_chassis(&cfg, 300.0, [2.0, 3.0, 4.0]);
    chassis.zeta = vec![0.02; 3];
    // The steering wheel on a lever: it moves twice as much as the body vertically.
    let wheel = chassis
        .points
        .iter_mut()
        .find(|p| p.name == "steering_wheel")
        .unwrap();
    wheel.shape[2][2] *= 2.0;
    let mut hybrid = CoupledModel::with_body(&cfg, chassis).unwrap();
    hybrid
        .set_crank_speed(0.0, 1500.0 * std::f64::consts::PI / 30.0, 0.0)
        .unwrap();
    let y0 = hybrid.static_equilibrium(0.0).unwrap();
    let options = BdfOptions {
        rtol: 1e-10,
        atol: Tolerance::Scalar(1e-13),
        ..BdfOptions::default()
    };
    let mut bdf = Bdf::new(&mut hybrid, 0.0, &y0, options).unwrap();
    let point = |name: &str| {
        let o = hybrid.output_points().iter().find(|o| o.name == name);
        o.unwrap().point
    };
    let (wheel, seat) = (point("steering_wheel"), point("seat_rail"));
    let velocity = |h: &CoupledModel, y: &[f64], p: usize| {
        let rates = &y[h.layout().eta_rate()];
        h.point_translation(p, rates)
    };
    let (t0, dt) = (0.15, 2e-5);
    bdf.advance_to(&mut hybrid, t0 - dt).unwrap();
    let before = [wheel, seat].map(|p| velocity(&hybrid, bdf.y(), p));
    bdf.advance_to(&mut hybrid, t0).unwrap();
    let out = hybrid.outputs(t0, bdf.y()).unwrap();
    bdf.advance_to(&mut hybrid, t0 + dt).unwrap();
    let after = [wheel, seat].map(|p| velocity(&hybrid, bdf.y(), p));
    let wheel_a = out.point("steering_wheel").unwrap().acceleration;
    let seat_a = out.point("seat_rail").unwrap().acceleration;
    for (k, a) in [wheel_a, seat_a].iter().enumerate() {
        let fd = (after[k] - before[k]) / (2.0 * dt);
        let norm = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
        assert!(norm > 1e-3, "point {k} hardly moves: {a:?}");
        for i in 0..3 {
            assert!(
                (fd[i] - a[i]).abs() < 2e-3 * norm,
                "point {k} axis {i}: output {} vs d/dt of the integrated velocity {}",
                a[i],
                fd[i]
            );
        }
    }
    // The lever doubles the vertical acceleration.
    let ratio = wheel_a[2] / seat_a[2];
    assert!((ratio - 2.0).abs() < 1e-12, "{ratio}");
}

#[test]
fn a_heavy_stiff_chassis_runs_like_rigid_ground() {
    use engine_mount_chassis::ode::{Bdf, BdfOptions, Tolerance};
    let cfg = VehicleConfig::default();
    let w = 1500.0 * std::f64::consts::PI / 30.0;
    let options = BdfOptions {
        rtol: 1e-8,
        atol: Tolerance::Scalar(1e-11),
        ..BdfOptions::default()
    };
    let times: Vec<f64> = (1..=40).map(|k| 0.1 + k as f64 * 2.5e-3).collect();

    let mut ground = CoupledModel::on_ground(&cfg).unwrap();
    ground.set_crank_speed(0.0, w, 0.0).unwrap();
    let y0 = ground.static_equilibrium(0.0).unwrap();
    let mut bdf = Bdf::new(&mut ground, 0.0, &y0, options.clone()).unwrap();
    let mut reference = Vec::new();
    for &t in &times {
        bdf.advance_to(&mut ground, t).unwrap();
        reference.push(ground.outputs(t, bdf.y()).unwrap().mount_forces);
    }

    // 10⁷ kg on 20 Hz springs: it moves by ~10⁻⁸ m under the mount forces.
    let mut chassis = rigid_chassis(&cfg, 1e7, [20.0; 3]);
    chassis.zeta = vec![0.05; 3];
    let mut hybrid = CoupledModel::with_body(&cfg, chassis).unwrap();
    hybrid.set_crank_speed(0.0, w, 0.0).unwrap();
    let y0 = hybrid.static_equilibrium(0.0).unwrap();
    let mut bdf = Bdf::new(&mut hybrid, 0.0, &y0, options).unwrap();
    let mut scale: f64 = 0.0;
    let mut worst: f64 = 0.0;
    for (&t, r) in times.iter().zip(&reference) {
        bdf.advance_to(&mut hybrid, t).unwrap();
        let f = hybrid.outputs(t, bdf.y()).unwrap().mount_forces;
        for (a, b) in f.iter().zip(r) {
            for i in 0..3 {
                scale = scale.max(b[i].abs());
                worst = worst.max((a[i] - b[i]).abs());
            }
        }
    }
    assert!(scale > 100.0);
    assert!(
        worst < 1e-6 * scale,
        "largest mount-force difference {worst} N of {scale} N"
    );
}
