//! The exported FMI 2.0 functions. Each one checks its pointers, catches panics (a panic must
//! never unwind into the C caller) and delegates to [`Instance`]. This file is the only place
//! with `unsafe` in the crate: every block says why it is sound.

#![allow(non_snake_case)]
#![allow(clippy::not_unsafe_ptr_arg_deref)] // the C ABI hands us raw pointers by design

use std::ffi::{c_char, CStr, CString};
use std::panic::{catch_unwind, AssertUnwindSafe};

use fmi_sys::fmi2::*;

use super::instance::{Core, Instance, Status};
use super::logger::{Level, Logger};
use super::snapshot;
use super::state::{self, Phase};
use super::uri::resource_path;
use super::variables::{BOOLEANS, GUID, INTEGERS, REALS, STRINGS, VR_BASE};

/// Marks a live instance allocated by `fmi2Instantiate`; cleared when freed, so a stale or
/// foreign pointer is recognised with high probability instead of being used.
const LIVE: u64 = 0x454d_4346_4d55_0001;

struct Handle {
    live: u64,
    instance: Instance,
    /// Strings returned by fmi2GetString stay valid until the next call on this instance.
    returned_strings: Vec<CString>,
    /// The FMU states this instance handed out (fmi2GetFMUstate, fmi2DeSerializeFMUstate) and
    /// that are not freed yet: they belong to it and are freed with it. A state pointer is
    /// recognised by its address among these, never dereferenced on trust. Boxed so that a
    /// state keeps its address, which the master holds, when the vector grows.
    #[allow(clippy::vec_box)]
    states: Vec<Box<StateHandle>>,
}

/// An FMU state handed out by `fmi2GetFMUstate`.
struct StateHandle {
    core: Core,
}

/// Index of the state behind `state` among an instance's `states`.
fn state_index(states: &[Box<StateHandle>], state: fmi2FMUstate) -> Option<usize> {
    states
        .iter()
        .position(|s| std::ptr::eq(&**s, state as *const StateHandle))
}

/// Keeps `core` as a new state among `states` and returns its handle.
#[allow(clippy::vec_box)] // the box gives the state the stable address the master holds
fn new_state(states: &mut Vec<Box<StateHandle>>, core: Core) -> fmi2FMUstate {
    let mut boxed = Box::new(StateHandle { core });
    let ptr: *mut StateHandle = &mut *boxed;
    states.push(boxed);
    ptr as fmi2FMUstate
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

/// Runs `f` on the instance behind `c`, turning a null/stale pointer into fmi2Error and a panic
/// into fmi2Fatal (the instance is then unusable).
fn with_handle(c: fmi2Component, f: impl FnOnce(&mut Handle) -> Status) -> fmi2Status {
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
    match catch_unwind(AssertUnwindSafe(|| f(handle))) {
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
                    "logStatusError",
                    &format!("internal error (bug), the instance is unusable: {what}"),
                );
            }));
            fmi2Status_fmi2Fatal
        }
    }
}

/// A slice from a C array of `n` elements; `None` for a null pointer with `n > 0`.
///
/// # Safety
/// `ptr` must point to `n` initialised elements that stay valid and unaliased for `'a`.
unsafe fn slice<'a, T>(ptr: *const T, n: usize) -> Option<&'a [T]> {
    if n == 0 {
        Some(&[])
    } else if ptr.is_null() {
        None
    } else {
        // SAFETY: guaranteed by the caller's contract above.
        Some(unsafe { std::slice::from_raw_parts(ptr, n) })
    }
}

/// # Safety
/// As [`slice`], for writing.
unsafe fn slice_mut<'a, T>(ptr: *mut T, n: usize) -> Option<&'a mut [T]> {
    if n == 0 {
        Some(&mut [])
    } else if ptr.is_null() {
        None
    } else {
        // SAFETY: guaranteed by the caller's contract above.
        Some(unsafe { std::slice::from_raw_parts_mut(ptr, n) })
    }
}

