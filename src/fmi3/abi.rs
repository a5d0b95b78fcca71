//! The exported FMI 3.0 functions: the standard's signatures over the runtime ([`crate::fmu`]),
//! the same one the FMI 2.0 ABI uses. Every entry point with an instance passes the runtime's
//! one guard ([`crate::fmu::guard::Abi::entry`]) with its 3.0 state mask ([`super::state`]); every
//! fmi3Error leads to the error state. Inside, C arguments become Rust values
//! ([`crate::fmu::c_args`]), value references (arrays among them) are resolved to the variable
//! table ([`super::values`]), and the runtime does the work.

#![allow(non_snake_case)]
#![allow(clippy::not_unsafe_ptr_arg_deref)] // the C ABI hands us raw pointers by design
#![allow(clippy::too_many_arguments)] // the signatures are the standard's

use std::ffi::c_char;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::PathBuf;

use fmi_sys::fmi3::*;

use super::state;
use super::values::{resolve, unknown};
use crate::cosim::FmuKind;
use crate::fmu::c_args::{array, array_mut, place, string_value, text, texts};
use crate::fmu::guard::{self, Abi, FunctionNames, Request};
use crate::fmu::instance::{Outcome, Status};
use crate::fmu::logger::{Level, Logger};
use crate::fmu::state::Phase;
use crate::fmu::values::{Slot, Typed};
use crate::variables::fmi3::{MODES_SIZE, MODES_SIZE_MAX};
use crate::variables::LogCategory;

/// FMI 3.0 as the runtime sees it.
pub static ABI: Abi = Abi {
    // Marks a live instance of fmi3InstantiateCoSimulation (another value than FMI 2.0's).
    live: 0x454d_4346_4d55_0003,
    kinds: &[FmuKind::Engine, FmuKind::Body],
    token: "instantiation token",
    resources: "resource path",
    errors_enter_error_state: true,
    phase_name: state::name,
    error_state_hint: " (after fmi3Error: fmi3SetFMUState, fmi3Reset or fmi3FreeInstance)",
    names: FunctionNames {
        instantiate: "fmi3InstantiateCoSimulation",
        free_instance: "fmi3FreeInstance",
        setup_experiment: "fmi3EnterInitializationMode",
        exit_initialization: "fmi3ExitInitializationMode",
        do_step: "fmi3DoStep",
        set_fmu_state: "fmi3SetFMUState",
    },
};

// ----- inquiry, creation and destruction -------------------------------------------------------

/// Returns `"3.0"`. Needs no instance.
#[no_mangle]
pub extern "C" fn fmi3GetVersion() -> *const c_char {
    c"3.0".as_ptr()
}
const _: fmi3GetVersionTYPE = Some(fmi3GetVersion);

/// Creates a co-simulation instance and returns it, or null after logging why through
/// `logMessage`: a missing `instanceName`, an instantiation token that is not this FMU's, a
/// resource path that is not a directory, or `eventModeUsed` (the FMU has no event mode).
/// `earlyReturnAllowed` is accepted (fmi3DoStep never returns early), and so are required
/// intermediate variables, ignored as the Reference-FMUs do: the FMU provides no intermediate
/// update, so nothing asks for them.
#[no_mangle]
pub extern "C" fn fmi3InstantiateCoSimulation(
    instanceName: fmi3String,
    instantiationToken: fmi3String,
    resourcePath: fmi3String,
    _visible: fmi3Boolean,
    loggingOn: fmi3Boolean,
    eventModeUsed: fmi3Boolean,
    _earlyReturnAllowed: fmi3Boolean,
    _requiredIntermediateVariables: *const fmi3ValueReference,
    _nRequiredIntermediateVariables: usize,
    instanceEnvironment: fmi3InstanceEnvironment,
    logMessage: fmi3LogMessageCallback,
    _intermediateUpdate: fmi3IntermediateUpdateCallback,
) -> fmi3Instance {
    let request = Request {
        name: instanceName,
        token: instantiationToken,
        resources: resourcePath,
        resource_dir,
    };
    // Required intermediate variables are ignored, as the Reference-FMUs do: without
    // intermediate update (providesIntermediateUpdate=false) no callback asks for them.
    let refusal =
        eventModeUsed.then_some("eventModeUsed: this FMU has no event mode (hasEventMode=false)");
    guard::instantiate(
        &ABI,
        request,
        |name| Logger::new_fmi3(logMessage, instanceEnvironment, name, loggingOn),
        refusal,
    )
}
const _: fmi3InstantiateCoSimulationTYPE = Some(fmi3InstantiateCoSimulation);

/// The resource directory a resource path names (`None`: none or an empty one given).
fn resource_dir(path: Option<&str>) -> Result<Option<PathBuf>, String> {
    match path.filter(|r| !r.is_empty()) {
        None => Ok(None),
        Some(r) if PathBuf::from(r).is_dir() => Ok(Some(PathBuf::from(r))),
        Some(r) => Err(format!("resource path {r} is not a directory")),
    }
}

/// Logs through `logMessage` that `interface` is not supported and returns null.
fn refuse_interface(
    interface: &str,
    instanceName: fmi3String,
    environment: fmi3InstanceEnvironment,
    logMessage: fmi3LogMessageCallback,
) -> fmi3Instance {
    let _ = catch_unwind(AssertUnwindSafe(|| {
        // SAFETY: FMI strings are NUL-terminated or null.
        let name = unsafe { text(instanceName) }.unwrap_or_default();
        Logger::new_fmi3(logMessage, environment, &name, false).log(
            Level::Error,
            LogCategory::StatusError,
            &format!("fmi3Instantiate{interface}: this FMU supports co-simulation only"),
        );
    }));
    std::ptr::null_mut()
}

