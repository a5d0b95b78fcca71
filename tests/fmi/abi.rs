//! The FMU's C ABI driven through the built library (dlopen), as a simulation tool drives it.

use crate::common;

use common::*;
use fmi_sys::fmi2::{fmi2StatusKind_fmi2LastSuccessfulTime, fmi2StatusKind_fmi2Terminated};

fn all_mount_forces() -> Vec<u32> {
    real::MOUNT_F.iter().flatten().copied().collect()
}

fn observed() -> Vec<u32> {
    let mut v = all_mount_forces();
    v.push(real::CRANK_ANGLE);
    v.extend(real::POWERTRAIN_R);
    v.extend(real::POWERTRAIN_PHI);
    v.extend(real::POWERTRAIN_A);
    v
}

fn assert_logged(slave: &Slave, needle: &str) {
    let logs = slave.logs();
    assert!(
        logs.iter().any(|l| l.contains(needle)),
        "no log line containing {needle:?} in {logs:#?}"
    );
}

#[test]
fn inquiry_functions_and_symbols() {
    let fmu = Fmu::load();
    // SAFETY: plain getters returning static C strings.
    unsafe {
        assert_eq!(
            std::ffi::CStr::from_ptr((fmu.f.fmi2GetVersion)())
                .to_str()
                .unwrap(),
            "2.0"
        );
        assert_eq!(
            std::ffi::CStr::from_ptr((fmu.f.fmi2GetTypesPlatform)())
                .to_str()
                .unwrap(),
            "default"
        );
    }
}

#[test]
fn wrong_guid_or_type_gives_null() {
    let fmu = Fmu::load();
    assert!(fmu
        .instantiate_with("wrong-guid", "{00000000-0000-0000-0000-000000000000}", None)
        .is_none());
    assert!(
        logs("wrong-guid").iter().any(|l| l.contains("GUID")),
        "{:?}",
        logs("wrong-guid")
    );
}

#[test]
fn resource_location_forms_are_accepted() {
    let fmu = Fmu::load();
    let dir = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("resources");
    let plain = dir.display().to_string();
    let encoded = plain
        .replace(' ', "%20")
        .replace('/', "%2F")
        .replacen("%2F", "/", 1);
    for (i, uri) in [
        format!("file://{plain}"),
        format!("file:{plain}"),
        format!("file://{encoded}"),
    ]
    .iter()
    .enumerate()
    {
        let name = format!("resources-{i}");
        let s = fmu
            .instantiate_with(&name, GUID, Some(uri))
            .expect("instantiate");
        s.initialize();
        assert!(
            !s.logs().iter().any(|l| l.contains("resource location")),
            "{uri}: {:?}",
            s.logs()
        );
    }
}

#[test]
fn illegal_call_sequences_are_errors_with_a_log_line() {
    let fmu = Fmu::load();
    let s = fmu.instantiate("illegal");
    assert_eq!(s.do_step(0.0, 1e-3), ERROR);
    assert_logged(&s, "fmi2DoStep is not allowed in phase Instantiated");
    assert_eq!(s.exit_init(), ERROR);
    assert_eq!(s.get_real(&[real::RPM]).0, ERROR);
    assert_eq!(s.terminate(), ERROR);
    s.initialize();
    assert_eq!(s.setup(0.0, None), ERROR);
    assert_eq!(s.enter_init(), ERROR);
    // fixed parameters cannot change once the model runs
    assert_eq!(s.set_real(&[real::SOLVER_REL_TOL], &[1e-3]), ERROR);
    assert_logged(&s, "cannot be set");
    // outputs can never be set
    assert_eq!(s.set_real(&[real::CRANK_ANGLE], &[1.0]), ERROR);
    // not provided: cancel; directional derivatives only of outputs with respect to inputs,
    // between steps
    // SAFETY: arguments are never dereferenced by this function on the error path.
    unsafe {
        assert_eq!((s.f().fmi2CancelStep)(s.c), ERROR);
    }
    let (status, _) =
        s.directional_derivative(&[real::CRANK_ANGLE], &[real::SOLVER_REL_TOL], &[1.0]);
    assert_eq!(status, ERROR);
    assert_logged(&s, "is not an input");
    assert_eq!(s.do_step(0.0, 1e-3), OK, "{:?}", s.logs());
    // a communication point that is not the FMU's time
    assert_eq!(s.do_step(0.5, 1e-3), ERROR);
    assert_logged(&s, "does not match the FMU time");
    assert_eq!(s.terminate(), OK);
    assert_eq!(s.do_step(1e-3, 1e-3), ERROR);
    // a null instance is refused, not dereferenced
    // SAFETY: null is explicitly handled by the FMU.
    unsafe {
        assert_eq!(
            (fmu.f.fmi2DoStep)(std::ptr::null_mut(), 0.0, 1e-3, 0),
            ERROR
        );
    }
}