/// A Rust string from a C string; `None` for null or invalid UTF-8.
///
/// # Safety
/// `ptr` is null or a NUL-terminated string valid for the call.
unsafe fn text(ptr: fmi2String) -> Option<String> {
    if ptr.is_null() {
        return None;
    }
    // SAFETY: non-null and NUL-terminated by the caller's contract.
    unsafe { CStr::from_ptr(ptr) }
        .to_str()
        .ok()
        .map(str::to_owned)
}

fn null_argument(inst: &Instance, function: &str) -> Status {
    inst.error(&format!("{function}: a required pointer argument is NULL"))
}

// ----- inquiry ---------------------------------------------------------------------------------

#[no_mangle]
pub extern "C" fn fmi2GetTypesPlatform() -> *const c_char {
    c"default".as_ptr()
}
const _: fmi2GetTypesPlatformTYPE = Some(fmi2GetTypesPlatform);

#[no_mangle]
pub extern "C" fn fmi2GetVersion() -> *const c_char {
    c"2.0".as_ptr()
}
const _: fmi2GetVersionTYPE = Some(fmi2GetVersion);

// ----- creation and destruction ----------------------------------------------------------------

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
        let name = unsafe { text(instanceName) }.unwrap_or_default();
        let logger = Logger::new(callback, environment, &name, loggingOn != 0);
        if instanceName.is_null() || name.is_empty() {
            logger.log(
                Level::Error,
                "logStatusError",
                "fmi2Instantiate: instanceName is missing",
            );
            return std::ptr::null_mut();
        }
        if fmuType != fmi2Type_fmi2CoSimulation {
            logger.log(
                Level::Error,
                "logStatusError",
                "fmi2Instantiate: this FMU supports co-simulation only (fmuType must be fmi2CoSimulation)",
            );
            return std::ptr::null_mut();
        }
        // SAFETY: as above.
        let guid = unsafe { text(fmuGUID) }.unwrap_or_default();
        if guid != GUID {
            logger.log(
                Level::Error,
                "logStatusError",
                &format!("fmi2Instantiate: GUID \"{guid}\" does not match this FMU's {GUID}"),
            );
            return std::ptr::null_mut();
        }
        // SAFETY: as above.
        let resource_dir = match unsafe { text(fmuResourceLocation) } {
            None => {
                logger.log(
                    Level::Warning,
                    "logStatusWarning",
                    "fmi2Instantiate: no resource location given; the built-in vehicle is used unless configFile names an absolute path",
                );
                None
            }
            Some(uri) => match resource_path(&uri) {
                Ok(p) if p.is_dir() => Some(p),
                Ok(p) => {
                    logger.log(
                        Level::Error,
                        "logStatusError",
                        &format!("fmi2Instantiate: the resource location {uri} names {}, which is not a directory", p.display()),
                    );
                    return std::ptr::null_mut();
                }
                Err(m) => {
                    logger.log(
                        Level::Error,
                        "logStatusError",
                        &format!("fmi2Instantiate: {m}"),
                    );
                    return std::ptr::null_mut();
                }
            },
        };
        let handle = Box::new(Handle {
            live: LIVE,
            instance: Instance::new(&name, logger, resource_dir),
            returned_strings: Vec::new(),
            states: Vec::new(),
        });
        Box::into_raw(handle) as fmi2Component
    }));
    result.unwrap_or(std::ptr::null_mut())
}
const _: fmi2InstantiateTYPE = Some(fmi2Instantiate);

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