/// Always null: the FMU supports co-simulation only (the refusal is logged).
#[no_mangle]
pub extern "C" fn fmi3InstantiateModelExchange(
    instanceName: fmi3String,
    _instantiationToken: fmi3String,
    _resourcePath: fmi3String,
    _visible: fmi3Boolean,
    _loggingOn: fmi3Boolean,
    instanceEnvironment: fmi3InstanceEnvironment,
    logMessage: fmi3LogMessageCallback,
) -> fmi3Instance {
    refuse_interface(
        "ModelExchange",
        instanceName,
        instanceEnvironment,
        logMessage,
    )
}
const _: fmi3InstantiateModelExchangeTYPE = Some(fmi3InstantiateModelExchange);

/// Always null: the FMU supports co-simulation only (the refusal is logged).
#[no_mangle]
pub extern "C" fn fmi3InstantiateScheduledExecution(
    instanceName: fmi3String,
    _instantiationToken: fmi3String,
    _resourcePath: fmi3String,
    _visible: fmi3Boolean,
    _loggingOn: fmi3Boolean,
    instanceEnvironment: fmi3InstanceEnvironment,
    logMessage: fmi3LogMessageCallback,
    _clockUpdate: fmi3ClockUpdateCallback,
    _lockPreemption: fmi3LockPreemptionCallback,
    _unlockPreemption: fmi3UnlockPreemptionCallback,
) -> fmi3Instance {
    refuse_interface(
        "ScheduledExecution",
        instanceName,
        instanceEnvironment,
        logMessage,
    )
}
const _: fmi3InstantiateScheduledExecutionTYPE = Some(fmi3InstantiateScheduledExecution);

/// Frees the instance and every FMU state it handed out; a null or already freed instance is
/// ignored. Allowed in every state, the fatal one included.
#[no_mangle]
pub extern "C" fn fmi3FreeInstance(instance: fmi3Instance) {
    guard::free(instance, &ABI)
}
const _: fmi3FreeInstanceTYPE = Some(fmi3FreeInstance);

/// As fmi2SetDebugLogging: no categories switch all; unknown names are refused.
#[no_mangle]
pub extern "C" fn fmi3SetDebugLogging(
    instance: fmi3Instance,
    loggingOn: fmi3Boolean,
    nCategories: usize,
    categories: *const fmi3String,
) -> fmi3Status {
    ABI.entry(instance, "fmi3SetDebugLogging", state::ANY, |h| {
        // SAFETY: FMI passes an array of nCategories C strings.
        let names = unsafe { texts(categories, nCategories, "categories") }?;
        h.instance.logger.set_debug_logging(loggingOn, &names)?;
        Ok(Status::Ok)
    })
}
const _: fmi3SetDebugLoggingTYPE = Some(fmi3SetDebugLogging);

// ----- configuration, initialisation, termination, reset ---------------------------------------

/// Enters configuration mode, where the structural parameter `modes.size` may be set.
#[no_mangle]
pub extern "C" fn fmi3EnterConfigurationMode(instance: fmi3Instance) -> fmi3Status {
    ABI.entry(
        instance,
        "fmi3EnterConfigurationMode",
        state::ENTER_FROM_INSTANTIATED,
        |h| h.instance.configuration_mode(true),
    )
}
const _: fmi3EnterConfigurationModeTYPE = Some(fmi3EnterConfigurationMode);

/// Leaves configuration mode for the instantiated state.
#[no_mangle]
pub extern "C" fn fmi3ExitConfigurationMode(instance: fmi3Instance) -> fmi3Status {
    ABI.entry(
        instance,
        "fmi3ExitConfigurationMode",
        state::EXIT_CONFIGURATION,
        |h| h.instance.configuration_mode(false),
    )
}
const _: fmi3ExitConfigurationModeTYPE = Some(fmi3ExitConfigurationMode);

/// Sets up the experiment as fmi2SetupExperiment does (start time, optional stop time, optional
/// tolerance that becomes the integrator's relative tolerance unless `solver.relTol` was set) and
/// enters initialisation mode; inadmissible times or tolerance are refused, changing nothing.
#[no_mangle]
pub extern "C" fn fmi3EnterInitializationMode(
    instance: fmi3Instance,
    toleranceDefined: fmi3Boolean,
    tolerance: fmi3Float64,
    startTime: fmi3Float64,
    stopTimeDefined: fmi3Boolean,
    stopTime: fmi3Float64,
) -> fmi3Status {
    ABI.entry(
        instance,
        "fmi3EnterInitializationMode",
        state::ENTER_FROM_INSTANTIATED,
        |h| {
            let setup = h.instance.setup_experiment(
                startTime,
                stopTimeDefined.then_some(stopTime),
                toleranceDefined.then_some(tolerance),
            )?;
            Ok(setup.max(h.instance.enter_initialization()?))
        },
    )
}
const _: fmi3EnterInitializationModeTYPE = Some(fmi3EnterInitializationMode);

/// Builds the model (as fmi2ExitInitializationMode) and enters step mode directly: without event
/// mode there is no event mode to pass through.
#[no_mangle]
pub extern "C" fn fmi3ExitInitializationMode(instance: fmi3Instance) -> fmi3Status {
    ABI.entry(
        instance,
        "fmi3ExitInitializationMode",
        state::EXIT_INITIALIZATION,
        |h| h.instance.exit_initialization(),
    )
}
const _: fmi3ExitInitializationModeTYPE = Some(fmi3ExitInitializationMode);

