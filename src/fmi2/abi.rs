//! The exported FMI 2.0 functions: the standard's signatures over the runtime ([`crate::fmu`]).
//! Every entry point that takes an instance passes the runtime's one guard
//! ([`crate::fmu::guard::Abi::entry`]) with its state mask ([`super::state`]); inside, C arguments
//! become Rust values ([`crate::fmu::c_args`]), value references become typed positions
//! ([`super::values`]), and the runtime does the rest.

#![allow(non_snake_case)]
#![allow(clippy::not_unsafe_ptr_arg_deref)] // the C ABI hands us raw pointers by design

use std::ffi::c_char;

use fmi_sys::fmi2::*;

use super::state;
use super::uri::resource_path;
use super::values::{indices, real_knowns, slots};
use crate::cosim::FmuKind;
use crate::fmu::c_args::{array, array_mut, place, string_value, texts};
use crate::fmu::guard::{self, Abi, FunctionNames, Request};
use crate::fmu::instance::{Outcome, Status};
use crate::fmu::logger::Logger;
use crate::fmu::state::Phase;
use crate::fmu::values::Typed;

/// FMI 2.0 as the runtime sees it.
pub static ABI: Abi = Abi {
    // Marks a live instance of fmi2Instantiate.
    live: 0x454d_4346_4d55_0001,
    kinds: &[FmuKind::Engine, FmuKind::Body],
    token: "GUID",
    resources: "resource location",
    errors_enter_error_state: false,
    phase_name: Phase::name,
    error_state_hint: "",
    names: FunctionNames {
        instantiate: "fmi2Instantiate",
        free_instance: "fmi2FreeInstance",
        setup_experiment: "fmi2SetupExperiment",
        exit_initialization: "fmi2ExitInitializationMode",
        do_step: "fmi2DoStep",
        set_fmu_state: "fmi2SetFMUstate",
    },
};

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
/// logger: a missing `instanceName`, a `fmuType` other than co-simulation, a GUID that is neither
/// of this library's FMUs', or a resource location that is not a directory. The model itself is
/// built only in [`fmi2ExitInitializationMode`], or earlier when an output or a calculated
/// parameter is read in initialisation mode.
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
    let (callback, environment) = if functions.is_null() {
        (None, std::ptr::null_mut())
    } else {
        // SAFETY: non-null; FMI 2.0 requires it to point to a callback struct that stays valid
        // for the instance's lifetime. We copy the two fields we use.
        let f = unsafe { &*functions };
        (f.logger, f.componentEnvironment)
    };
    let request = Request {
        name: instanceName,
        token: fmuGUID,
        resources: fmuResourceLocation,
        resource_dir,
    };
    let refusal = (fmuType != fmi2Type_fmi2CoSimulation)
        .then_some("this FMU supports co-simulation only (fmuType must be fmi2CoSimulation)");
    guard::instantiate(
        &ABI,
        request,
        |name| Logger::new(callback, environment, name, loggingOn != 0),
        refusal,
    )
}
const _: fmi2InstantiateTYPE = Some(fmi2Instantiate);

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