#[no_mangle]
pub extern "C" fn fmi2SetDebugLogging(
    c: fmi2Component,
    loggingOn: fmi2Boolean,
    nCategories: usize,
    categories: *const fmi2String,
) -> fmi2Status {
    with_handle(c, |h| {
        let inst = &mut h.instance;
        if let Err(s) = inst.allowed("fmi2SetDebugLogging", state::ANY_BUT_FATAL) {
            return s;
        }
        // SAFETY: FMI passes an array of nCategories C strings.
        let Some(raw) = (unsafe { slice(categories, nCategories) }) else {
            return null_argument(inst, "fmi2SetDebugLogging");
        };
        // SAFETY: each entry is a NUL-terminated string (or null, rejected below).
        let names: Option<Vec<String>> = raw.iter().map(|p| unsafe { text(*p) }).collect();
        let Some(names) = names else {
            return inst.error("fmi2SetDebugLogging: a category name is NULL or not UTF-8");
        };
        match inst.logger.set_debug_logging(loggingOn != 0, &names) {
            Ok(()) => Status::Ok,
            Err(m) => inst.error(&format!("fmi2SetDebugLogging: {m}")),
        }
    })
}
const _: fmi2SetDebugLoggingTYPE = Some(fmi2SetDebugLogging);

// ----- initialisation, termination, reset ------------------------------------------------------

#[no_mangle]
pub extern "C" fn fmi2SetupExperiment(
    c: fmi2Component,
    toleranceDefined: fmi2Boolean,
    tolerance: fmi2Real,
    startTime: fmi2Real,
    stopTimeDefined: fmi2Boolean,
    stopTime: fmi2Real,
) -> fmi2Status {
    with_handle(c, |h| {
        let inst = &mut h.instance;
        if let Err(s) = inst.allowed("fmi2SetupExperiment", state::SETUP_EXPERIMENT) {
            return s;
        }
        inst.setup_experiment(
            startTime,
            (stopTimeDefined != 0).then_some(stopTime),
            (toleranceDefined != 0).then_some(tolerance),
        )
    })
}
const _: fmi2SetupExperimentTYPE = Some(fmi2SetupExperiment);

#[no_mangle]
pub extern "C" fn fmi2EnterInitializationMode(c: fmi2Component) -> fmi2Status {
    with_handle(c, |h| {
        let inst = &mut h.instance;
        if let Err(s) = inst.allowed("fmi2EnterInitializationMode", state::ENTER_INITIALIZATION) {
            return s;
        }
        inst.enter_initialization()
    })
}
const _: fmi2EnterInitializationModeTYPE = Some(fmi2EnterInitializationMode);

#[no_mangle]
pub extern "C" fn fmi2ExitInitializationMode(c: fmi2Component) -> fmi2Status {
    with_handle(c, |h| {
        let inst = &mut h.instance;
        if let Err(s) = inst.allowed("fmi2ExitInitializationMode", state::EXIT_INITIALIZATION) {
            return s;
        }
        inst.exit_initialization()
    })
}
const _: fmi2ExitInitializationModeTYPE = Some(fmi2ExitInitializationMode);

#[no_mangle]
pub extern "C" fn fmi2Terminate(c: fmi2Component) -> fmi2Status {
    with_handle(c, |h| {
        let inst = &mut h.instance;
        if let Err(s) = inst.allowed("fmi2Terminate", state::TERMINATE) {
            return s;
        }
        inst.terminate()
    })
}
const _: fmi2TerminateTYPE = Some(fmi2Terminate);

#[no_mangle]
pub extern "C" fn fmi2Reset(c: fmi2Component) -> fmi2Status {
    with_handle(c, |h| {
        let inst = &mut h.instance;
        if let Err(s) = inst.allowed("fmi2Reset", state::ANY_BUT_FATAL) {
            return s;
        }
        inst.reset()
    })
}
const _: fmi2ResetTYPE = Some(fmi2Reset);

// ----- getting and setting values --------------------------------------------------------------

/// The FMU's variables are indexed per type inside; their value references are unique across
/// types ([`VR_BASE`]). Maps the master's value references of one type to indices, or logs the
/// first unknown one.
fn indices(
    inst: &Instance,
    function: &str,
    type_index: usize,
    count: usize,
    vrs: &[fmi2ValueReference],
) -> Result<Vec<u32>, Status> {
    let base = VR_BASE[type_index];
    vrs.iter()
        .map(|&vr| {
            vr.checked_sub(base)
                .filter(|i| (*i as usize) < count)
                .ok_or_else(|| inst.error(&format!("{function}: unknown value reference {vr}")))
        })
        .collect()
}