/// Always refused: the FMU has no event mode (hasEventMode=false).
#[no_mangle]
pub extern "C" fn fmi3EnterEventMode(instance: fmi3Instance) -> fmi3Status {
    ABI.entry(instance, "fmi3EnterEventMode", state::UNSUPPORTED, |_| {
        Err("this FMU has no event mode (hasEventMode=false)".into())
    })
}
const _: fmi3EnterEventModeTYPE = Some(fmi3EnterEventMode);

/// Always refused: step mode is entered by fmi3ExitInitializationMode, event mode does not exist.
#[no_mangle]
pub extern "C" fn fmi3EnterStepMode(instance: fmi3Instance) -> fmi3Status {
    ABI.entry(instance, "fmi3EnterStepMode", state::UNSUPPORTED, |_| {
        Err("this FMU has no event mode to leave (hasEventMode=false)".into())
    })
}
const _: fmi3EnterStepModeTYPE = Some(fmi3EnterStepMode);

/// Ends the simulation: values can still be read, no step taken.
#[no_mangle]
pub extern "C" fn fmi3Terminate(instance: fmi3Instance) -> fmi3Status {
    ABI.entry(instance, "fmi3Terminate", state::TERMINATE, |h| {
        h.instance.terminate()
    })
}
const _: fmi3TerminateTYPE = Some(fmi3Terminate);

/// Back to the instantiated state with start values (also out of the error state); FMU states
/// handed out stay valid.
#[no_mangle]
pub extern "C" fn fmi3Reset(instance: fmi3Instance) -> fmi3Status {
    ABI.entry(instance, "fmi3Reset", state::ANY, |h| h.instance.reset())
}
const _: fmi3ResetTYPE = Some(fmi3Reset);

// ----- getting and setting values --------------------------------------------------------------

/// `fmi3GetXXX` for the model's types: the values behind `vr` (arrays row-major), converted.
fn get_values<T: Typed, C>(
    instance: fmi3Instance,
    function: &'static str,
    vr: *const fmi3ValueReference,
    nvr: usize,
    value: *mut C,
    n_values: usize,
    convert: impl Fn(T) -> C,
    time: impl Fn(f64) -> Option<C>,
) -> fmi3Status {
    ABI.entry(instance, function, state::GET_VALUES, |h| {
        // SAFETY: FMI passes nvr value references and room for nValues values.
        let (vrs, out) = unsafe { (array(vr, nvr, "vr")?, array_mut(value, n_values, "values")?) };
        let slots = resolve::<T>(vrs, h.instance.modes_size, n_values)?;
        h.read(&slots, out, convert, time)
    })
}

/// `fmi3SetXXX` for the model's types: all values checked before any is applied (by the
/// instance), `time` refused.
fn set_values<T: Typed, C: Copy>(
    instance: fmi3Instance,
    function: &'static str,
    vr: *const fmi3ValueReference,
    nvr: usize,
    value: *const C,
    n_values: usize,
    convert: impl Fn(C) -> Result<T, String>,
) -> fmi3Status {
    ABI.entry(instance, function, state::SET_VALUES, |h| {
        // SAFETY: FMI passes nvr value references and nValues values.
        let (vrs, given) = unsafe { (array(vr, nvr, "vr")?, array(value, n_values, "values")?) };
        let slots = resolve::<T>(vrs, h.instance.modes_size, n_values)?;
        let values = given
            .iter()
            .map(|x| convert(*x))
            .collect::<Result<Vec<T>, String>>()?;
        h.write(&slots, &values)
    })
}

/// A C `bool` read as its byte: a value other than 0 or 1 is refused instead of being undefined
/// behaviour.
fn boolean(b: u8) -> Result<bool, String> {
    match b {
        0 => Ok(false),
        1 => Ok(true),
        other => Err(format!(
            "Boolean value {other} is neither true (1) nor false (0)"
        )),
    }
}

/// Reads Float64 variables and arrays (`time` too); calculated parameters (the natural modes) are
/// computed when first read, outputs read in initialisation mode build the model first.
#[no_mangle]
pub extern "C" fn fmi3GetFloat64(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *mut fmi3Float64,
    nValues: usize,
) -> fmi3Status {
    get_values::<f64, _>(
        instance,
        "fmi3GetFloat64",
        valueReferences,
        nValueReferences,
        values,
        nValues,
        |x| x,
        Some,
    )
}
const _: fmi3GetFloat64TYPE = Some(fmi3GetFloat64);

/// Reads Int32 variables (the solver counters, `modes.count`, the Integer parameters).
#[no_mangle]
pub extern "C" fn fmi3GetInt32(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *mut fmi3Int32,
    nValues: usize,
) -> fmi3Status {
    get_values::<i32, _>(
        instance,
        "fmi3GetInt32",
        valueReferences,
        nValueReferences,
        values,
        nValues,
        |x| x,
        |_| None,
    )
}
const _: fmi3GetInt32TYPE = Some(fmi3GetInt32);

/// Reads Boolean variables (the effect switches and other Boolean parameters).
#[no_mangle]
pub extern "C" fn fmi3GetBoolean(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *mut fmi3Boolean,
    nValues: usize,
) -> fmi3Status {
    get_values::<bool, _>(
        instance,
        "fmi3GetBoolean",
        valueReferences,
        nValueReferences,
        values,
        nValues,
        |x| x,
        |_| None,
    )
}
const _: fmi3GetBooleanTYPE = Some(fmi3GetBoolean);

