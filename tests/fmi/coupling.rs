//! The coupling ports through the C ABI: scene 3's body-motion inputs and their direct
//! feedthrough, the body FMU served by the same library, directional derivatives against
//! central differences, and bad interface input.

use crate::common::*;
use engine_mount_chassis::fmi2::variables::{Causality, BODY_GUID, REALS};
use engine_mount_chassis::fmi2::{BODY_MODEL_DESCRIPTION_XML, MODEL_DESCRIPTION_XML};

/// An engine instance in scene 3 (engine on an external body), initialised, a few steps run.
fn scene_3<'a>(fmu: &'a Fmu, name: &str) -> Slave<'a> {
    let s = fmu.instantiate(name);
    let scene = [integer::SCENE];
    assert_eq!(s.setup(0.0, None), OK);
    assert_eq!(s.enter_init(), OK);
    assert_eq!(s.set_integer(&scene, &[3]), OK, "{:?}", s.logs());
    assert_eq!(s.exit_init(), OK, "{:?}", s.logs());
    for k in 0..20 {
        assert_eq!(s.do_step(k as f64 * 1e-3, 1e-3), OK, "{:?}", s.logs());
    }
    s
}

/// A body instance, initialised with the engine's weight on its mounts, a few steps run.
fn body<'a>(fmu: &'a Fmu, name: &str) -> Slave<'a> {
    let s = fmu
        .instantiate_with(name, BODY_GUID, Some(&resources_uri()))
        .expect("the library instantiates the body FMU");
    assert_eq!(s.setup(0.0, None), OK);
    assert_eq!(s.enter_init(), OK);
    let fz: Vec<u32> = real::BODY_MOUNT_F.iter().map(|m| m[2]).collect();
    assert_eq!(s.set_real(&fz, &[-600.0, -450.0, -400.0, -315.0]), OK);
    assert_eq!(s.exit_init(), OK, "{:?}", s.logs());
    for k in 0..20 {
        assert_eq!(s.do_step(k as f64 * 1e-3, 1e-3), OK, "{:?}", s.logs());
    }
    s
}

fn reals_of(c: Causality, fmus: u8) -> Vec<u32> {
    REALS
        .iter()
        .filter(|v| v.causality == c && v.fmus & fmus != 0)
        .map(|v| v.vr)
        .collect()
}

/// Per output value reference, the value references its `<Outputs>` entry lists as direct
/// dependencies.
fn declared(xml: &str) -> std::collections::BTreeMap<u32, Vec<u32>> {
    let mut vr_of_index = Vec::new();
    for line in xml.lines().filter(|l| l.contains("<ScalarVariable")) {
        let vr = line
            .split("valueReference=\"")
            .nth(1)
            .and_then(|r| r.split('"').next())
            .and_then(|v| v.parse::<u32>().ok())
            .expect("valueReference");
        vr_of_index.push(vr);
    }
    let section = xml
        .split("<Outputs>")
        .nth(1)
        .and_then(|r| r.split("</Outputs>").next())
        .expect("Outputs");
    let attr = |line: &str, key: &str| -> String {
        line.split(&format!("{key}=\""))
            .nth(1)
            .and_then(|r| r.split('"').next())
            .unwrap_or("")
            .to_owned()
    };
    section
        .lines()
        .filter(|l| l.contains("<Unknown"))
        .map(|l| {
            let index: usize = attr(l, "index").parse().unwrap();
            let deps = attr(l, "dependencies")
                .split_whitespace()
                .map(|d| vr_of_index[d.parse::<usize>().unwrap() - 1])
                .collect();
            (vr_of_index[index - 1], deps)
        })
        .collect()
}

/// Sets each input in turn (without a step) and checks that every output that moves declares
/// that input as a direct dependency; returns how many (input, output) pairs moved.
fn check_feedthrough(s: &Slave, xml: &str, fmus: u8, delta: impl Fn(u32) -> f64) -> usize {
    let outputs = reals_of(Causality::Output, fmus);
    let declared = declared(xml);
    let mut moved = 0;
    for input in reals_of(Causality::Input, fmus) {
        let start = s.reals(&[input])[0];
        let before = s.reals(&outputs);
        assert_eq!(
            s.set_real(&[input], &[start + delta(input)]),
            OK,
            "{:?}",
            s.logs()
        );
        let after = s.reals(&outputs);
        for (k, &out) in outputs.iter().enumerate() {
            if after[k] != before[k] {
                moved += 1;
                assert!(
                    declared[&out].contains(&input),
                    "output {} moved when input {} was set, but does not declare it",
                    REALS[out as usize].name,
                    REALS[input as usize].name
                );
            }
        }
        assert_eq!(s.set_real(&[input], &[start]), OK);
        assert_eq!(s.reals(&outputs), before, "setting {input} back");
    }
    moved
}

