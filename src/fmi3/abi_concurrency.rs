//! One FMI 3.0 instance called from two threads: every entry point with an instance, called
//! while another call is inside it, refuses with fmi3Error, says that the instance is busy and
//! changes nothing; a second thread calling them all in a loop while the first steps never
//! crashes the instance or corrupts it. The arguments are zeros and nulls: a busy instance is
//! refused before any argument is read, and an admitted call refuses the nulls.

use super::*;
use crate::fmu::guard;
use crate::variables::GUID;

/// A zero or null argument of any type an FMI 3.0 function takes.
trait Zero {
    fn zero() -> Self;
}

impl<T> Zero for *const T {
    fn zero() -> Self {
        std::ptr::null()
    }
}
impl<T> Zero for *mut T {
    fn zero() -> Self {
        std::ptr::null_mut()
    }
}
macro_rules! zero_is_default {
    ($($t:ty),*) => { $(impl Zero for $t { fn zero() -> Self { Default::default() } })* };
}
zero_is_default!(usize, u32, f64, bool);
impl<T> Zero for Option<T> {
    fn zero() -> Self {
        None
    }
}

fn z<T: Zero>() -> T {
    T::zero()
}

type Call = fn(fmi3Instance) -> fmi3Status;

/// Every function of `fmi3Functions.h` that takes an instance, but freeing it.
///
/// Long on purpose: a table, one entry per entry point.
fn calls() -> Vec<(&'static str, Call)> {
    vec![
        ("fmi3SetDebugLogging", |i| {
            fmi3SetDebugLogging(i, z(), z(), z())
        }),
        ("fmi3EnterInitializationMode", |i| {
            fmi3EnterInitializationMode(i, z(), z(), z(), z(), z())
        }),
        ("fmi3ExitInitializationMode", |i| {
            fmi3ExitInitializationMode(i)
        }),
        ("fmi3EnterEventMode", |i| fmi3EnterEventMode(i)),
        ("fmi3Terminate", |i| fmi3Terminate(i)),
        ("fmi3Reset", |i| fmi3Reset(i)),
        ("fmi3GetFloat32", |i| fmi3GetFloat32(i, z(), z(), z(), z())),
        ("fmi3GetFloat64", |i| fmi3GetFloat64(i, z(), z(), z(), z())),
        ("fmi3GetInt8", |i| fmi3GetInt8(i, z(), z(), z(), z())),
        ("fmi3GetUInt8", |i| fmi3GetUInt8(i, z(), z(), z(), z())),
        ("fmi3GetInt16", |i| fmi3GetInt16(i, z(), z(), z(), z())),
        ("fmi3GetUInt16", |i| fmi3GetUInt16(i, z(), z(), z(), z())),
        ("fmi3GetInt32", |i| fmi3GetInt32(i, z(), z(), z(), z())),
        ("fmi3GetUInt32", |i| fmi3GetUInt32(i, z(), z(), z(), z())),
        ("fmi3GetInt64", |i| fmi3GetInt64(i, z(), z(), z(), z())),
        ("fmi3GetUInt64", |i| fmi3GetUInt64(i, z(), z(), z(), z())),
        ("fmi3GetBoolean", |i| fmi3GetBoolean(i, z(), z(), z(), z())),
        ("fmi3GetString", |i| fmi3GetString(i, z(), z(), z(), z())),
        ("fmi3GetBinary", |i| {
            fmi3GetBinary(i, z(), z(), z(), z(), z())
        }),
        ("fmi3GetClock", |i| fmi3GetClock(i, z(), z(), z())),
        ("fmi3SetFloat32", |i| fmi3SetFloat32(i, z(), z(), z(), z())),
        ("fmi3SetFloat64", |i| fmi3SetFloat64(i, z(), z(), z(), z())),
        ("fmi3SetInt8", |i| fmi3SetInt8(i, z(), z(), z(), z())),
        ("fmi3SetUInt8", |i| fmi3SetUInt8(i, z(), z(), z(), z())),
        ("fmi3SetInt16", |i| fmi3SetInt16(i, z(), z(), z(), z())),
        ("fmi3SetUInt16", |i| fmi3SetUInt16(i, z(), z(), z(), z())),
        ("fmi3SetInt32", |i| fmi3SetInt32(i, z(), z(), z(), z())),
        ("fmi3SetUInt32", |i| fmi3SetUInt32(i, z(), z(), z(), z())),
        ("fmi3SetInt64", |i| fmi3SetInt64(i, z(), z(), z(), z())),
        ("fmi3SetUInt64", |i| fmi3SetUInt64(i, z(), z(), z(), z())),
        ("fmi3SetBoolean", |i| fmi3SetBoolean(i, z(), z(), z(), z())),
        ("fmi3SetString", |i| fmi3SetString(i, z(), z(), z(), z())),
        ("fmi3SetBinary", |i| {
            fmi3SetBinary(i, z(), z(), z(), z(), z())
        }),
        ("fmi3SetClock", |i| fmi3SetClock(i, z(), z(), z())),
        ("fmi3GetNumberOfVariableDependencies", |i| {
            fmi3GetNumberOfVariableDependencies(i, z(), z())
        }),
        ("fmi3GetVariableDependencies", |i| {
            fmi3GetVariableDependencies(i, z(), z(), z(), z(), z(), z())
        }),
        ("fmi3GetFMUState", |i| fmi3GetFMUState(i, z())),
        ("fmi3SetFMUState", |i| fmi3SetFMUState(i, z())),
        ("fmi3FreeFMUState", |i| fmi3FreeFMUState(i, z())),
        ("fmi3SerializedFMUStateSize", |i| {
            fmi3SerializedFMUStateSize(i, z(), z())
        }),
        ("fmi3SerializeFMUState", |i| {
            fmi3SerializeFMUState(i, z(), z(), z())
        }),
        ("fmi3DeserializeFMUState", |i| {
            fmi3DeserializeFMUState(i, z(), z(), z())
        }),
        ("fmi3GetDirectionalDerivative", |i| {
            fmi3GetDirectionalDerivative(i, z(), z(), z(), z(), z(), z(), z(), z())
        }),
        ("fmi3GetAdjointDerivative", |i| {
            fmi3GetAdjointDerivative(i, z(), z(), z(), z(), z(), z(), z(), z())
        }),
        ("fmi3EnterConfigurationMode", |i| {
            fmi3EnterConfigurationMode(i)
        }),
        ("fmi3ExitConfigurationMode", |i| {
            fmi3ExitConfigurationMode(i)
        }),
        ("fmi3GetIntervalDecimal", |i| {
            fmi3GetIntervalDecimal(i, z(), z(), z(), z())
        }),
        ("fmi3GetIntervalFraction", |i| {
            fmi3GetIntervalFraction(i, z(), z(), z(), z(), z())
        }),
        ("fmi3GetShiftDecimal", |i| {
            fmi3GetShiftDecimal(i, z(), z(), z())
        }),
        ("fmi3GetShiftFraction", |i| {
            fmi3GetShiftFraction(i, z(), z(), z(), z())
        }),
        ("fmi3SetIntervalDecimal", |i| {
            fmi3SetIntervalDecimal(i, z(), z(), z())
        }),
        ("fmi3SetIntervalFraction", |i| {
            fmi3SetIntervalFraction(i, z(), z(), z(), z())
        }),
        ("fmi3SetShiftDecimal", |i| {
            fmi3SetShiftDecimal(i, z(), z(), z())
        }),
        ("fmi3SetShiftFraction", |i| {
            fmi3SetShiftFraction(i, z(), z(), z(), z())
        }),
        ("fmi3EvaluateDiscreteStates", |i| {
            fmi3EvaluateDiscreteStates(i)
        }),
        ("fmi3UpdateDiscreteStates", |i| {
            fmi3UpdateDiscreteStates(i, z(), z(), z(), z(), z(), z())
        }),
        ("fmi3EnterStepMode", |i| fmi3EnterStepMode(i)),
        ("fmi3GetOutputDerivatives", |i| {
            fmi3GetOutputDerivatives(i, z(), z(), z(), z(), z())
        }),
        ("fmi3DoStep", |i| {
            fmi3DoStep(i, z(), z(), z(), z(), z(), z(), z())
        }),
        ("fmi3EnterContinuousTimeMode", |i| {
            fmi3EnterContinuousTimeMode(i)
        }),
        ("fmi3CompletedIntegratorStep", |i| {
            fmi3CompletedIntegratorStep(i, z(), z(), z())
        }),
        ("fmi3SetTime", |i| fmi3SetTime(i, z())),
        ("fmi3SetContinuousStates", |i| {
            fmi3SetContinuousStates(i, z(), z())
        }),
        ("fmi3GetContinuousStateDerivatives", |i| {
            fmi3GetContinuousStateDerivatives(i, z(), z())
        }),
        ("fmi3GetEventIndicators", |i| {
            fmi3GetEventIndicators(i, z(), z())
        }),
        ("fmi3GetContinuousStates", |i| {
            fmi3GetContinuousStates(i, z(), z())
        }),
        ("fmi3GetNominalsOfContinuousStates", |i| {
            fmi3GetNominalsOfContinuousStates(i, z(), z())
        }),
        ("fmi3GetNumberOfEventIndicators", |i| {
            fmi3GetNumberOfEventIndicators(i, z())
        }),
        ("fmi3GetNumberOfContinuousStates", |i| {
            fmi3GetNumberOfContinuousStates(i, z())
        }),
        ("fmi3ActivateModelPartition", |i| {
            fmi3ActivateModelPartition(i, z(), z())
        }),
    ]
}