/// Reads String variables; the pointers stay valid until the next fmi3GetString on this instance
/// or until it is freed.
#[no_mangle]
pub extern "C" fn fmi3GetString(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *mut fmi3String,
    nValues: usize,
) -> fmi3Status {
    ABI.entry(instance, "fmi3GetString", state::GET_VALUES, |h| {
        // SAFETY: FMI passes nValueReferences value references and nValues string slots.
        let (vrs, out) = unsafe {
            (
                array(valueReferences, nValueReferences, "valueReferences")?,
                array_mut(values, nValues, "values")?,
            )
        };
        let slots = resolve::<String>(vrs, h.instance.modes_size, nValues)?;
        h.read_strings(&slots, out)
    })
}
const _: fmi3GetStringTYPE = Some(fmi3GetString);

/// Reads the structural parameter `modes.size`, the one UInt64 variable.
#[no_mangle]
pub extern "C" fn fmi3GetUInt64(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *mut fmi3UInt64,
    nValues: usize,
) -> fmi3Status {
    ABI.entry(instance, "fmi3GetUInt64", state::GET_STRUCTURAL, |h| {
        // SAFETY: FMI passes nValueReferences value references and room for nValues values.
        let (vrs, out) = unsafe {
            (
                array(valueReferences, nValueReferences, "valueReferences")?,
                array_mut(values, nValues, "values")?,
            )
        };
        structural(vrs, nValues)?;
        out.iter_mut().for_each(|o| *o = h.instance.modes_size);
        Ok(Status::Ok)
    })
}
const _: fmi3GetUInt64TYPE = Some(fmi3GetUInt64);

/// Sets the structural parameter `modes.size` (1 to the 2.0 table's slots), in configuration
/// mode only.
#[no_mangle]
pub extern "C" fn fmi3SetUInt64(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *const fmi3UInt64,
    nValues: usize,
) -> fmi3Status {
    ABI.entry(instance, "fmi3SetUInt64", state::SET_STRUCTURAL, |h| {
        // SAFETY: FMI passes nValueReferences value references and nValues values.
        let (vrs, given) = unsafe {
            (
                array(valueReferences, nValueReferences, "valueReferences")?,
                array(values, nValues, "values")?,
            )
        };
        structural(vrs, nValues)?;
        if let Some(bad) = given.iter().find(|n| !(1..=MODES_SIZE_MAX).contains(*n)) {
            return Err(format!(
                "modes.size = {bad} is outside [1, {MODES_SIZE_MAX}]"
            ));
        }
        if let Some(last) = given.last() {
            h.instance.modes_size = *last;
        }
        Ok(Status::Ok)
    })
}
const _: fmi3SetUInt64TYPE = Some(fmi3SetUInt64);

/// Checks that `vrs` name `modes.size` only, one value each.
fn structural(vrs: &[u32], n_values: usize) -> Result<(), String> {
    if let Some(vr) = vrs.iter().find(|vr| **vr != MODES_SIZE) {
        return Err(unknown(*vr, "UInt64"));
    }
    if n_values != vrs.len() {
        return Err(format!(
            "nValues = {n_values} for {} scalar variables",
            vrs.len()
        ));
    }
    Ok(())
}

/// Sets Float64 inputs and parameters (arrays row-major), all checked before any is applied;
/// `time` is refused. An input set between steps takes effect at the next fmi3DoStep, held or
/// continued with the slope of the last values as in FMI 2.0.
#[no_mangle]
pub extern "C" fn fmi3SetFloat64(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *const fmi3Float64,
    nValues: usize,
) -> fmi3Status {
    set_values::<f64, _>(
        instance,
        "fmi3SetFloat64",
        valueReferences,
        nValueReferences,
        values,
        nValues,
        Ok,
    )
}
const _: fmi3SetFloat64TYPE = Some(fmi3SetFloat64);

/// Sets Int32 parameters (`scene`, `solver.maxOrder`, …), all checked before any is applied.
#[no_mangle]
pub extern "C" fn fmi3SetInt32(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *const fmi3Int32,
    nValues: usize,
) -> fmi3Status {
    set_values::<i32, _>(
        instance,
        "fmi3SetInt32",
        valueReferences,
        nValueReferences,
        values,
        nValues,
        Ok,
    )
}
const _: fmi3SetInt32TYPE = Some(fmi3SetInt32);

/// Sets Boolean parameters; a byte other than 0 or 1 is refused.
#[no_mangle]
pub extern "C" fn fmi3SetBoolean(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *const fmi3Boolean,
    nValues: usize,
) -> fmi3Status {
    // C bools are read as bytes: a stray value must not become an invalid Rust bool.
    set_values::<bool, u8>(
        instance,
        "fmi3SetBoolean",
        valueReferences,
        nValueReferences,
        values as *const u8,
        nValues,
        boolean,
    )
}
const _: fmi3SetBooleanTYPE = Some(fmi3SetBoolean);

/// Sets String parameters (`configFile`, `chassis.cacheDir`); null or non-UTF-8 is refused.
#[no_mangle]
pub extern "C" fn fmi3SetString(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *const fmi3String,
    nValues: usize,
) -> fmi3Status {
    set_values::<String, _>(
        instance,
        "fmi3SetString",
        valueReferences,
        nValueReferences,
        values,
        nValues,
        |p| {
            // SAFETY: each entry of an FMI string array is null or NUL-terminated.
            unsafe { string_value(p) }
        },
    )
}
const _: fmi3SetStringTYPE = Some(fmi3SetString);

