//! Medium blocks ([`MEDIUM`] bytes up to [`LARGE`]) packed into huge-page regions.
//!
//! A block of 128 KiB–1 MiB (a 256² field of `f64` is 512 KiB) cannot cover an aligned huge
//! page alone, and the C allocator maps each afresh (they are above its mapping threshold),
//! so its every 4 KiB page faults at first touch. On the virtual machine of docs/bem_history.md a
//! fault costs about 5 µs: the first 256² BEM solve of a process spent about 7 ms of its
//! 46 ms faulting in its fields (free boundaries, 2 threads; measured by touching them
//! beforehand).
//!
//! [`Pool`] carves such blocks one after another out of regions of [`REGION`] bytes,
//! aligned to 2 MiB and marked for huge pages, in sizes rounded up to [`GRANULE`]: fields
//! share huge pages, and a first touch maps 2 MiB. A freed block goes on the free list of
//! its size and is handed out again for a block of the same size, zeroed on demand. The
//! memory of freed blocks is kept for that reuse, never returned to the system: a process
//! holds, for each size, at most the most blocks it had of that size at once.

use std::cell::UnsafeCell;
use std::sync::atomic::{AtomicBool, Ordering};

use super::{map, HUGE_PAGE, LARGE};

/// Blocks of at least this many bytes (128 KiB, the C allocator's default mapping
/// threshold) and below [`LARGE`] are medium.
pub const MEDIUM: usize = 128 << 10;

/// Medium blocks take whole multiples of this (64 KiB), which is also their alignment.
const GRANULE: usize = 64 << 10;

/// The size classes: a block of `c` granules is of class `c` (2 to 16).
const CLASSES: usize = LARGE / GRANULE + 1;

/// Bytes of address space mapped at a time for medium blocks (8 huge pages).
const REGION: usize = 8 * HUGE_PAGE;

/// Whether a block of `size` bytes aligned to `align` is medium.
pub(super) fn is_medium(size: usize, align: usize) -> bool {
    cfg!(target_os = "linux") && (MEDIUM..LARGE).contains(&size) && align <= GRANULE
}

/// The size class of a medium block of `size` bytes.
fn class_of(size: usize) -> usize {
    size.div_ceil(GRANULE)
}

/// The medium blocks of the process (see the module docs).
pub(super) struct Pool {
    lock: AtomicBool,
    state: UnsafeCell<State>,
}

// SAFETY: `state` is only reached under `lock` (`Pool::with_state`).
unsafe impl Sync for Pool {}

/// A pool's free lists and the unused rest of its current region.
struct State {
    /// Heads of the free lists, one per class; each free block holds the next.
    free: [*mut u8; CLASSES],
    /// Start and end of the part of the current region not yet handed out.
    next: usize,
    end: usize,
}

impl Pool {
    /// An empty pool (it maps its first region on its first block).
    pub(super) const fn new() -> Self {
        Pool {
            lock: AtomicBool::new(false),
            state: UnsafeCell::new(State {
                free: [std::ptr::null_mut(); CLASSES],
                next: 0,
                end: 0,
            }),
        }
    }

    /// A medium block of `size` bytes (zeroed with `zeroed`), aligned to [`GRANULE`]; null
    /// if the system refuses a new region.
    pub(super) unsafe fn alloc(&self, size: usize, zeroed: bool) -> *mut u8 {
        let (block, reused) = self.with_state(|state| state.take(class_of(size)));
        if reused && zeroed {
            // SAFETY: the block holds at least `size` bytes and is ours alone.
            unsafe { block.write_bytes(0, size) };
        }
        block
    }

    /// Takes back a block of `size` bytes from [`Pool::alloc`] for reuse.
    pub(super) unsafe fn dealloc(&self, block: *mut u8, size: usize) {
        self.with_state(|state| state.give(block, class_of(size)));
    }

    /// Whether blocks of `old` and `new` bytes take the same room.
    pub(super) fn same_room(old: usize, new: usize) -> bool {
        class_of(old) == class_of(new)
    }

    /// Runs `f` on the state under the lock (held for a few instructions, or a mapping).
    fn with_state<R>(&self, f: impl FnOnce(&mut State) -> R) -> R {
        self.lock();
        // SAFETY: the lock is held: no other reference to the state exists.
        let result = f(unsafe { &mut *self.state.get() });
        self.unlock();
        result
    }

    /// Takes the lock (spinning: it is held for a few instructions, or a mapping).
    pub(super) fn lock(&self) {
        while self
            .lock
            .compare_exchange_weak(false, true, Ordering::Acquire, Ordering::Relaxed)
            .is_err()
        {
            std::hint::spin_loop();
        }
    }

    /// Releases the lock taken by [`Pool::lock`].
    pub(super) fn unlock(&self) {
        self.lock.store(false, Ordering::Release);
    }
}

