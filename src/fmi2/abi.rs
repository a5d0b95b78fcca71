//! The exported FMI 2.0 functions. Every entry point that takes an instance passes one guard,
//! `entry`: the instance pointer is checked, panics are caught (a panic must never unwind into
//! the C caller), the call is checked against the state machine ([`super::state`]), and a
//! refusal is logged once, naming the function. Inside, C arguments become slices (`array`,
//! `array_mut`, null pointers refused), value references become typed positions through the
//! one table ([`super::values::indices`]), and the instance does the rest. This file, the
//! logger's callback and [`crate::fmi3::abi`] (which reuses the slice helpers here) are the only
//! places with `unsafe` in the crate: every block says why it is sound.

#![allow(non_snake_case)]
#![allow(clippy::not_unsafe_ptr_arg_deref)] // the C ABI hands us raw pointers by design

use std::ffi::{c_char, CStr, CString};
use std::panic::{catch_unwind, AssertUnwindSafe};

use fmi_sys::fmi2::*;

use super::fmu_states::FmuStates;
use super::instance::{Instance, Outcome, Status};
use super::logger::{Level, Logger};
use super::snapshot;
use super::state::{self, Mask, Phase};
use super::uri::resource_path;
use super::values::{indices, Typed};
use super::variables::{
    string, LogCategory, BODY_GUID, BODY_MODEL_IDENTIFIER, GUID, MODEL_IDENTIFIER, STRINGS,
};
use crate::cosim::FmuKind;

/// Marks a live instance allocated by `fmi2Instantiate`; cleared when freed, so a stale or
/// foreign pointer is recognised with high probability instead of being used.
const LIVE: u64 = 0x454d_4346_4d55_0001;

struct Handle {
    live: u64,
    instance: Instance,
    /// Strings returned by fmi2GetString stay valid until the next call on this instance.
    returned_strings: Vec<CString>,
    /// The FMU states this instance handed out (fmi2GetFMUstate, fmi2DeSerializeFMUstate) and
    /// that are not freed yet: they belong to it and are freed with it.
    states: FmuStates,
}

fn status(s: Status) -> fmi2Status {
    match s {
        Status::Ok => fmi2Status_fmi2OK,
        Status::Warning => fmi2Status_fmi2Warning,
        Status::Discard => fmi2Status_fmi2Discard,
        Status::Error => fmi2Status_fmi2Error,
        Status::Fatal => fmi2Status_fmi2Fatal,
    }
}

/// The guard of every entry point with an instance: runs `body` on the instance behind `c` if
/// `function` may be called in its phase (`mask`). A null or stale pointer gives fmi2Error, a
/// refusal is logged as "`function`: reason" with fmi2Error, a panic gives fmi2Fatal (the
/// instance is then unusable), and in the fatal phase only fmi2FreeInstance is allowed.
fn entry(
    c: fmi2Component,
    function: &'static str,
    mask: Mask,
    body: impl FnOnce(&mut Handle) -> Outcome,
) -> fmi2Status {
    if c.is_null() {
        return fmi2Status_fmi2Error;
    }
    let ptr = c as *mut Handle;
    // SAFETY: a non-null fmi2Component is, per FMI 2.0, the pointer fmi2Instantiate returned and
    // fmi2FreeInstance has not been called on it; the caller must not use one instance from two
    // threads at once (FMI 2.0 §2.1.4), so this is the only live reference.
    let handle = unsafe { &mut *ptr };
    if handle.live != LIVE {
        return fmi2Status_fmi2Error;
    }
    let result = catch_unwind(AssertUnwindSafe(|| {
        let inst = &handle.instance;
        inst.logger.log(Level::Info, LogCategory::Calls, function);
        let phase = inst.phase();
        if phase == Phase::Fatal {
            inst.logger.log(
                Level::Fatal,
                LogCategory::StatusError,
                &format!("{function}: the instance is in a fatal state; only fmi2FreeInstance is allowed"),
            );
            return Status::Fatal;
        }
        if !mask.allows(phase) {
            inst.log_error(&format!("{function} is not allowed in phase {phase:?}"));
            return Status::Error;
        }
        match body(handle) {
            Ok(s) => s,
            Err(message) => {
                handle.instance.log_error(&format!("{function}: {message}"));
                Status::Error
            }
        }
    }));
    match result {
        Ok(s) => status(s),
        Err(panic) => {
            let what = panic
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| panic.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".to_owned());
            let _ = catch_unwind(AssertUnwindSafe(|| {
                handle.instance.core.phase = Phase::Fatal;
                handle.instance.logger.log(
                    Level::Fatal,
                    LogCategory::StatusError,
                    &format!("{function}: internal error (bug), the instance is unusable: {what}"),
                );
            }));
            fmi2Status_fmi2Fatal
        }
    }
}

