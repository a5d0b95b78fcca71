//! Every entry point in every state, against the co-simulation state table of FMI 2.0
//! (§4.2.4), which is written out here independently of [`super::state`]: a call the table
//! allows is not refused for its state; a call it forbids returns fmi2Error and says so; in the
//! fatal state everything but fmi2FreeInstance returns fmi2Fatal.

use std::collections::HashMap;
use std::ffi::CString;
use std::sync::{Mutex, OnceLock};

use super::*;
use crate::variables::GUID;
use crate::variables::{boolean, integer, real, string, BOOLEANS, INTEGERS, REALS, STRINGS};

/// Log lines per instance name, from fmi-sys' logger through the `log` crate.
struct Capture(Mutex<HashMap<String, Vec<String>>>);

impl log::Log for Capture {
    fn enabled(&self, _: &log::Metadata) -> bool {
        true
    }
    fn log(&self, record: &log::Record) {
        if let Ok(mut m) = self.0.lock() {
            m.entry(record.target().to_owned())
                .or_default()
                .push(record.args().to_string());
        }
    }
    fn flush(&self) {}
}

fn capture() -> &'static Capture {
    static CAPTURE: OnceLock<&'static Capture> = OnceLock::new();
    CAPTURE.get_or_init(|| {
        let c: &'static Capture = Box::leak(Box::new(Capture(Mutex::new(HashMap::new()))));
        let _ = log::set_logger(c);
        log::set_max_level(log::LevelFilter::Trace);
        c
    })
}

fn logs(name: &str) -> Vec<String> {
    capture()
        .0
        .lock()
        .map(|m| m.get(name).cloned().unwrap_or_default())
        .unwrap_or_default()
}

/// The states an instance can be in here (no `stepInProgress`/`stepCanceled`: steps are
/// synchronous).
const PHASES: [Phase; 6] = [
    Phase::Instantiated,
    Phase::InitializationMode,
    Phase::StepComplete,
    Phase::StepFailed,
    Phase::Terminated,
    Phase::Error,
];

/// FMI 2.0 §4.2.4: in which states a co-simulation function may be called.
fn allowed_by_the_standard(function: &str, phase: Phase) -> bool {
    use Phase::*;
    let p = phase;
    match function {
        "fmi2SetDebugLogging"
        | "fmi2Reset"
        | "fmi2GetFMUstate"
        | "fmi2SetFMUstate"
        | "fmi2FreeFMUstate"
        | "fmi2SerializedFMUstateSize"
        | "fmi2SerializeFMUstate"
        | "fmi2DeSerializeFMUstate" => true,
        "fmi2SetupExperiment" | "fmi2EnterInitializationMode" => p == Instantiated,
        "fmi2ExitInitializationMode" => p == InitializationMode,
        "fmi2Terminate" => matches!(p, StepComplete | StepFailed),
        "fmi2GetReal"
        | "fmi2GetInteger"
        | "fmi2GetBoolean"
        | "fmi2GetString"
        | "fmi2GetDirectionalDerivative" => p != Instantiated,
        "fmi2SetReal"
        | "fmi2SetInteger"
        | "fmi2SetBoolean"
        | "fmi2SetString"
        | "fmi2SetRealInputDerivatives" => {
            matches!(p, Instantiated | InitializationMode | StepComplete)
        }
        "fmi2GetRealOutputDerivatives" => {
            matches!(p, StepComplete | StepFailed | Terminated | Error)
        }
        "fmi2DoStep" => p == StepComplete,
        "fmi2CancelStep" => false,
        "fmi2GetStatus"
        | "fmi2GetRealStatus"
        | "fmi2GetIntegerStatus"
        | "fmi2GetBooleanStatus"
        | "fmi2GetStringStatus" => matches!(p, StepComplete | StepFailed | Terminated),
        other => panic!("{other} is not in the table"),
    }
}