impl State {
    /// A block of `class` granules, and whether it was freed before (else it is fresh, zero
    /// memory); null if a new region is refused.
    fn take(&mut self, class: usize) -> (*mut u8, bool) {
        let head = self.free[class];
        if !head.is_null() {
            // SAFETY: a free block starts with the next free block of its class (`give`).
            self.free[class] = unsafe { head.cast::<*mut u8>().read() };
            return (head, true);
        }
        let len = class * GRANULE;
        if self.end - self.next < len {
            // The rest of the region (less than a medium block) stays unused.
            // SAFETY: a fresh mapping, ours alone.
            let region = unsafe { map::map(REGION) };
            if region.is_null() {
                return (region, false);
            }
            (self.next, self.end) = (region as usize, region as usize + REGION);
        }
        let block = self.next as *mut u8;
        self.next += len;
        (block, false)
    }

    /// Puts a block of `class` granules on its free list.
    fn give(&mut self, block: *mut u8, class: usize) {
        // SAFETY: the block is at least a granule long, aligned, and no longer in use.
        unsafe { block.cast::<*mut u8>().write(self.free[class]) };
        self.free[class] = block;
    }
}

#[cfg(all(test, target_os = "linux"))]
mod tests {
    use super::*;

    /// Byte `i` of the test pattern of `seed`.
    fn pattern(i: usize, seed: u8) -> u8 {
        (i as u8).wrapping_mul(31).wrapping_add(seed)
    }

    /// Fills `len` bytes at `p` with the pattern of `seed`.
    unsafe fn fill(p: *mut u8, len: usize, seed: u8) {
        for i in 0..len {
            unsafe { *p.add(i) = pattern(i, seed) };
        }
    }

    /// Whether `len` bytes at `p` hold the pattern of `seed`.
    unsafe fn holds(p: *const u8, len: usize, seed: u8) -> bool {
        (0..len).all(|i| unsafe { *p.add(i) } == pattern(i, seed))
    }

    #[test]
    fn live_blocks_are_disjoint_aligned_and_keep_their_contents() {
        let pool = Pool::new();
        let sizes = [MEDIUM, MEDIUM + 1, 300_000, 512 << 10, LARGE - 1, 700_001];
        let blocks: Vec<(*mut u8, usize)> = (0..40)
            .map(|i| {
                let size = sizes[i % sizes.len()];
                let p = unsafe { pool.alloc(size, true) };
                assert!(!p.is_null());
                assert_eq!(p as usize % GRANULE, 0, "aligned");
                let zeros = unsafe { std::slice::from_raw_parts(p, size) };
                assert!(
                    zeros.iter().all(|&b| b == 0),
                    "fresh block of {size} is zero"
                );
                unsafe { fill(p, size, i as u8) };
                (p, size)
            })
            .collect();
        for (i, &(p, size)) in blocks.iter().enumerate() {
            assert!(unsafe { holds(p, size, i as u8) }, "block {i} overwritten");
        }
        // 40 blocks of up to 16 granules: more than one region.
        let regions: std::collections::BTreeSet<usize> =
            blocks.iter().map(|&(p, _)| p as usize / REGION).collect();
        assert!(regions.len() > 1);
        for (p, size) in blocks {
            unsafe { pool.dealloc(p, size) };
        }
    }

    #[test]
    fn freed_blocks_are_reused_for_their_size_and_zeroed_on_demand() {
        let pool = Pool::new();
        let (a, b) = unsafe { (pool.alloc(300_000, false), pool.alloc(600_000, false)) };
        unsafe {
            fill(a, 300_000, 1);
            fill(b, 600_000, 2);
            pool.dealloc(a, 300_000);
            pool.dealloc(b, 600_000);
        }
        // Same class (5 granules): the freed block, zeroed on demand.
        let c = unsafe { pool.alloc(320_000, true) };
        assert_eq!(c, a);
        assert!(unsafe { std::slice::from_raw_parts(c, 320_000) }
            .iter()
            .all(|&x| x == 0));
        // Another class: a fresh block, not the freed one of 10 granules.
        let d = unsafe { pool.alloc(200_000, false) };
        assert!(d != a && d != b);
        // Class 10 again, not zeroed: the old contents.
        let e = unsafe { pool.alloc(600_000, false) };
        assert_eq!(e, b);
        let kept = unsafe { std::slice::from_raw_parts(e, 600_000) };
        assert!(
            (8..600_000).all(|i| kept[i] == pattern(i, 2)),
            "past its list link"
        );
        assert!(Pool::same_room(300_000, 320_000) && !Pool::same_room(300_000, 330_000));
    }

    #[test]
    fn threads_share_a_pool_without_losing_blocks() {
        let pool = Pool::new();
        std::thread::scope(|s| {
            for t in 0..4u8 {
                let pool = &pool;
                s.spawn(move || {
                    for round in 0..50u8 {
                        let size =
                            MEDIUM + (t as usize * 97_000 + round as usize * 13_000) % 800_000;
                        let seed = t.wrapping_mul(50).wrapping_add(round);
                        let p = unsafe { pool.alloc(size, true) };
                        assert!(!p.is_null());
                        unsafe {
                            fill(p, size, seed);
                            std::thread::yield_now();
                            assert!(holds(p, size, seed), "thread {t} round {round}");
                            pool.dealloc(p, size);
                        }
                    }
                });
            }
        });
    }
}
