//! The FMU states an instance hands out (`GetFMUstate`, `DeSerializeFMUstate`), shared by the
//! FMI 2.0 and 3.0 ABIs: both standards pass a state as an opaque pointer that the master holds.
//!
//! A state is recognised by its address among the ones this instance handed out and has not
//! freed, never dereferenced on trust; each is boxed so that its address, which the master
//! holds, stays put when the list grows. Nothing here dereferences a pointer.

use std::ffi::c_void;

use super::instance::{Core, Outcome, Status};
use super::snapshot;

/// One FMU state: everything getting the FMU state captured.
struct Saved {
    core: Core,
}

/// The FMU states of one instance; they are freed with it.
#[derive(Default)]
pub struct FmuStates {
    #[allow(clippy::vec_box)]
    states: Vec<Box<Saved>>,
}

impl FmuStates {
    fn position(&self, state: *const c_void) -> Result<usize, String> {
        self.states
            .iter()
            .position(|s| std::ptr::eq(&**s, state as *const Saved))
            .ok_or_else(|| "not an FMU state of this instance".to_owned())
    }

    /// The captured state behind `state`, if this instance handed it out.
    pub fn core(&self, state: *const c_void) -> Result<&Core, String> {
        Ok(&self.states[self.position(state)?].core)
    }

    /// Puts `core` into the state slot the master passed: a new state for a null slot, the same
    /// state overwritten for one of ours.
    pub fn store(&mut self, slot: &mut *mut c_void, core: Core) -> Outcome {
        if slot.is_null() {
            let mut boxed = Box::new(Saved { core });
            let ptr: *mut Saved = &mut *boxed;
            self.states.push(boxed);
            *slot = ptr as *mut c_void;
        } else {
            let i = self.position(*slot)?;
            self.states[i].core = core;
        }
        Ok(Status::Ok)
    }

    /// Frees the state in `slot` and sets the slot to null; a null slot is ignored.
    pub fn free(&mut self, slot: &mut *mut c_void) -> Outcome {
        if slot.is_null() {
            return Ok(Status::Ok);
        }
        let i = self.position(*slot)?;
        self.states.swap_remove(i);
        *slot = std::ptr::null_mut();
        Ok(Status::Ok)
    }

    /// The bytes of `state` serialized for the FMU of `guid`.
    pub fn serialized(&self, state: *const c_void, guid: &str) -> Result<Vec<u8>, String> {
        Ok(snapshot::serialize(self.core(state)?, guid))
    }

    /// Serializes `state` into `out`, which must have exactly the serialized size.
    pub fn serialize_into(
        &self,
        state: *const c_void,
        guid: &str,
        out: &mut [u8],
    ) -> Result<(), String> {
        let bytes = self.serialized(state, guid)?;
        if bytes.len() != out.len() {
            return Err(format!(
                "buffer has {} bytes, the state needs {}",
                out.len(),
                bytes.len()
            ));
        }
        out.copy_from_slice(&bytes);
        Ok(())
    }
}
