//! Bad inputs a master or a user can give: each is an error status with a log line naming the
//! cause; nothing hangs, nothing reads without bound, nothing is half applied.

use crate::common::*;
use engine_mount_chassis::fmi2::variables::{boolean, real, string, GUID};

fn logged(s: &Slave, needle: &str) -> bool {
    s.logs().iter().any(|l| l.contains(needle))
}

/// Replaces the first occurrence of `from`'s bytes in `bytes` by `to`'s.
fn patch_f64(bytes: &mut [u8], from: f64, to: f64) {
    let needle = from.to_le_bytes();
    let at = bytes
        .windows(8)
        .position(|w| w == needle)
        .expect("value present in the serialized state");
    bytes[at..at + 8].copy_from_slice(&to.to_le_bytes());
}

#[test]
fn a_serialized_state_with_inadmissible_values_is_refused() {
    let fmu = Fmu::load();
    let s = fmu.instantiate("bad-state");
    let (rpm, scale) = (1_234.567_891, 0.876_543_21);
    assert_eq!(s.set_real(&[real::RPM], &[rpm]), OK);
    assert_eq!(s.set_real(&[real::MOUNT_STIFFNESS_SCALE[2]], &[scale]), OK);
    s.initialize();
    assert_eq!(s.do_step(0.0, 1e-3), OK);
    let state = s.get_state();
    let bytes = s.serialize(state);
    let (st, good) = s.deserialize(&bytes);
    assert_eq!(st, OK, "{:?}", s.logs());
    s.free_state(good);
    for (from, to, cause) in [
        (rpm, f64::NAN, "rpm = NaN is not finite"),
        (scale, -1.0, "mount[3].stiffnessScale = -1 is outside"),
    ] {
        let mut bad = bytes.clone();
        patch_f64(&mut bad, from, to);
        // Changed after it was written: the checksum says so.
        let (st, handle) = s.deserialize(&bad);
        assert_eq!(st, ERROR, "{cause}");
        assert!(handle.is_null());
        assert!(logged(&s, "checksum does not match"), "{:?}", s.logs());
        // Resealed with a valid checksum: the value itself is refused, by name.
        reseal(&mut bad);
        let (st, handle) = s.deserialize(&bad);
        assert_eq!(st, ERROR, "{cause}");
        assert!(handle.is_null());
        assert!(logged(&s, cause), "{cause}: {:?}", s.logs());
    }
    s.free_state(state);
}

/// Recomputes the SHA-256 trailer of a saved state (header: 8-byte magic and a one-byte
/// version) as a forger would, so that the value checks behind the checksum are tested.
pub(crate) fn reseal(bytes: &mut [u8]) {
    use sha2::{Digest, Sha256};
    let end = bytes.len() - 32;
    let checksum = Sha256::digest(&bytes[9..end]);
    bytes[end..].copy_from_slice(&checksum);
}

/// Issue 28: a ramp down onto 0 read back -2.2e-25 and the next step failed; a ramp up with a
/// huge derivative stopped 7e-12 above the maximum.
#[test]
fn ramps_onto_a_bound_end_exactly_there_and_the_run_goes_on() {
    let fmu = Fmu::load();
    for (vr, start, slope, bound) in [
        (real::RPM, 800.0, -1000.0, 0.0),
        (real::MOUNT_STIFFNESS_SCALE[0], 1.0, -3.0, 0.0),
        (real::RPM, 5999.0, 1e9, 6000.0),
    ] {
        let s = fmu.instantiate("ramp-to-bound");
        assert_eq!(s.set_real(&[vr], &[start]), OK);
        s.initialize();
        assert_eq!(s.set_input_derivatives(&[vr], &[slope]), OK);
        let (h, mut t) = (1e-3, 0.0);
        let steps = ((bound - start) / slope / h).ceil() as usize + 5;
        let mut warned = false;
        for _ in 0..steps {
            let st = s.do_step(t, h);
            assert!(
                st == OK || st == WARNING,
                "{vr} at {t}: {st} {:?}",
                s.logs()
            );
            warned |= st == WARNING;
            t += h;
            let value = s.reals(&[vr])[0];
            assert!(
                (value - start) * slope.signum() <= (bound - start) * slope.signum(),
                "{vr} = {value} beyond {bound}"
            );
        }
        assert!(warned, "bending the ramp is a warning");
        assert_eq!(s.reals(&[vr])[0], bound, "{vr} ends on its bound");
        assert!(
            logged(&s, &format!("with slope {slope} per s")),
            "the warning names the slope asked for: {:?}",
            s.logs()
        );
    }
}