#[test]
fn scene_3_mount_forces_follow_the_body_motion_at_once_as_declared() {
    let fmu = Fmu::load();
    let s = scene_3(&fmu, "feedthrough3");
    let moved = check_feedthrough(&s, MODEL_DESCRIPTION_XML, 1, |vr| {
        if vr == real::RPM {
            300.0
        } else if vr == real::LOAD_TORQUE {
            50.0
        } else if real::MOUNT_BODY_R.iter().flatten().any(|&v| v == vr) {
            2e-4
        } else if real::MOUNT_BODY_V.iter().flatten().any(|&v| v == vr) {
            1e-2
        } else {
            -0.3
        }
    });
    // Each mount's force responds to each of its own attachment's components: not vacuous.
    let f = real::MOUNT_F;
    let before = s.reals(&f[1]);
    assert_eq!(s.set_real(&[real::MOUNT_BODY_R[1][2]], &[1e-4]), OK);
    let after = s.reals(&f[1]);
    // The body rising 0.1 mm into the mount compresses it: the mount pushes the body down
    // harder, by its vertical stiffness (tens of kN/m) times the displacement.
    assert!(
        after[2] - before[2] < -1.0,
        "force on the body as it rises into the mount: {before:?} -> {after:?}"
    );
    assert!(moved >= 12, "only {moved} input-output pairs moved");
}

#[test]
fn the_body_fmu_shares_the_library_and_its_accelerations_follow_the_forces_as_declared() {
    let fmu = Fmu::load();
    let s = body(&fmu, "body-feedthrough");
    // The engine's variables are not the body's.
    assert_eq!(s.set_real(&[real::RPM], &[1000.0]), ERROR);
    assert!(
        s.logs()
            .iter()
            .any(|l| l.contains("is not a variable of EngineMountBody")),
        "{:?}",
        s.logs()
    );
    let moved = check_feedthrough(&s, BODY_MODEL_DESCRIPTION_XML, 2, |_| 25.0);
    assert!(moved >= 12, "only {moved} input-output pairs moved");
    // Under the static forces the body has sunk; displacements and velocities do not respond
    // at once to a force, accelerations do.
    let r = s.reals(&[real::BODY_MOUNT_R[0][2]]);
    assert!(r[0] < -1e-4, "front-left mount point at {} m", r[0]);
    let watched = [
        real::BODY_MOUNT_R[0][2],
        real::BODY_MOUNT_V[0][2],
        real::BODY_MOUNT_A[0][2],
    ];
    let before = s.reals(&watched);
    assert_eq!(s.set_real(&[real::BODY_MOUNT_F[0][2]], &[-700.0]), OK);
    let after = s.reals(&watched);
    assert_eq!(after[..2], before[..2]);
    assert!(after[2] < before[2], "{before:?} -> {after:?}");
}

/// Central difference of `outputs` with respect to input `input` at its current value.
fn central(s: &Slave, outputs: &[u32], input: u32, h: f64) -> Vec<f64> {
    let x = s.reals(&[input])[0];
    assert_eq!(s.set_real(&[input], &[x + h]), OK);
    let plus = s.reals(outputs);
    assert_eq!(s.set_real(&[input], &[x - h]), OK);
    let minus = s.reals(outputs);
    assert_eq!(s.set_real(&[input], &[x]), OK);
    plus.iter()
        .zip(&minus)
        .map(|(p, m)| (p - m) / (2.0 * h))
        .collect()
}

fn assert_close(analytic: &[f64], difference: &[f64], scale: f64, what: &str) {
    for (a, d) in analytic.iter().zip(difference) {
        assert!(
            (a - d).abs() <= 1e-6 * scale,
            "{what}: directional derivative {a:e} vs central difference {d:e} (scale {scale:e})"
        );
    }
}