/// A slice from the C array `name` of `n` elements; a null pointer with `n > 0` is refused.
///
/// # Safety
/// `ptr` must be null or point to `n` initialised elements that stay valid and unaliased for `'a`.
pub(crate) unsafe fn array<'a, T>(ptr: *const T, n: usize, name: &str) -> Result<&'a [T], String> {
    if n == 0 {
        Ok(&[])
    } else if ptr.is_null() {
        Err(format!("argument {name} is NULL"))
    } else {
        // SAFETY: guaranteed by the caller's contract above.
        Ok(unsafe { std::slice::from_raw_parts(ptr, n) })
    }
}

/// As [`array`], for writing.
///
/// # Safety
/// As [`array`], and the elements must be writable.
pub(crate) unsafe fn array_mut<'a, T>(
    ptr: *mut T,
    n: usize,
    name: &str,
) -> Result<&'a mut [T], String> {
    if n == 0 {
        Ok(&mut [])
    } else if ptr.is_null() {
        Err(format!("argument {name} is NULL"))
    } else {
        // SAFETY: guaranteed by the caller's contract above.
        Ok(unsafe { std::slice::from_raw_parts_mut(ptr, n) })
    }
}

/// The single writable element behind `ptr`; a null pointer is refused.
///
/// # Safety
/// `ptr` must be null or point to a writable `T` valid for `'a`.
pub(crate) unsafe fn place<'a, T>(ptr: *mut T, name: &str) -> Result<&'a mut T, String> {
    // SAFETY: guaranteed by the caller's contract above.
    unsafe { ptr.as_mut() }.ok_or_else(|| format!("argument {name} is NULL"))
}

/// A Rust string from a C string; `None` for null or invalid UTF-8.
///
/// # Safety
/// `ptr` is null or a NUL-terminated string valid for the call.
pub(crate) unsafe fn text(ptr: fmi2String) -> Option<String> {
    if ptr.is_null() {
        return None;
    }
    // SAFETY: non-null and NUL-terminated by the caller's contract.
    unsafe { CStr::from_ptr(ptr) }
        .to_str()
        .ok()
        .map(str::to_owned)
}

/// Strings from the C array `name` of `n` C strings; null or non-UTF-8 entries are refused.
///
/// # Safety
/// As [`array`], each entry null or a NUL-terminated string valid for the call.
pub(crate) unsafe fn texts(
    ptr: *const fmi2String,
    n: usize,
    name: &str,
) -> Result<Vec<String>, String> {
    // SAFETY: the caller's contract.
    let raw = unsafe { array(ptr, n, name) }?;
    raw.iter()
        // SAFETY: each entry is null or NUL-terminated, by the caller's contract.
        .map(|p| unsafe { text(*p) })
        .collect::<Option<Vec<_>>>()
        .ok_or_else(|| format!("an entry of {name} is NULL or not UTF-8"))
}

// ----- inquiry ---------------------------------------------------------------------------------

/// Returns `"default"`: the FMU uses the standard FMI 2.0 C types. Needs no instance.
#[no_mangle]
pub extern "C" fn fmi2GetTypesPlatform() -> *const c_char {
    c"default".as_ptr()
}
const _: fmi2GetTypesPlatformTYPE = Some(fmi2GetTypesPlatform);

/// Returns `"2.0"`, the FMI version of the headers this FMU was compiled against. Needs no instance.
#[no_mangle]
pub extern "C" fn fmi2GetVersion() -> *const c_char {
    c"2.0".as_ptr()
}
const _: fmi2GetVersionTYPE = Some(fmi2GetVersion);

// ----- creation and destruction ----------------------------------------------------------------