#[test]
fn bad_values_are_rejected_and_leave_the_state_unchanged() {
    let fmu = Fmu::load();
    let s = fmu.instantiate("bad-values");
    s.initialize();
    assert_eq!(s.do_step(0.0, 1e-3), OK);
    let state = s.get_state();
    let before = s.serialize(state);
    let inputs = [real::RPM, real::MOUNT_STIFFNESS_SCALE[0]];
    let start = s.reals(&inputs);

    for (vr, value, needle) in [
        (real::RPM, f64::NAN, "not finite"),
        (real::LOAD_TORQUE, f64::INFINITY, "not finite"),
        (real::MOUNT_STIFFNESS_SCALE[0], -1.0, "stiffnessScale"),
        (real::MOUNT_DAMPING_SCALE[2], -0.1, "dampingScale"),
        (real::RPM, -5.0, "rpm"),
    ] {
        // a valid value in the same call must not be applied either
        assert_eq!(s.set_real(&[real::RPM, vr], &[1234.0, value]), ERROR);
        assert_logged(&s, needle);
    }
    assert_eq!(s.set_real(&[9999], &[1.0]), ERROR);
    assert_logged(&s, "unknown value reference 9999");
    assert_eq!(s.get_real(&[9999]).0, ERROR);
    assert_eq!(s.set_integer(&[9999], &[1]), ERROR);
    assert_eq!(s.set_boolean(&[9999], &[true]), ERROR);
    assert_eq!(s.set_input_derivatives(&[real::RPM], &[f64::NAN]), ERROR);
    assert_eq!(s.set_input_derivatives(&[real::CRANK_ANGLE], &[1.0]), ERROR);

    assert_eq!(s.reals(&inputs), start);
    let after_state = s.get_state();
    assert_eq!(
        s.serialize(after_state),
        before,
        "a rejected call changed the FMU state"
    );
    // and the instance still works
    assert_eq!(s.do_step(1e-3, 1e-3), OK, "{:?}", s.logs());
    s.free_state(state);
    s.free_state(after_state);
}

#[test]
fn static_equilibrium_carries_the_weight_at_the_start() {
    let fmu = Fmu::load();
    let s = fmu.instantiate("statics");
    assert_eq!(s.setup(0.0, None), OK);
    assert_eq!(s.enter_init(), OK);
    // outputs in initialisation mode are the static equilibrium's
    let f = s.reals(&all_mount_forces());
    let vertical: f64 = (0..4).map(|i| f[3 * i + 2]).sum();
    assert!(vertical < 0.0, "mounts push the ground down: {vertical}");
    assert_eq!(s.exit_init(), OK);
    let f2 = s.reals(&all_mount_forces());
    assert_eq!(f, f2);
}

/// Steps from `t0` through `steps`, recording the observed outputs after each step.
fn run_from(s: &Slave, t0: f64, steps: &[f64]) -> Vec<(f64, Vec<f64>)> {
    let mut t = t0;
    let mut out = Vec::new();
    for h in steps {
        assert_eq!(s.do_step(t, *h), OK, "{:?}", s.logs());
        t += h;
        out.push((t, s.reals(&observed())));
    }
    out
}

fn run(s: &Slave, steps: &[f64]) -> Vec<(f64, Vec<f64>)> {
    run_from(s, 0.0, steps)
}

