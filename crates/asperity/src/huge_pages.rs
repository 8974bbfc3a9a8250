//! A global allocator that backs large buffers with transparent huge pages (Linux).
//!
//! The solvers' fields are megabytes each (a 512² grid of `f64` is 2 MiB, its padded
//! spectrum 8 MiB), and with 4 KiB pages every first touch of a page is a fault: the first
//! 512² BEM solve of a process faulted 6 049 times (free boundaries, 2 threads; 473 with
//! this allocator) and took 0.23–0.24 s instead of 0.22 s. The kernel's transparent huge
//! pages (THP) map 2 MiB per fault, but only in 2 MiB-aligned ranges of a mapping marked
//! for them (`/sys/kernel/mm/transparent_hugepage/enabled` = `madvise`, the common
//! default) or in any mapping (`always`). The C allocator aligns its large blocks to 4 KiB
//! only, so a 2 MiB field never covers an aligned range.
//!
//! [`HugePageAlloc`] maps every block of at least [`LARGE`] bytes by itself, aligned to
//! 2 MiB and marked `MADV_HUGEPAGE`; packs blocks of [`MEDIUM`] bytes up to [`LARGE`] into
//! shared regions marked the same way (`huge_pages/medium.rs`); and leaves smaller blocks
//! to the system allocator. Mapped memory is zero, so zeroed blocks cost no pass of their
//! own. Where the kernel
//! gives no huge pages (THP `never`, or no contiguous memory) the mapping is an ordinary
//! one: nothing fails, the pages are just small. Applications opt in, as the `asperity`
//! binary and the Python module do:
//!
//! ```
//! #[global_allocator]
//! static ALLOCATOR: asperity::huge_pages::HugePageAlloc = asperity::huge_pages::HugePageAlloc;
//! # fn main() { let v = vec![0.0f64; 1 << 20]; assert_eq!(v[12345], 0.0); }
//! ```

use std::alloc::{GlobalAlloc, Layout, System};

mod medium;

pub use medium::MEDIUM;
use medium::{is_medium, Pool};

/// Blocks of at least this many bytes (1 MiB) are mapped on their own; smaller ones, most
/// allocations, keep the system allocator's speed. A block of less than a huge page gains
/// nothing yet costs nothing either (its pages stay small), so the bound need not be
/// exact.
pub const LARGE: usize = 1 << 20;

/// The huge page size of x86-64 and (with 4 KiB base pages) aarch64.
const HUGE_PAGE: usize = 2 << 20;

/// The allocator of the module docs.
#[derive(Debug, Clone, Copy, Default)]
pub struct HugePageAlloc;

/// The medium blocks of every [`HugePageAlloc`]; reached through [`medium_blocks`].
static MEDIUM_BLOCKS: Pool = Pool::new();

/// [`MEDIUM_BLOCKS`], with its lock held across `fork` (registered on first use): a child
/// forked while another thread held it (Python's `multiprocessing` forks by default) would
/// otherwise find it held for ever, or the free lists half updated. The C allocator guards
/// its own locks the same way.
fn medium_blocks() -> &'static Pool {
    #[cfg(target_os = "linux")]
    {
        static FORK_HANDLERS: std::sync::Once = std::sync::Once::new();
        extern "C" fn before_fork() {
            MEDIUM_BLOCKS.lock();
        }
        extern "C" fn after_fork() {
            MEDIUM_BLOCKS.unlock();
        }
        // SAFETY: the handlers only take and release the pool's lock.
        FORK_HANDLERS.call_once(|| unsafe {
            libc::pthread_atfork(Some(before_fork), Some(after_fork), Some(after_fork));
        });
    }
    &MEDIUM_BLOCKS
}

/// Where a block lives: decided by its layout alone, so that a block is returned where it
/// came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Home {
    /// The system allocator (small blocks, and any of a stricter alignment).
    System,
    /// [`MEDIUM_BLOCKS`] (`medium.rs`).
    Medium,
    /// A mapping of its own.
    Mapped,
}