/// Creates an instance and returns its handle, or null after logging why through the master's
/// logger: a missing `instanceName`, a `fmuType` other than co-simulation, a GUID that is not
/// this FMU's, or a resource location that is not a directory. The model itself is built only in
/// [`fmi2ExitInitializationMode`], or earlier when an output or a calculated parameter is read
/// in initialisation mode.
#[no_mangle]
pub extern "C" fn fmi2Instantiate(
    instanceName: fmi2String,
    fmuType: fmi2Type,
    fmuGUID: fmi2String,
    fmuResourceLocation: fmi2String,
    functions: *const fmi2CallbackFunctions,
    _visible: fmi2Boolean,
    loggingOn: fmi2Boolean,
) -> fmi2Component {
    let result = catch_unwind(AssertUnwindSafe(|| {
        let (callback, environment) = if functions.is_null() {
            (None, std::ptr::null_mut())
        } else {
            // SAFETY: non-null; FMI 2.0 requires it to point to a callback struct that stays
            // valid for the instance's lifetime. We copy the two fields we use.
            let f = unsafe { &*functions };
            (f.logger, f.componentEnvironment)
        };
        // SAFETY: FMI strings are NUL-terminated or null.
        let (name, guid, resources) = unsafe {
            (
                text(instanceName).unwrap_or_default(),
                text(fmuGUID).unwrap_or_default(),
                text(fmuResourceLocation),
            )
        };
        let logger = Logger::new(callback, environment, &name, loggingOn != 0);
        let refuse = |logger: &Logger, message: &str| {
            let message = format!("fmi2Instantiate: {message}");
            logger.log(Level::Error, LogCategory::StatusError, &message);
            std::ptr::null_mut()
        };
        if name.is_empty() {
            return refuse(&logger, "instanceName is missing");
        }
        if fmuType != fmi2Type_fmi2CoSimulation {
            return refuse(
                &logger,
                "this FMU supports co-simulation only (fmuType must be fmi2CoSimulation)",
            );
        }
        let kind = if guid == GUID {
            FmuKind::Engine
        } else if guid == BODY_GUID {
            FmuKind::Body
        } else {
            return refuse(
                &logger,
                &format!(
                    "GUID \"{guid}\" matches neither {MODEL_IDENTIFIER} ({GUID}) nor {BODY_MODEL_IDENTIFIER} ({BODY_GUID}), the FMUs of this library"
                ),
            );
        };
        let resource_dir = match resource_dir(resources.as_deref()) {
            Ok(dir) => dir,
            Err(m) => return refuse(&logger, &m),
        };
        if resource_dir.is_none() {
            let config = STRINGS[string::CONFIG_FILE as usize].name;
            logger.log(
                Level::Warning,
                LogCategory::StatusWarning,
                &format!("fmi2Instantiate: no resource location given; the built-in vehicle is used unless {config} names an absolute path"),
            );
        }
        let handle = Box::new(Handle {
            live: LIVE,
            instance: Instance::new(&name, kind, logger, resource_dir),
            returned_strings: Vec::new(),
            states: FmuStates::default(),
        });
        Box::into_raw(handle) as fmi2Component
    }));
    result.unwrap_or(std::ptr::null_mut())
}

/// The resource directory a resource location URI names (`None`: no location given).
fn resource_dir(uri: Option<&str>) -> Result<Option<std::path::PathBuf>, String> {
    let Some(uri) = uri else {
        return Ok(None);
    };
    let path = resource_path(uri)?;
    if !path.is_dir() {
        return Err(format!(
            "the resource location {uri} names {}, which is not a directory",
            path.display()
        ));
    }
    Ok(Some(path))
}
const _: fmi2InstantiateTYPE = Some(fmi2Instantiate);

/// Frees the instance and every FMU state it handed out. A null or already freed handle is
/// ignored; allowed in every phase, including after a fatal error.
#[no_mangle]
pub extern "C" fn fmi2FreeInstance(c: fmi2Component) {
    if c.is_null() {
        return;
    }
    let ptr = c as *mut Handle;
    // SAFETY: c came from fmi2Instantiate (Box::into_raw) and is freed at most once by contract;
    // the live marker catches the common double free before we take ownership back.
    unsafe {
        if (*ptr).live != LIVE {
            return;
        }
        (*ptr).live = 0;
        drop(Box::from_raw(ptr));
    }
}
const _: fmi2FreeInstanceTYPE = Some(fmi2FreeInstance);

/// Without categories, switches debug logging on or off for all of them; with categories and
/// `loggingOn`, logs exactly those; with categories and not `loggingOn`, switches those off. An
/// unknown category name is refused with fmi2Error. Errors and warnings are always logged.
#[no_mangle]
pub extern "C" fn fmi2SetDebugLogging(
    c: fmi2Component,
    loggingOn: fmi2Boolean,
    nCategories: usize,
    categories: *const fmi2String,
) -> fmi2Status {
    entry(c, "fmi2SetDebugLogging", state::SET_DEBUG_LOGGING, |h| {
        // SAFETY: FMI passes an array of nCategories C strings.
        let names = unsafe { texts(categories, nCategories, "categories") }?;
        h.instance
            .logger
            .set_debug_logging(loggingOn != 0, &names)?;
        Ok(Status::Ok)
    })
}
const _: fmi2SetDebugLoggingTYPE = Some(fmi2SetDebugLogging);