static LOG: std::sync::Mutex<Vec<String>> = std::sync::Mutex::new(Vec::new());

unsafe extern "C" fn log_message(
    _env: fmi3InstanceEnvironment,
    _status: fmi3Status,
    _category: fmi3String,
    message: fmi3String,
) {
    // SAFETY: the FMU passes a NUL-terminated message valid for the call.
    let message = unsafe { std::ffi::CStr::from_ptr(message) }.to_string_lossy();
    if let Ok(mut log) = LOG.lock() {
        log.push(message.into_owned());
    }
}

#[test]
fn every_entry_point_on_a_busy_instance_is_refused_and_changes_nothing() {
    let calls = calls();
    // Every exported function (the build script's list) less the version, the three
    // instantiations and freeing.
    let source = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("build/fmi3_description.rs"),
    )
    .unwrap();
    let listed = source.split("pub const FMI3_FUNCTIONS").nth(1).unwrap();
    let exported: Vec<&str> = listed
        .split("];")
        .next()
        .unwrap()
        .split('"')
        .skip(1)
        .step_by(2)
        .collect();
    let without_instance = [
        "fmi3GetVersion",
        "fmi3InstantiateModelExchange",
        "fmi3InstantiateCoSimulation",
        "fmi3InstantiateScheduledExecution",
        "fmi3FreeInstance",
    ];
    let tested: Vec<&str> = calls.iter().map(|(name, _)| *name).collect();
    let expected: Vec<&str> = exported
        .iter()
        .copied()
        .filter(|name| !without_instance.contains(name))
        .collect();
    assert_eq!(tested, expected);
    let i = instantiate(c"busy3");
    for (function, call) in &calls {
        // SAFETY: i is live and outlives the guard; no call is inside it.
        let held = unsafe { guard::hold(i) };
        let status = call(i);
        drop(held);
        assert_eq!(
            status, fmi3Status_fmi3Error,
            "{function} on a busy instance"
        );
        let log = LOG.lock().unwrap();
        assert!(
            log.iter()
                .any(|l| l.starts_with(&format!("{function}: the instance is busy"))),
            "{function}: {log:?}"
        );
    }
    // Nothing changed: still instantiated (not the error state), so initialisation proceeds.
    assert_eq!(
        fmi3EnterInitializationMode(i, false, 0.0, 0.0, false, 0.0),
        fmi3Status_fmi3OK
    );
    assert_eq!(fmi3ExitInitializationMode(i), fmi3Status_fmi3OK);
    fmi3FreeInstance(i);
}