impl Home {
    fn of(layout: Layout) -> Home {
        if mapped(layout) {
            Home::Mapped
        } else if is_medium(layout.size(), layout.align()) {
            Home::Medium
        } else {
            Home::System
        }
    }
}

/// Whether a block goes to its own mapping: large, and aligned to no more than a huge page
/// (a stricter alignment, never asked in practice, stays with the system allocator).
fn mapped(layout: Layout) -> bool {
    cfg!(target_os = "linux") && layout.size() >= LARGE && layout.align() <= HUGE_PAGE
}

/// The length of the mapping of a block of `size` bytes: whole pages. Not whole huge
/// pages: the kernel maps the 2 MiB ranges of the block with huge pages and its tail with
/// small ones, so that a block holds no more memory than with the system allocator.
fn mapping_len(size: usize) -> usize {
    size.next_multiple_of(page_size())
}

/// The system's (small) page size.
fn page_size() -> usize {
    #[cfg(target_os = "linux")]
    {
        // SAFETY: sysconf reads a constant of the process.
        match unsafe { libc::sysconf(libc::_SC_PAGESIZE) } {
            size if size > 0 => size as usize,
            _ => 4096,
        }
    }
    #[cfg(not(target_os = "linux"))]
    4096
}

#[cfg(target_os = "linux")]
mod map {
    use super::{mapping_len, HUGE_PAGE};

    /// A zeroed mapping of `mapping_len(size)` bytes starting on a huge page boundary,
    /// marked for huge pages; null if the system refuses it.
    pub(super) unsafe fn map(size: usize) -> *mut u8 {
        let len = mapping_len(size);
        // Over-map by one huge page, then return the unaligned head and the tail.
        let Some(padded) = len.checked_add(HUGE_PAGE) else {
            return std::ptr::null_mut();
        };
        let protection = libc::PROT_READ | libc::PROT_WRITE;
        let flags = libc::MAP_PRIVATE | libc::MAP_ANONYMOUS;
        // SAFETY: a fresh anonymous mapping; no existing memory is touched.
        let raw = unsafe { libc::mmap(std::ptr::null_mut(), padded, protection, flags, -1, 0) };
        if raw == libc::MAP_FAILED {
            return std::ptr::null_mut();
        }
        let start = raw as usize;
        let aligned = start.next_multiple_of(HUGE_PAGE);
        let head = aligned - start;
        let tail = padded - head - len;
        // SAFETY: both ranges lie inside the mapping just made, outside the block kept.
        unsafe {
            if head > 0 {
                libc::munmap(raw, head);
            }
            if tail > 0 {
                libc::munmap((aligned + len) as *mut libc::c_void, tail);
            }
            // Advice only: without THP the mapping simply keeps small pages.
            libc::madvise(aligned as *mut libc::c_void, len, libc::MADV_HUGEPAGE);
        }
        aligned as *mut u8
    }

    /// Returns a block of `size` bytes made by [`map`].
    pub(super) unsafe fn unmap(ptr: *mut u8, size: usize) {
        // SAFETY: the caller passes a block of `map` and its size, mapped whole.
        unsafe { libc::munmap(ptr.cast(), mapping_len(size)) };
    }
}

#[cfg(not(target_os = "linux"))]
mod map {
    pub(super) unsafe fn map(_size: usize) -> *mut u8 {
        unreachable!("only Linux maps blocks (`mapped`)")
    }
    pub(super) unsafe fn unmap(_ptr: *mut u8, _size: usize) {
        unreachable!("only Linux maps blocks (`mapped`)")
    }
}