// ----- initialisation, termination, reset ------------------------------------------------------

/// Sets the start time and the optional stop time (finite, not before the start) and the
/// optional tolerance, which becomes the integrator's relative tolerance unless `solver.relTol`
/// was set explicitly; a tolerance outside `solver.relTol`'s range is refused.
#[no_mangle]
pub extern "C" fn fmi2SetupExperiment(
    c: fmi2Component,
    toleranceDefined: fmi2Boolean,
    tolerance: fmi2Real,
    startTime: fmi2Real,
    stopTimeDefined: fmi2Boolean,
    stopTime: fmi2Real,
) -> fmi2Status {
    entry(c, "fmi2SetupExperiment", state::SETUP_EXPERIMENT, |h| {
        h.instance.setup_experiment(
            startTime,
            (stopTimeDefined != 0).then_some(stopTime),
            (toleranceDefined != 0).then_some(tolerance),
        )
    })
}
const _: fmi2SetupExperimentTYPE = Some(fmi2SetupExperiment);

/// Enters initialisation mode, where parameters and inputs may still be set and outputs already
/// read (they are then those of the static equilibrium).
#[no_mangle]
pub extern "C" fn fmi2EnterInitializationMode(c: fmi2Component) -> fmi2Status {
    entry(
        c,
        "fmi2EnterInitializationMode",
        state::ENTER_INITIALIZATION,
        |h| h.instance.enter_initialization(),
    )
}
const _: fmi2EnterInitializationModeTYPE = Some(fmi2EnterInitializationMode);

/// Builds the model from the parameters (loading the configuration and reducing or reading the
/// cached chassis for scene 2), finds its static equilibrium (or the periodic steady state with
/// `initialization.periodic`) and enters step mode. A model that cannot be built is refused with
/// fmi2Error and the reason logged.
#[no_mangle]
pub extern "C" fn fmi2ExitInitializationMode(c: fmi2Component) -> fmi2Status {
    entry(
        c,
        "fmi2ExitInitializationMode",
        state::EXIT_INITIALIZATION,
        |h| h.instance.exit_initialization(),
    )
}
const _: fmi2ExitInitializationModeTYPE = Some(fmi2ExitInitializationMode);

/// Ends the simulation: afterwards values can still be read, but no step taken.
#[no_mangle]
pub extern "C" fn fmi2Terminate(c: fmi2Component) -> fmi2Status {
    entry(c, "fmi2Terminate", state::TERMINATE, |h| {
        h.instance.terminate()
    })
}
const _: fmi2TerminateTYPE = Some(fmi2Terminate);

/// Returns the instance to the state just after instantiation: start values, no model, no
/// experiment. FMU states handed out stay valid.
#[no_mangle]
pub extern "C" fn fmi2Reset(c: fmi2Component) -> fmi2Status {
    entry(c, "fmi2Reset", state::RESET, |h| h.instance.reset())
}
const _: fmi2ResetTYPE = Some(fmi2Reset);

// ----- getting and setting values --------------------------------------------------------------

/// `fmi2GetXXX`: the values of type `T` behind `vr`, written to `value` through `convert`.
fn get_values<T: Typed, C>(
    c: fmi2Component,
    function: &'static str,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut C,
    convert: impl Fn(T) -> C,
) -> fmi2Status {
    entry(c, function, state::GET_VALUES, |h| {
        // SAFETY: FMI passes arrays of nvr value references and nvr values.
        let (vrs, out) = unsafe { (array(vr, nvr, "vr")?, array_mut(value, nvr, "value")?) };
        let read = h.instance.get::<T>(&indices::<T>(vrs)?)?;
        for (o, x) in out.iter_mut().zip(read) {
            *o = convert(x);
        }
        Ok(Status::Ok)
    })
}

/// `fmi2SetXXX`: the values of type `T` behind `vr`, read from `value` through `convert`.
fn set_values<T: Typed, C: Copy>(
    c: fmi2Component,
    function: &'static str,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const C,
    convert: impl Fn(u32, C) -> Result<T, String>,
) -> fmi2Status {
    entry(c, function, state::SET_VALUES, |h| {
        // SAFETY: FMI passes arrays of nvr value references and nvr values.
        let (vrs, given) = unsafe { (array(vr, nvr, "vr")?, array(value, nvr, "value")?) };
        let values = vrs
            .iter()
            .zip(given)
            .map(|(vr, x)| convert(*vr, *x))
            .collect::<Result<Vec<T>, String>>()?;
        h.instance.set::<T>(&indices::<T>(vrs)?, &values)
    })
}