fn instantiate(name: &std::ffi::CStr) -> fmi3Instance {
    let token = std::ffi::CString::new(GUID).unwrap();
    let i = fmi3InstantiateCoSimulation(
        name.as_ptr(),
        token.as_ptr(),
        std::ptr::null(),
        false,
        false,
        false,
        false,
        std::ptr::null(),
        0,
        std::ptr::null_mut(),
        Some(log_message),
        None,
    );
    assert!(!i.is_null());
    i
}

/// An instance pointer handed to a second thread: exactly what FMI forbids and this test does.
#[derive(Clone, Copy)]
struct Shared(fmi3Instance);
// SAFETY: the point of the test; the guard makes the concurrent calls safe.
unsafe impl Send for Shared {}

impl Shared {
    /// The pointer (a method, so that a closure captures the whole `Shared`, not its field).
    fn ptr(self) -> fmi3Instance {
        self.0
    }
}
// SAFETY: as above.
unsafe impl Sync for Shared {}

/// Initialises `i` (scene 1 at its start values) and takes `steps` steps of 1 ms, reading the
/// mount forces after each; `None` when a call fails (the other thread reset
/// the instance or drove it into the error state).
fn run(i: fmi3Instance, steps: usize) -> Option<Vec<f64>> {
    let forces = crate::variables::fmi3::VARIABLES
        .iter()
        .find(|v| v.name == "mount.F")
        .expect("mount.F");
    let n = forces.indices.len();
    let ok = |s: fmi3Status| (s == fmi3Status_fmi3OK).then_some(());
    ok(fmi3EnterInitializationMode(i, false, 0.0, 0.0, false, 0.0))?;
    ok(fmi3ExitInitializationMode(i))?;
    let mut out = Vec::with_capacity(steps);
    let (mut a, mut b, mut c, mut last) = (false, false, false, 0.0);
    for k in 0..steps {
        ok(fmi3DoStep(
            i,
            k as f64 * 1e-3,
            1e-3,
            true,
            &mut a,
            &mut b,
            &mut c,
            &mut last,
        ))?;
        let mut v = vec![0.0; n];
        ok(fmi3GetFloat64(i, &forces.vr, 1, v.as_mut_ptr(), n))?;
        out.extend(v);
    }
    Some(out)
}