#[test]
fn get_set_state_reproduces_the_run_bit_for_bit() {
    let fmu = Fmu::load();
    let s = fmu.instantiate("state");
    s.initialize();
    let steps = vec![1e-3; 50];
    let t1 = run(&s, &steps[..20]).last().unwrap().0;
    let state = s.get_state();
    let bytes = s.serialize(state);
    let first = run_from(&s, t1, &steps[20..]);
    assert_eq!(s.set_state(state), OK);
    // continuing from the restored state gives identical outputs, bit for bit
    let mut t = t1;
    for (t_ref, out_ref) in &first {
        assert_eq!(s.do_step(t, 1e-3), OK);
        t += 1e-3;
        assert_eq!(t, *t_ref);
        assert_eq!(&s.reals(&observed()), out_ref);
    }
    // serialize → deserialize → set: identical again
    let (st, restored) = s.deserialize(&bytes);
    assert_eq!(st, OK, "{:?}", s.logs());
    assert_eq!(s.serialize(restored), bytes);
    assert_eq!(s.set_state(restored), OK);
    let check = s.get_state();
    assert_eq!(s.serialize(check), bytes, "state after set differs");
    let mut t = t1;
    for (_, out_ref) in &first {
        assert_eq!(s.do_step(t, 1e-3), OK);
        t += 1e-3;
        assert_eq!(&s.reals(&observed()), out_ref);
    }
    // truncated, foreign or corrupted buffers are refused
    assert_eq!(s.deserialize(&bytes[..bytes.len() - 3]).0, ERROR);
    assert_eq!(s.deserialize(b"definitely not an FMU state").0, ERROR);
    let mut foreign = bytes.clone();
    foreign[12] ^= 0x55; // inside the GUID
    assert_eq!(s.deserialize(&foreign).0, ERROR);
    assert_logged(&s, "fmi2DeSerializeFMUstate");
    s.free_state(state);
    s.free_state(restored);
}

#[test]
fn reset_then_rerun_equals_a_fresh_instance() {
    let fmu = Fmu::load();
    let steps = vec![2e-3; 40];
    let a = fmu.instantiate("reset-a");
    a.initialize();
    assert_eq!(a.set_real(&[real::RPM], &[1500.0]), OK);
    run(&a, &steps);
    assert_eq!(a.reset(), OK);
    // start values are back (values are readable from initialisation mode on)
    assert_eq!(a.setup(0.0, None), OK);
    assert_eq!(a.enter_init(), OK);
    assert_eq!(a.reals(&[real::RPM]), vec![800.0]);
    assert_eq!(a.exit_init(), OK);
    let again = run(&a, &steps);
    let b = fmu.instantiate("reset-b");
    b.initialize();
    let fresh = run(&b, &steps);
    assert_eq!(again, fresh);
}

#[test]
fn instances_are_independent_also_on_two_threads() {
    let fmu = Fmu::load();
    let steps = vec![1e-3; 100];
    let reference = |name: &str, rpm: f64| {
        let s = fmu.instantiate(name);
        s.initialize();
        assert_eq!(s.set_real(&[real::RPM], &[rpm]), OK);
        run(&s, &steps)
    };
    let slow = reference("serial-slow", 900.0);
    let fast = reference("serial-fast", 2400.0);
    assert_ne!(slow, fast);
    let (a, b) = std::thread::scope(|scope| {
        let ha = scope.spawn(|| reference("thread-slow", 900.0));
        let hb = scope.spawn(|| reference("thread-fast", 2400.0));
        (ha.join().unwrap(), hb.join().unwrap())
    });
    assert_eq!(a, slow);
    assert_eq!(b, fast);
}

#[test]
fn communication_step_sizes_agree_at_common_points() {
    let fmu = Fmu::load();
    let end = 0.2;
    let by_step = |name: &str, steps: Vec<f64>| {
        let s = fmu.instantiate(name);
        s.initialize();
        let out = run(&s, &steps);
        let (t, v) = out.last().unwrap().clone();
        assert!((t - end).abs() < 1e-12, "{t}");
        v
    };
    let fine = by_step("comm-1ms", vec![1e-3; 200]);
    let coarse = by_step("comm-10ms", vec![1e-2; 20]);
    let mut irregular = Vec::new();
    let mut t = 0.0;
    let mut k = 0;
    while t < end - 1e-12 {
        let h: f64 = [3e-3, 7e-4, 1.3e-2, 2e-3][k % 4];
        let h = h.min(end - t);
        irregular.push(h);
        t += h;
        k += 1;
    }
    let odd = by_step("comm-irregular", irregular);
    let forces = all_mount_forces().len();
    for other in [&coarse, &odd] {
        for i in 0..forces {
            let scale = fine[..forces].iter().map(|x| x.abs()).fold(1.0, f64::max);
            assert!(
                (fine[i] - other[i]).abs() <= 1e-3 * scale,
                "mount force {i}: {} vs {}",
                fine[i],
                other[i]
            );
        }
    }
}