fn boolean(vr: u32, b: fmi2Boolean) -> Result<bool, String> {
    match b {
        0 => Ok(false),
        1 => Ok(true),
        other => Err(format!(
            "value {other} for value reference {vr} is neither fmi2True (1) nor fmi2False (0)"
        )),
    }
}

/// Reads Real variables. Calculated parameters (the natural modes `mode[k].*`) are computed on
/// first read; outputs read in initialisation mode build the model first. An unknown value
/// reference is refused.
#[no_mangle]
pub extern "C" fn fmi2GetReal(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Real,
) -> fmi2Status {
    get_values::<f64, _>(c, "fmi2GetReal", vr, nvr, value, |x| x)
}
const _: fmi2GetRealTYPE = Some(fmi2GetReal);

/// Reads Integer variables (the solver counters, `modes.count` and the Integer parameters); an
/// unknown value reference is refused.
#[no_mangle]
pub extern "C" fn fmi2GetInteger(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Integer,
) -> fmi2Status {
    get_values::<i32, _>(c, "fmi2GetInteger", vr, nvr, value, |x| x)
}
const _: fmi2GetIntegerTYPE = Some(fmi2GetInteger);

/// Reads Boolean variables (the effect switches and other Boolean parameters) as fmi2True or
/// fmi2False; an unknown value reference is refused.
#[no_mangle]
pub extern "C" fn fmi2GetBoolean(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Boolean,
) -> fmi2Status {
    get_values::<bool, _>(c, "fmi2GetBoolean", vr, nvr, value, |x| {
        fmi2Boolean::from(x)
    })
}
const _: fmi2GetBooleanTYPE = Some(fmi2GetBoolean);

/// Reads String variables. The returned pointers stay valid until the next fmi2GetString on
/// this instance or until it is freed; an unknown value reference is refused.
#[no_mangle]
pub extern "C" fn fmi2GetString(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2String,
) -> fmi2Status {
    entry(c, "fmi2GetString", state::GET_VALUES, |h| {
        // SAFETY: FMI passes arrays of nvr value references and nvr string slots.
        let (vrs, out) = unsafe { (array(vr, nvr, "vr")?, array_mut(value, nvr, "value")?) };
        let read = h.instance.get::<String>(&indices::<String>(vrs)?)?;
        h.returned_strings = read
            .iter()
            .map(|t| CString::new(t.replace('\0', "")).unwrap_or_default())
            .collect();
        for (o, t) in out.iter_mut().zip(&h.returned_strings) {
            *o = t.as_ptr();
        }
        Ok(Status::Ok)
    })
}
const _: fmi2GetStringTYPE = Some(fmi2GetString);

/// Sets Real inputs and parameters. All values are checked (range, finiteness, whether the
/// variable may be set in this phase: fixed parameters only before initialisation ends) before any
/// is applied, so a refused call changes nothing. An input set between steps takes effect at the
/// next fmi2DoStep: as a ramp with a derivative set by fmi2SetRealInputDerivatives, otherwise as
/// a first-order hold of the values set (see [`super::input_track`]).
#[no_mangle]
pub extern "C" fn fmi2SetReal(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Real,
) -> fmi2Status {
    set_values::<f64, _>(c, "fmi2SetReal", vr, nvr, value, |_, x| Ok(x))
}
const _: fmi2SetRealTYPE = Some(fmi2SetReal);

/// Sets Integer parameters (e.g. `scene`, `solver.maxOrder`): all checked for range and phase
/// before any is applied; outputs and calculated parameters are refused.
#[no_mangle]
pub extern "C" fn fmi2SetInteger(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Integer,
) -> fmi2Status {
    set_values::<i32, _>(c, "fmi2SetInteger", vr, nvr, value, |_, x| Ok(x))
}
const _: fmi2SetIntegerTYPE = Some(fmi2SetInteger);

/// Sets Boolean parameters (the effect switches, …): all checked before any is applied; a value
/// other than fmi2True (1) or fmi2False (0) is refused.
#[no_mangle]
pub extern "C" fn fmi2SetBoolean(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Boolean,
) -> fmi2Status {
    set_values::<bool, _>(c, "fmi2SetBoolean", vr, nvr, value, boolean)
}
const _: fmi2SetBooleanTYPE = Some(fmi2SetBoolean);