/// An instance of the built-in vehicle on rigid ground, brought into `phase`: through the
/// entry points where the state machine leads there, set directly for the failure states.
fn instance_in(name: &str, phase: Phase) -> fmi2Component {
    let name_c = CString::new(name).unwrap();
    let guid = CString::new(GUID).unwrap();
    let callbacks = Box::leak(Box::new(fmi2CallbackFunctions {
        logger: Some(fmi_sys::fmi2::logger::callback_logger_handler),
        allocateMemory: None,
        freeMemory: None,
        stepFinished: None,
        componentEnvironment: std::ptr::null_mut(),
    }));
    capture();
    let c = fmi2Instantiate(
        name_c.as_ptr(),
        fmi2Type_fmi2CoSimulation,
        guid.as_ptr(),
        std::ptr::null(),
        callbacks,
        0,
        0,
    );
    assert!(!c.is_null());
    let ok = |s| assert_eq!(s, fmi2Status_fmi2OK, "{name} on the way to {phase:?}");
    if phase != Phase::Instantiated {
        ok(fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0));
        ok(fmi2EnterInitializationMode(c));
    }
    if phase != Phase::Instantiated && phase != Phase::InitializationMode {
        ok(fmi2ExitInitializationMode(c));
        ok(fmi2DoStep(c, 0.0, 1e-3, 1));
    }
    match phase {
        Phase::Terminated => ok(fmi2Terminate(c)),
        Phase::StepFailed | Phase::Error => {
            // SAFETY: c is a live instance from fmi2Instantiate, used by this thread alone.
            let handle = unsafe { guard::handle_mut(c) };
            handle.instance.core.phase = phase;
        }
        _ => {}
    }
    c
}

/// What a call needs from the instance, taken before the call: an FMU state of it and its time.
#[derive(Clone, Copy)]
struct Prepared {
    state: fmi2FMUstate,
    time: f64,
    /// The serialized size of `state`.
    size: usize,
}

impl Prepared {
    /// An FMU state of `c` (allowed in every state but the fatal one) and its time.
    fn of(c: fmi2Component) -> Prepared {
        let mut state: fmi2FMUstate = std::ptr::null_mut();
        assert_eq!(fmi2GetFMUstate(c, &mut state), fmi2Status_fmi2OK);
        // SAFETY: c is a live instance from fmi2Instantiate, used by this thread alone.
        let time = unsafe { guard::handle_mut(c) }.instance.core.time;
        let mut size = 0;
        assert_eq!(
            fmi2SerializedFMUstateSize(c, state, &mut size),
            fmi2Status_fmi2OK
        );
        Prepared { state, time, size }
    }

    /// For calls without an instance.
    fn none() -> Prepared {
        Prepared {
            state: std::ptr::null_mut(),
            time: 0.0,
            size: 8,
        }
    }
}

type Call = fn(fmi2Component, Prepared) -> fmi2Status;