#[test]
fn directional_derivatives_match_central_differences() {
    let fmu = Fmu::load();
    let s = scene_3(&fmu, "derivatives3");
    // A displaced, moving body so that the mounts are off their operating point.
    let r: Vec<u32> = real::MOUNT_BODY_R.iter().flatten().copied().collect();
    let v: Vec<u32> = real::MOUNT_BODY_V.iter().flatten().copied().collect();
    let offsets: Vec<f64> = (0..12).map(|k| 1e-4 * ((k % 5) as f64 - 2.0)).collect();
    assert_eq!(s.set_real(&r, &offsets), OK);
    assert_eq!(
        s.set_real(&v, &offsets.iter().map(|x| 30.0 * x).collect::<Vec<_>>()),
        OK
    );
    let mut unknowns: Vec<u32> = real::MOUNT_F.iter().flatten().copied().collect();
    unknowns.extend(real::POWERTRAIN_A);
    unknowns.push(real::CRANK_ANGLE);
    for (inputs, h) in [(&r, 1e-7), (&v, 1e-6)] {
        for &input in inputs {
            let (status, analytic) = s.directional_derivative(&unknowns, &[input], &[1.0]);
            assert_eq!(status, OK, "{:?}", s.logs());
            let difference = central(&s, &unknowns, input, h);
            let scale = analytic.iter().fold(1.0f64, |m, x| m.max(x.abs()));
            assert_close(&analytic, &difference, scale, REALS[input as usize].name);
        }
    }
    // Linear in the seeds: two knowns at once are the sum.
    let (_, both) = s.directional_derivative(&unknowns, &[r[2], v[5]], &[2.0, -3.0]);
    let (_, a) = s.directional_derivative(&unknowns, &[r[2]], &[1.0]);
    let (_, b) = s.directional_derivative(&unknowns, &[v[5]], &[1.0]);
    for k in 0..unknowns.len() {
        let sum = 2.0 * a[k] - 3.0 * b[k];
        assert!((both[k] - sum).abs() <= 1e-9 * sum.abs().max(1.0));
    }

    let b = body(&fmu, "derivatives-body");
    let forces: Vec<u32> = real::BODY_MOUNT_F.iter().flatten().copied().collect();
    let mut unknowns: Vec<u32> = real::BODY_MOUNT_A.iter().flatten().copied().collect();
    unknowns.extend(real::STEERING_WHEEL_A);
    unknowns.extend(real::SEAT_A);
    unknowns.extend(real::BODY_MOUNT_R.iter().flatten());
    for &input in &forces {
        let (status, analytic) = b.directional_derivative(&unknowns, &[input], &[1.0]);
        assert_eq!(status, OK, "{:?}", b.logs());
        let difference = central(&b, &unknowns, input, 1.0);
        let scale = analytic.iter().fold(1e-6f64, |m, x| m.max(x.abs()));
        assert_close(&analytic, &difference, scale, REALS[input as usize].name);
    }
    // Only outputs with respect to inputs.
    let (status, _) = b.directional_derivative(&[real::BODY_MOUNT_F[0][0]], &[forces[0]], &[1.0]);
    assert_eq!(status, ERROR);
}

#[test]
fn bad_body_motion_is_refused_naming_the_mount_and_changes_nothing() {
    let fmu = Fmu::load();
    let s = scene_3(&fmu, "bad-body-motion");
    let watched: Vec<u32> = real::MOUNT_F.iter().flatten().copied().collect();
    let before = s.reals(&watched);
    assert_eq!(s.set_real(&[real::MOUNT_BODY_V[2][0]], &[f64::NAN]), ERROR);
    assert!(
        s.logs()
            .iter()
            .any(|l| l.contains("mount[3].body.v[1]") && l.contains("NaN")),
        "{:?}",
        s.logs()
    );
    // 5 cm up into a mount: beyond any engine mount's characteristic.
    assert_eq!(s.set_real(&[real::MOUNT_BODY_R[0][2]], &[0.05]), ERROR);
    assert!(
        s.logs()
            .iter()
            .any(|l| l.contains("external body") && l.contains("mount 1 ")),
        "{:?}",
        s.logs()
    );
    assert_eq!(s.reals(&[real::MOUNT_BODY_R[0][2]]), [0.0]);
    assert_eq!(s.reals(&watched), before);
    assert_eq!(s.do_step(0.02, 1e-3), OK, "{:?}", s.logs());
    assert!(s.reals(&watched).iter().all(|x| x.is_finite()));
}