#[test]
fn a_state_of_another_configuration_or_instance_is_refused() {
    let fmu = Fmu::load();
    let a = fmu.instantiate("config-a");
    assert_eq!(a.set_boolean(&[boolean::EFFECT_GAS_FORCES], &[false]), OK);
    a.initialize();
    let b = fmu.instantiate("config-b");
    b.initialize();
    let from_a = a.get_state();
    // a state pointer of another instance is not this instance's
    assert_eq!(b.set_state(from_a), ERROR);
    assert!(
        logged(&b, "not an FMU state of this instance"),
        "{:?}",
        b.logs()
    );
    // the same state moved by serialization: it parses, but it was taken with other parameters
    let (st, moved) = b.deserialize(&a.serialize(from_a));
    assert_eq!(st, OK);
    assert_eq!(b.set_state(moved), ERROR);
    assert!(
        logged(&b, "the state was taken with effects.gasForces = false"),
        "{:?}",
        b.logs()
    );
    // b is unchanged and still runs
    assert_eq!(b.do_step(0.0, 1e-3), OK);
    b.free_state(moved);
    a.free_state(from_a);
}

#[test]
fn states_not_freed_by_the_master_go_with_their_instance() {
    let fmu = Fmu::load();
    for round in 0..3 {
        let s = fmu.instantiate(&format!("leaky-{round}"));
        s.initialize();
        for _ in 0..5 {
            let _forgotten = s.get_state();
        }
        // dropping the slave calls fmi2FreeInstance, which frees the five states with it
    }
}

#[test]
fn booleans_other_than_true_and_false_are_refused() {
    let fmu = Fmu::load();
    let s = fmu.instantiate("booleans");
    for value in [2, 255, -1] {
        // SAFETY: one value reference and one value.
        let st = unsafe {
            (s.f().fmi2SetBoolean)(
                s.c,
                value_references(2, &[boolean::EFFECT_GAS_FORCES]).as_ptr(),
                1,
                [value].as_ptr(),
            )
        };
        assert_eq!(st, ERROR, "{value}");
        assert!(
            logged(&s, &format!("value {value} for value reference")),
            "{:?}",
            s.logs()
        );
    }
    assert_eq!(s.setup(0.0, None), OK);
    assert_eq!(s.enter_init(), OK);
    let (st, v) = s.get_boolean(&[boolean::EFFECT_GAS_FORCES]);
    assert_eq!((st, v), (OK, vec![true]));
}

