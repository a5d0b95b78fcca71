//! What every exported function of either ABI goes through: the instance's handle (a live
//! marker of its standard, the instance, the strings and FMU states it handed out), the one
//! guard [`Abi::entry`] (instance pointer, liveness, state mask, panics), instantiation and freeing,
//! and the work both standards share behind their own signatures: reading and writing values
//! at resolved positions, and the FMU-state functions.
//!
//! Each ABI describes itself once, as an [`Abi`] ([`super::abi`]): its live marker, how it names
//! its phases and functions, and whether every refusal leads to the error state (FMI 3.0) or
//! leaves the phase as it was (FMI 2.0).

use std::cell::UnsafeCell;
use std::ffi::{c_char, c_void, CString};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

pub use super::abi::{guid, model_identifier, Abi, FunctionNames};
use super::c_args::{array, array_mut, place, text};
use super::fmu_states::FmuStates;
use super::instance::{Instance, Outcome, Status};
use super::logger::{Level, Logger};
use super::snapshot;
use super::state::{Mask, Phase};
use super::values::{Slot, Typed};
use crate::variables::{string, LogCategory, STRINGS};

/// What the pointer both ABIs hand out points to: the instance's handle behind a flag that
/// admits one call at a time.
///
/// FMI forbids a master to call one instance from two threads at once (FMI 2.0 §2.1.4, FMI 3.0
/// §2.2.2), but a master that does (a Dask worker with several threads sharing one instance,
/// say) must get an error, not a corrupted instance. So everything a call may touch before it
/// owns the instance is atomic or immutable after instantiation: the live marker, the busy flag
/// and a copy of the logger to refuse with. The handle itself is reached only through
/// [`Shell::enter`], which takes the busy flag first.
struct Shell {
    /// Marks a live instance of one standard ([`Abi::live`]); zero once freed.
    live: AtomicU64,
    /// Taken by the one call inside the instance, for the length of that call.
    busy: AtomicBool,
    /// The instance's logger as it was at instantiation; a refused concurrent call logs through
    /// it (errors always reach the environment, so later debug-logging settings do not matter).
    alarm: Logger,
    handle: UnsafeCell<Handle>,
}

/// A call inside a [`Shell`]: it holds the busy flag, and with it the only access to the
/// handle, until it drops.
struct Entered<'a>(&'a Shell);

impl std::ops::Deref for Entered<'_> {
    type Target = Handle;
    fn deref(&self) -> &Handle {
        // SAFETY: this call holds the busy flag (taken in `Shell::enter`), and every access to
        // the handle goes through an `Entered`, so no other reference to it exists meanwhile.
        unsafe { &*self.0.handle.get() }
    }
}

impl std::ops::DerefMut for Entered<'_> {
    fn deref_mut(&mut self) -> &mut Handle {
        // SAFETY: as in `deref`; `&mut self` makes this the only reference through this guard.
        unsafe { &mut *self.0.handle.get() }
    }
}

impl Drop for Entered<'_> {
    fn drop(&mut self) {
        self.0.busy.store(false, Ordering::Release);
    }
}

impl Shell {
    /// The shell behind an instance pointer of `abi`, if it is live.
    ///
    /// A shared reference is all a call may hold before [`Shell::enter`]: two threads may hold
    /// one at once, and what it reaches outside the cell is atomic or never written again.
    fn of<'a>(ptr: *mut c_void, abi: &Abi) -> Option<&'a Shell> {
        if ptr.is_null() {
            return None;
        }
        // SAFETY: a non-null instance pointer is, per FMI 2.0 and 3.0, the pointer instantiation
        // returned (a boxed Shell), not freed since; a shared reference aliases safely, as the
        // only fields written after instantiation are atomics and the UnsafeCell's content.
        let shell = unsafe { &*(ptr as *const Shell) };
        (shell.live.load(Ordering::Acquire) == abi.live).then_some(shell)
    }

    /// The handle for the calling thread alone, or `None` while another call is inside it.
    fn enter(&self) -> Option<Entered<'_>> {
        self.busy
            .compare_exchange(false, true, Ordering::Acquire, Ordering::Relaxed)
            .ok()
            .map(|_| Entered(self))
    }

    /// Logs that `function` was refused because another call is inside the instance.
    fn refuse_busy(&self, function: &str) {
        self.alarm.log(
            Level::Error,
            LogCategory::StatusError,
            &format!(
                "{function}: the instance is busy: another thread is inside a call on it; an \
                 instance takes one call at a time (a master must not use it from two threads \
                 at once), so this call did nothing"
            ),
        );
    }
}