/// The trial of the coupling ports: a force far beyond any a mount carries (1e300 N gave outputs
/// near 1e297 with fmi2OK) is refused naming the input, its derivative too, and nothing changes.
/// The bound is 100 times the powertrain's weight: 100 × 180 kg × 9.81 m/s² = 176.6 kN for the
/// built-in vehicle (at least 100 times the largest static mount force, which is a share of it).
#[test]
fn body_forces_beyond_the_plausible_bound_are_refused_naming_the_input() {
    let fmu = Fmu::load();
    let s = body(&fmu, "body-force-bound");
    let watched = reals_of(Causality::Output, 2);
    let before = s.reals(&watched);
    let input = [real::BODY_MOUNT_F[1][2]];
    for f in [1e300, -1e300, 1.8e5] {
        assert_eq!(s.set_real(&input, &[f]), ERROR, "{f}");
        assert!(
            s.logs()
                .iter()
                .any(|l| l.contains("mount[2].F[3]") && l.contains("plausible bound")),
            "{f}: {:?}",
            s.logs()
        );
    }
    assert_eq!(s.set_input_derivatives(&input, &[1e300]), ERROR);
    assert!(
        s.logs()
            .iter()
            .any(|l| l.contains("mount[2].F[3]") && l.contains("N/s")),
        "{:?}",
        s.logs()
    );
    assert_eq!(s.reals(&watched), before);
    // A bump stop's 10 kN is a force a mount carries.
    assert_eq!(s.set_real(&input, &[-1e4]), OK, "{:?}", s.logs());
    assert_eq!(s.do_step(0.02, 1e-3), OK, "{:?}", s.logs());
    assert!(s.reals(&watched).iter().all(|x| x.is_finite()));
}

/// Inputs are checked when they are set; a step checks only the signals that continue a ramp
/// nobody set, which reach values nobody checked: a force ramp crossing the plausible bound
/// (176.6 kN) between steps is refused at the step that would start beyond it, naming the input,
/// and nothing changes.
#[test]
fn a_force_ramp_continued_past_the_bound_is_refused_at_the_step() {
    let fmu = Fmu::load();
    let s = body(&fmu, "continued-force");
    let input = [real::BODY_MOUNT_F[1][2]];
    // 1.76e5 N is within the bound, and 1e6 N/s (1 kN per ms) within the bound's rate.
    assert_eq!(s.set_real(&input, &[1.76e5]), OK, "{:?}", s.logs());
    assert_eq!(
        s.set_input_derivatives(&input, &[1e6]),
        OK,
        "{:?}",
        s.logs()
    );
    assert_eq!(s.do_step(0.02, 1e-3), OK, "{:?}", s.logs());
    let reached = s.reals(&input)[0];
    assert!((reached - 1.77e5).abs() < 1e-6, "{reached}");
    let watched = reals_of(Causality::Output, 2);
    let before = s.reals(&watched);
    assert_eq!(s.do_step(0.021, 1e-3), ERROR);
    assert!(
        s.logs()
            .iter()
            .any(|l| l.contains("mount[2].F[3] = 177000") && l.contains("plausible bound")),
        "{:?}",
        s.logs()
    );
    assert_eq!(s.reals(&watched), before);
    assert_eq!(s.reals(&input), [reached]);
    // A value set brings the signal back; the run goes on from where it was.
    assert_eq!(s.set_real(&input, &[-1e4]), OK);
    assert_eq!(s.set_input_derivatives(&input, &[0.0]), OK);
    assert_eq!(s.do_step(0.021, 1e-3), OK, "{:?}", s.logs());
}

