//! The FMI 3.0 ABI of the same cdylib: its state machine with the error state, the refusals of
//! what the FMU does not provide, arrays over the 2.0 variables, and a 3.0 run that repeats a
//! 2.0 run of the same library bit for bit.

#![allow(non_snake_case)] // the symbol fields carry the FMI function names

use std::ffi::{c_char, CStr, CString};
use std::path::PathBuf;
use std::sync::Mutex;

use fmi_sys::fmi3::*;
use libloading::Library;

use crate::common::{self, integer, real, Fmu, GUID};
use engine_mount_chassis::variables::fmi3::{MODES_SIZE, MODES_SIZE_MAX, TIME};
use engine_mount_chassis::variables::BODY_GUID;

const OK: fmi3Status = fmi3Status_fmi3OK;
const ERROR: fmi3Status = fmi3Status_fmi3Error;

/// Messages of every 3.0 instance, as "status category message".
static LOG: Mutex<Vec<String>> = Mutex::new(Vec::new());

unsafe extern "C" fn log_message(
    _env: fmi3InstanceEnvironment,
    status: fmi3Status,
    category: fmi3String,
    message: fmi3String,
) {
    // SAFETY: the FMU passes NUL-terminated strings valid for the call.
    let (category, message) = unsafe {
        (
            CStr::from_ptr(category).to_string_lossy(),
            CStr::from_ptr(message).to_string_lossy(),
        )
    };
    if let Ok(mut log) = LOG.lock() {
        log.push(format!("{status} {category} {message}"));
    }
}

fn logged(part: &str) -> bool {
    LOG.lock().is_ok_and(|l| l.iter().any(|m| m.contains(part)))
}

macro_rules! symbols {
    ($($name:ident : $ty:ident),* $(,)?) => {
        #[allow(non_snake_case)]
        pub(crate) struct F3 { _lib: Library, $(pub(crate) $name: <$ty as Inner>::F,)* }
        impl F3 {
            pub(crate) fn load() -> F3 {
                let path = common::library_path();
                // SAFETY: our own cdylib; the symbols have the signatures of fmi-sys' fmi3
                // typedefs, and the copied pointers live no longer than the library in F3.
                unsafe {
                    let lib = Library::new(&path).expect("load the cdylib");
                    $(let $name = *lib
                        .get::<<$ty as Inner>::F>(concat!(stringify!($name), "\0").as_bytes())
                        .expect(stringify!($name));)*
                    F3 { _lib: lib, $($name,)* }
                }
            }
        }
    };
}

pub(crate) trait Inner {
    type F: Copy;
}
impl<F: Copy> Inner for Option<F> {
    type F = F;
}

symbols! {
    fmi3InstantiateCoSimulation: fmi3InstantiateCoSimulationTYPE,
    fmi3InstantiateModelExchange: fmi3InstantiateModelExchangeTYPE,
    fmi3FreeInstance: fmi3FreeInstanceTYPE,
    fmi3EnterInitializationMode: fmi3EnterInitializationModeTYPE,
    fmi3ExitInitializationMode: fmi3ExitInitializationModeTYPE,
    fmi3EnterConfigurationMode: fmi3EnterConfigurationModeTYPE,
    fmi3ExitConfigurationMode: fmi3ExitConfigurationModeTYPE,
    fmi3EnterEventMode: fmi3EnterEventModeTYPE,
    fmi3Terminate: fmi3TerminateTYPE,
    fmi3Reset: fmi3ResetTYPE,
    fmi3GetFloat64: fmi3GetFloat64TYPE,
    fmi3SetFloat64: fmi3SetFloat64TYPE,
    fmi3SetInt32: fmi3SetInt32TYPE,
    fmi3GetDirectionalDerivative: fmi3GetDirectionalDerivativeTYPE,
    fmi3GetFloat32: fmi3GetFloat32TYPE,
    fmi3GetInt32: fmi3GetInt32TYPE,
    fmi3GetUInt64: fmi3GetUInt64TYPE,
    fmi3SetUInt64: fmi3SetUInt64TYPE,
    fmi3SetBoolean: fmi3SetBooleanTYPE,
    fmi3GetFMUState: fmi3GetFMUStateTYPE,
    fmi3SetFMUState: fmi3SetFMUStateTYPE,
    fmi3FreeFMUState: fmi3FreeFMUStateTYPE,
    fmi3GetOutputDerivatives: fmi3GetOutputDerivativesTYPE,
    fmi3SetIntervalDecimal: fmi3SetIntervalDecimalTYPE,
    fmi3DoStep: fmi3DoStepTYPE,
}