macro_rules! get_values {
    ($fn_name:ident, $ty:ty, $check:ident, $method:ident, $zero:expr, $conv:expr, $type_index:expr, $table:ident) => {
        #[no_mangle]
        pub extern "C" fn $fn_name(
            c: fmi2Component,
            vr: *const fmi2ValueReference,
            nvr: usize,
            value: *mut $ty,
        ) -> fmi2Status {
            with_handle(c, |h| {
                let inst = &mut h.instance;
                // SAFETY: FMI passes arrays of nvr value references and nvr values.
                let (Some(vrs), Some(out)) =
                    (unsafe { slice(vr, nvr) }, unsafe { slice_mut(value, nvr) })
                else {
                    return null_argument(inst, stringify!($fn_name));
                };
                let vrs = match indices(inst, stringify!($fn_name), $type_index, $table.len(), vrs)
                {
                    Ok(v) => v,
                    Err(s) => return s,
                };
                let mut tmp = vec![$zero; nvr];
                let s = inst.$method(&vrs, &mut tmp);
                if s == Status::Ok {
                    for (o, t) in out.iter_mut().zip(tmp) {
                        *o = $conv(t);
                    }
                }
                s
            })
        }
        const _: $check = Some($fn_name);
    };
}

get_values!(
    fmi2GetReal,
    fmi2Real,
    fmi2GetRealTYPE,
    get_real,
    0.0f64,
    |x: f64| x,
    0,
    REALS
);
get_values!(
    fmi2GetInteger,
    fmi2Integer,
    fmi2GetIntegerTYPE,
    get_integer,
    0i32,
    |x: i32| x,
    1,
    INTEGERS
);
get_values!(
    fmi2GetBoolean,
    fmi2Boolean,
    fmi2GetBooleanTYPE,
    get_boolean,
    false,
    |x: bool| {
        if x {
            fmi2True as fmi2Boolean
        } else {
            fmi2False as fmi2Boolean
        }
    },
    2,
    BOOLEANS
);

#[no_mangle]
pub extern "C" fn fmi2GetString(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2String,
) -> fmi2Status {
    with_handle(c, |h| {
        // SAFETY: FMI passes arrays of nvr value references and nvr string slots.
        let (Some(vrs), Some(out)) = (unsafe { slice(vr, nvr) }, unsafe { slice_mut(value, nvr) })
        else {
            return null_argument(&h.instance, "fmi2GetString");
        };
        let vrs = match indices(&h.instance, "fmi2GetString", 3, STRINGS.len(), vrs) {
            Ok(v) => v,
            Err(s) => return s,
        };
        let mut strings = Vec::new();
        let s = h.instance.get_string(&vrs, &mut strings);
        if s != Status::Ok {
            return s;
        }
        h.returned_strings = strings
            .iter()
            .map(|t| CString::new(t.replace('\0', "")).unwrap_or_default())
            .collect();
        for (o, t) in out.iter_mut().zip(&h.returned_strings) {
            *o = t.as_ptr();
        }
        Status::Ok
    })
}
const _: fmi2GetStringTYPE = Some(fmi2GetString);

#[no_mangle]
pub extern "C" fn fmi2SetReal(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Real,
) -> fmi2Status {
    with_handle(c, |h| {
        let inst = &mut h.instance;
        // SAFETY: FMI passes arrays of nvr value references and nvr values.
        let (Some(vrs), Some(vals)) = (unsafe { slice(vr, nvr) }, unsafe { slice(value, nvr) })
        else {
            return null_argument(inst, "fmi2SetReal");
        };
        inst.set_real(vrs, vals)
    })
}
const _: fmi2SetRealTYPE = Some(fmi2SetReal);

