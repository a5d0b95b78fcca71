//! The natural modes as calculated parameters (`modes.count`, `mode[k].frequency`, `.damping`,
//! `.powertrainShare`): the coupled frequencies a Campbell diagram needs, from the FMU alone.
//! Truth: the analytic frequencies of the decoupled rigid mount layout and the paper's Table 1.

use crate::common::*;
use engine_mount_chassis::fmi2::variables::{boolean, integer, real, string};
use engine_mount_chassis::paper::{TABLE1_RIGID, TABLE1_RING_CARRIER};

const TWO_PI: f64 = 2.0 * std::f64::consts::PI;

fn read_modes(s: &Slave<'_>) -> (i32, Vec<f64>, Vec<f64>, Vec<f64>) {
    let (status, count) = s.get_integer(&[integer::MODES_COUNT]);
    assert_eq!(status, OK, "{:?}", s.logs());
    let n = real::MODE_FREQUENCY.len();
    let frequency = s.reals(&real::MODE_FREQUENCY);
    let damping = s.reals(&real::MODE_DAMPING);
    let share = s.reals(&real::MODE_POWERTRAIN_SHARE);
    assert_eq!(frequency.len(), n);
    (count[0], frequency, damping, share)
}

#[test]
fn rigid_powertrain_modes_match_the_decoupled_analytic_frequencies() {
    // With rigid ring carriers the default layout decouples: f = sqrt(k/m)/2pi per direction
    // with the summed mount rates (4 mounts: 51.5, 36.6, 48.3 kN/m in x, y, z) and the
    // powertrain's effective inertias about the mount plane.
    let fmu = Fmu::load();
    let s = fmu.instantiate("modes-rigid");
    assert_eq!(s.set_integer(&[integer::SCENE], &[1]), OK);
    assert_eq!(s.set_boolean(&[boolean::EFFECT_RING_CARRIER], &[false]), OK);
    s.initialize();
    let (count, f, zeta, share) = read_modes(&s);
    assert_eq!(count, 6, "{f:?}");
    let (kx, ky, kz): (f64, f64, f64) = (4.0 * 51_500.0, 4.0 * 36_600.0, 4.0 * 48_300.0);
    let analytic = [
        (ky / 180.0).sqrt() / TWO_PI,
        (kz / 180.0).sqrt() / TWO_PI,
        (kx / 180.0).sqrt() / TWO_PI,
        (kz * 0.16 / 6.8).sqrt() / TWO_PI,
        (kz * 0.09 / 3.1).sqrt() / TWO_PI,
        ((kx * 0.16 + ky * 0.09) / 6.9).sqrt() / TWO_PI,
    ];
    for (k, want) in analytic.iter().enumerate() {
        assert!(
            (f[k] / want - 1.0).abs() < 0.005,
            "mode {k}: {} vs {want}",
            f[k]
        );
        assert!(
            zeta[k] > 0.0 && zeta[k] < 0.5,
            "mode {k}: damping {}",
            zeta[k]
        );
        assert!(
            (share[k] - 1.0).abs() < 1e-9,
            "mode {k}: share {}",
            share[k]
        );
    }
    assert!(f[6..].iter().chain(&zeta[6..]).all(|x| *x == 0.0));
}

#[test]
fn ground_modes_are_the_papers_table_1_and_stay_fixed_while_the_engine_runs() {
    let fmu = Fmu::load();
    let s = fmu.instantiate("modes-ground");
    assert_eq!(s.set_integer(&[integer::SCENE], &[1]), OK);
    s.setup(0.0, None);
    s.enter_init();
    // Readable in initialisation mode (FMI 2.0: calculated parameters are initial unknowns).
    let (count, f, _, _) = read_modes(&s);
    assert_eq!(count, 12, "{f:?}");
    for (k, (want, name)) in TABLE1_RIGID.iter().chain(&TABLE1_RING_CARRIER).enumerate() {
        assert!(
            (f[k] / want - 1.0).abs() < 0.05,
            "{name}: {} vs paper {want}",
            f[k]
        );
    }
    assert_eq!(s.exit_init(), OK);
    for k in 0..20 {
        assert_eq!(s.do_step(k as f64 * 1e-3, 1e-3), OK);
    }
    assert_eq!(
        read_modes(&s).1,
        f,
        "the modes are a property of the model, not of the run"
    );

    // After a reset with other parameters they are recomputed, never stale.
    assert_eq!(s.reset(), OK);
    assert_eq!(s.set_integer(&[integer::SCENE], &[1]), OK);
    assert_eq!(s.set_boolean(&[boolean::EFFECT_RING_CARRIER], &[false]), OK);
    s.initialize();
    assert_eq!(read_modes(&s).0, 6);
}

#[test]
fn a_stiffer_mount_set_raises_the_rigid_frequencies_by_the_square_root() {
    // Scaling every mount's stiffness by 4 at the start scales each rigid-body frequency by 2
    // (the decoupled layout, the mounts' linear range).
    let fmu = Fmu::load();
    let frequencies = |scale: f64| {
        let s = fmu.instantiate("modes-scaled");
        assert_eq!(s.set_integer(&[integer::SCENE], &[1]), OK);
        assert_eq!(s.set_boolean(&[boolean::EFFECT_RING_CARRIER], &[false]), OK);
        let scales: Vec<u32> = real::MOUNT_STIFFNESS_SCALE.to_vec();
        assert_eq!(s.set_real(&scales, &[scale; 4]), OK);
        s.initialize();
        read_modes(&s).1
    };
    let (base, stiff) = (frequencies(1.0), frequencies(4.0));
    for k in 0..6 {
        assert!(
            (stiff[k] / base[k] - 2.0).abs() < 0.02,
            "mode {k}: {} -> {}",
            base[k],
            stiff[k]
        );
    }
}