pub(crate) struct Instance<'a> {
    pub(crate) f: &'a F3,
    pub(crate) i: fmi3Instance,
}

impl F3 {
    pub(crate) fn try_instantiate(&self, token: &str, event_mode: bool) -> Option<Instance<'_>> {
        self.try_instantiate_with(token, event_mode, &[])
    }

    /// As [`F3::try_instantiate`], with the master's required intermediate variables.
    fn try_instantiate_with(
        &self,
        token: &str,
        event_mode: bool,
        intermediate: &[u32],
    ) -> Option<Instance<'_>> {
        let name = CString::new("three").unwrap();
        let token = CString::new(token).unwrap();
        let resources = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("resources");
        let resources = CString::new(format!("{}/", resources.display())).unwrap();
        // SAFETY: valid NUL-terminated strings and a logger that lives for the whole test binary.
        let i = unsafe {
            (self.fmi3InstantiateCoSimulation)(
                name.as_ptr(),
                token.as_ptr(),
                resources.as_ptr(),
                false,
                false,
                event_mode,
                !intermediate.is_empty(),
                intermediate.as_ptr(),
                intermediate.len(),
                std::ptr::null_mut(),
                Some(log_message),
                None,
            )
        };
        (!i.is_null()).then_some(Instance { f: self, i })
    }

    pub(crate) fn instantiate(&self) -> Instance<'_> {
        self.try_instantiate(GUID, false).expect("instantiate")
    }
}

// SAFETY (all methods): `i` is a live instance of this library, the slices are valid for the
// lengths passed, and out-pointers point to locals.
impl Instance<'_> {
    pub(crate) fn init(&self) -> fmi3Status {
        let s =
            unsafe { (self.f.fmi3EnterInitializationMode)(self.i, false, 0.0, 0.0, false, 0.0) };
        if s != OK {
            return s;
        }
        unsafe { (self.f.fmi3ExitInitializationMode)(self.i) }
    }
    pub(crate) fn step(&self, t: f64, h: f64) -> (fmi3Status, [bool; 3], f64) {
        let (mut e, mut term, mut early, mut last) = (true, true, true, -1.0);
        let s = unsafe {
            (self.f.fmi3DoStep)(self.i, t, h, true, &mut e, &mut term, &mut early, &mut last)
        };
        (s, [e, term, early], last)
    }
    pub(crate) fn get(&self, vrs: &[u32], n: usize) -> (fmi3Status, Vec<f64>) {
        let mut v = vec![0.0; n];
        let s =
            unsafe { (self.f.fmi3GetFloat64)(self.i, vrs.as_ptr(), vrs.len(), v.as_mut_ptr(), n) };
        (s, v)
    }
    pub(crate) fn set(&self, vrs: &[u32], values: &[f64]) -> fmi3Status {
        unsafe {
            (self.f.fmi3SetFloat64)(
                self.i,
                vrs.as_ptr(),
                vrs.len(),
                values.as_ptr(),
                values.len(),
            )
        }
    }
    pub(crate) fn derivative(
        &self,
        unknowns: &[u32],
        n: usize,
        knowns: &[u32],
        seed: &[f64],
    ) -> Vec<f64> {
        let mut out = vec![0.0; n];
        let s = unsafe {
            (self.f.fmi3GetDirectionalDerivative)(
                self.i,
                unknowns.as_ptr(),
                unknowns.len(),
                knowns.as_ptr(),
                knowns.len(),
                seed.as_ptr(),
                seed.len(),
                out.as_mut_ptr(),
                n,
            )
        };
        assert_eq!(s, OK, "fmi3GetDirectionalDerivative");
        out
    }
    pub(crate) fn get_state(&self) -> (fmi3Status, fmi3FMUState) {
        let mut state = std::ptr::null_mut();
        let s = unsafe { (self.f.fmi3GetFMUState)(self.i, &mut state) };
        (s, state)
    }
}