#[test]
fn status_functions_report_the_last_successful_time() {
    let fmu = Fmu::load();
    let s = fmu.instantiate("status");
    s.initialize();
    assert_eq!(s.do_step(0.0, 1e-2), OK);
    let (st, t) = s.real_status(fmi2StatusKind_fmi2LastSuccessfulTime);
    assert_eq!(st, OK);
    assert!((t - 1e-2).abs() < 1e-15);
    let (st, terminated) = s.boolean_status(fmi2StatusKind_fmi2Terminated);
    assert_eq!(st, OK);
    assert!(!terminated);
}

#[test]
fn input_derivatives_make_a_ramp_continuous() {
    let fmu = Fmu::load();
    let s = fmu.instantiate("ramp");
    // one rigid powertrain, so its rotation is the monoblock's
    assert_eq!(s.set_boolean(&[boolean::EFFECT_RING_CARRIER], &[false]), OK);
    s.initialize();
    // 800 → 1000 rpm over 0.1 s as a ramp given by derivatives: no input jump is logged
    let mut t = 0.0;
    for k in 0..10 {
        let rpm = 800.0 + 2000.0 * t;
        assert_eq!(s.set_real(&[real::RPM], &[rpm]), OK);
        assert_eq!(s.set_input_derivatives(&[real::RPM], &[2000.0]), OK);
        assert_eq!(s.do_step(t, 1e-2), OK, "step {k}: {:?}", s.logs());
        t += 1e-2;
    }
    assert!(
        !s.logs().iter().any(|l| l.contains("discontinuity")),
        "{:?}",
        s.logs()
    );
    // the input speed is absolute; the crank angle output is relative to the monoblock, so
    // angle + block rotation about the crank axis integrates the ramp: ∫ ω dt = 0.1 (800 + 100) rpm s,
    // less the lag of the crank that follows the set-point critically damped (time constant τ):
    // it starts with zero acceleration, so it falls behind by ∫ a t e^(−t/τ) dt = a τ² in angle.
    let out = s.reals(&[real::CRANK_ANGLE, real::POWERTRAIN_PHI[1]]);
    let absolute = out[0] + out[1];
    let tau = engine_mount_chassis::model::SpeedFollower::default().time_constant;
    let rate = 2000.0 * std::f64::consts::PI / 30.0;
    let expected = (800.0 * 0.1 + 1000.0 * 0.01) * std::f64::consts::PI / 30.0 - rate * tau * tau;
    assert!(
        (absolute - expected).abs() < 1e-6 * expected,
        "{absolute} vs {expected} (block {})",
        out[1]
    );
}