/// The trial: a derivative of 1e300 m/s on a body-point input failed the next step with "Newton
/// convergence failures"; it is refused when set, naming the input, as is any speed beyond
/// what a point of a car body does (100 m/s) and any acceleration beyond 1e4 m/s².
#[test]
fn a_huge_derivative_of_a_body_point_input_is_refused_naming_the_input() {
    let fmu = Fmu::load();
    let s = scene_3(&fmu, "huge-body-derivative");
    let watched: Vec<u32> = real::MOUNT_F.iter().flatten().copied().collect();
    let before = s.reals(&watched);
    for (input, rate, name) in [
        (real::MOUNT_BODY_R[0][2], 1e300, "mount[1].body.r[3]"),
        (real::MOUNT_BODY_R[3][0], 1e6, "mount[4].body.r[1]"),
        (real::MOUNT_BODY_V[1][1], 1e300, "mount[2].body.v[2]"),
    ] {
        assert_eq!(s.set_input_derivatives(&[input], &[rate]), ERROR, "{name}");
        assert!(
            s.logs()
                .iter()
                .any(|l| l.contains(name) && l.contains("a point of a car body")),
            "{name}: {:?}",
            s.logs()
        );
    }
    assert_eq!(s.set_real(&[real::MOUNT_BODY_V[2][2]], &[1e3]), ERROR);
    assert_eq!(s.reals(&watched), before);
    assert_eq!(s.do_step(0.02, 1e-3), OK, "{:?}", s.logs());
}

/// The trial: body-point inputs set in scenes without an external body were accepted and
/// ignored (an SSP whose scene binding was lost ran uncoupled with no sign). They are answered
/// with a warning, once per instance: at the end of initialisation if set before, else when set.
#[test]
fn body_point_inputs_outside_scene_3_are_answered_with_a_warning_once() {
    let fmu = Fmu::load();
    let warned = |s: &Slave| {
        s.logs()
            .iter()
            .filter(|l| l.contains("used in scene = 3 only"))
            .count()
    };
    let a = fmu.instantiate("unused-body-point-a");
    assert_eq!(a.setup(0.0, None), OK);
    assert_eq!(a.enter_init(), OK);
    assert_eq!(a.set_real(&[real::MOUNT_BODY_R[0][2]], &[1e-3]), OK);
    assert_eq!(a.exit_init(), WARNING, "{:?}", a.logs());
    assert!(
        a.logs()
            .iter()
            .any(|l| l.contains("mount[1].body.r[3]") && l.contains("scene = 1 ignores it")),
        "{:?}",
        a.logs()
    );
    assert_eq!(a.do_step(0.0, 1e-3), OK);
    assert_eq!(a.set_real(&[real::MOUNT_BODY_V[1][0]], &[0.1]), OK);
    assert_eq!(warned(&a), 1);

    let b = fmu.instantiate("unused-body-point-b");
    b.initialize();
    assert_eq!(b.do_step(0.0, 1e-3), OK);
    assert_eq!(b.set_real(&[real::RPM], &[900.0]), OK);
    assert_eq!(b.set_real(&[real::MOUNT_BODY_V[1][0]], &[0.1]), WARNING);
    assert_eq!(b.set_real(&[real::MOUNT_BODY_V[1][0]], &[0.2]), OK);
    assert_eq!(warned(&b), 1);
    // A body point at rest is what scene 1 assumes: a master feeding every input zeros there
    // (fmusim, the packaged reference experiments) is not warned, before or after initialisation.
    let d = fmu.instantiate("body-point-at-rest");
    assert_eq!(d.setup(0.0, None), OK);
    assert_eq!(d.enter_init(), OK);
    assert_eq!(d.set_real(&[real::MOUNT_BODY_R[0][2]], &[0.0]), OK);
    assert_eq!(d.exit_init(), OK, "{:?}", d.logs());
    assert_eq!(d.set_real(&[real::MOUNT_BODY_V[1][0]], &[0.0]), OK);
    assert_eq!(d.do_step(0.0, 1e-3), OK);
    assert_eq!(warned(&d), 0, "{:?}", d.logs());
    assert_eq!(d.set_real(&[real::MOUNT_BODY_V[1][0]], &[0.1]), WARNING);
    assert_eq!(warned(&d), 1);
    // In scene 3 they are the scene's inputs: no warning.
    let c = scene_3(&fmu, "used-body-point");
    assert_eq!(c.set_real(&[real::MOUNT_BODY_R[0][2]], &[1e-4]), OK);
    assert_eq!(warned(&c), 0);
}