/// The getters and setters of the types this FMU has no variable of: an empty call succeeds,
/// any value reference is refused (naming the variable's real type if it has one).
macro_rules! no_such_type {
    ($get:ident, $get_ty:ident, $set:ident, $set_ty:ident, $c:ty, $name:literal) => {
        #[doc = concat!("Refuses every value reference: this FMU has no ", $name, " variable.")]
        #[no_mangle]
        pub extern "C" fn $get(
            instance: fmi3Instance,
            valueReferences: *const fmi3ValueReference,
            nValueReferences: usize,
            _values: *mut $c,
            _nValues: usize,
        ) -> fmi3Status {
            ABI.entry(instance, stringify!($get), state::GET_VALUES, |_| {
                none_of_type(valueReferences, nValueReferences, $name)
            })
        }
        const _: $get_ty = Some($get);

        #[doc = concat!("Refuses every value reference: this FMU has no ", $name, " variable.")]
        #[no_mangle]
        pub extern "C" fn $set(
            instance: fmi3Instance,
            valueReferences: *const fmi3ValueReference,
            nValueReferences: usize,
            _values: *const $c,
            _nValues: usize,
        ) -> fmi3Status {
            ABI.entry(instance, stringify!($set), state::SET_VALUES, |_| {
                none_of_type(valueReferences, nValueReferences, $name)
            })
        }
        const _: $set_ty = Some($set);
    };
}

/// Ok for no value references, otherwise the refusal of the first.
fn none_of_type(vr: *const fmi3ValueReference, nvr: usize, ty: &str) -> Outcome {
    // SAFETY: FMI passes nvr value references.
    let vrs = unsafe { array(vr, nvr, "valueReferences") }?;
    match vrs.first() {
        None => Ok(Status::Ok),
        Some(vr) => Err(unknown(*vr, ty)),
    }
}

no_such_type!(
    fmi3GetFloat32,
    fmi3GetFloat32TYPE,
    fmi3SetFloat32,
    fmi3SetFloat32TYPE,
    fmi3Float32,
    "Float32"
);
no_such_type!(
    fmi3GetInt8,
    fmi3GetInt8TYPE,
    fmi3SetInt8,
    fmi3SetInt8TYPE,
    fmi3Int8,
    "Int8"
);
no_such_type!(
    fmi3GetUInt8,
    fmi3GetUInt8TYPE,
    fmi3SetUInt8,
    fmi3SetUInt8TYPE,
    fmi3UInt8,
    "UInt8"
);
no_such_type!(
    fmi3GetInt16,
    fmi3GetInt16TYPE,
    fmi3SetInt16,
    fmi3SetInt16TYPE,
    fmi3Int16,
    "Int16"
);
no_such_type!(
    fmi3GetUInt16,
    fmi3GetUInt16TYPE,
    fmi3SetUInt16,
    fmi3SetUInt16TYPE,
    fmi3UInt16,
    "UInt16"
);
no_such_type!(
    fmi3GetUInt32,
    fmi3GetUInt32TYPE,
    fmi3SetUInt32,
    fmi3SetUInt32TYPE,
    fmi3UInt32,
    "UInt32"
);
no_such_type!(
    fmi3GetInt64,
    fmi3GetInt64TYPE,
    fmi3SetInt64,
    fmi3SetInt64TYPE,
    fmi3Int64,
    "Int64"
);

/// Refuses every value reference: this FMU has no Binary variable.
#[no_mangle]
pub extern "C" fn fmi3GetBinary(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    _valueSizes: *mut usize,
    _values: *mut fmi3Binary,
    _nValues: usize,
) -> fmi3Status {
    ABI.entry(instance, "fmi3GetBinary", state::GET_VALUES, |_| {
        none_of_type(valueReferences, nValueReferences, "Binary")
    })
}
const _: fmi3GetBinaryTYPE = Some(fmi3GetBinary);

/// Refuses every value reference: this FMU has no Binary variable.
#[no_mangle]
pub extern "C" fn fmi3SetBinary(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    _valueSizes: *const usize,
    _values: *const fmi3Binary,
    _nValues: usize,
) -> fmi3Status {
    ABI.entry(instance, "fmi3SetBinary", state::SET_VALUES, |_| {
        none_of_type(valueReferences, nValueReferences, "Binary")
    })
}
const _: fmi3SetBinaryTYPE = Some(fmi3SetBinary);

/// Refuses every value reference: this FMU has no clocks.
#[no_mangle]
pub extern "C" fn fmi3GetClock(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    _values: *mut fmi3Clock,
) -> fmi3Status {
    ABI.entry(instance, "fmi3GetClock", state::GET_VALUES, |_| {
        none_of_type(valueReferences, nValueReferences, "Clock")
    })
}
const _: fmi3GetClockTYPE = Some(fmi3GetClock);

/// Refuses every value reference: this FMU has no clocks.
#[no_mangle]
pub extern "C" fn fmi3SetClock(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    _values: *const fmi3Clock,
) -> fmi3Status {
    ABI.entry(instance, "fmi3SetClock", state::SET_VALUES, |_| {
        none_of_type(valueReferences, nValueReferences, "Clock")
    })
}
const _: fmi3SetClockTYPE = Some(fmi3SetClock);

// ----- clocks, discrete states, dependencies, derivatives: not provided ------------------------

/// Generates entry points that always refuse with the reason given (the model description does
/// not declare what they serve).
macro_rules! refused {
    ($name:ident, $ty:ident, $reason:literal, ($($arg:ident: $argty:ty),*)) => {
        #[doc = concat!("Always refused with fmi3Error: ", $reason, ".")]
        #[no_mangle]
        pub extern "C" fn $name(instance: fmi3Instance, $($arg: $argty),*) -> fmi3Status {
            $(let _ = $arg;)*
            ABI.entry(instance, stringify!($name), state::UNSUPPORTED, |_| Err($reason.into()))
        }
        const _: $ty = Some($name);
    };
}