#[test]
fn a_second_thread_calling_every_entry_point_never_crashes_or_corrupts_the_instance() {
    let calls = calls();
    let i = Shared(instantiate(c"race3"));
    let done = std::sync::atomic::AtomicBool::new(false);
    let (runs, completed) = std::thread::scope(|scope| {
        // The first thread runs and, whenever a call fails (the second thread's nulls drive the
        // instance into the error state, or it was busy), resets and starts again: every status
        // but fatal is fair under such a caller.
        let runner = scope.spawn(|| {
            let start = std::time::Instant::now();
            let (mut runs, mut completed) = (0, 0);
            while start.elapsed() < std::time::Duration::from_millis(1500) {
                runs += 1;
                if run(i.ptr(), 20).is_some() {
                    completed += 1;
                }
                let s = fmi3Reset(i.ptr());
                assert_ne!(s, fmi3Status_fmi3Fatal);
            }
            done.store(true, std::sync::atomic::Ordering::Release);
            (runs, completed)
        });
        scope.spawn(|| {
            let mut k = 0;
            while !done.load(std::sync::atomic::Ordering::Acquire) {
                let (function, call) = &calls[k % calls.len()];
                assert_ne!(call(i.ptr()), fmi3Status_fmi3Fatal, "{function}");
                k += 1;
            }
        });
        runner.join().unwrap()
    });
    eprintln!("FMI 3.0 race: {completed} of {runs} runs completed under the second thread");
    // Not corrupted: reset, the instance runs the reference case to the bit.
    assert_eq!(fmi3Reset(i.ptr()), fmi3Status_fmi3OK);
    let raced = run(i.ptr(), 50).unwrap_or_else(|| {
        let log = LOG.lock().unwrap();
        panic!(
            "a run after the race failed: {:?}",
            &log[log.len().saturating_sub(5)..]
        )
    });
    let reference = instantiate(c"race3-reference");
    assert_eq!(raced, run(reference, 50).unwrap());
    assert!(LOG
        .lock()
        .unwrap()
        .iter()
        .any(|l| l.contains(": the instance is busy")));
    fmi3FreeInstance(reference);
    fmi3FreeInstance(i.ptr());
}