impl Drop for Instance<'_> {
    fn drop(&mut self) {
        unsafe { (self.f.fmi3FreeInstance)(self.i) }
    }
}

#[test]
fn instantiation_refuses_event_mode_a_foreign_token_and_model_exchange() {
    let f = F3::load();
    assert!(f.try_instantiate(GUID, true).is_none());
    assert!(logged("eventModeUsed"));
    assert!(f.try_instantiate("{not-this-fmu}", false).is_none());
    assert!(logged("does not match"));
    let name = CString::new("me").unwrap();
    let token = CString::new(GUID).unwrap();
    // SAFETY: valid strings; the FMU returns null without keeping any pointer.
    let me = unsafe {
        (f.fmi3InstantiateModelExchange)(
            name.as_ptr(),
            token.as_ptr(),
            std::ptr::null::<c_char>(),
            false,
            false,
            std::ptr::null_mut(),
            Some(log_message),
        )
    };
    assert!(me.is_null());
    assert!(f.try_instantiate(GUID, false).is_some());
}

/// `fmusim --early-return-allowed --record-intermediate-values` lists required intermediate
/// variables; the FMU provides no intermediate update, so it ignores the list, as the
/// Reference-FMUs do, instead of refusing to instantiate.
#[test]
fn required_intermediate_variables_are_ignored_as_the_reference_fmus_do() {
    let f = F3::load();
    let a = f
        .try_instantiate_with(GUID, false, &[real::CRANK_ANGLE, real::MOUNT_F[0][2]])
        .expect("instantiated with required intermediate variables");
    assert_eq!(a.init(), OK);
    let (s, flags, _) = a.step(0.0, 1e-3);
    assert_eq!((s, flags), (OK, [false, false, false]));
}

#[test]
fn an_error_leads_to_the_error_state_left_by_reset_or_a_restored_state() {
    let f = F3::load();
    let a = f.instantiate();
    // Stepping before initialisation is refused, and from then on only recovery is allowed.
    assert_eq!(a.step(0.0, 1e-3).0, ERROR);
    assert!(logged("fmi3DoStep is not allowed in phase Instantiated"));
    // Reading for diagnosis is allowed in the error state, but before initialisation there is
    // nothing to read (a natural mode would build the model).
    let modes = [real::MODE_FREQUENCY[0]];
    assert_eq!(a.get(&modes, MODES_SIZE_MAX as usize).0, ERROR);
    assert!(logged("nothing to read before initialisation"));
    assert_eq!(
        unsafe { (f.fmi3EnterInitializationMode)(a.i, false, 0.0, 0.0, false, 0.0) },
        ERROR
    );
    assert!(logged("is not allowed in phase Error"));
    assert_eq!(unsafe { (f.fmi3Reset)(a.i) }, OK);
    assert_eq!(a.init(), OK);
    let (s, saved) = a.get_state();
    assert_eq!(s, OK);
    assert_eq!(a.step(0.0, 1e-3).0, OK);
    // A step from the wrong time is an error; restoring the saved state leaves the error state.
    assert_eq!(a.step(0.5, 1e-3).0, ERROR);
    assert_eq!(a.step(1e-3, 1e-3).0, ERROR);
    assert_eq!(unsafe { (f.fmi3SetFMUState)(a.i, saved) }, OK);
    let (s, flags, last) = a.step(0.0, 1e-3);
    assert_eq!((s, flags), (OK, [false, false, false]));
    assert!((last - 1e-3).abs() < 1e-15);
    assert_eq!(unsafe { (f.fmi3Terminate)(a.i) }, OK);
    assert_eq!(a.step(1e-3, 1e-3).0, ERROR);
    let mut saved = saved;
    assert_eq!(unsafe { (f.fmi3FreeFMUState)(a.i, &mut saved) }, OK);
    assert!(saved.is_null());
}