// SAFETY: every block is the system allocator's (and returned to it with the same layout),
// a medium block of at least its size aligned to 64 KiB (`medium.rs`), or a mapping of its
// own of at least its size aligned to 2 MiB, returned whole: the home depends on the
// layout only ([`Home::of`]; blocks of stricter alignments stay with the system
// allocator), and a reallocation keeps the alignment.
unsafe impl GlobalAlloc for HugePageAlloc {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        match Home::of(layout) {
            Home::System => unsafe { System.alloc(layout) },
            Home::Medium => unsafe { medium_blocks().alloc(layout.size(), false) },
            Home::Mapped => unsafe { map::map(layout.size()) },
        }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        match Home::of(layout) {
            Home::System => unsafe { System.alloc_zeroed(layout) },
            Home::Medium => unsafe { medium_blocks().alloc(layout.size(), true) },
            // Anonymous mappings are zero.
            Home::Mapped => unsafe { map::map(layout.size()) },
        }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        match Home::of(layout) {
            Home::System => unsafe { System.dealloc(ptr, layout) },
            Home::Medium => unsafe { medium_blocks().dealloc(ptr, layout.size()) },
            Home::Mapped => unsafe { map::unmap(ptr, layout.size()) },
        }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        // SAFETY: the caller guarantees a valid size for the alignment.
        let new_layout = unsafe { Layout::from_size_align_unchecked(new_size, layout.align()) };
        let (old_size, old_home) = (layout.size(), Home::of(layout));
        let in_place = match (old_home, Home::of(new_layout)) {
            (Home::System, Home::System) => {
                return unsafe { System.realloc(ptr, layout, new_size) };
            }
            // The block's spare room (up to the mapping's last page, or the end of its
            // size class) is already there.
            (Home::Mapped, Home::Mapped) => mapping_len(new_size) == mapping_len(old_size),
            (Home::Medium, Home::Medium) => Pool::same_room(old_size, new_size),
            _ => false,
        };
        if in_place {
            return ptr;
        }
        let moved = unsafe { self.alloc(new_layout) };
        if !moved.is_null() {
            unsafe {
                std::ptr::copy_nonoverlapping(ptr, moved, old_size.min(new_size));
                self.dealloc(ptr, layout);
            }
        }
        moved
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every path of the allocator through its trait: small and large, zeroed, grown and
    /// shrunk across the threshold and within a mapping's pages, the contents kept.
    #[test]
    fn blocks_keep_their_contents_across_every_path() {
        let a = HugePageAlloc;
        for &(from, to) in &[
            (64, 4096),
            (4096, MEDIUM + 8),
            (MEDIUM + 8, MEDIUM + 100),
            (MEDIUM + 100, 3 * MEDIUM),
            (3 * MEDIUM, LARGE + 8),
            (LARGE + 8, 5 * MEDIUM),
            (5 * MEDIUM, 100),
            (4096, LARGE + 8),
            (LARGE + 8, 3 * LARGE),
            (3 * LARGE, 3 * LARGE + 100),
            (3 * LARGE + 100, 3 * LARGE + 200),
            (3 * LARGE + 100, 100),
            (5 * HUGE_PAGE + 1, HUGE_PAGE),
        ] {
            let layout = Layout::from_size_align(from, 8).unwrap();
            unsafe {
                let p = a.alloc_zeroed(layout);
                assert!(!p.is_null());
                let zeros = std::slice::from_raw_parts(p, from);
                assert!(zeros.iter().all(|&b| b == 0), "zeroed block of {from}");
                for i in 0..from {
                    *p.add(i) = (i % 251) as u8;
                }
                match Home::of(layout) {
                    Home::Mapped => assert_eq!(p as usize % HUGE_PAGE, 0, "{from} aligned"),
                    Home::Medium => assert_eq!(p as usize % (64 << 10), 0, "{from} aligned"),
                    Home::System => {}
                }
                let q = a.realloc(p, layout, to);
                assert!(!q.is_null());
                let kept = from.min(to);
                let bytes = std::slice::from_raw_parts(q, kept);
                assert!(bytes.iter().enumerate().all(|(i, &b)| b == (i % 251) as u8));
                let last = to - 1;
                *q.add(last) = 7; // the whole new size is writable
                a.dealloc(q, Layout::from_size_align(to, 8).unwrap());
            }
        }
    }

