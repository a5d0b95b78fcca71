//! Drives the built cdylib through its C ABI, as a simulation tool would: dlopen with
//! libloading, resolve the fmi2 symbols, and wrap them in a small safe API for the tests.
//! Log messages are captured through fmi-sys' printf-style logger, keyed by instance name.

#![allow(dead_code)]
#![allow(non_snake_case)] // fields carry the FMI function names

use std::collections::HashMap;
use std::ffi::{c_char, CStr, CString};
use std::path::PathBuf;
use std::sync::{Mutex, OnceLock};

use fmi_sys::fmi2::*;
use libloading::Library;

pub use engine_mount_chassis::fmi2::variables::{boolean, integer, real, string, GUID};

pub const OK: fmi2Status = fmi2Status_fmi2OK;
pub const WARNING: fmi2Status = fmi2Status_fmi2Warning;
pub const DISCARD: fmi2Status = fmi2Status_fmi2Discard;
pub const ERROR: fmi2Status = fmi2Status_fmi2Error;

/// Captured log lines per instance name.
struct Capture(Mutex<HashMap<String, Vec<String>>>);

impl log::Log for Capture {
    fn enabled(&self, _: &log::Metadata) -> bool {
        true
    }
    fn log(&self, record: &log::Record) {
        if let Ok(mut m) = self.0.lock() {
            m.entry(record.target().to_owned())
                .or_default()
                .push(format!("{}", record.args()));
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

/// Path of the cdylib next to the test executable (target/<profile>/).
///
/// `cargo test` builds the library only as an rlib, so the cdylib comes from `cargo build`
/// (scripts/test.sh runs it first). A library older than any source file would test stale code:
/// refuse it with instructions instead.
pub fn library_path() -> PathBuf {
    let exe = std::env::current_exe().expect("test executable path");
    let dir = exe.parent().and_then(|d| d.parent()).expect("target dir");
    let lib = dir.join("libengine_mount_chassis.so");
    let built = std::fs::metadata(&lib)
        .and_then(|m| m.modified())
        .unwrap_or_else(|_| {
            panic!(
                "{} is missing: run `cargo build --release` first",
                lib.display()
            )
        });
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let newest = newest_mtime(&root.join("src"))
        .into_iter()
        .chain(newest_mtime(&root.join("modelDescription")))
        .chain(
            std::fs::metadata(root.join("build.rs"))
                .and_then(|m| m.modified())
                .ok(),
        )
        .max();
    if let Some(newest) = newest {
        assert!(
            built >= newest,
            "{} is older than the sources: run `cargo build --release` first",
            lib.display()
        );
    }
    lib
}

fn newest_mtime(dir: &std::path::Path) -> Option<std::time::SystemTime> {
    let mut newest = None;
    for entry in std::fs::read_dir(dir).ok()?.flatten() {
        let path = entry.path();
        let t = if path.is_dir() {
            newest_mtime(&path)
        } else {
            entry.metadata().and_then(|m| m.modified()).ok()
        };
        newest = newest.max(t);
    }
    newest
}

pub fn resources_uri() -> String {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("resources");
    format!("file://{}", dir.display())
}

/// The loaded library. Function pointers stay valid while `_lib` lives.
pub struct Fmu {
    _lib: Library,
    pub f: Functions,
}

macro_rules! functions {
    ($($name:ident : $ty:ident),* $(,)?) => {
        pub struct Functions { $(pub $name: <$ty as OptionInner>::F,)* }
        impl Functions {
            fn load(lib: &Library) -> Functions {
                // SAFETY: the symbols are the FMI 2.0 functions with the signatures of fmi-sys'
                // typedefs; the library outlives the copied pointers (kept together in Fmu).
                unsafe {
                    Functions { $($name: *lib.get::<<$ty as OptionInner>::F>(concat!(stringify!($name), "\0").as_bytes()).expect(stringify!($name)),)* }
                }
            }
        }
    };
}

pub trait OptionInner {
    type F: Copy;
}
impl<T: Copy> OptionInner for Option<T> {
    type F = T;
}

functions! {
    fmi2GetTypesPlatform: fmi2GetTypesPlatformTYPE,
    fmi2GetVersion: fmi2GetVersionTYPE,
    fmi2SetDebugLogging: fmi2SetDebugLoggingTYPE,
    fmi2Instantiate: fmi2InstantiateTYPE,
    fmi2FreeInstance: fmi2FreeInstanceTYPE,
    fmi2SetupExperiment: fmi2SetupExperimentTYPE,
    fmi2EnterInitializationMode: fmi2EnterInitializationModeTYPE,
    fmi2ExitInitializationMode: fmi2ExitInitializationModeTYPE,
    fmi2Terminate: fmi2TerminateTYPE,
    fmi2Reset: fmi2ResetTYPE,
    fmi2GetReal: fmi2GetRealTYPE,
    fmi2GetInteger: fmi2GetIntegerTYPE,
    fmi2GetBoolean: fmi2GetBooleanTYPE,
    fmi2GetString: fmi2GetStringTYPE,
    fmi2SetReal: fmi2SetRealTYPE,
    fmi2SetInteger: fmi2SetIntegerTYPE,
    fmi2SetBoolean: fmi2SetBooleanTYPE,
    fmi2SetString: fmi2SetStringTYPE,
    fmi2GetFMUstate: fmi2GetFMUstateTYPE,
    fmi2SetFMUstate: fmi2SetFMUstateTYPE,
    fmi2FreeFMUstate: fmi2FreeFMUstateTYPE,
    fmi2SerializedFMUstateSize: fmi2SerializedFMUstateSizeTYPE,
    fmi2SerializeFMUstate: fmi2SerializeFMUstateTYPE,
    fmi2DeSerializeFMUstate: fmi2DeSerializeFMUstateTYPE,
    fmi2GetDirectionalDerivative: fmi2GetDirectionalDerivativeTYPE,
    fmi2SetRealInputDerivatives: fmi2SetRealInputDerivativesTYPE,
    fmi2GetRealOutputDerivatives: fmi2GetRealOutputDerivativesTYPE,
    fmi2DoStep: fmi2DoStepTYPE,
    fmi2CancelStep: fmi2CancelStepTYPE,
    fmi2GetStatus: fmi2GetStatusTYPE,
    fmi2GetRealStatus: fmi2GetRealStatusTYPE,
    fmi2GetIntegerStatus: fmi2GetIntegerStatusTYPE,
    fmi2GetBooleanStatus: fmi2GetBooleanStatusTYPE,
    fmi2GetStringStatus: fmi2GetStringStatusTYPE,
}

impl Fmu {
    pub fn load() -> Fmu {
        capture();
        let path = library_path();
        // SAFETY: loading our own cdylib runs no foreign initialisers beyond Rust's std.
        let lib = unsafe { Library::new(&path) }
            .unwrap_or_else(|e| panic!("load {}: {e}", path.display()));
        let f = Functions::load(&lib);
        Fmu { _lib: lib, f }
    }

    /// Instantiates with explicit GUID and resource URI; `None` when the FMU returns NULL.
    pub fn instantiate_with(
        &self,
        name: &str,
        guid: &str,
        resources: Option<&str>,
    ) -> Option<Slave<'_>> {
        let name_c = CString::new(name).unwrap();
        let guid_c = CString::new(guid).unwrap();
        let res_c = resources.map(|r| CString::new(r).unwrap());
        let callbacks = Box::new(fmi2CallbackFunctions {
            logger: Some(fmi_sys::fmi2::logger::callback_logger_handler),
            allocateMemory: None,
            freeMemory: None,
            stepFinished: None,
            componentEnvironment: std::ptr::null_mut(),
        });
        // SAFETY: all pointers are valid NUL-terminated strings / a callback struct that the
        // Slave keeps alive for the instance's lifetime.
        let c = unsafe {
            (self.f.fmi2Instantiate)(
                name_c.as_ptr(),
                fmi2Type_fmi2CoSimulation,
                guid_c.as_ptr(),
                res_c.as_ref().map_or(std::ptr::null(), |r| r.as_ptr()),
                &*callbacks,
                0,
                0,
            )
        };
        if c.is_null() {
            return None;
        }
        Some(Slave {
            fmu: self,
            c,
            name: name.to_owned(),
            _callbacks: callbacks,
        })
    }

    pub fn instantiate(&self, name: &str) -> Slave<'_> {
        self.instantiate_with(name, GUID, Some(&resources_uri()))
            .expect("instantiate")
    }
}

/// The tests name variables by the generated per-type indices (`integer::SCENE`, …); the C API
/// takes the XML's value references, unique across types (`VR_BASE`).
pub fn value_references(type_index: usize, indices: &[u32]) -> Vec<u32> {
    let base = engine_mount_chassis::fmi2::variables::VR_BASE[type_index];
    indices.iter().map(|i| i + base).collect()
}

pub fn logs(name: &str) -> Vec<String> {
    capture()
        .0
        .lock()
        .map(|m| m.get(name).cloned().unwrap_or_default())
        .unwrap_or_default()
}

pub fn clear_logs(name: &str) {
    if let Ok(mut m) = capture().0.lock() {
        m.remove(name);
    }
}

pub struct Slave<'a> {
    pub fmu: &'a Fmu,
    pub c: fmi2Component,
    pub name: String,
    _callbacks: Box<fmi2CallbackFunctions>,
}