refused!(fmi3GetIntervalDecimal, fmi3GetIntervalDecimalTYPE, "this FMU has no clocks",
    (vr: *const fmi3ValueReference, nvr: usize, intervals: *mut fmi3Float64,
     qualifiers: *mut fmi3IntervalQualifier));
refused!(fmi3GetIntervalFraction, fmi3GetIntervalFractionTYPE, "this FMU has no clocks",
    (vr: *const fmi3ValueReference, nvr: usize, counters: *mut fmi3UInt64,
     resolutions: *mut fmi3UInt64, qualifiers: *mut fmi3IntervalQualifier));
refused!(fmi3GetShiftDecimal, fmi3GetShiftDecimalTYPE, "this FMU has no clocks",
    (vr: *const fmi3ValueReference, nvr: usize, shifts: *mut fmi3Float64));
refused!(fmi3GetShiftFraction, fmi3GetShiftFractionTYPE, "this FMU has no clocks",
    (vr: *const fmi3ValueReference, nvr: usize, counters: *mut fmi3UInt64,
     resolutions: *mut fmi3UInt64));
refused!(fmi3SetIntervalDecimal, fmi3SetIntervalDecimalTYPE, "this FMU has no clocks",
    (vr: *const fmi3ValueReference, nvr: usize, intervals: *const fmi3Float64));
refused!(fmi3SetIntervalFraction, fmi3SetIntervalFractionTYPE, "this FMU has no clocks",
    (vr: *const fmi3ValueReference, nvr: usize, counters: *const fmi3UInt64,
     resolutions: *const fmi3UInt64));
refused!(fmi3SetShiftDecimal, fmi3SetShiftDecimalTYPE, "this FMU has no clocks",
    (vr: *const fmi3ValueReference, nvr: usize, shifts: *const fmi3Float64));
refused!(fmi3SetShiftFraction, fmi3SetShiftFractionTYPE, "this FMU has no clocks",
    (vr: *const fmi3ValueReference, nvr: usize, counters: *const fmi3UInt64,
     resolutions: *const fmi3UInt64));
refused!(
    fmi3EvaluateDiscreteStates,
    fmi3EvaluateDiscreteStatesTYPE,
    "not provided (providesEvaluateDiscreteStates=false)",
    ()
);
refused!(fmi3UpdateDiscreteStates, fmi3UpdateDiscreteStatesTYPE,
    "this FMU has no event mode (hasEventMode=false)",
    (discreteStatesNeedUpdate: *mut fmi3Boolean, terminateSimulation: *mut fmi3Boolean,
     nominalsOfContinuousStatesChanged: *mut fmi3Boolean,
     valuesOfContinuousStatesChanged: *mut fmi3Boolean, nextEventTimeDefined: *mut fmi3Boolean,
     nextEventTime: *mut fmi3Float64));
refused!(fmi3GetNumberOfVariableDependencies, fmi3GetNumberOfVariableDependenciesTYPE,
    "not provided (providesPerElementDependencies=false; the model structure lists the dependencies)",
    (valueReference: fmi3ValueReference, nDependencies: *mut usize));
refused!(fmi3GetVariableDependencies, fmi3GetVariableDependenciesTYPE,
    "not provided (providesPerElementDependencies=false; the model structure lists the dependencies)",
    (dependent: fmi3ValueReference, elementIndicesOfDependent: *mut usize,
     independents: *mut fmi3ValueReference, elementIndicesOfIndependents: *mut usize,
     dependencyKinds: *mut fmi3DependencyKind, nDependencies: usize));
refused!(fmi3GetAdjointDerivative, fmi3GetAdjointDerivativeTYPE,
    "not provided (providesAdjointDerivatives=false)",
    (unknowns: *const fmi3ValueReference, nUnknowns: usize, knowns: *const fmi3ValueReference,
     nKnowns: usize, seed: *const fmi3Float64, nSeed: usize, sensitivity: *mut fmi3Float64,
     nSensitivity: usize));

/// Directional derivatives of Float64 outputs with respect to Float64 inputs
/// (`providesDirectionalDerivatives="true"`, as FMI 2.0's fmi2GetDirectionalDerivative):
/// `sensitivity[i] = Σ_k ∂unknown_i/∂known_k · seed[k]`, arrays standing for their elements
/// (row-major); in initialisation mode of the initialisation, between steps at the current
/// communication point, the state held (see `Instance::directional_derivative`).
#[no_mangle]
pub extern "C" fn fmi3GetDirectionalDerivative(
    instance: fmi3Instance,
    unknowns: *const fmi3ValueReference,
    nUnknowns: usize,
    knowns: *const fmi3ValueReference,
    nKnowns: usize,
    seed: *const fmi3Float64,
    nSeed: usize,
    sensitivity: *mut fmi3Float64,
    nSensitivity: usize,
) -> fmi3Status {
    ABI.entry(
        instance,
        "fmi3GetDirectionalDerivative",
        state::DIRECTIONAL_DERIVATIVE,
        |h| {
            // SAFETY: FMI passes nUnknowns and nKnowns value references, nSeed seeds and room
            // for nSensitivity results.
            let (unknowns, knowns, seed, out) = unsafe {
                (
                    array(unknowns, nUnknowns, "unknowns")?,
                    array(knowns, nKnowns, "knowns")?,
                    array(seed, nSeed, "seed")?,
                    array_mut(sensitivity, nSensitivity, "sensitivity")?,
                )
            };
            let size = h.instance.modes_size;
            let unknowns = elements(&resolve::<f64>(unknowns, size, nSensitivity)?)?;
            let knowns = elements(&resolve::<f64>(knowns, size, nSeed)?)?;
            let values = h
                .instance
                .directional_derivative(&unknowns, &knowns, seed)?;
            out.copy_from_slice(&values);
            Ok(Status::Ok)
        },
    )
}
const _: fmi3GetDirectionalDerivativeTYPE = Some(fmi3GetDirectionalDerivative);