/// Every entry point that takes an instance, each with admissible arguments.
///
/// Long on purpose: a table, one entry per entry point.
fn calls() -> Vec<(&'static str, Call)> {
    vec![
        ("fmi2SetDebugLogging", |c, _| {
            fmi2SetDebugLogging(c, 1, 0, std::ptr::null())
        }),
        ("fmi2SetupExperiment", |c, _| {
            fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0)
        }),
        ("fmi2EnterInitializationMode", |c, _| {
            fmi2EnterInitializationMode(c)
        }),
        ("fmi2ExitInitializationMode", |c, _| {
            fmi2ExitInitializationMode(c)
        }),
        ("fmi2Terminate", |c, _| fmi2Terminate(c)),
        ("fmi2Reset", |c, _| fmi2Reset(c)),
        ("fmi2GetReal", |c, _| {
            let mut v = [0.0];
            fmi2GetReal(c, &REALS[real::RPM as usize].vr, 1, v.as_mut_ptr())
        }),
        ("fmi2GetInteger", |c, _| {
            let mut v = [0];
            fmi2GetInteger(c, &INTEGERS[integer::SCENE as usize].vr, 1, v.as_mut_ptr())
        }),
        ("fmi2GetBoolean", |c, _| {
            let mut v = [0];
            let vr = BOOLEANS[boolean::EFFECT_GAS_FORCES as usize].vr;
            fmi2GetBoolean(c, &vr, 1, v.as_mut_ptr())
        }),
        ("fmi2GetString", |c, _| {
            let mut v = [std::ptr::null()];
            let vr = STRINGS[string::CONFIG_FILE as usize].vr;
            fmi2GetString(c, &vr, 1, v.as_mut_ptr())
        }),
        ("fmi2SetReal", |c, _| {
            fmi2SetReal(c, &REALS[real::RPM as usize].vr, 1, &1000.0)
        }),
        ("fmi2SetInteger", |c, _| {
            let vr = INTEGERS[integer::SOLVER_MAX_ORDER as usize].vr;
            fmi2SetInteger(c, &vr, 1, &5)
        }),
        ("fmi2SetBoolean", |c, _| {
            let vr = BOOLEANS[boolean::EFFECT_GAS_FORCES as usize].vr;
            fmi2SetBoolean(c, &vr, 1, &1)
        }),
        ("fmi2SetString", |c, _| {
            let vr = STRINGS[string::CHASSIS_CACHE_DIR as usize].vr;
            fmi2SetString(c, &vr, 1, &c"".as_ptr())
        }),
        ("fmi2GetFMUstate", |c, _| {
            let mut state: fmi2FMUstate = std::ptr::null_mut();
            fmi2GetFMUstate(c, &mut state)
        }),
        ("fmi2SetFMUstate", |c, p| fmi2SetFMUstate(c, p.state)),
        ("fmi2FreeFMUstate", |c, p| {
            let mut state = p.state;
            fmi2FreeFMUstate(c, &mut state)
        }),
        ("fmi2SerializedFMUstateSize", |c, p| {
            let mut size = 0;
            fmi2SerializedFMUstateSize(c, p.state, &mut size)
        }),
        ("fmi2SerializeFMUstate", |c, p| {
            let mut buffer = vec![0 as fmi2Byte; p.size];
            fmi2SerializeFMUstate(c, p.state, buffer.as_mut_ptr(), p.size)
        }),
        ("fmi2DeSerializeFMUstate", |c, p| {
            let mut buffer = vec![0 as fmi2Byte; p.size];
            if !p.state.is_null() {
                // Serialized while the instance's own state allows it (fatal: refused, zeros).
                fmi2SerializeFMUstate(c, p.state, buffer.as_mut_ptr(), p.size);
            }
            let mut restored: fmi2FMUstate = std::ptr::null_mut();
            fmi2DeSerializeFMUstate(c, buffer.as_ptr(), buffer.len(), &mut restored)
        }),
        ("fmi2GetDirectionalDerivative", |c, _| {
            let (unknown, known) = (
                REALS[real::MOUNT_F[0][0] as usize].vr,
                REALS[real::RPM as usize].vr,
            );
            let mut dv = [0.0];
            fmi2GetDirectionalDerivative(c, &unknown, 1, &known, 1, &1.0, dv.as_mut_ptr())
        }),
        ("fmi2SetRealInputDerivatives", |c, _| {
            fmi2SetRealInputDerivatives(c, &REALS[real::RPM as usize].vr, 1, &1, &10.0)
        }),
        ("fmi2GetRealOutputDerivatives", |c, _| {
            let mut v = [0.0];
            let vr = REALS[real::MOUNT_F[0][0] as usize].vr;
            fmi2GetRealOutputDerivatives(c, &vr, 1, &1, v.as_mut_ptr())
        }),
        ("fmi2DoStep", |c, p| fmi2DoStep(c, p.time, 1e-3, 1)),
        ("fmi2CancelStep", |c, _| fmi2CancelStep(c)),
        ("fmi2GetStatus", |c, _| {
            let mut s = fmi2Status_fmi2OK;
            fmi2GetStatus(c, fmi2StatusKind_fmi2DoStepStatus, &mut s)
        }),
        ("fmi2GetRealStatus", |c, _| {
            let mut t = 0.0;
            fmi2GetRealStatus(c, fmi2StatusKind_fmi2LastSuccessfulTime, &mut t)
        }),
        ("fmi2GetIntegerStatus", |c, _| {
            let mut v = 0;
            fmi2GetIntegerStatus(c, fmi2StatusKind_fmi2DoStepStatus, &mut v)
        }),
        ("fmi2GetBooleanStatus", |c, _| {
            let mut v = 0;
            fmi2GetBooleanStatus(c, fmi2StatusKind_fmi2Terminated, &mut v)
        }),
        ("fmi2GetStringStatus", |c, _| {
            let mut v = std::ptr::null();
            fmi2GetStringStatus(c, fmi2StatusKind_fmi2PendingStatus, &mut v)
        }),
    ]
}