// The FMU allows an instance to be used from another thread as long as calls don't overlap.
unsafe impl Send for Slave<'_> {}

impl Slave<'_> {
    pub fn f(&self) -> &Functions {
        &self.fmu.f
    }

    pub fn logs(&self) -> Vec<String> {
        logs(&self.name)
    }

    pub fn setup(&self, start: f64, stop: Option<f64>) -> fmi2Status {
        // SAFETY: c is a live instance.
        unsafe {
            (self.f().fmi2SetupExperiment)(
                self.c,
                0,
                0.0,
                start,
                stop.is_some() as i32,
                stop.unwrap_or(0.0),
            )
        }
    }
    /// Switches debug logging on for every category.
    pub fn log_everything(&self) {
        // SAFETY: c is a live instance; zero categories with a null array is allowed.
        let status = unsafe { (self.f().fmi2SetDebugLogging)(self.c, 1, 0, std::ptr::null()) };
        assert_eq!(status, OK);
    }
    /// `fmi2SetupExperiment` at t = 0 with a defined tolerance.
    pub fn setup_with_tolerance(&self, tolerance: f64) -> fmi2Status {
        // SAFETY: c is a live instance.
        unsafe { (self.f().fmi2SetupExperiment)(self.c, 1, tolerance, 0.0, 0, 0.0) }
    }
    pub fn enter_init(&self) -> fmi2Status {
        // SAFETY: c is a live instance.
        unsafe { (self.f().fmi2EnterInitializationMode)(self.c) }
    }
    pub fn exit_init(&self) -> fmi2Status {
        // SAFETY: c is a live instance.
        unsafe { (self.f().fmi2ExitInitializationMode)(self.c) }
    }
    /// setup(0) + enter + exit, asserting OK.
    pub fn initialize(&self) {
        assert_eq!(self.setup(0.0, None), OK, "{:?}", self.logs());
        assert_eq!(self.enter_init(), OK, "{:?}", self.logs());
        assert_eq!(self.exit_init(), OK, "{:?}", self.logs());
    }
    pub fn do_step(&self, t: f64, h: f64) -> fmi2Status {
        // SAFETY: c is a live instance.
        unsafe { (self.f().fmi2DoStep)(self.c, t, h, 1) }
    }
    pub fn terminate(&self) -> fmi2Status {
        // SAFETY: c is a live instance.
        unsafe { (self.f().fmi2Terminate)(self.c) }
    }
    pub fn reset(&self) -> fmi2Status {
        // SAFETY: c is a live instance.
        unsafe { (self.f().fmi2Reset)(self.c) }
    }
    pub fn set_real(&self, vrs: &[u32], values: &[f64]) -> fmi2Status {
        assert_eq!(vrs.len(), values.len());
        // SAFETY: arrays of equal length nvr.
        unsafe { (self.f().fmi2SetReal)(self.c, vrs.as_ptr(), vrs.len(), values.as_ptr()) }
    }
    pub fn set_integer(&self, vrs: &[u32], values: &[i32]) -> fmi2Status {
        let vrs = &value_references(1, vrs);
        // SAFETY: arrays of equal length nvr.
        unsafe { (self.f().fmi2SetInteger)(self.c, vrs.as_ptr(), vrs.len(), values.as_ptr()) }
    }
    pub fn set_boolean(&self, vrs: &[u32], values: &[bool]) -> fmi2Status {
        let vrs = &value_references(2, vrs);
        let v: Vec<i32> = values.iter().map(|b| *b as i32).collect();
        // SAFETY: arrays of equal length nvr.
        unsafe { (self.f().fmi2SetBoolean)(self.c, vrs.as_ptr(), vrs.len(), v.as_ptr()) }
    }
    pub fn set_string(&self, vrs: &[u32], values: &[&str]) -> fmi2Status {
        let vrs = &value_references(3, vrs);
        let owned: Vec<CString> = values.iter().map(|s| CString::new(*s).unwrap()).collect();
        let ptrs: Vec<*const c_char> = owned.iter().map(|s| s.as_ptr()).collect();
        // SAFETY: arrays of equal length nvr of valid C strings.
        unsafe { (self.f().fmi2SetString)(self.c, vrs.as_ptr(), vrs.len(), ptrs.as_ptr()) }
    }
    pub fn get_real(&self, vrs: &[u32]) -> (fmi2Status, Vec<f64>) {
        let mut out = vec![f64::NAN; vrs.len()];
        // SAFETY: arrays of equal length nvr.
        let s =
            unsafe { (self.f().fmi2GetReal)(self.c, vrs.as_ptr(), vrs.len(), out.as_mut_ptr()) };
        (s, out)
    }
    pub fn reals(&self, vrs: &[u32]) -> Vec<f64> {
        let (s, v) = self.get_real(vrs);
        assert_eq!(s, OK, "{:?}", self.logs());
        v
    }
    pub fn get_integer(&self, vrs: &[u32]) -> (fmi2Status, Vec<i32>) {
        let vrs = &value_references(1, vrs);
        let mut out = vec![0; vrs.len()];
        // SAFETY: arrays of equal length nvr.
        let s =
            unsafe { (self.f().fmi2GetInteger)(self.c, vrs.as_ptr(), vrs.len(), out.as_mut_ptr()) };
        (s, out)
    }
    pub fn get_boolean(&self, vrs: &[u32]) -> (fmi2Status, Vec<bool>) {
        let vrs = &value_references(2, vrs);
        let mut out = vec![0; vrs.len()];
        // SAFETY: arrays of equal length nvr.
        let s =
            unsafe { (self.f().fmi2GetBoolean)(self.c, vrs.as_ptr(), vrs.len(), out.as_mut_ptr()) };
        (s, out.iter().map(|b| *b != 0).collect())
    }
    pub fn get_string(&self, vrs: &[u32]) -> (fmi2Status, Vec<String>) {
        let vrs = &value_references(3, vrs);
        let mut out = vec![std::ptr::null(); vrs.len()];
        // SAFETY: arrays of equal length nvr; returned strings are valid until the next call.
        let s =
            unsafe { (self.f().fmi2GetString)(self.c, vrs.as_ptr(), vrs.len(), out.as_mut_ptr()) };
        let strings = out
            .iter()
            .map(|p| {
                if p.is_null() {
                    String::new()
                } else {
                    unsafe { CStr::from_ptr(*p) }.to_string_lossy().into_owned()
                }
            })
            .collect();
        (s, strings)
    }
    /// `fmi2GetDirectionalDerivative` of `unknowns` for seeds `seeds` on `knowns`.
    pub fn directional_derivative(
        &self,
        unknowns: &[u32],
        knowns: &[u32],
        seeds: &[f64],
    ) -> (fmi2Status, Vec<f64>) {
        let mut out = vec![0.0; unknowns.len()];
        // SAFETY: arrays of the lengths passed.
        let s = unsafe {
            (self.f().fmi2GetDirectionalDerivative)(
                self.c,
                unknowns.as_ptr(),
                unknowns.len(),
                knowns.as_ptr(),
                knowns.len(),
                seeds.as_ptr(),
                out.as_mut_ptr(),
            )
        };
        (s, out)
    }

    pub fn set_input_derivatives(&self, vrs: &[u32], values: &[f64]) -> fmi2Status {
        let orders = vec![1; vrs.len()];
        // SAFETY: arrays of equal length nvr.
        unsafe {
            (self.f().fmi2SetRealInputDerivatives)(
                self.c,
                vrs.as_ptr(),
                vrs.len(),
                orders.as_ptr(),
                values.as_ptr(),
            )
        }
    }
    pub fn get_state(&self) -> fmi2FMUstate {
        let mut s: fmi2FMUstate = std::ptr::null_mut();
        // SAFETY: s is a writable slot.
        assert_eq!(unsafe { (self.f().fmi2GetFMUstate)(self.c, &mut s) }, OK);
        s
    }
    pub fn set_state(&self, s: fmi2FMUstate) -> fmi2Status {
        // SAFETY: s came from this FMU.
        unsafe { (self.f().fmi2SetFMUstate)(self.c, s) }
    }
    pub fn free_state(&self, mut s: fmi2FMUstate) {
        // SAFETY: s came from this FMU.
        assert_eq!(unsafe { (self.f().fmi2FreeFMUstate)(self.c, &mut s) }, OK);
        assert!(s.is_null());
    }
    pub fn serialize(&self, s: fmi2FMUstate) -> Vec<u8> {
        let mut size = 0usize;
        // SAFETY: valid state and size slot.
        assert_eq!(
            unsafe { (self.f().fmi2SerializedFMUstateSize)(self.c, s, &mut size) },
            OK
        );
        let mut buf = vec![0u8; size];
        // SAFETY: buffer of `size` bytes.
        assert_eq!(
            unsafe {
                (self.f().fmi2SerializeFMUstate)(self.c, s, buf.as_mut_ptr() as *mut c_char, size)
            },
            OK
        );
        buf
    }
    pub fn deserialize(&self, bytes: &[u8]) -> (fmi2Status, fmi2FMUstate) {
        let mut s: fmi2FMUstate = std::ptr::null_mut();
        // SAFETY: buffer of bytes.len() bytes and a writable slot.
        let st = unsafe {
            (self.f().fmi2DeSerializeFMUstate)(
                self.c,
                bytes.as_ptr() as *const c_char,
                bytes.len(),
                &mut s,
            )
        };
        (st, s)
    }
    pub fn real_status(&self, kind: fmi2StatusKind) -> (fmi2Status, f64) {
        let mut v = f64::NAN;
        // SAFETY: valid out pointer.
        let s = unsafe { (self.f().fmi2GetRealStatus)(self.c, kind, &mut v) };
        (s, v)
    }
    pub fn boolean_status(&self, kind: fmi2StatusKind) -> (fmi2Status, bool) {
        let mut v = 0;
        // SAFETY: valid out pointer.
        let s = unsafe { (self.f().fmi2GetBooleanStatus)(self.c, kind, &mut v) };
        (s, v != 0)
    }
}

impl Drop for Slave<'_> {
    fn drop(&mut self) {
        // SAFETY: c is a live instance, freed exactly once here.
        unsafe { (self.fmu.f.fmi2FreeInstance)(self.c) }
    }
}