#[no_mangle]
pub extern "C" fn fmi2SetInteger(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Integer,
) -> fmi2Status {
    with_handle(c, |h| {
        let inst = &mut h.instance;
        // SAFETY: FMI passes arrays of nvr value references and nvr values.
        let (Some(vrs), Some(vals)) = (unsafe { slice(vr, nvr) }, unsafe { slice(value, nvr) })
        else {
            return null_argument(inst, "fmi2SetInteger");
        };
        match indices(inst, "fmi2SetInteger", 1, INTEGERS.len(), vrs) {
            Ok(vrs) => inst.set_integer(&vrs, vals),
            Err(s) => s,
        }
    })
}
const _: fmi2SetIntegerTYPE = Some(fmi2SetInteger);

#[no_mangle]
pub extern "C" fn fmi2SetBoolean(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Boolean,
) -> fmi2Status {
    with_handle(c, |h| {
        let inst = &mut h.instance;
        // SAFETY: FMI passes arrays of nvr value references and nvr values.
        let (Some(vrs), Some(vals)) = (unsafe { slice(vr, nvr) }, unsafe { slice(value, nvr) })
        else {
            return null_argument(inst, "fmi2SetBoolean");
        };
        if let Some((vr, b)) = vrs.iter().zip(vals).find(|(_, b)| **b != 0 && **b != 1) {
            return inst.error(&format!(
                "fmi2SetBoolean: value {b} for value reference {vr} is neither fmi2True (1) nor fmi2False (0)"
            ));
        }
        let vals: Vec<bool> = vals.iter().map(|b| *b != 0).collect();
        match indices(inst, "fmi2SetBoolean", 2, BOOLEANS.len(), vrs) {
            Ok(vrs) => inst.set_boolean(&vrs, &vals),
            Err(s) => s,
        }
    })
}
const _: fmi2SetBooleanTYPE = Some(fmi2SetBoolean);

#[no_mangle]
pub extern "C" fn fmi2SetString(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2String,
) -> fmi2Status {
    with_handle(c, |h| {
        let inst = &mut h.instance;
        // SAFETY: FMI passes arrays of nvr value references and nvr C strings.
        let (Some(vrs), Some(vals)) = (unsafe { slice(vr, nvr) }, unsafe { slice(value, nvr) })
        else {
            return null_argument(inst, "fmi2SetString");
        };
        // SAFETY: each entry is a NUL-terminated string or null.
        let strings: Option<Vec<String>> = vals.iter().map(|p| unsafe { text(*p) }).collect();
        let Some(strings) = strings else {
            return inst.error("fmi2SetString: a value is NULL or not UTF-8");
        };
        match indices(inst, "fmi2SetString", 3, STRINGS.len(), vrs) {
            Ok(vrs) => inst.set_string(&vrs, &strings),
            Err(s) => s,
        }
    })
}
const _: fmi2SetStringTYPE = Some(fmi2SetString);

// ----- FMU state -------------------------------------------------------------------------------

#[no_mangle]
pub extern "C" fn fmi2GetFMUstate(c: fmi2Component, FMUstate: *mut fmi2FMUstate) -> fmi2Status {
    with_handle(c, |h| {
        let inst = &mut h.instance;
        if let Err(s) = inst.allowed("fmi2GetFMUstate", state::FMU_STATE) {
            return s;
        }
        if FMUstate.is_null() {
            return null_argument(inst, "fmi2GetFMUstate");
        }
        // SAFETY: FMUstate points to a writable fmi2FMUstate slot (FMI 2.0 §2.1.8).
        let slot = unsafe { &mut *FMUstate };
        let core = inst.core.clone();
        if slot.is_null() {
            *slot = new_state(&mut h.states, core);
        } else if let Some(i) = state_index(&h.states, *slot) {
            h.states[i].core = core;
        } else {
            return inst
                .error("fmi2GetFMUstate: the given FMU state is not one of this instance's");
        }
        Status::Ok
    })
}
const _: fmi2GetFMUstateTYPE = Some(fmi2GetFMUstate);