#[test]
fn what_the_fmu_does_not_have_is_refused() {
    let f = F3::load();
    let a = f.instantiate();
    assert_eq!(unsafe { (f.fmi3EnterEventMode)(a.i) }, ERROR);
    assert!(logged("hasEventMode=false"));
    let b = f.instantiate();
    assert_eq!(b.init(), OK);
    let vr = [real::CRANK_ANGLE];
    let (order, mut value) = ([2], [0.0]);
    // SAFETY: arrays of one element each.
    let s = unsafe {
        (f.fmi3GetOutputDerivatives)(b.i, vr.as_ptr(), 1, order.as_ptr(), value.as_mut_ptr(), 1)
    };
    assert_eq!(s, ERROR);
    assert!(logged("derivative order 2 is not provided"));
    let c = f.instantiate();
    assert_eq!(c.init(), OK);
    let mut x = [0f32];
    // SAFETY: one value reference, room for one value.
    assert_eq!(
        unsafe { (f.fmi3GetFloat32)(c.i, vr.as_ptr(), 1, x.as_mut_ptr(), 1) },
        ERROR
    );
    assert!(logged(
        "is not a Float32 variable of this FMU (crankAngle is a Float64)"
    ));
    let d = f.instantiate();
    assert_eq!(
        unsafe { (f.fmi3SetIntervalDecimal)(d.i, vr.as_ptr(), 1, [1.0].as_ptr()) },
        ERROR
    );
    assert!(logged("no clocks"));
    // Booleans arrive as bytes: 2 is neither true nor false.
    let e = f.instantiate();
    let vr = [common::value_references(2, &[common::boolean::EFFECT_GAS_FORCES])[0]];
    let two = [2u8];
    // SAFETY: one value reference and one byte where the C API has one bool.
    let s = unsafe { (f.fmi3SetBoolean)(e.i, vr.as_ptr(), 1, two.as_ptr() as *const bool, 1) };
    assert_eq!(s, ERROR);
}

#[test]
fn arrays_count_their_elements_and_modes_size_is_set_in_configuration_mode() {
    let f = F3::load();
    let a = f.instantiate();
    let size = [MODES_SIZE];
    // SAFETY: one value reference and one value, in and out.
    unsafe {
        assert_eq!(
            (f.fmi3SetUInt64)(a.i, size.as_ptr(), 1, [5u64].as_ptr(), 1),
            ERROR
        );
        assert_eq!((f.fmi3Reset)(a.i), OK);
        assert_eq!((f.fmi3EnterConfigurationMode)(a.i), OK);
        let too_many = [MODES_SIZE_MAX + 1];
        assert_eq!(
            (f.fmi3SetUInt64)(a.i, size.as_ptr(), 1, too_many.as_ptr(), 1),
            ERROR
        );
        assert_eq!((f.fmi3Reset)(a.i), OK);
        assert_eq!((f.fmi3EnterConfigurationMode)(a.i), OK);
        assert_eq!(
            (f.fmi3SetUInt64)(a.i, size.as_ptr(), 1, [5u64].as_ptr(), 1),
            OK
        );
        assert_eq!((f.fmi3ExitConfigurationMode)(a.i), OK);
        let mut n = [0u64];
        assert_eq!(
            (f.fmi3GetUInt64)(a.i, size.as_ptr(), 1, n.as_mut_ptr(), 1),
            OK
        );
        assert_eq!(n, [5]);
    }
    assert_eq!(a.init(), OK);
    let modes = [real::MODE_FREQUENCY[0]];
    assert_eq!(a.get(&modes, 6).0, ERROR);
    let b = f.instantiate();
    assert_eq!(b.init(), OK);
    let (s, all) = b.get(&modes, MODES_SIZE_MAX as usize);
    assert_eq!(s, OK);
    let c = f.instantiate();
    unsafe {
        assert_eq!((f.fmi3EnterConfigurationMode)(c.i), OK);
        assert_eq!(
            (f.fmi3SetUInt64)(c.i, size.as_ptr(), 1, [5u64].as_ptr(), 1),
            OK
        );
        assert_eq!((f.fmi3ExitConfigurationMode)(c.i), OK);
    }
    assert_eq!(c.init(), OK);
    let (s, five) = c.get(&modes, 5);
    assert_eq!(s, OK);
    assert_eq!(five, all[..5]);
    assert!(five[0] > 0.0);
    // time reads as the FMU's time and cannot be set.
    assert_eq!(c.get(&[TIME], 1), (OK, vec![0.0]));
    assert_eq!(c.set(&[TIME], &[1.0]), ERROR);
}