#[test]
fn parameters_strings_and_debug_logging() {
    let fmu = Fmu::load();
    let s = fmu.instantiate("params");
    assert_eq!(
        s.set_string(&[string::CONFIG_FILE], &["/nonexistent/engine.json"]),
        OK
    );
    assert_eq!(s.setup(0.0, None), OK);
    assert_eq!(s.enter_init(), OK);
    let (st, v) = s.get_string(&[string::CONFIG_FILE]);
    assert_eq!(st, OK);
    assert_eq!(v, vec!["/nonexistent/engine.json".to_owned()]);
    assert_eq!(s.exit_init(), ERROR);
    assert_logged(&s, "/nonexistent/engine.json");

    let s = fmu.instantiate("params-2");
    assert_eq!(s.set_integer(&[integer::SOLVER_MAX_ORDER], &[7]), ERROR);
    assert_eq!(s.set_integer(&[integer::SOLVER_MAX_ORDER], &[2]), OK);
    // A negative mode count is out of the declared range: rejected when set, naming the variable.
    assert_eq!(s.set_integer(&[integer::CHASSIS_MAX_MODES], &[-1]), ERROR);
    assert_logged(&s, "chassis.maxModes");
    assert_eq!(s.set_boolean(&[boolean::EFFECT_GAS_FORCES], &[false]), OK);
    let cats = [c"logEvents".as_ptr(), c"noSuchCategory".as_ptr()];
    // SAFETY: an array of two valid C strings.
    unsafe {
        assert_eq!((s.f().fmi2SetDebugLogging)(s.c, 1, 1, cats.as_ptr()), OK);
        assert_eq!((s.f().fmi2SetDebugLogging)(s.c, 1, 2, cats.as_ptr()), ERROR);
    }
    s.initialize();
    assert_logged(&s, "building scene");
    let (st, v) = s.get_integer(&[integer::SOLVER_MAX_ORDER]);
    assert_eq!((st, v[0]), (OK, 2));
    let (st, v) = s.get_boolean(&[boolean::EFFECT_GAS_FORCES]);
    assert_eq!((st, v[0]), (OK, false));
    assert_eq!(s.do_step(0.0, 1e-2), OK);
    let (st, n) = s.get_integer(&[integer::SOLVER_STEPS]);
    assert_eq!(st, OK);
    assert!(n[0] > 0);
}

#[test]
fn stop_time_is_respected_with_jitter() {
    let fmu = Fmu::load();
    let s = fmu.instantiate("stop");
    assert_eq!(s.setup(0.0, Some(0.03)), OK);
    assert_eq!(s.enter_init(), OK);
    assert_eq!(s.exit_init(), OK);
    let mut t = 0.0;
    for _ in 0..3 {
        assert_eq!(s.do_step(t, 0.01), OK);
        t += 0.01; // 0.030000000000000002 after three steps
    }
    assert_eq!(s.do_step(t, 0.01), ERROR);
    assert_logged(&s, "stop time");
}

#[test]
fn unsupported_functions_answer_with_an_error_not_a_crash() {
    let fmu = Fmu::load();
    let s = fmu.instantiate("unsupported");
    s.initialize();
    assert_eq!(s.do_step(0.0, 1e-3), OK);
    let vr = [real::MOUNT_F[0][2]];
    let order = [1];
    let mut value = [0.0];
    let mut status = 0;
    let mut int_value = 0;
    let mut text: *const std::ffi::c_char = std::ptr::null();
    // SAFETY: valid arrays of length 1 and writable out-parameters.
    unsafe {
        assert_eq!(
            (s.f().fmi2GetRealOutputDerivatives)(
                s.c,
                vr.as_ptr(),
                1,
                order.as_ptr(),
                value.as_mut_ptr()
            ),
            ERROR
        );
        assert_eq!((s.f().fmi2GetStatus)(s.c, 0, &mut status), ERROR);
        assert_eq!((s.f().fmi2GetIntegerStatus)(s.c, 0, &mut int_value), ERROR);
        assert_eq!((s.f().fmi2GetStringStatus)(s.c, 1, &mut text), ERROR);
    }
    assert_logged(&s, "maxOutputDerivativeOrder=0");
    assert_logged(&s, "canRunAsynchronuously=false");
    // the instance is still usable
    assert_eq!(s.do_step(1e-3, 1e-3), OK);
}

#[test]
fn model_exchange_is_refused() {
    let fmu = Fmu::load();
    let name = c"model-exchange";
    let guid = std::ffi::CString::new(GUID).unwrap();
    // SAFETY: valid C strings; null callbacks are allowed by this FMU (no logging).
    let c = unsafe {
        (fmu.f.fmi2Instantiate)(
            name.as_ptr(),
            fmi_sys::fmi2::fmi2Type_fmi2ModelExchange,
            guid.as_ptr(),
            std::ptr::null(),
            std::ptr::null(),
            0,
            0,
        )
    };
    assert!(c.is_null());
}

fn comfort_outputs() -> Vec<u32> {
    let mut v = observed();
    v.extend(real::STEERING_WHEEL_A);
    v.extend(real::SEAT_A);
    v
}

