//! A global allocator that backs large buffers with transparent huge pages (Linux).
//!
//! The solvers' fields are megabytes each (a 512² grid of `f64` is 2 MiB, its padded
//! spectrum 8 MiB), and with 4 KiB pages every first touch of a page is a fault: the first
//! 512² BEM solve of a process faulted 6 049 times (free boundaries, 2 threads; 473 with
//! this allocator) and took 0.23–0.24 s instead of 0.22 s. The kernel's transparent huge
//! pages (THP) map 2 MiB per fault, but only in 2 MiB-aligned ranges of a mapping marked
//! for them (`/sys/kernel/mm/transparent_hugepage/enabled` = `madvise`, the common
//! default) or in any mapping (`always`). The C allocator aligns its large blocks to 4 KiB only, so a
//! 2 MiB field never covers an aligned range.
//!
//! [`HugePageAlloc`] maps every block of at least [`LARGE`] bytes by itself, aligned to
//! 2 MiB and marked `MADV_HUGEPAGE`, and leaves smaller blocks to the system allocator.
//! Mapped memory is zero, so zeroed blocks cost no pass of their own. Where the kernel
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

/// The medium blocks of every [`HugePageAlloc`].
static MEDIUM_BLOCKS: Pool = Pool::new();

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
            Home::Medium => unsafe { MEDIUM_BLOCKS.alloc(layout.size(), false) },
            Home::Mapped => unsafe { map::map(layout.size()) },
        }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        match Home::of(layout) {
            Home::System => unsafe { System.alloc_zeroed(layout) },
            Home::Medium => unsafe { MEDIUM_BLOCKS.alloc(layout.size(), true) },
            // Anonymous mappings are zero.
            Home::Mapped => unsafe { map::map(layout.size()) },
        }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        match Home::of(layout) {
            Home::System => unsafe { System.dealloc(ptr, layout) },
            Home::Medium => unsafe { MEDIUM_BLOCKS.dealloc(ptr, layout.size()) },
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
}