#[test]
fn a_3_0_run_repeats_the_2_0_run_of_the_same_library_bit_for_bit() {
    let f = F3::load();
    let fmu2 = common::Fmu::load();
    let two = fmu2.instantiate("two-beside-three");
    let three = f.instantiate();
    two.initialize();
    assert_eq!(three.init(), OK);
    let forces: Vec<u32> = real::MOUNT_F.iter().flatten().copied().collect();
    let steps_vr = common::value_references(1, &[integer::SOLVER_STEPS]);
    let mut steps3 = [0i32];
    for k in 0..100 {
        let t = k as f64 * 1e-3;
        let rpm = 1200.0 + 3000.0 * t;
        assert_eq!(two.set_real(&[real::RPM], &[rpm]), common::OK);
        assert_eq!(three.set(&[real::RPM], &[rpm]), OK);
        assert_eq!(two.do_step(t, 1e-3), common::OK);
        assert_eq!(three.step(t, 1e-3).0, OK);
        let (s, x3) = three.get(&[real::MOUNT_F[0][0]], 12);
        assert_eq!(s, OK);
        assert_eq!(two.reals(&forces), x3, "mount forces at step {k}");
    }
    // SAFETY: one value reference, room for one value.
    let s = unsafe { (f.fmi3GetInt32)(three.i, steps_vr.as_ptr(), 1, steps3.as_mut_ptr(), 1) };
    assert_eq!(s, OK);
    assert_eq!(
        two.get_integer(&[integer::SOLVER_STEPS]),
        (common::OK, steps3.to_vec())
    );
    assert!(steps3[0] > 0);
}

impl Instance<'_> {
    fn derivatives(&self, vrs: &[u32], n: usize) -> (fmi3Status, Vec<f64>) {
        let orders = vec![1; vrs.len()];
        let mut v = vec![0.0; n];
        // SAFETY: vrs and orders of equal length, room for n values.
        let s = unsafe {
            (self.f.fmi3GetOutputDerivatives)(
                self.i,
                vrs.as_ptr(),
                vrs.len(),
                orders.as_ptr(),
                v.as_mut_ptr(),
                n,
            )
        };
        (s, v)
    }
}

/// The output derivatives are the slopes of the outputs' trajectories: compared with central
/// differences of the outputs over 20 µs communication steps (their error ~ (20 µs)² ω² / 6 of
/// the derivative, and the integrator's tolerance), and asking for them changes nothing in the run.
#[test]
fn output_derivatives_are_the_slopes_of_the_trajectories_and_change_nothing() {
    let f = F3::load();
    let (a, b) = (f.instantiate(), f.instantiate());
    let tight = [real::SOLVER_REL_TOL];
    for x in [&a, &b] {
        assert_eq!(x.set(&tight, &[1e-9]), OK);
        assert_eq!(x.init(), OK);
    }
    let vrs = [
        real::CRANK_ANGLE,
        real::POWERTRAIN_R[0],
        real::MOUNT_F[0][0],
    ];
    let h = 2e-5;
    let mut outputs = Vec::new();
    let mut slopes = Vec::new();
    for k in 0..3000 {
        let t = k as f64 * h;
        assert_eq!(a.step(t, h).0, OK);
        assert_eq!(b.step(t, h).0, OK);
        let (s, y) = a.get(&vrs, 1 + 3 + 12);
        assert_eq!(s, OK);
        let (s, dy) = a.derivatives(&vrs, 1 + 3 + 12);
        assert_eq!(s, OK);
        assert_eq!(
            b.get(&vrs, 16).1,
            y,
            "a run that asks for derivatives is the same run"
        );
        outputs.push(y);
        slopes.push(dy);
    }
    // The crank angle's rate: the set-point, 800 rpm, plus the block's rocking about the crank
    // axis (the angle is measured against the block).
    let speed = 800.0 * std::f64::consts::PI / 30.0;
    assert!(
        (slopes[2999][0] - speed).abs() < 1e-2 * speed,
        "{}",
        slopes[2999][0]
    );
    let mut worst = 0.0f64;
    for k in [1000, 2000, 2998] {
        for e in 0..16 {
            let difference = (outputs[k + 1][e] - outputs[k - 1][e]) / (2.0 * h);
            let scale = slopes.iter().map(|s| s[e].abs()).fold(0.0, f64::max);
            worst = worst.max((slopes[k][e] - difference).abs() / scale);
            assert!(
                (slopes[k][e] - difference).abs() <= 5e-4 * scale,
                "element {e} at step {k}: derivative {} vs central difference {difference}",
                slopes[k][e]
            );
        }
    }
    println!("output derivatives vs central differences: {worst:.1e} of the largest derivative");
    // An input is not an output.
    assert_eq!(a.derivatives(&[real::RPM], 1).0, ERROR);
}