#[test]
fn every_entry_point_in_every_state_follows_the_standard_state_table() {
    let calls = calls();
    // The 34 functions less the 4 without an instance (inquiry, instantiate, free).
    assert_eq!(calls.len(), 30);
    for phase in PHASES {
        for (function, call) in &calls {
            let name = format!("table-{function}-{phase:?}");
            let c = instance_in(&name, phase);
            let status = call(c, Prepared::of(c));
            let refused = logs(&name)
                .iter()
                .any(|l| l.contains(&format!("{function} is not allowed in phase {phase:?}")));
            if allowed_by_the_standard(function, phase) {
                assert!(
                    !refused && status != fmi2Status_fmi2Fatal,
                    "{function} in {phase:?}: refused ({status}): {:?}",
                    logs(&name)
                );
            } else {
                assert!(
                    refused && status == fmi2Status_fmi2Error,
                    "{function} in {phase:?} must be refused, gave {status}: {:?}",
                    logs(&name)
                );
            }
            fmi2FreeInstance(c);
        }
    }
}

#[test]
fn a_fatal_instance_answers_fatal_to_everything_but_free() {
    for (function, call) in calls() {
        let name = format!("fatal-{function}");
        let c = instance_in(&name, Phase::StepComplete);
        let prepared = Prepared::of(c);
        // SAFETY: c is a live instance from fmi2Instantiate, used by this thread alone.
        unsafe { guard::handle_mut(c) }.instance.core.phase = Phase::Fatal;
        assert_eq!(call(c, prepared), fmi2Status_fmi2Fatal, "{function}");
        fmi2FreeInstance(c);
    }
}

#[test]
fn a_null_or_freed_instance_is_an_error_not_a_crash() {
    for (function, call) in calls() {
        assert_eq!(
            call(std::ptr::null_mut(), Prepared::none()),
            fmi2Status_fmi2Error,
            "{function}"
        );
    }
    fmi2FreeInstance(std::ptr::null_mut());
}

#[test]
fn every_entry_point_on_a_busy_instance_is_refused_and_changes_nothing() {
    let calls = calls();
    let name = "busy";
    let c = instance_in(name, Phase::StepComplete);
    let prepared = Prepared::of(c);
    for (function, call) in &calls {
        let before = logs(name).len();
        // SAFETY: c is live and outlives the guard; no call is inside it.
        let held = unsafe { guard::hold(c) };
        let status = call(c, prepared);
        drop(held);
        let said = logs(name)[before..].to_vec();
        assert_eq!(
            status, fmi2Status_fmi2Error,
            "{function} on a busy instance"
        );
        assert!(
            said.iter()
                .any(|l| l.contains(&format!("{function}: the instance is busy"))),
            "{function}: {said:?}"
        );
    }
    // The refusals changed nothing: the instance is where it was and goes on.
    // SAFETY: c is live and no call is inside it.
    let handle = unsafe { guard::handle_mut(c) };
    assert_eq!(handle.instance.core.phase, Phase::StepComplete);
    assert_eq!(handle.instance.core.time, prepared.time);
    assert_eq!(fmi2DoStep(c, prepared.time, 1e-3, 1), fmi2Status_fmi2OK);
    // Freeing a busy instance is refused too (it would free memory another call is using).
    // SAFETY: as above.
    let held = unsafe { guard::hold(c) };
    fmi2FreeInstance(c);
    drop(held);
    assert!(logs(name)
        .iter()
        .any(|l| l.contains("fmi2FreeInstance: the instance is busy")));
    assert_eq!(
        fmi2DoStep(c, prepared.time + 1e-3, 1e-3, 1),
        fmi2Status_fmi2OK
    );
    fmi2FreeInstance(c);
}

/// An instance pointer handed to a second thread: exactly what FMI forbids and these tests do.
#[derive(Clone, Copy)]
struct Shared(fmi2Component);
// SAFETY: the point of the tests below; the guard makes the concurrent calls safe.
unsafe impl Send for Shared {}