#[no_mangle]
pub extern "C" fn fmi2SetFMUstate(c: fmi2Component, FMUstate: fmi2FMUstate) -> fmi2Status {
    with_handle(c, |h| {
        let inst = &mut h.instance;
        if let Err(s) = inst.allowed("fmi2SetFMUstate", state::FMU_STATE) {
            return s;
        }
        let Some(i) = state_index(&h.states, FMUstate) else {
            return inst.error("fmi2SetFMUstate: not an FMU state of this instance");
        };
        if let Err(m) = inst.check_state_fits(&h.states[i].core) {
            return inst.error(&format!("fmi2SetFMUstate: {m}"));
        }
        inst.core = h.states[i].core.clone();
        Status::Ok
    })
}
const _: fmi2SetFMUstateTYPE = Some(fmi2SetFMUstate);

#[no_mangle]
pub extern "C" fn fmi2FreeFMUstate(c: fmi2Component, FMUstate: *mut fmi2FMUstate) -> fmi2Status {
    with_handle(c, |h| {
        let inst = &mut h.instance;
        if FMUstate.is_null() {
            return Status::Ok;
        }
        // SAFETY: FMUstate points to a slot holding null or a state we handed out.
        let slot = unsafe { &mut *FMUstate };
        if slot.is_null() {
            return Status::Ok;
        }
        let Some(i) = state_index(&h.states, *slot) else {
            return inst.error("fmi2FreeFMUstate: not an FMU state of this instance");
        };
        h.states.swap_remove(i);
        *slot = std::ptr::null_mut();
        Status::Ok
    })
}
const _: fmi2FreeFMUstateTYPE = Some(fmi2FreeFMUstate);

#[no_mangle]
pub extern "C" fn fmi2SerializedFMUstateSize(
    c: fmi2Component,
    FMUstate: fmi2FMUstate,
    size: *mut usize,
) -> fmi2Status {
    with_handle(c, |h| {
        let inst = &mut h.instance;
        let Some(i) = state_index(&h.states, FMUstate) else {
            return inst.error("fmi2SerializedFMUstateSize: not an FMU state of this instance");
        };
        let s = &h.states[i];
        if size.is_null() {
            return null_argument(inst, "fmi2SerializedFMUstateSize");
        }
        // SAFETY: size is a non-null writable usize.
        unsafe { *size = snapshot::serialize(&s.core).len() };
        Status::Ok
    })
}
const _: fmi2SerializedFMUstateSizeTYPE = Some(fmi2SerializedFMUstateSize);

#[no_mangle]
pub extern "C" fn fmi2SerializeFMUstate(
    c: fmi2Component,
    FMUstate: fmi2FMUstate,
    serializedState: *mut fmi2Byte,
    size: usize,
) -> fmi2Status {
    with_handle(c, |h| {
        let inst = &mut h.instance;
        let Some(i) = state_index(&h.states, FMUstate) else {
            return inst.error("fmi2SerializeFMUstate: not an FMU state of this instance");
        };
        let s = &h.states[i];
        let bytes = snapshot::serialize(&s.core);
        if bytes.len() != size {
            return inst.error(&format!(
                "fmi2SerializeFMUstate: buffer has {size} bytes, the state needs {}",
                bytes.len()
            ));
        }
        // SAFETY: the caller provides a writable buffer of `size` bytes.
        let Some(out) = (unsafe { slice_mut(serializedState as *mut u8, size) }) else {
            return null_argument(inst, "fmi2SerializeFMUstate");
        };
        out.copy_from_slice(&bytes);
        Status::Ok
    })
}
const _: fmi2SerializeFMUstateTYPE = Some(fmi2SerializeFMUstate);