/// Sets String parameters (`configFile`, `chassis.cacheDir`): all checked before any is
/// applied; a null or non-UTF-8 string is refused.
#[no_mangle]
pub extern "C" fn fmi2SetString(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2String,
) -> fmi2Status {
    set_values::<String, _>(c, "fmi2SetString", vr, nvr, value, |_, p| {
        // SAFETY: each entry of an FMI string array is null or NUL-terminated.
        unsafe { text(p) }.ok_or_else(|| "a value is NULL or not UTF-8".to_owned())
    })
}
const _: fmi2SetStringTYPE = Some(fmi2SetString);

// ----- FMU state -------------------------------------------------------------------------------

/// Copies the instance's complete state (values, input signals, time and integrator history)
/// into a new FMU state, or into the given one if `*FMUstate` is a state of this instance.
#[no_mangle]
pub extern "C" fn fmi2GetFMUstate(c: fmi2Component, FMUstate: *mut fmi2FMUstate) -> fmi2Status {
    entry(c, "fmi2GetFMUstate", state::FMU_STATE, |h| {
        // SAFETY: FMUstate points to a writable fmi2FMUstate slot (FMI 2.0 §2.1.8).
        let slot = unsafe { place(FMUstate, "FMUstate") }?;
        let core = h.instance.core.clone();
        h.states.store(slot, core)
    })
}
const _: fmi2GetFMUstateTYPE = Some(fmi2GetFMUstate);

/// Restores a state this instance handed out. Refused if the state was taken with different
/// parameters than the model this instance has built (it would silently change the model).
#[no_mangle]
pub extern "C" fn fmi2SetFMUstate(c: fmi2Component, FMUstate: fmi2FMUstate) -> fmi2Status {
    entry(c, "fmi2SetFMUstate", state::FMU_STATE, |h| {
        let core = h.states.core(FMUstate)?;
        h.instance.check_state_fits(core)?;
        h.instance.core = core.clone();
        Ok(Status::Ok)
    })
}
const _: fmi2SetFMUstateTYPE = Some(fmi2SetFMUstate);

/// Frees an FMU state of this instance and sets `*FMUstate` to null; a null state is ignored, a
/// foreign pointer refused.
#[no_mangle]
pub extern "C" fn fmi2FreeFMUstate(c: fmi2Component, FMUstate: *mut fmi2FMUstate) -> fmi2Status {
    entry(c, "fmi2FreeFMUstate", state::FMU_STATE, |h| {
        // SAFETY: FMUstate is null or points to a slot holding null or a state we handed out.
        let Some(slot) = (unsafe { FMUstate.as_mut() }) else {
            return Ok(Status::Ok);
        };
        h.states.free(slot)
    })
}
const _: fmi2FreeFMUstateTYPE = Some(fmi2FreeFMUstate);

/// Writes the number of bytes [`fmi2SerializeFMUstate`] needs for this state.
#[no_mangle]
pub extern "C" fn fmi2SerializedFMUstateSize(
    c: fmi2Component,
    FMUstate: fmi2FMUstate,
    size: *mut usize,
) -> fmi2Status {
    entry(c, "fmi2SerializedFMUstateSize", state::FMU_STATE, |h| {
        let bytes = h.states.serialized(FMUstate, h.instance.guid())?;
        // SAFETY: size points to a writable usize.
        let size = unsafe { place(size, "size") }?;
        *size = bytes.len();
        Ok(Status::Ok)
    })
}
const _: fmi2SerializedFMUstateSizeTYPE = Some(fmi2SerializedFMUstateSize);

/// Serialises an FMU state of this instance into the caller's buffer, which must have exactly
/// the size [`fmi2SerializedFMUstateSize`] reported.
#[no_mangle]
pub extern "C" fn fmi2SerializeFMUstate(
    c: fmi2Component,
    FMUstate: fmi2FMUstate,
    serializedState: *mut fmi2Byte,
    size: usize,
) -> fmi2Status {
    entry(c, "fmi2SerializeFMUstate", state::FMU_STATE, |h| {
        // SAFETY: the caller provides a writable buffer of `size` bytes.
        let out = unsafe { array_mut(serializedState as *mut u8, size, "serializedState") }?;
        h.states.serialize_into(FMUstate, h.instance.guid(), out)?;
        Ok(Status::Ok)
    })
}
const _: fmi2SerializeFMUstateTYPE = Some(fmi2SerializeFMUstate);