/// The variables' elements behind `slots`; `time` is neither an input nor an output.
fn elements(slots: &[Slot]) -> Result<Vec<usize>, String> {
    slots
        .iter()
        .map(|s| {
            s.element()
                .ok_or_else(|| "time is neither an input nor an output".to_owned())
        })
        .collect()
}

/// The first time derivatives (order 1, `maxOutputDerivativeOrder="1"`) of continuous Float64
/// outputs at the current communication point, along the trajectory the integrator follows
/// there: from the state derivative of the equations of motion, by a central difference of the
/// outputs along it ([`crate::cosim::Simulation::output_derivatives`]). Arrays give all their
/// elements; another order, a non-output or a count that does not match is refused.
#[no_mangle]
pub extern "C" fn fmi3GetOutputDerivatives(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    orders: *const fmi3Int32,
    values: *mut fmi3Float64,
    nValues: usize,
) -> fmi3Status {
    ABI.entry(
        instance,
        "fmi3GetOutputDerivatives",
        state::GET_OUTPUT_DERIVATIVES,
        |h| {
            // SAFETY: FMI passes nValueReferences value references and orders, and room for
            // nValues values.
            let (vrs, orders, out) = unsafe {
                (
                    array(valueReferences, nValueReferences, "valueReferences")?,
                    array(orders, nValueReferences, "orders")?,
                    array_mut(values, nValues, "values")?,
                )
            };
            if let Some(order) = orders.iter().find(|o| **o != 1) {
                return Err(format!(
                    "derivative order {order} is not provided (maxOutputDerivativeOrder=1)"
                ));
            }
            let outputs = elements(&resolve::<f64>(vrs, h.instance.modes_size, nValues)?)?;
            let derivatives = h.instance.output_derivatives(&outputs)?;
            out.copy_from_slice(&derivatives);
            Ok(Status::Ok)
        },
    )
}
const _: fmi3GetOutputDerivativesTYPE = Some(fmi3GetOutputDerivatives);

// ----- model exchange and scheduled execution: never instantiated ------------------------------

// Masters such as fmpy resolve every function of fmi3Functions.h, so the model-exchange and
// scheduled-execution ones exist too; a co-simulation instance refuses them.

refused!(
    fmi3EnterContinuousTimeMode,
    fmi3EnterContinuousTimeModeTYPE,
    "model exchange only; this is a co-simulation instance",
    ()
);
refused!(fmi3CompletedIntegratorStep, fmi3CompletedIntegratorStepTYPE,
    "model exchange only; this is a co-simulation instance",
    (noSetFMUStatePriorToCurrentPoint: fmi3Boolean, enterEventMode: *mut fmi3Boolean,
     terminateSimulation: *mut fmi3Boolean));
refused!(fmi3SetTime, fmi3SetTimeTYPE,
    "model exchange only; this is a co-simulation instance", (time: fmi3Float64));
refused!(fmi3SetContinuousStates, fmi3SetContinuousStatesTYPE,
    "model exchange only; this is a co-simulation instance",
    (continuousStates: *const fmi3Float64, nContinuousStates: usize));
refused!(fmi3GetContinuousStateDerivatives, fmi3GetContinuousStateDerivativesTYPE,
    "model exchange only; this is a co-simulation instance",
    (derivatives: *mut fmi3Float64, nContinuousStates: usize));
refused!(fmi3GetEventIndicators, fmi3GetEventIndicatorsTYPE,
    "model exchange only; this is a co-simulation instance",
    (eventIndicators: *mut fmi3Float64, nEventIndicators: usize));
refused!(fmi3GetContinuousStates, fmi3GetContinuousStatesTYPE,
    "model exchange only; this is a co-simulation instance",
    (continuousStates: *mut fmi3Float64, nContinuousStates: usize));
refused!(fmi3GetNominalsOfContinuousStates, fmi3GetNominalsOfContinuousStatesTYPE,
    "model exchange only; this is a co-simulation instance",
    (nominals: *mut fmi3Float64, nContinuousStates: usize));
refused!(fmi3GetNumberOfEventIndicators, fmi3GetNumberOfEventIndicatorsTYPE,
    "model exchange only; this is a co-simulation instance", (nEventIndicators: *mut usize));
refused!(fmi3GetNumberOfContinuousStates, fmi3GetNumberOfContinuousStatesTYPE,
    "model exchange only; this is a co-simulation instance", (nContinuousStates: *mut usize));
refused!(fmi3ActivateModelPartition, fmi3ActivateModelPartitionTYPE,
    "scheduled execution only; this is a co-simulation instance",
    (clockReference: fmi3ValueReference, activationTime: fmi3Float64));

// ----- FMU state -------------------------------------------------------------------------------

/// Copies the instance's complete state (values, input signals, time, integrator history) into a
/// new FMU state, or into the given one if `*FMUState` is a state of this instance.
#[no_mangle]
pub extern "C" fn fmi3GetFMUState(
    instance: fmi3Instance,
    FMUState: *mut fmi3FMUState,
) -> fmi3Status {
    ABI.entry(instance, "fmi3GetFMUState", state::GET_FMU_STATE, |h| {
        // SAFETY: FMUState points to a writable fmi3FMUState slot (FMI 3.0 §2.3.6.5).
        unsafe { h.get_fmu_state(FMUState) }
    })
}
const _: fmi3GetFMUStateTYPE = Some(fmi3GetFMUState);