#[no_mangle]
pub extern "C" fn fmi2DeSerializeFMUstate(
    c: fmi2Component,
    serializedState: *const fmi2Byte,
    size: usize,
    FMUstate: *mut fmi2FMUstate,
) -> fmi2Status {
    with_handle(c, |h| {
        let inst = &mut h.instance;
        if let Err(s) = inst.allowed("fmi2DeSerializeFMUstate", state::FMU_STATE) {
            return s;
        }
        // SAFETY: the caller provides `size` readable bytes.
        let Some(bytes) = (unsafe { slice(serializedState as *const u8, size) }) else {
            return null_argument(inst, "fmi2DeSerializeFMUstate");
        };
        if FMUstate.is_null() {
            return null_argument(inst, "fmi2DeSerializeFMUstate");
        }
        let core = match snapshot::deserialize(bytes, |core, dynamic| {
            inst.restore_simulation(core, dynamic)
        }) {
            Ok(core) => core,
            Err(m) => return inst.error(&format!("fmi2DeSerializeFMUstate: {m}")),
        };
        // SAFETY: FMUstate points to a writable slot.
        let slot = unsafe { &mut *FMUstate };
        if slot.is_null() {
            *slot = new_state(&mut h.states, core);
        } else if let Some(i) = state_index(&h.states, *slot) {
            h.states[i].core = core;
        } else {
            return inst.error(
                "fmi2DeSerializeFMUstate: the given FMU state slot holds a state of another instance",
            );
        }
        Status::Ok
    })
}
const _: fmi2DeSerializeFMUstateTYPE = Some(fmi2DeSerializeFMUstate);

#[no_mangle]
pub extern "C" fn fmi2GetDirectionalDerivative(
    c: fmi2Component,
    _vUnknown_ref: *const fmi2ValueReference,
    _nUnknown: usize,
    _vKnown_ref: *const fmi2ValueReference,
    _nKnown: usize,
    _dvKnown: *const fmi2Real,
    _dvUnknown: *mut fmi2Real,
) -> fmi2Status {
    with_handle(c, |h| {
        h.instance.error(
            "fmi2GetDirectionalDerivative: not provided (providesDirectionalDerivative=false)",
        )
    })
}
const _: fmi2GetDirectionalDerivativeTYPE = Some(fmi2GetDirectionalDerivative);

// ----- co-simulation ---------------------------------------------------------------------------

#[no_mangle]
pub extern "C" fn fmi2SetRealInputDerivatives(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    order: *const fmi2Integer,
    value: *const fmi2Real,
) -> fmi2Status {
    with_handle(c, |h| {
        let inst = &mut h.instance;
        // SAFETY: FMI passes three arrays of nvr elements.
        let (Some(vrs), Some(orders), Some(vals)) = (
            unsafe { slice(vr, nvr) },
            unsafe { slice(order, nvr) },
            unsafe { slice(value, nvr) },
        ) else {
            return null_argument(inst, "fmi2SetRealInputDerivatives");
        };
        inst.set_real_input_derivatives(vrs, orders, vals)
    })
}
const _: fmi2SetRealInputDerivativesTYPE = Some(fmi2SetRealInputDerivatives);

#[no_mangle]
pub extern "C" fn fmi2GetRealOutputDerivatives(
    c: fmi2Component,
    _vr: *const fmi2ValueReference,
    _nvr: usize,
    _order: *const fmi2Integer,
    _value: *mut fmi2Real,
) -> fmi2Status {
    with_handle(c, |h| {
        let inst = &mut h.instance;
        if let Err(s) = inst.allowed(
            "fmi2GetRealOutputDerivatives",
            state::GET_OUTPUT_DERIVATIVES,
        ) {
            return s;
        }
        inst.error("fmi2GetRealOutputDerivatives: not provided (maxOutputDerivativeOrder=0)")
    })
}
const _: fmi2GetRealOutputDerivativesTYPE = Some(fmi2GetRealOutputDerivatives);

#[no_mangle]
pub extern "C" fn fmi2DoStep(
    c: fmi2Component,
    currentCommunicationPoint: fmi2Real,
    communicationStepSize: fmi2Real,
    _noSetFMUStatePriorToCurrentPoint: fmi2Boolean,
) -> fmi2Status {
    with_handle(c, |h| {
        h.instance
            .do_step(currentCommunicationPoint, communicationStepSize)
    })
}
const _: fmi2DoStepTYPE = Some(fmi2DoStep);