/// Frees the instance and every FMU state it handed out. A null or already freed handle is
/// ignored; allowed in every phase, including after a fatal error.
#[no_mangle]
pub extern "C" fn fmi2FreeInstance(c: fmi2Component) {
    guard::free(c, &ABI)
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
    ABI.entry(c, "fmi2SetDebugLogging", state::SET_DEBUG_LOGGING, |h| {
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
    ABI.entry(c, "fmi2SetupExperiment", state::SETUP_EXPERIMENT, |h| {
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
    ABI.entry(
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
    ABI.entry(
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
    ABI.entry(c, "fmi2Terminate", state::TERMINATE, |h| {
        h.instance.terminate()
    })
}
const _: fmi2TerminateTYPE = Some(fmi2Terminate);

/// Returns the instance to the state just after instantiation: start values, no model, no
/// experiment. FMU states handed out stay valid.
#[no_mangle]
pub extern "C" fn fmi2Reset(c: fmi2Component) -> fmi2Status {
    ABI.entry(c, "fmi2Reset", state::RESET, |h| h.instance.reset())
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
    ABI.entry(c, function, state::GET_VALUES, |h| {
        // SAFETY: FMI passes arrays of nvr value references and nvr values.
        let (vrs, out) = unsafe { (array(vr, nvr, "vr")?, array_mut(value, nvr, "value")?) };
        h.read::<T, C>(&slots::<T>(vrs)?, out, convert, |_| None)
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
    ABI.entry(c, function, state::SET_VALUES, |h| {
        // SAFETY: FMI passes arrays of nvr value references and nvr values.
        let (vrs, given) = unsafe { (array(vr, nvr, "vr")?, array(value, nvr, "value")?) };
        let values = vrs
            .iter()
            .zip(given)
            .map(|(vr, x)| convert(*vr, *x))
            .collect::<Result<Vec<T>, String>>()?;
        h.write(&slots::<T>(vrs)?, &values)
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
    ABI.entry(c, "fmi2GetString", state::GET_VALUES, |h| {
        // SAFETY: FMI passes arrays of nvr value references and nvr string slots.
        let (vrs, out) = unsafe { (array(vr, nvr, "vr")?, array_mut(value, nvr, "value")?) };
        h.read_strings(&slots::<String>(vrs)?, out)
    })
}
const _: fmi2GetStringTYPE = Some(fmi2GetString);

/// Sets Real inputs and parameters. All values are checked (range, finiteness, whether the
/// variable may be set in this phase: fixed parameters only before initialisation ends) before any
/// is applied, so a refused call changes nothing. An input set between steps takes effect at the
/// next fmi2DoStep: as a ramp with a derivative set by fmi2SetRealInputDerivatives, otherwise as
/// a first-order hold of the values set (see [`crate::fmu::input_track`]).
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
        unsafe { string_value(p) }
    })
}
const _: fmi2SetStringTYPE = Some(fmi2SetString);

// ----- FMU state -------------------------------------------------------------------------------

/// Copies the instance's complete state (values, input signals, time and integrator history)
/// into a new FMU state, or into the given one if `*FMUstate` is a state of this instance.
#[no_mangle]
pub extern "C" fn fmi2GetFMUstate(c: fmi2Component, FMUstate: *mut fmi2FMUstate) -> fmi2Status {
    ABI.entry(c, "fmi2GetFMUstate", state::FMU_STATE, |h| {
        // SAFETY: FMUstate points to a writable fmi2FMUstate slot (FMI 2.0 §2.1.8).
        unsafe { h.get_fmu_state(FMUstate) }
    })
}
const _: fmi2GetFMUstateTYPE = Some(fmi2GetFMUstate);

/// Restores a state this instance handed out. Refused if the state was taken with different
/// parameters than the model this instance has built (it would silently change the model).
#[no_mangle]
pub extern "C" fn fmi2SetFMUstate(c: fmi2Component, FMUstate: fmi2FMUstate) -> fmi2Status {
    ABI.entry(c, "fmi2SetFMUstate", state::FMU_STATE, |h| {
        h.set_fmu_state(FMUstate)
    })
}
const _: fmi2SetFMUstateTYPE = Some(fmi2SetFMUstate);

/// Frees an FMU state of this instance and sets `*FMUstate` to null; a null state is ignored, a
/// foreign pointer refused.
#[no_mangle]
pub extern "C" fn fmi2FreeFMUstate(c: fmi2Component, FMUstate: *mut fmi2FMUstate) -> fmi2Status {
    ABI.entry(c, "fmi2FreeFMUstate", state::FMU_STATE, |h| {
        // SAFETY: FMUstate is null or points to a slot holding null or a state.
        unsafe { h.free_fmu_state(FMUstate) }
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
    ABI.entry(c, "fmi2SerializedFMUstateSize", state::FMU_STATE, |h| {
        // SAFETY: size points to a writable size_t.
        unsafe { h.serialized_fmu_state_size(FMUstate, size) }
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
    ABI.entry(c, "fmi2SerializeFMUstate", state::FMU_STATE, |h| {
        // SAFETY: the master provides a writable buffer of `size` bytes.
        unsafe { h.serialize_fmu_state(FMUstate, serializedState as *mut u8, size) }
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
    ABI.entry(c, "fmi2DeSerializeFMUstate", state::FMU_STATE, |h| {
        // SAFETY: the master provides `size` readable bytes and a writable state slot.
        unsafe { h.deserialize_fmu_state(serializedState as *const u8, size, FMUstate) }
    })
}
const _: fmi2DeSerializeFMUstateTYPE = Some(fmi2DeSerializeFMUstate);

/// Directional derivatives of Real outputs with respect to Real inputs
/// (`providesDirectionalDerivative="true"`): `dvUnknown[i] = Σ_k ∂unknown_i/∂known_k · dvKnown[k]`,
/// in initialisation mode of the initial unknowns and between steps at the current
/// communication point, the state held (see `Instance::directional_derivative`). A known of
/// another type is accepted with a zero seed (`real_knowns`).
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
    ABI.entry(
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
            let (knowns, seeds) = real_knowns(knowns, seeds, h.instance.fmu_bit())?;
            let values = h
                .instance
                .directional_derivative(&unknowns, &knowns, &seeds)?;
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
    ABI.entry(
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
    ABI.entry(
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
    ABI.entry(c, "fmi2DoStep", state::DO_STEP, |h| {
        h.instance
            .do_step(currentCommunicationPoint, communicationStepSize)
    })
}
const _: fmi2DoStepTYPE = Some(fmi2DoStep);

/// Always refused with fmi2Error: fmi2DoStep completes before returning, so no step is ever in
/// progress.
#[no_mangle]
pub extern "C" fn fmi2CancelStep(c: fmi2Component) -> fmi2Status {
    ABI.entry(c, "fmi2CancelStep", state::CANCEL_STEP, |_| {
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
    ABI.entry(c, "fmi2GetStatus", state::GET_STATUS, |_| {
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
    ABI.entry(c, "fmi2GetRealStatus", state::GET_STATUS, |h| {
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
    ABI.entry(c, "fmi2GetIntegerStatus", state::GET_STATUS, |_| {
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
    ABI.entry(c, "fmi2GetBooleanStatus", state::GET_STATUS, |h| {
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
    ABI.entry(c, "fmi2GetStringStatus", state::GET_STATUS, |_| {
        no_status(s, "String")
    })
}
const _: fmi2GetStringStatusTYPE = Some(fmi2GetStringStatus);

#[cfg(test)]
#[path = "abi_state_table.rs"]
mod state_table;