#[test]
fn a_stiffer_front_plate_raises_the_steering_wheel_modes_in_the_elastic_body() {
    // Paper §7.1: "the eigenfrequencies of the steering wheel were increased by a stiffer
    // integration of the front plate which supports the steering column". The steering-wheel
    // pair is the pair of body modes near 31.5 / 32 Hz (the procedural body's tuning targets).
    let fmu = Fmu::load();
    let body_modes = |plate: bool| {
        let s = fmu.instantiate("modes-plate");
        assert_eq!(s.set_integer(&[integer::SCENE], &[2]), OK);
        assert_eq!(
            s.set_boolean(&[boolean::CHASSIS_STIFF_FRONT_PLATE], &[plate]),
            OK
        );
        s.initialize();
        let (count, f, _, share) = read_modes(&s);
        (0..count as usize)
            .filter(|&k| share[k] < 0.1)
            .map(|k| f[k])
            .collect::<Vec<f64>>()
    };
    let (base, plate) = (body_modes(false), body_modes(true));
    let near = |modes: &[f64], target: f64| {
        modes
            .iter()
            .copied()
            .min_by(|a, b| (a - target).abs().total_cmp(&(b - target).abs()))
            .unwrap()
    };
    let (v, l) = (near(&base, 31.5), near(&base, 32.0));
    assert!((v - 31.5).abs() < 1.0 && (l - 32.0).abs() < 1.0, "{base:?}");
    // Each mode of the pair moves up (this body: by about 1 %; the column's own bending
    // dominates the pair, the plate only its clamping).
    let (pv, pl) = (near(&plate, v * 1.01), near(&plate, l * 1.01));
    assert!(
        pv > v * 1.005 && pl > l * 1.005,
        "steering wheel {v:.2} / {l:.2} Hz -> {pv:.2} / {pl:.2} Hz"
    );
}

#[test]
fn the_chassis_cutoff_in_use_is_read_from_the_parameters_without_building_a_model() {
    // Truth: the rule the parameters' descriptions state, 2500 rpm / 60 × order 4.5 × 1.2 =
    // 225 Hz by default; an explicit chassis.modeCutoff is used as given. A configuration file
    // that does not exist would fail any model build: the read must not need one.
    let fmu = Fmu::load();
    let cases: [(&[(u32, f64)], f64); 3] = [
        (&[], 225.0),
        (
            &[
                (real::SCENE_MAX_RPM, 4000.0),
                (real::SCENE_MAX_ENGINE_ORDER, 3.0),
            ],
            240.0,
        ),
        (&[(real::CHASSIS_MODE_CUTOFF, 400.0)], 400.0),
    ];
    for (k, (parameters, want)) in cases.iter().enumerate() {
        let s = fmu.instantiate(&format!("cutoff-{k}"));
        assert_eq!(s.set_integer(&[integer::SCENE], &[2]), OK);
        assert_eq!(
            s.set_string(&[string::CONFIG_FILE], &["/nonexistent/vehicle.json"]),
            OK
        );
        for (index, value) in parameters.iter() {
            assert_eq!(s.set_real(&[*index], &[*value]), OK);
        }
        s.setup(0.0, None);
        assert_eq!(s.enter_init(), OK);
        let (status, cutoff) = s.get_real(&[real::CHASSIS_MODE_CUTOFF_IN_USE]);
        assert_eq!(status, OK, "{:?}", s.logs());
        assert!(
            (cutoff[0] - want).abs() < 1e-9,
            "case {k}: {} Hz",
            cutoff[0]
        );
    }
}

#[test]
fn static_mount_deflections_carry_the_load_torque_as_the_mount_rates_say() {
    // Truth: at the design position the preloads carry the weight, so without a load torque the
    // static deflections are zero; a load torque T about the crank axis (y) turns the powertrain
    // on the mounts, and for the small turn the static deflections answer like linear springs:
    // doubling every mount's stiffness halves them, and T and −T give deflections of opposite
    // sign and (nearly) equal size.
    let fmu = Fmu::load();
    let deflections = |torque: f64, scale: f64| -> Vec<f64> {
        let s = fmu.instantiate(&format!("static-{torque}-{scale}"));
        assert_eq!(s.set_integer(&[integer::SCENE], &[1]), OK);
        assert_eq!(s.set_real(&[real::LOAD_TORQUE], &[torque]), OK);
        for i in real::MOUNT_STIFFNESS_SCALE {
            assert_eq!(s.set_real(&[i], &[scale]), OK);
        }
        s.setup(0.0, None);
        assert_eq!(s.enter_init(), OK);
        let vrs: Vec<u32> = real::MOUNT_STATIC_DEFLECTION
            .iter()
            .flatten()
            .copied()
            .collect();
        let (status, d) = s.get_real(&vrs);
        assert_eq!(status, OK, "{:?}", s.logs());
        d
    };
    assert!(deflections(0.0, 1.0).iter().all(|d| d.abs() < 1e-6));
    let soft = deflections(50.0, 1.0);
    let stiff = deflections(50.0, 2.0);
    let reverse = deflections(-50.0, 1.0);
    let largest = soft.iter().fold(0.0_f64, |m, d| m.max(d.abs()));
    assert!(largest > 1e-4 && largest < 3e-3, "{soft:?}");
    for k in 0..soft.len() {
        if soft[k].abs() < 0.05 * largest {
            continue;
        }
        assert!(
            (stiff[k] / soft[k] - 0.5).abs() < 0.02,
            "{k}: {} vs {}",
            stiff[k],
            soft[k]
        );
        assert!(
            (reverse[k] / soft[k] + 1.0).abs() < 0.02,
            "{k}: {} vs {}",
            reverse[k],
            soft[k]
        );
    }
}