/// Turns on the logEvents category (set-up messages).
fn log_events(s: &Slave) {
    let cats = [c"logEvents".as_ptr()];
    // SAFETY: an array of one valid C string.
    unsafe {
        assert_eq!((s.f().fmi2SetDebugLogging)(s.c, 1, 1, cats.as_ptr()), OK);
    }
}

/// Scene 2 with the chassis cache in a directory of its own.
fn hybrid_slave<'a>(fmu: &'a Fmu, name: &str, cache: &std::path::Path) -> Slave<'a> {
    let s = fmu.instantiate(name);
    log_events(&s);
    assert_eq!(s.set_integer(&[integer::SCENE], &[2]), OK);
    assert_eq!(
        s.set_string(&[string::CHASSIS_CACHE_DIR], &[cache.to_str().unwrap()]),
        OK
    );
    assert_eq!(s.set_real(&[real::RPM], &[1500.0]), OK);
    s
}

#[test]
fn scene_2_runs_with_comfort_outputs_and_restores_bit_for_bit() {
    let cache = std::env::temp_dir().join(format!("emc-abi-hybrid-{}", std::process::id()));
    let fmu = Fmu::load();
    let s = hybrid_slave(&fmu, "hybrid", &cache);
    assert_eq!(s.setup(0.0, None), OK);
    assert_eq!(s.enter_init(), OK);
    let f = s.reals(&all_mount_forces());
    let vertical: f64 = (0..4).map(|i| f[3 * i + 2]).sum();
    assert!(
        (vertical + 1765.8).abs() < 0.5,
        "static vertical mount forces {vertical} N"
    );
    assert_eq!(s.exit_init(), OK);
    assert_logged(&s, "scene 2 (engine in the elastic chassis)");
    assert_logged(&s, "chassis (Craig-Bampton");

    let steps = vec![1e-3; 40];
    let t1 = run(&s, &steps[..20]).last().unwrap().0;
    let state = s.get_state();
    let bytes = s.serialize(state);
    let mut reference = Vec::new();
    let mut t = t1;
    for h in &steps[20..] {
        assert_eq!(s.do_step(t, *h), OK, "{:?}", s.logs());
        t += h;
        reference.push(s.reals(&comfort_outputs()));
    }
    let last = reference.last().unwrap();
    assert!(last.iter().all(|x| x.is_finite()));
    let wheel = &last[last.len() - 6..last.len() - 3];
    assert!(
        wheel.iter().any(|a| a.abs() > 1e-5),
        "steering wheel a = {wheel:?}"
    );

    for restored in [state, s.deserialize(&bytes).1] {
        assert_eq!(s.set_state(restored), OK, "{:?}", s.logs());
        let mut t = t1;
        for out_ref in &reference {
            assert_eq!(s.do_step(t, 1e-3), OK);
            t += 1e-3;
            assert_eq!(&s.reals(&comfort_outputs()), out_ref);
        }
        s.free_state(restored);
    }
    drop(s);
    let _ = std::fs::remove_dir_all(&cache);
}

#[test]
fn scene_1_reports_zero_comfort_accelerations() {
    let fmu = Fmu::load();
    let s = fmu.instantiate("ground-comfort");
    s.initialize();
    run(&s, &[1e-3; 5]);
    let a = s.reals(&[real::STEERING_WHEEL_A, real::SEAT_A].concat());
    assert_eq!(a, vec![0.0; 6]);
}

#[test]
fn chassis_cache_can_be_disabled_and_bad_chassis_parameters_are_refused() {
    let fmu = Fmu::load();
    let s = fmu.instantiate("hybrid-nocache");
    log_events(&s);
    assert_eq!(s.set_integer(&[integer::SCENE], &[2]), OK);
    assert_eq!(
        s.set_boolean(&[boolean::CHASSIS_CACHE_ENABLED], &[false]),
        OK
    );
    assert_eq!(s.set_integer(&[integer::CHASSIS_MAX_MODES], &[-1]), ERROR);
    assert_eq!(s.set_real(&[real::CHASSIS_MODE_CUTOFF], &[f64::NAN]), ERROR);
    assert_eq!(s.set_integer(&[integer::CHASSIS_MAX_MODES], &[20]), OK);
    s.initialize();
    assert_logged(&s, "caching disabled");
    run(&s, &[1e-3; 5]);
}