/// An instance as the master holds it.
pub struct Handle {
    /// The instance.
    pub instance: Instance,
    /// Strings returned by a string getter stay valid until the next such call on this instance.
    returned_strings: Vec<CString>,
    /// The FMU states this instance handed out and has not freed: they belong to it and are
    /// freed with it.
    states: FmuStates,
}

impl Abi {
    /// `entry` for this standard, with the status as the standard's C status (fmi2Status and
    /// fmi3Status number the statuses as [`Status`]).
    pub fn entry(
        &self,
        ptr: *mut c_void,
        function: &'static str,
        mask: Mask,
        body: impl FnOnce(&mut Handle) -> Outcome,
    ) -> u32 {
        entry(ptr, self, function, mask, body) as u32
    }
}

/// The guard of every entry point with an instance: runs `body` on the instance behind `ptr`
/// if `function` may be called in its phase (`mask`). A null or stale pointer, or one of the
/// other standard, gives an error; so does a call while another thread's call is inside the
/// instance (logged as busy, nothing done); a refusal is logged as "`function`: reason" and
/// gives an error (and, for FMI 3.0, the error state); a panic gives a fatal status (the instance
/// is then unusable); in the fatal phase only freeing the instance is allowed.
fn entry(
    ptr: *mut c_void,
    abi: &Abi,
    function: &'static str,
    mask: Mask,
    body: impl FnOnce(&mut Handle) -> Outcome,
) -> Status {
    let Some(shell) = Shell::of(ptr, abi) else {
        return Status::Error;
    };
    // A refused concurrent call changes nothing, not even the phase: the call inside owns it.
    let Some(mut entered) = shell.enter() else {
        shell.refuse_busy(function);
        return Status::Error;
    };
    let handle: &mut Handle = &mut entered;
    let result = catch_unwind(AssertUnwindSafe(|| {
        let inst = &handle.instance;
        inst.logger.log(Level::Info, LogCategory::Calls, function);
        let phase = inst.phase();
        if phase == Phase::Fatal {
            inst.logger.log(
                Level::Fatal,
                LogCategory::StatusError,
                &format!(
                    "{function}: the instance is in a fatal state; only {} is allowed",
                    abi.names.free_instance
                ),
            );
            return Status::Fatal;
        }
        if !mask.allows(phase) {
            let hint = if phase == Phase::Error {
                abi.error_state_hint
            } else {
                ""
            };
            inst.log_error(&format!(
                "{function} is not allowed in phase {}{hint}",
                (abi.phase_name)(phase)
            ));
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
        Ok(s) => {
            if s == Status::Error && abi.errors_enter_error_state {
                handle.instance.core.phase = Phase::Error;
            }
            s
        }
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
            Status::Fatal
        }
    }
}

/// What a master passed to instantiate, read by the ABI.
pub struct Request {
    /// `instanceName`.
    pub name: *const c_char,
    /// The GUID or instantiation token.
    pub token: *const c_char,
    /// The resource location or path as given (null: none).
    pub resources: *const c_char,
    /// How the ABI turns the resources argument into a directory (`None`: none given).
    pub resource_dir: fn(Option<&str>) -> Result<Option<PathBuf>, String>,
}

/// Creates an instance and returns its handle, or null after logging why through the logger
/// `logger` makes for the instance's name: a missing `instanceName`, `refusal` (the ABI's own
/// reason, such as an interface it does not provide), a token that is none of this ABI's FMUs,
/// or resources that are not a directory. The model itself is built only when initialisation
/// ends, or earlier when an output or a calculated parameter is read in initialisation mode.
pub fn instantiate(
    abi: &'static Abi,
    request: Request,
    logger: impl FnOnce(&str) -> Logger,
    refusal: Option<&str>,
) -> *mut c_void {
    let result = catch_unwind(AssertUnwindSafe(|| {
        // SAFETY: FMI strings are NUL-terminated or null.
        let (name, token, resources) = unsafe {
            (
                text(request.name).unwrap_or_default(),
                text(request.token).unwrap_or_default(),
                text(request.resources),
            )
        };
        let logger = logger(&name);
        let refuse = |message: &str| {
            let message = format!("{}: {message}", abi.names.instantiate);
            logger.log(Level::Error, LogCategory::StatusError, &message);
            std::ptr::null_mut()
        };
        if name.is_empty() {
            return refuse("instanceName is missing");
        }
        if let Some(reason) = refusal {
            return refuse(reason);
        }
        let Some(&kind) = abi.kinds.iter().find(|k| guid(**k) == token) else {
            let fmus: Vec<String> = abi
                .kinds
                .iter()
                .map(|k| format!("{} ({})", model_identifier(*k), guid(*k)))
                .collect();
            return refuse(&format!(
                "{} \"{token}\" does not match {}, the FMUs of this library",
                abi.token,
                fmus.join(" or ")
            ));
        };
        let resource_dir = match (request.resource_dir)(resources.as_deref()) {
            Ok(dir) => dir,
            Err(m) => return refuse(&m),
        };
        if resource_dir.is_none() {
            let config = STRINGS[string::CONFIG_FILE as usize].name;
            logger.log(
                Level::Warning,
                LogCategory::StatusWarning,
                &format!(
                    "{}: no {} given; the built-in vehicle is used unless {config} names an absolute path",
                    abi.names.instantiate, abi.resources
                ),
            );
        }
        let shell = Box::new(Shell {
            live: AtomicU64::new(abi.live),
            busy: AtomicBool::new(false),
            alarm: logger.clone(),
            handle: UnsafeCell::new(Handle {
                instance: Instance::new(&name, kind, abi, logger, resource_dir),
                returned_strings: Vec::new(),
                states: FmuStates::default(),
            }),
        });
        Box::into_raw(shell) as *mut c_void
    }));
    result.unwrap_or(std::ptr::null_mut())
}

/// Frees the instance behind `ptr` and every FMU state it handed out. A null or already freed
/// pointer, or one of the other standard, is ignored; allowed in every phase. While another
/// thread's call is inside the instance it is not freed (that call would go on in freed memory):
/// the refusal is logged, and the master may free it once the call has returned.
pub fn free(ptr: *mut c_void, abi: &Abi) {
    let Some(shell) = Shell::of(ptr, abi) else {
        return;
    };
    let Some(entered) = shell.enter() else {
        shell.refuse_busy(abi.names.free_instance);
        return;
    };
    // The live marker catches the common double free, and a pointer of the other standard,
    // before ownership is taken back; only the thread that clears it frees.
    let freed_here = shell
        .live
        .compare_exchange(abi.live, 0, Ordering::AcqRel, Ordering::Acquire)
        .is_ok();
    drop(entered);
    if freed_here {
        // SAFETY: ptr came from `instantiate` (Box::into_raw of a Shell); this thread cleared
        // its live marker while holding its busy flag, so no call is inside it and no later
        // call or free gets past `Shell::of`; it is freed exactly once.
        drop(unsafe { Box::from_raw(ptr as *mut Shell) });
    }
}

/// The handle behind a live instance pointer, for tests that put an instance into a state the
/// entry points do not lead to.
///
/// # Safety
/// `ptr` is a live instance of this library and no call is inside it.
#[cfg(test)]
pub(crate) unsafe fn handle_mut<'a>(ptr: *mut c_void) -> &'a mut Handle {
    // SAFETY: the caller's contract.
    unsafe { &mut *(*(ptr as *const Shell)).handle.get() }
}

/// Keeps the instance behind `ptr` busy until the returned guard drops, as a call from
/// another thread would; for tests of the refusal.
///
/// # Safety
/// `ptr` is a live instance of this library, outliving the guard.
#[cfg(test)]
pub(crate) unsafe fn hold(ptr: *mut c_void) -> impl Drop {
    // SAFETY: the caller's contract.
    let shell: &'static Shell = unsafe { &*(ptr as *const Shell) };
    shell.enter().expect("the instance is not busy")
}

impl Handle {
    /// Reads the values of type `T` at `slots` into `out` through `convert` (`time` gives the
    /// independent variable's value, where the standard has one).
    pub fn read<T: Typed, C>(
        &mut self,
        slots: &[Slot],
        out: &mut [C],
        convert: impl Fn(T) -> C,
        time: impl Fn(f64) -> Option<C>,
    ) -> Outcome {
        let elements: Vec<usize> = slots.iter().filter_map(Slot::element).collect();
        let mut read = self.instance.get::<T>(&elements)?.into_iter();
        let now = self.instance.core.time;
        for (o, s) in out.iter_mut().zip(slots) {
            *o = match s {
                Slot::Element(_) => convert(read.next().ok_or("value count")?),
                Slot::Time => time(now).ok_or("time has no value of this type")?,
            };
        }
        Ok(Status::Ok)
    }

    /// Reads String variables into `out`: the pointers stay valid until the next call of this
    /// function on this instance or until it is freed.
    pub fn read_strings(&mut self, slots: &[Slot], out: &mut [*const c_char]) -> Outcome {
        let elements: Vec<usize> = slots.iter().filter_map(Slot::element).collect();
        let read = self.instance.get::<String>(&elements)?;
        self.returned_strings = read
            .iter()
            .map(|t| CString::new(t.replace('\0', "")).unwrap_or_default())
            .collect();
        for (o, t) in out.iter_mut().zip(&self.returned_strings) {
            *o = t.as_ptr();
        }
        Ok(Status::Ok)
    }

    /// Sets the variables of type `T` at `slots` to `values`, all checked before any is
    /// applied; the independent variable is refused.
    pub fn write<T: Typed>(&mut self, slots: &[Slot], values: &[T]) -> Outcome {
        let mut elements = Vec::with_capacity(slots.len());
        for s in slots {
            match s {
                Slot::Element(i) => elements.push(*i),
                Slot::Time => {
                    return Err("time is the independent variable and cannot be set".into())
                }
            }
        }
        self.instance.set::<T>(&elements, values)
    }

    /// Copies the instance's complete state into a new FMU state, or into the one in `*slot` if
    /// it is a state of this instance.
    ///
    /// # Safety
    /// `slot` is null or points to the master's writable FMU-state slot.
    pub unsafe fn get_fmu_state(&mut self, slot: *mut *mut c_void) -> Outcome {
        // SAFETY: the caller's contract.
        let slot = unsafe { place(slot, "FMUstate") }?;
        let core = self.instance.core.clone();
        self.states.store(slot, core)
    }

    /// Restores a state this instance handed out; refused if it was taken with other parameters
    /// than the model this instance has built (it would silently change the model).
    pub fn set_fmu_state(&mut self, state: *mut c_void) -> Outcome {
        let core = self.states.core(state)?;
        self.instance.check_state_fits(core)?;
        self.instance.core = core.clone();
        Ok(Status::Ok)
    }

    /// Frees an FMU state of this instance and sets `*slot` to null; a null slot or state is
    /// ignored, a foreign state refused.
    ///
    /// # Safety
    /// `slot` is null or points to a writable slot holding null or a state.
    pub unsafe fn free_fmu_state(&mut self, slot: *mut *mut c_void) -> Outcome {
        // SAFETY: the caller's contract.
        let Some(slot) = (unsafe { slot.as_mut() }) else {
            return Ok(Status::Ok);
        };
        self.states.free(slot)
    }

    /// Writes the number of bytes [`Handle::serialize_fmu_state`] needs for `state` to `*size`.
    ///
    /// # Safety
    /// `size` is null or points to a writable `usize`.
    pub unsafe fn serialized_fmu_state_size(
        &mut self,
        state: *mut c_void,
        size: *mut usize,
    ) -> Outcome {
        let bytes = self.states.serialized(state, self.instance.guid())?;
        // SAFETY: the caller's contract.
        *unsafe { place(size, "size") }? = bytes.len();
        Ok(Status::Ok)
    }

    /// Serialises an FMU state of this instance into the master's buffer of `size` bytes, which
    /// must be exactly the serialized size.
    ///
    /// # Safety
    /// `buffer` is null or points to `size` writable bytes.
    pub unsafe fn serialize_fmu_state(
        &mut self,
        state: *mut c_void,
        buffer: *mut u8,
        size: usize,
    ) -> Outcome {
        // SAFETY: the caller's contract.
        let out = unsafe { array_mut(buffer, size, "serializedState") }?;
        self.states
            .serialize_into(state, self.instance.guid(), out)?;
        Ok(Status::Ok)
    }

    /// Creates an FMU state from `size` bytes of a serialized one (possibly of another process,
    /// of either standard's FMU of the same model) into `*slot`; bytes of another model,
    /// malformed or with inadmissible values are refused. The model is rebuilt from the state's
    /// own parameters.
    ///
    /// # Safety
    /// `bytes` is null or points to `size` readable bytes; `slot` is null or points to a
    /// writable FMU-state slot.
    pub unsafe fn deserialize_fmu_state(
        &mut self,
        bytes: *const u8,
        size: usize,
        slot: *mut *mut c_void,
    ) -> Outcome {
        // SAFETY: the caller's contract.
        let (bytes, slot) = unsafe {
            (
                array(bytes, size, "serializedState")?,
                place(slot, "FMUstate")?,
            )
        };
        let inst = &self.instance;
        let core = snapshot::deserialize(bytes, inst.guid(), |core, dynamic| {
            inst.restore_simulation(core, dynamic)
        })?;
        self.states.store(slot, core)
    }
}