#[test]
fn config_files_must_be_regular_and_complete() {
    let fmu = Fmu::load();
    let dir = std::env::temp_dir().join(format!("emc-bad-config-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let fifo = dir.join("fifo.json");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    let unknown = dir.join("unknown.json");
    std::fs::write(
        &unknown,
        r#"{"extends": "default", "engine": {"cylinderz": 4}}"#,
    )
    .unwrap();
    let mut cases = vec![
        ("/dev/urandom".to_owned(), "not a regular file".to_owned()),
        (
            unknown.display().to_string(),
            "unknown field `cylinderz`".to_owned(),
        ),
        (dir.display().to_string(), "not a regular file".to_owned()),
    ];
    if made.is_ok_and(|s| s.success()) {
        cases.push((fifo.display().to_string(), "not a regular file".to_owned()));
    }
    for (i, (path, cause)) in cases.iter().enumerate() {
        let s = fmu.instantiate(&format!("config-{i}"));
        assert_eq!(s.set_string(&[string::CONFIG_FILE], &[path]), OK);
        assert_eq!(s.setup(0.0, None), OK);
        assert_eq!(s.enter_init(), OK);
        assert_eq!(s.exit_init(), ERROR, "{path}");
        assert!(logged(&s, cause), "{path}: {:?}", s.logs());
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn an_unusable_resource_location_is_an_error() {
    let fmu = Fmu::load();
    let missing = std::env::temp_dir().join("emc-no-such-resources");
    assert!(fmu
        .instantiate_with(
            "no-resources",
            GUID,
            Some(&format!("file://{}", missing.display()))
        )
        .is_none());
    assert!(
        logs("no-resources")
            .iter()
            .any(|l| l.contains("not a directory") || l.contains("resource")),
        "{:?}",
        logs("no-resources")
    );
    assert!(fmu
        .instantiate_with("http-resources", GUID, Some("http://example.com/resources"))
        .is_none());
    // resources without the FMU's vehicle: an error at initialisation, not the built-in data
    let empty = std::env::temp_dir().join(format!("emc-empty-resources-{}", std::process::id()));
    std::fs::create_dir_all(&empty).unwrap();
    let s = fmu
        .instantiate_with(
            "empty-resources",
            GUID,
            Some(&format!("file://{}", empty.display())),
        )
        .expect("a directory is a valid resource location");
    assert_eq!(s.setup(0.0, None), OK);
    assert_eq!(s.enter_init(), OK);
    assert_eq!(s.exit_init(), ERROR);
    assert!(logged(&s, "have no vehicle.json"), "{:?}", s.logs());
    let _ = std::fs::remove_dir_all(&empty);
}

/// Issue 28: after a failed fmi2ExitInitializationMode every later call built the model again
/// (10 builds for 9 calls). Unchanged parameters give the same answer without a new build; a
/// change builds again.
#[test]
fn a_failed_set_up_is_not_repeated_until_something_changes() {
    let fmu = Fmu::load();
    let s = fmu.instantiate("failed-setup");
    assert_eq!(
        s.set_real(&real::MOUNT_STIFFNESS_SCALE, &[0.0; 4]),
        OK,
        "a stiffness scale of 0 is admissible"
    );
    s.log_everything();
    assert_eq!(s.setup(0.0, None), OK);
    assert_eq!(s.enter_init(), OK);
    assert_eq!(s.exit_init(), ERROR);
    assert!(
        logged(&s, "stiffness scale 0 on"),
        "the cause names the mounts without stiffness: {:?}",
        s.logs()
    );
    for _ in 0..8 {
        assert_eq!(s.get_real(&[real::MOUNT_F[0][2]]).0, ERROR);
    }
    assert_eq!(s.exit_init(), ERROR);
    let builds = |s: &Slave| {
        s.logs()
            .iter()
            .filter(|l| l.contains("building scene"))
            .count()
    };
    assert_eq!(builds(&s), 1, "{:?}", s.logs());
    assert_eq!(s.set_real(&real::MOUNT_STIFFNESS_SCALE, &[1.0; 4]), OK);
    assert_eq!(s.exit_init(), OK);
    assert_eq!(builds(&s), 2);
}

/// Issue 28: NaN in a saved state's time field passed deserialisation and the next step failed.
#[test]
fn a_saved_state_with_a_non_finite_time_is_refused() {
    let fmu = Fmu::load();
    let s = fmu.instantiate("nan-time");
    s.initialize();
    let h = 1.234_567e-3;
    for k in 0..3 {
        assert_eq!(s.do_step(k as f64 * h, h), OK);
    }
    let state = s.get_state();
    let mut bytes = s.serialize(state);
    s.free_state(state);
    let t = s
        .real_status(fmi_sys::fmi2::fmi2StatusKind_fmi2LastSuccessfulTime)
        .1;
    patch_f64(&mut bytes, t, f64::NAN);
    reseal(&mut bytes);
    let (st, handle) = s.deserialize(&bytes);
    assert_eq!(st, ERROR);
    assert!(handle.is_null());
    assert!(logged(&s, "not finite"), "{:?}", s.logs());
}