#[no_mangle]
pub extern "C" fn fmi2CancelStep(c: fmi2Component) -> fmi2Status {
    with_handle(c, |h| {
        h.instance.error(
            "fmi2CancelStep: no step is in progress (fmi2DoStep always completes synchronously)",
        )
    })
}
const _: fmi2CancelStepTYPE = Some(fmi2CancelStep);

#[no_mangle]
pub extern "C" fn fmi2GetStatus(
    c: fmi2Component,
    _s: fmi2StatusKind,
    _value: *mut fmi2Status,
) -> fmi2Status {
    with_handle(c, |h| {
        let inst = &mut h.instance;
        if let Err(s) = inst.allowed("fmi2GetStatus", state::GET_STATUS) {
            return s;
        }
        inst.error(
            "fmi2GetStatus: no asynchronous step status exists (canRunAsynchronuously=false)",
        )
    })
}
const _: fmi2GetStatusTYPE = Some(fmi2GetStatus);

#[no_mangle]
pub extern "C" fn fmi2GetRealStatus(
    c: fmi2Component,
    s: fmi2StatusKind,
    value: *mut fmi2Real,
) -> fmi2Status {
    with_handle(c, |h| {
        let inst = &mut h.instance;
        if let Err(st) = inst.allowed("fmi2GetRealStatus", state::GET_STATUS) {
            return st;
        }
        if value.is_null() {
            return null_argument(inst, "fmi2GetRealStatus");
        }
        if s != fmi2StatusKind_fmi2LastSuccessfulTime {
            return inst.error(&format!(
                "fmi2GetRealStatus: status kind {s} has no Real value"
            ));
        }
        // SAFETY: value is a non-null writable fmi2Real.
        unsafe { *value = inst.last_successful_time() };
        Status::Ok
    })
}
const _: fmi2GetRealStatusTYPE = Some(fmi2GetRealStatus);

#[no_mangle]
pub extern "C" fn fmi2GetIntegerStatus(
    c: fmi2Component,
    s: fmi2StatusKind,
    _value: *mut fmi2Integer,
) -> fmi2Status {
    with_handle(c, |h| {
        let inst = &mut h.instance;
        if let Err(st) = inst.allowed("fmi2GetIntegerStatus", state::GET_STATUS) {
            return st;
        }
        inst.error(&format!(
            "fmi2GetIntegerStatus: status kind {s} has no Integer value"
        ))
    })
}
const _: fmi2GetIntegerStatusTYPE = Some(fmi2GetIntegerStatus);

#[no_mangle]
pub extern "C" fn fmi2GetBooleanStatus(
    c: fmi2Component,
    s: fmi2StatusKind,
    value: *mut fmi2Boolean,
) -> fmi2Status {
    with_handle(c, |h| {
        let inst = &mut h.instance;
        if let Err(st) = inst.allowed("fmi2GetBooleanStatus", state::GET_STATUS) {
            return st;
        }
        if value.is_null() {
            return null_argument(inst, "fmi2GetBooleanStatus");
        }
        if s != fmi2StatusKind_fmi2Terminated {
            return inst.error(&format!(
                "fmi2GetBooleanStatus: status kind {s} has no Boolean value"
            ));
        }
        let terminated = if inst.core.terminated {
            fmi2True
        } else {
            fmi2False
        };
        // SAFETY: value is a non-null writable fmi2Boolean.
        unsafe { *value = terminated as fmi2Boolean };
        Status::Ok
    })
}
const _: fmi2GetBooleanStatusTYPE = Some(fmi2GetBooleanStatus);

#[no_mangle]
pub extern "C" fn fmi2GetStringStatus(
    c: fmi2Component,
    s: fmi2StatusKind,
    _value: *mut fmi2String,
) -> fmi2Status {
    with_handle(c, |h| {
        let inst = &mut h.instance;
        if let Err(st) = inst.allowed("fmi2GetStringStatus", state::GET_STATUS) {
            return st;
        }
        inst.error(&format!(
            "fmi2GetStringStatus: status kind {s} has no String value"
        ))
    })
}
const _: fmi2GetStringStatusTYPE = Some(fmi2GetStringStatus);