/// Restores a state this instance handed out (also out of the error state). Refused if it was
/// taken with other parameters than the model this instance has built.
#[no_mangle]
pub extern "C" fn fmi3SetFMUState(instance: fmi3Instance, FMUState: fmi3FMUState) -> fmi3Status {
    ABI.entry(instance, "fmi3SetFMUState", state::ANY, |h| {
        h.set_fmu_state(FMUState)
    })
}
const _: fmi3SetFMUStateTYPE = Some(fmi3SetFMUState);

/// Frees an FMU state of this instance and sets `*FMUState` to null; null is ignored, a foreign
/// pointer refused.
#[no_mangle]
pub extern "C" fn fmi3FreeFMUState(
    instance: fmi3Instance,
    FMUState: *mut fmi3FMUState,
) -> fmi3Status {
    ABI.entry(instance, "fmi3FreeFMUState", state::ANY, |h| {
        // SAFETY: FMUState is null or points to a slot holding null or a state.
        unsafe { h.free_fmu_state(FMUState) }
    })
}
const _: fmi3FreeFMUStateTYPE = Some(fmi3FreeFMUState);

/// Writes the number of bytes [`fmi3SerializeFMUState`] needs for this state.
#[no_mangle]
pub extern "C" fn fmi3SerializedFMUStateSize(
    instance: fmi3Instance,
    FMUState: fmi3FMUState,
    size: *mut usize,
) -> fmi3Status {
    ABI.entry(instance, "fmi3SerializedFMUStateSize", state::ANY, |h| {
        // SAFETY: size points to a writable size_t.
        unsafe { h.serialized_fmu_state_size(FMUState, size) }
    })
}
const _: fmi3SerializedFMUStateSizeTYPE = Some(fmi3SerializedFMUStateSize);

/// Serialises an FMU state of this instance into a buffer of exactly the size
/// [`fmi3SerializedFMUStateSize`] reported (the 2.0 FMU's format: the bytes are interchangeable
/// between the two FMUs).
#[no_mangle]
pub extern "C" fn fmi3SerializeFMUState(
    instance: fmi3Instance,
    FMUState: fmi3FMUState,
    serializedState: *mut fmi3Byte,
    size: usize,
) -> fmi3Status {
    ABI.entry(instance, "fmi3SerializeFMUState", state::ANY, |h| {
        // SAFETY: the master provides a writable buffer of `size` bytes.
        unsafe { h.serialize_fmu_state(FMUState, serializedState, size) }
    })
}
const _: fmi3SerializeFMUStateTYPE = Some(fmi3SerializeFMUState);

/// Creates an FMU state from serialised bytes (of either FMU, possibly another process);
/// bytes of another model, malformed or inadmissible, are refused. The model is rebuilt from
/// the state's own parameters.
#[no_mangle]
pub extern "C" fn fmi3DeserializeFMUState(
    instance: fmi3Instance,
    serializedState: *const fmi3Byte,
    size: usize,
    FMUState: *mut fmi3FMUState,
) -> fmi3Status {
    ABI.entry(instance, "fmi3DeserializeFMUState", state::ANY, |h| {
        // SAFETY: the master provides `size` readable bytes and a writable state slot.
        unsafe { h.deserialize_fmu_state(serializedState, size, FMUState) }
    })
}
const _: fmi3DeserializeFMUStateTYPE = Some(fmi3DeserializeFMUState);

// ----- co-simulation ---------------------------------------------------------------------------

/// Integrates from `currentCommunicationPoint` (the FMU's time) over `communicationStepSize`
/// (> 0, not past the stop time), exactly as fmi2DoStep. Never returns early and never needs
/// event handling. fmi3Warning if an input ramp was bent onto a bound; fmi3Discard if the
/// integrator failed: `lastSuccessfulTime` is where it stopped and `terminateSimulation` is true
/// (afterwards only fmi3Terminate, reading values or restoring an FMU state continue).
#[no_mangle]
pub extern "C" fn fmi3DoStep(
    instance: fmi3Instance,
    currentCommunicationPoint: fmi3Float64,
    communicationStepSize: fmi3Float64,
    _noSetFMUStatePriorToCurrentPoint: fmi3Boolean,
    eventHandlingNeeded: *mut fmi3Boolean,
    terminateSimulation: *mut fmi3Boolean,
    earlyReturn: *mut fmi3Boolean,
    lastSuccessfulTime: *mut fmi3Float64,
) -> fmi3Status {
    ABI.entry(instance, "fmi3DoStep", state::DO_STEP, |h| {
        // SAFETY: FMI 3.0 passes four writable out-arguments.
        let (event, terminate, early, last) = unsafe {
            (
                place(eventHandlingNeeded, "eventHandlingNeeded")?,
                place(terminateSimulation, "terminateSimulation")?,
                place(earlyReturn, "earlyReturn")?,
                place(lastSuccessfulTime, "lastSuccessfulTime")?,
            )
        };
        *event = false;
        *early = false;
        if h.instance.core.phase == Phase::StepFailed {
            *terminate = true;
            *last = h.instance.last_successful_time();
            return Err("an earlier step failed (terminateSimulation); call fmi3Terminate or restore an FMU state".into());
        }
        let result = h
            .instance
            .do_step(currentCommunicationPoint, communicationStepSize);
        *terminate = h.instance.core.terminated;
        *last = h.instance.last_successful_time();
        result
    })
}
const _: fmi3DoStepTYPE = Some(fmi3DoStep);

#[cfg(test)]
#[path = "abi_concurrency.rs"]
mod concurrency;