/// Creates an FMU state from bytes of [`fmi2SerializeFMUstate`], possibly written by another
/// process; bytes of an FMU with another GUID, malformed or with inadmissible values are
/// refused. The model is rebuilt from the state's own parameters.
#[no_mangle]
pub extern "C" fn fmi2DeSerializeFMUstate(
    c: fmi2Component,
    serializedState: *const fmi2Byte,
    size: usize,
    FMUstate: *mut fmi2FMUstate,
) -> fmi2Status {
    entry(c, "fmi2DeSerializeFMUstate", state::FMU_STATE, |h| {
        // SAFETY: the caller provides `size` readable bytes and a writable state slot.
        let (bytes, slot) = unsafe {
            (
                array(serializedState as *const u8, size, "serializedState")?,
                place(FMUstate, "FMUstate")?,
            )
        };
        let inst = &h.instance;
        let core = snapshot::deserialize(bytes, inst.guid(), |core, dynamic| {
            inst.restore_simulation(core, dynamic)
        })?;
        h.states.store(slot, core)
    })
}
const _: fmi2DeSerializeFMUstateTYPE = Some(fmi2DeSerializeFMUstate);

/// Directional derivatives of Real outputs with respect to Real inputs between steps
/// (`providesDirectionalDerivative="true"`): `dvUnknown[i] = Σ_k ∂unknown_i/∂known_k · dvKnown[k]`
/// at the current communication point, the state held. Non-zero only through the interface
/// inputs the model structure declares as direct dependencies.
#[no_mangle]
pub extern "C" fn fmi2GetDirectionalDerivative(
    c: fmi2Component,
    vUnknown_ref: *const fmi2ValueReference,
    nUnknown: usize,
    vKnown_ref: *const fmi2ValueReference,
    nKnown: usize,
    dvKnown: *const fmi2Real,
    dvUnknown: *mut fmi2Real,
) -> fmi2Status {
    entry(
        c,
        "fmi2GetDirectionalDerivative",
        state::DIRECTIONAL_DERIVATIVE,
        |h| {
            // SAFETY: FMI passes nUnknown unknown references, nKnown known references and seeds,
            // and a writable array of nUnknown results.
            let (unknowns, knowns, seeds, out) = unsafe {
                (
                    array(vUnknown_ref, nUnknown, "vUnknown_ref")?,
                    array(vKnown_ref, nKnown, "vKnown_ref")?,
                    array(dvKnown, nKnown, "dvKnown")?,
                    array_mut(dvUnknown, nUnknown, "dvUnknown")?,
                )
            };
            let unknowns = indices::<f64>(unknowns)?;
            let knowns = indices::<f64>(knowns)?;
            let values = h
                .instance
                .directional_derivative(&unknowns, &knowns, seeds)?;
            out.copy_from_slice(&values);
            Ok(Status::Ok)
        },
    )
}
const _: fmi2GetDirectionalDerivativeTYPE = Some(fmi2GetDirectionalDerivative);

// ----- co-simulation ---------------------------------------------------------------------------

/// Sets the first time derivatives of Real inputs: each input then ramps linearly over the
/// coming steps (bent onto its declared bound, with a warning, if the ramp would leave its range).
/// Only order 1 and inputs are accepted.
#[no_mangle]
pub extern "C" fn fmi2SetRealInputDerivatives(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    order: *const fmi2Integer,
    value: *const fmi2Real,
) -> fmi2Status {
    entry(
        c,
        "fmi2SetRealInputDerivatives",
        state::SET_INPUT_DERIVATIVES,
        |h| {
            // SAFETY: FMI passes three arrays of nvr elements.
            let (vrs, orders, values) = unsafe {
                (
                    array(vr, nvr, "vr")?,
                    array(order, nvr, "order")?,
                    array(value, nvr, "value")?,
                )
            };
            h.instance
                .set_real_input_derivatives(&indices::<f64>(vrs)?, orders, values)
        },
    )
}
const _: fmi2SetRealInputDerivativesTYPE = Some(fmi2SetRealInputDerivatives);

/// Always refused with fmi2Error: the model description declares
/// `maxOutputDerivativeOrder="0"`.
#[no_mangle]
pub extern "C" fn fmi2GetRealOutputDerivatives(
    c: fmi2Component,
    _vr: *const fmi2ValueReference,
    _nvr: usize,
    _order: *const fmi2Integer,
    _value: *mut fmi2Real,
) -> fmi2Status {
    entry(
        c,
        "fmi2GetRealOutputDerivatives",
        state::GET_OUTPUT_DERIVATIVES,
        |_| Err("not provided (maxOutputDerivativeOrder=0)".into()),
    )
}
const _: fmi2GetRealOutputDerivativesTYPE = Some(fmi2GetRealOutputDerivatives);