impl Shared {
    /// The pointer (a method, so that a closure captures the whole `Shared`, not its field).
    fn ptr(self) -> fmi2Component {
        self.0
    }
}
// SAFETY: as above.
unsafe impl Sync for Shared {}
// SAFETY: an FMU state of an instance the race tests share; as above.
unsafe impl Send for Prepared {}
// SAFETY: as above.
unsafe impl Sync for Prepared {}

/// Value references of the outputs the race tests compare.
fn compared_outputs() -> Vec<fmi2ValueReference> {
    let mut vrs: Vec<_> = real::MOUNT_F
        .iter()
        .flatten()
        .map(|&i| REALS[i as usize].vr)
        .collect();
    vrs.extend(real::STEERING_WHEEL_A.map(|i| REALS[i as usize].vr));
    vrs
}

/// `call` until it is not refused as busy (another thread is inside the instance); panics on
/// any other status than OK.
fn until_not_busy(function: &str, mut call: impl FnMut() -> fmi2Status) -> usize {
    for refusals in 0..10_000_000 {
        match call() {
            s if s == fmi2Status_fmi2OK => return refusals,
            s if s == fmi2Status_fmi2Error => std::hint::spin_loop(),
            s => panic!("{function} answered {s} under a concurrent caller"),
        }
    }
    panic!("{function} refused ten million times");
}

/// Scene 1 at 2000 rpm from the start, `steps` steps of 1 ms, the compared outputs after each,
/// every call repeated while refused as busy; returns them and the number of refusals.
fn stepped_outputs(c: fmi2Component, steps: usize) -> (Vec<f64>, usize) {
    let vrs = compared_outputs();
    let rpm = REALS[real::RPM as usize].vr;
    let mut refusals = 0;
    refusals += until_not_busy("fmi2SetupExperiment", || {
        fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0)
    });
    refusals += until_not_busy("fmi2SetReal", || fmi2SetReal(c, &rpm, 1, &2000.0));
    refusals += until_not_busy("fmi2EnterInitializationMode", || {
        fmi2EnterInitializationMode(c)
    });
    refusals += until_not_busy("fmi2ExitInitializationMode", || {
        fmi2ExitInitializationMode(c)
    });
    let mut outputs = Vec::with_capacity(steps * vrs.len());
    let mut values = vec![0.0; vrs.len()];
    for k in 0..steps {
        refusals += until_not_busy("fmi2DoStep", || fmi2DoStep(c, k as f64 * 1e-3, 1e-3, 1));
        refusals += until_not_busy("fmi2GetReal", || {
            fmi2GetReal(c, vrs.as_ptr(), vrs.len(), values.as_mut_ptr())
        });
        outputs.extend_from_slice(&values);
    }
    (outputs, refusals)
}

#[test]
fn a_second_thread_reading_a_stepping_instance_gets_refusals_or_right_values_never_a_crash() {
    const STEPS: usize = 400;
    let reference = instance_in("race-reference", Phase::Instantiated);
    let (expected, none) = stepped_outputs(reference, STEPS);
    assert_eq!(none, 0);
    fmi2FreeInstance(reference);

    // Raced until the guard has refused at least once (nearly always the first time).
    for attempt in 0..5 {
        let name = format!("race-readers-{attempt}");
        let c = Shared(instance_in(&name, Phase::Instantiated));
        let (outputs, refused, reads) = race_with_reader(c, STEPS);
        // Identical to the bit: a refused call did nothing, an admitted one ran alone.
        assert_eq!(outputs, expected);
        let busy = logs(&name)
            .iter()
            .filter(|l| l.contains(": the instance is busy"))
            .count();
        assert!(busy >= refused);
        eprintln!("race with a reader: {reads} reads, {busy} calls refused as busy ({refused} of the stepper's)");
        fmi2FreeInstance(c.ptr());
        if busy > 0 {
            return;
        }
    }
    panic!("the two threads never met inside the instance in five runs");
}