/// The body's static forces at its mounts, N, vertical (row-major 4 × 3 as `mount.F`).
fn static_forces() -> Vec<f64> {
    let fz = [-600.0, -450.0, -400.0, -315.0];
    (0..12)
        .map(|k| if k % 3 == 2 { fz[k / 3] } else { 0.0 })
        .collect()
}

/// The 3.0 body FMU of the same library, initialised under the static forces.
fn body3(f: &F3) -> Instance<'_> {
    let b = f
        .try_instantiate(BODY_GUID, false)
        .expect("the library instantiates the FMI 3.0 body FMU");
    let s = unsafe { (f.fmi3EnterInitializationMode)(b.i, false, 0.0, 0.0, false, 0.0) };
    assert_eq!(s, OK);
    assert_eq!(b.set(&[real::BODY_MOUNT_F[0][0]], &static_forces()), OK);
    assert_eq!(unsafe { (f.fmi3ExitInitializationMode)(b.i) }, OK);
    b
}

/// The body's outputs as 3.0 arrays (value references of the first elements) and the 2.0
/// scalars they stand for, row-major.
fn body_outputs() -> (Vec<u32>, Vec<u32>) {
    let arrays = vec![
        real::BODY_MOUNT_R[0][0],
        real::BODY_MOUNT_V[0][0],
        real::BODY_MOUNT_A[0][0],
        real::STEERING_WHEEL_A[0],
        real::SEAT_A[0],
    ];
    let mut scalars: Vec<u32> = [real::BODY_MOUNT_R, real::BODY_MOUNT_V, real::BODY_MOUNT_A]
        .iter()
        .flatten()
        .flatten()
        .copied()
        .collect();
    scalars.extend(real::STEERING_WHEEL_A);
    scalars.extend(real::SEAT_A);
    (arrays, scalars)
}

/// The body FMU as FMI 3.0: the same library, instance and numbers as the 2.0 body under the
/// same varying mount forces (to 1e-12 of each output's size).
#[test]
fn the_3_0_body_gives_the_numbers_of_the_2_0_body() {
    let f = F3::load();
    let b3 = body3(&f);
    let fmu = Fmu::load();
    let b2 = fmu
        .instantiate_with("body2", BODY_GUID, Some(&common::resources_uri()))
        .expect("2.0 body");
    let forces2: Vec<u32> = real::BODY_MOUNT_F.iter().flatten().copied().collect();
    assert_eq!(b2.setup(0.0, None), OK);
    assert_eq!(b2.enter_init(), OK);
    assert_eq!(b2.set_real(&forces2, &static_forces()), OK);
    assert_eq!(b2.exit_init(), OK);
    let (arrays, scalars) = body_outputs();
    let h = 1e-3;
    let mut largest = 0.0f64;
    for k in 0..60 {
        let t = k as f64 * h;
        let forces: Vec<f64> = static_forces()
            .iter()
            .enumerate()
            .map(|(c, f0)| f0 + 80.0 * (2.0 * std::f64::consts::PI * (31.0 + c as f64) * t).sin())
            .collect();
        assert_eq!(b3.set(&[real::BODY_MOUNT_F[0][0]], &forces), OK);
        assert_eq!(b2.set_real(&forces2, &forces), OK);
        assert_eq!(b3.step(t, h).0, OK);
        assert_eq!(b2.do_step(t, h), OK);
        let (s, three) = b3.get(&arrays, scalars.len());
        assert_eq!(s, OK);
        let two = b2.reals(&scalars);
        for (x, y) in three.iter().zip(&two) {
            assert!(x.is_finite());
            let d = (x - y).abs() / y.abs().max(1e-12);
            largest = largest.max(d);
            assert!(
                (x - y).abs() <= 1e-12 * y.abs().max(1e-9),
                "t = {t}: 3.0 {x} vs 2.0 {y}"
            );
        }
    }
    eprintln!("3.0 body vs 2.0 body: largest relative difference {largest:e}");
}