/// Integrates from `currentCommunicationPoint` (which must be the FMU's time) over
/// `communicationStepSize` (> 0, not past the stop time). Returns fmi2Warning if an input ramp was
/// bent onto a bound, and fmi2Discard if the integrator failed: the FMU then stays at the last
/// successful time and reports itself terminated.
#[no_mangle]
pub extern "C" fn fmi2DoStep(
    c: fmi2Component,
    currentCommunicationPoint: fmi2Real,
    communicationStepSize: fmi2Real,
    _noSetFMUStatePriorToCurrentPoint: fmi2Boolean,
) -> fmi2Status {
    entry(c, "fmi2DoStep", state::DO_STEP, |h| {
        h.instance
            .do_step(currentCommunicationPoint, communicationStepSize)
    })
}
const _: fmi2DoStepTYPE = Some(fmi2DoStep);

/// Always refused with fmi2Error: fmi2DoStep completes before returning, so no step is ever in
/// progress.
#[no_mangle]
pub extern "C" fn fmi2CancelStep(c: fmi2Component) -> fmi2Status {
    entry(c, "fmi2CancelStep", state::CANCEL_STEP, |_| {
        Err("no step is in progress (fmi2DoStep always completes synchronously)".into())
    })
}
const _: fmi2CancelStepTYPE = Some(fmi2CancelStep);

/// The status kinds without a value of the asked type.
fn no_status(kind: fmi2StatusKind, ty: &str) -> Outcome {
    Err(format!("status kind {kind} has no {ty} value"))
}

/// Always refused with fmi2Error: no asynchronous step exists whose status could be asked.
#[no_mangle]
pub extern "C" fn fmi2GetStatus(
    c: fmi2Component,
    _s: fmi2StatusKind,
    _value: *mut fmi2Status,
) -> fmi2Status {
    entry(c, "fmi2GetStatus", state::GET_STATUS, |_| {
        Err("no asynchronous step status exists (canRunAsynchronuously=false)".into())
    })
}
const _: fmi2GetStatusTYPE = Some(fmi2GetStatus);

/// Gives `fmi2LastSuccessfulTime` (s), the time the FMU has reached (after a discarded step,
/// where the integrator stopped); other status kinds are refused.
#[no_mangle]
pub extern "C" fn fmi2GetRealStatus(
    c: fmi2Component,
    s: fmi2StatusKind,
    value: *mut fmi2Real,
) -> fmi2Status {
    entry(c, "fmi2GetRealStatus", state::GET_STATUS, |h| {
        if s != fmi2StatusKind_fmi2LastSuccessfulTime {
            return no_status(s, "Real");
        }
        // SAFETY: value points to a writable fmi2Real.
        *unsafe { place(value, "value") }? = h.instance.last_successful_time();
        Ok(Status::Ok)
    })
}
const _: fmi2GetRealStatusTYPE = Some(fmi2GetRealStatus);

/// Always refused with fmi2Error: no status kind has an Integer value.
#[no_mangle]
pub extern "C" fn fmi2GetIntegerStatus(
    c: fmi2Component,
    s: fmi2StatusKind,
    _value: *mut fmi2Integer,
) -> fmi2Status {
    entry(c, "fmi2GetIntegerStatus", state::GET_STATUS, |_| {
        no_status(s, "Integer")
    })
}
const _: fmi2GetIntegerStatusTYPE = Some(fmi2GetIntegerStatus);

/// Gives `fmi2Terminated`: true after a failed step (the simulation cannot go on); other status
/// kinds are refused.
#[no_mangle]
pub extern "C" fn fmi2GetBooleanStatus(
    c: fmi2Component,
    s: fmi2StatusKind,
    value: *mut fmi2Boolean,
) -> fmi2Status {
    entry(c, "fmi2GetBooleanStatus", state::GET_STATUS, |h| {
        if s != fmi2StatusKind_fmi2Terminated {
            return no_status(s, "Boolean");
        }
        // SAFETY: value points to a writable fmi2Boolean.
        *unsafe { place(value, "value") }? = fmi2Boolean::from(h.instance.core.terminated);
        Ok(Status::Ok)
    })
}
const _: fmi2GetBooleanStatusTYPE = Some(fmi2GetBooleanStatus);

/// Always refused with fmi2Error: `fmi2PendingStatus` needs an asynchronous step, which does not
/// exist.
#[no_mangle]
pub extern "C" fn fmi2GetStringStatus(
    c: fmi2Component,
    s: fmi2StatusKind,
    _value: *mut fmi2String,
) -> fmi2Status {
    entry(c, "fmi2GetStringStatus", state::GET_STATUS, |_| {
        no_status(s, "String")
    })
}
const _: fmi2GetStringStatusTYPE = Some(fmi2GetStringStatus);

#[cfg(test)]
#[path = "abi_state_table.rs"]
mod state_table;
