//! A counting global allocator for the library's allocation tests (`bem_allocation.rs`,
//! `bem_adhesion_allocation.rs`, `zip_bombs.rs`). Each of those test binaries installs it with
//! `#[global_allocator] static GLOBAL: common::Counting = common::Counting;`, so it stays out
//! of the library and of the other tests, and holds one test so that no other test allocates
//! while it counts.
//!
//! Counted per thread, so that only the measured work counts (it runs on the thread that
//! calls it): the test harness's other threads allocate whenever they like (its "running for
//! over 60 seconds" warning on a busy machine once added 4).
//!
//! Every test file is its own crate and compiles this module whole, using only part of it.
#![allow(dead_code)]

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

/// Forwards every call to the system allocator and records, for the calling thread, the
/// number of allocations, their bytes and the largest one.
pub struct Counting;

thread_local! {
    // Const-initialised cells without a destructor: touching them inside the allocator
    // allocates nothing and works while a thread exits.
    static ALLOCATIONS: Cell<u64> = const { Cell::new(0) };
    static BYTES: Cell<u64> = const { Cell::new(0) };
    static LARGEST: Cell<usize> = const { Cell::new(0) };
}

fn note(bytes: usize) {
    ALLOCATIONS.with(|count| count.set(count.get() + 1));
    BYTES.with(|total| total.set(total.get() + bytes as u64));
    LARGEST.with(|largest| largest.set(largest.get().max(bytes)));
}

// SAFETY: forwards every call to the system allocator unchanged; only counts.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        note(layout.size());
        // SAFETY: the caller's contract for `alloc` is passed on.
        unsafe { System.alloc(layout) }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        note(layout.size());
        // SAFETY: as for `alloc`.
        unsafe { System.alloc_zeroed(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: `ptr` came from `System` with this layout.
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        note(new_size);
        // SAFETY: as for `dealloc`; `new_size` is the caller's.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

/// `(value, allocations, bytes)`: what `f` returns and what this thread allocated meanwhile.
pub fn count<T>(f: impl FnOnce() -> T) -> (T, u64, u64) {
    let (a, b) = (ALLOCATIONS.with(Cell::get), BYTES.with(Cell::get));
    let value = f();
    let (a2, b2) = (ALLOCATIONS.with(Cell::get), BYTES.with(Cell::get));
    (value, a2 - a, b2 - b)
}

/// `(value, largest)`: what `f` returns and the largest single allocation this thread made
/// meanwhile (bytes).
pub fn largest_allocation<T>(f: impl FnOnce() -> T) -> (T, usize) {
    LARGEST.with(|largest| largest.set(0));
    let value = f();
    (value, LARGEST.with(Cell::get))
}
