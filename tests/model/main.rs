//! Integration tests of the coupled engine–mount–body model (`src/model`): statics, modes, orders, Jacobians, time domain.

mod engine_imperfections;
mod engine_inputs_outputs;
mod engine_jacobian;
mod engine_modes;
mod engine_reactions;
mod engine_statics;
mod engine_time_domain;
mod hybrid_coupling;
mod hybrid_paper;
mod inline_four;
mod rhs_allocations;
mod scene_effects;
mod torque_path;
mod vehicle_json_properties;
mod wrench_orders;

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

/// The system allocator, counting allocations per thread (for `rhs_allocations`).
struct CountingAllocator;

thread_local! {
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

// SAFETY: every call is forwarded unchanged to the system allocator, which upholds
// `GlobalAlloc`'s contract; the counter is a thread-local `Cell` with a const initialiser, so
// touching it neither allocates nor re-enters the allocator.
unsafe impl GlobalAlloc for CountingAllocator {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.with(|c| c.set(c.get() + 1));
        // SAFETY: same layout as our caller passed, per the trait's contract.
        unsafe { System.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: `ptr` came from `System.alloc` with this layout (all allocations go there).
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.with(|c| c.set(c.get() + 1));
        // SAFETY: `ptr` and `layout` come from a previous allocation of ours.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static COUNTING_ALLOCATOR: CountingAllocator = CountingAllocator;

/// Allocations (and reallocations) made on the calling thread so far.
pub fn allocations_on_this_thread() -> usize {
    ALLOCATIONS.with(|c| c.get())
}