/// Central difference of the `n` elements of the arrays `outputs` with respect to element `k`
/// of the array input `input` (all `values` set at once, as FMI 3.0 sets arrays).
fn central3(
    i: &Instance,
    outputs: &[u32],
    n: usize,
    input: u32,
    values: &[f64],
    k: usize,
    h: f64,
) -> Vec<f64> {
    let mut x = values.to_vec();
    x[k] = values[k] + h;
    assert_eq!(i.set(&[input], &x), OK);
    let plus = i.get(outputs, n).1;
    x[k] = values[k] - h;
    assert_eq!(i.set(&[input], &x), OK);
    let minus = i.get(outputs, n).1;
    assert_eq!(i.set(&[input], values), OK);
    plus.iter()
        .zip(&minus)
        .map(|(p, m)| (p - m) / (2.0 * h))
        .collect()
}

fn assert_close3(analytic: &[f64], difference: &[f64], what: &str) {
    let scale = analytic.iter().fold(1e-6f64, |m, x| m.max(x.abs()));
    for (a, d) in analytic.iter().zip(difference) {
        assert!(
            (a - d).abs() <= 1e-6 * scale,
            "{what}: directional derivative {a:e} vs central difference {d:e} (scale {scale:e})"
        );
    }
}

/// fmi3GetDirectionalDerivative in both 3.0 FMUs, arrays for their elements, against central
/// differences of the outputs as the 2.0 ones are checked (tests/fmi/coupling.rs): the body's
/// accelerations with respect to the mount forces, and in scene 3 the engine's mount forces and
/// powertrain acceleration with respect to the body's motion at the mounts.
#[test]
fn directional_derivatives_of_the_3_0_fmus_match_central_differences() {
    let f = F3::load();
    let b = body3(&f);
    assert_eq!(b.step(0.0, 1e-3).0, OK);
    let unknowns = [
        real::BODY_MOUNT_A[0][0],
        real::STEERING_WHEEL_A[0],
        real::SEAT_A[0],
    ];
    let forces = static_forces();
    for k in 0..12 {
        let mut seed = vec![0.0; 12];
        seed[k] = 1.0;
        let analytic = b.derivative(&unknowns, 18, &[real::BODY_MOUNT_F[0][0]], &seed);
        let difference = central3(&b, &unknowns, 18, real::BODY_MOUNT_F[0][0], &forces, k, 1.0);
        assert_close3(
            &analytic,
            &difference,
            &format!("body, mount.F element {k}"),
        );
    }

    let e = f.instantiate();
    let scene = common::value_references(1, &[integer::SCENE]);
    let s = unsafe { (f.fmi3EnterInitializationMode)(e.i, false, 0.0, 0.0, false, 0.0) };
    assert_eq!(s, OK);
    assert_eq!(
        unsafe { (f.fmi3SetInt32)(e.i, scene.as_ptr(), 1, [3].as_ptr(), 1) },
        OK
    );
    assert_eq!(unsafe { (f.fmi3ExitInitializationMode)(e.i) }, OK);
    for k in 0..10 {
        assert_eq!(e.step(k as f64 * 1e-3, 1e-3).0, OK);
    }
    // A displaced, moving body so that the mounts are off their operating point.
    let (r, v) = (real::MOUNT_BODY_R[0][0], real::MOUNT_BODY_V[0][0]);
    let offsets: Vec<f64> = (0..12).map(|k| 1e-4 * ((k % 5) as f64 - 2.0)).collect();
    let speeds: Vec<f64> = offsets.iter().map(|x| 30.0 * x).collect();
    assert_eq!(e.set(&[r], &offsets), OK);
    assert_eq!(e.set(&[v], &speeds), OK);
    let unknowns = [real::MOUNT_F[0][0], real::POWERTRAIN_A[0]];
    for (input, values, h) in [(r, &offsets, 1e-7), (v, &speeds, 1e-6)] {
        for k in 0..12 {
            let mut seed = vec![0.0; 12];
            seed[k] = 1.0;
            let analytic = e.derivative(&unknowns, 15, &[input], &seed);
            let difference = central3(&e, &unknowns, 15, input, values, k, h);
            assert_close3(
                &analytic,
                &difference,
                &format!("engine, input {input} element {k}"),
            );
        }
    }
}