    /// A large vector through the allocator reads and writes like any other, and a block
    /// with a stricter alignment than a huge page is left to the system allocator.
    #[test]
    fn large_and_overaligned_blocks_are_usable() {
        let a = HugePageAlloc;
        let layout = Layout::from_size_align(LARGE, 4 * HUGE_PAGE).unwrap();
        assert!(!mapped(layout));
        unsafe {
            let p = a.alloc(layout);
            assert!(!p.is_null());
            assert_eq!(p as usize % (4 * HUGE_PAGE), 0);
            a.dealloc(p, layout);
        }
        let layout = Layout::array::<f64>(1 << 18).unwrap();
        assert_eq!(mapped(layout), cfg!(target_os = "linux"));
        unsafe {
            let p = a.alloc(layout).cast::<f64>();
            let field = std::slice::from_raw_parts_mut(p, 1 << 18);
            field
                .iter_mut()
                .enumerate()
                .for_each(|(i, x)| *x = i as f64);
            assert_eq!(
                field.iter().sum::<f64>(),
                ((1u64 << 18) * ((1 << 18) - 1) / 2) as f64
            );
            a.dealloc(p.cast(), layout);
        }
    }

    /// A child forked while other threads take and return medium blocks can take one too:
    /// the pool's lock is held across the fork, never inherited held.
    #[cfg(target_os = "linux")]
    #[test]
    fn a_forked_child_can_take_medium_blocks() {
        let layout = Layout::from_size_align(3 * MEDIUM, 8).unwrap();
        let stop = std::sync::atomic::AtomicBool::new(false);
        std::thread::scope(|s| {
            for _ in 0..2 {
                s.spawn(|| {
                    while !stop.load(std::sync::atomic::Ordering::Relaxed) {
                        unsafe {
                            let p = HugePageAlloc.alloc(layout);
                            HugePageAlloc.dealloc(p, layout);
                        }
                    }
                });
            }
            let statuses: Vec<_> = (0..50)
                .map(|_| {
                    // SAFETY: the child only allocates, frees and exits.
                    let child = unsafe { libc::fork() };
                    assert!(child >= 0, "fork failed");
                    if child == 0 {
                        unsafe {
                            let p = HugePageAlloc.alloc_zeroed(layout);
                            let ok = !p.is_null() && *p.add(12345) == 0;
                            HugePageAlloc.dealloc(p, layout);
                            libc::_exit(if ok { 0 } else { 1 });
                        }
                    }
                    exit_status(child)
                })
                .collect();
            stop.store(true, std::sync::atomic::Ordering::Relaxed);
            assert!(statuses.iter().all(|&s| s == Some(0)), "{statuses:?}");
        });
    }

    /// The exit status of child `pid`, or `None` (after killing it) if it has not exited
    /// within 60 s (a deadlocked child never does; a busy machine may hold a healthy one
    /// for seconds: issue 33 item 16).
    #[cfg(target_os = "linux")]
    fn exit_status(pid: libc::pid_t) -> Option<i32> {
        let started = std::time::Instant::now();
        let mut status = 0;
        while started.elapsed() < std::time::Duration::from_secs(60) {
            // SAFETY: waiting on our own child.
            if unsafe { libc::waitpid(pid, &mut status, libc::WNOHANG) } == pid {
                return libc::WIFEXITED(status).then(|| libc::WEXITSTATUS(status));
            }
            std::thread::sleep(std::time::Duration::from_millis(1));
        }
        unsafe {
            libc::kill(pid, libc::SIGKILL);
            libc::waitpid(pid, &mut status, 0);
        }
        None
    }
}