/// Steps `c` as [`stepped_outputs`] while a second thread reads it as fast as it can; returns
/// the outputs, the stepper's refused calls and the reader's calls.
fn race_with_reader(c: Shared, steps: usize) -> (Vec<f64>, usize, usize) {
    let done = std::sync::atomic::AtomicBool::new(false);
    let vrs = compared_outputs();
    std::thread::scope(|scope| {
        let stepper = scope.spawn(|| {
            let result = stepped_outputs(c.ptr(), steps);
            done.store(true, std::sync::atomic::Ordering::Release);
            result
        });
        let reader = scope.spawn(|| {
            let mut reads = 0usize;
            let mut values = vec![0.0; vrs.len()];
            let mut status = 0;
            while !done.load(std::sync::atomic::Ordering::Acquire) {
                // Read-only calls: whatever they return, they must not change the stepper's
                // run; refused as busy, or in initialisation for not being allowed there.
                let s = match reads % 3 {
                    0 => fmi2GetReal(c.ptr(), vrs.as_ptr(), vrs.len(), values.as_mut_ptr()),
                    1 => fmi2GetStatus(c.ptr(), fmi2StatusKind_fmi2DoStepStatus, &mut status),
                    _ => {
                        let mut t = 0.0;
                        fmi2GetRealStatus(c.ptr(), fmi2StatusKind_fmi2LastSuccessfulTime, &mut t)
                    }
                };
                assert!(
                    s == fmi2Status_fmi2OK || s == fmi2Status_fmi2Error,
                    "status {s}"
                );
                if s == fmi2Status_fmi2OK {
                    assert!(values.iter().all(|v| v.is_finite()));
                }
                reads += 1;
            }
            reads
        });
        let (outputs, refused) = stepper.join().unwrap();
        (outputs, refused, reader.join().unwrap())
    })
}

#[test]
fn a_second_thread_calling_every_entry_point_never_crashes_or_corrupts_the_instance() {
    let calls = calls();
    let c = Shared(instance_in("race-all", Phase::StepComplete));
    let prepared = Prepared::of(c.ptr());
    let done = std::sync::atomic::AtomicBool::new(false);
    std::thread::scope(|scope| {
        // The first thread runs, and starts again whenever the second has reset, terminated
        // or failed it: every status but fatal is fair under such a caller.
        scope.spawn(|| {
            let start = std::time::Instant::now();
            let mut t = prepared.time;
            while start.elapsed() < std::time::Duration::from_millis(1500) {
                let s = fmi2DoStep(c.ptr(), t, 1e-3, 1);
                assert_ne!(s, fmi2Status_fmi2Fatal, "{:?}", logs("race-all"));
                if s == fmi2Status_fmi2OK {
                    t += 1e-3;
                } else {
                    fmi2Reset(c.ptr());
                    fmi2SetupExperiment(c.ptr(), 0, 0.0, 0.0, 0, 0.0);
                    fmi2EnterInitializationMode(c.ptr());
                    fmi2ExitInitializationMode(c.ptr());
                    let mut now = 0.0;
                    if fmi2GetRealStatus(c.ptr(), fmi2StatusKind_fmi2LastSuccessfulTime, &mut now)
                        == fmi2Status_fmi2OK
                    {
                        t = now;
                    }
                }
            }
            done.store(true, std::sync::atomic::Ordering::Release);
        });
        scope.spawn(|| {
            let mut k = 0;
            while !done.load(std::sync::atomic::Ordering::Acquire) {
                let (function, call) = &calls[k % calls.len()];
                let s = call(c.ptr(), prepared);
                assert_ne!(
                    s,
                    fmi2Status_fmi2Fatal,
                    "{function}: {:?}",
                    logs("race-all")
                );
                k += 1;
            }
        });
    });
    // Not corrupted: reset, the instance runs the reference case to the bit.
    assert_eq!(fmi2Reset(c.ptr()), fmi2Status_fmi2OK);
    let (outputs, _) = stepped_outputs(c.ptr(), 50);
    let reference = instance_in("race-all-reference", Phase::Instantiated);
    assert_eq!(outputs, stepped_outputs(reference, 50).0);
    assert!(logs("race-all")
        .iter()
        .any(|l| l.contains(": the instance is busy")));
    fmi2FreeInstance(reference);
    fmi2FreeInstance(c.ptr());
}
