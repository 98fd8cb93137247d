//! The process's allocator: mimalloc rather than glibc's malloc. The engine makes and
//! frees many small objects per step and the world reader many small strings, which
//! mimalloc serves much faster (docs/BENCHMARKS.md has the figures). The `mimalloc`
//! crate's allocator asks for the alignment on every call (`mi_malloc_aligned`), a slower
//! path; mimalloc aligns every block to 16 bytes anyway, so only larger alignments take it
//! here.
//!
//! A library, so that what a run does with memory is said where the run is: the binary
//! declares [`MiMalloc`] its `#[global_allocator]` and calls [`tune`] before `main`; the
//! run's pipeline (`aviary_pipeline::fly`) calls [`give_back`] where it has just freed the
//! texts; a command calls [`short_lived`]. In a process whose allocator is another (a
//! test), the tuning functions touch only mimalloc's own, unused, state: they change
//! nothing and cost next to nothing.
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used, clippy::panic))]
// The one crate whose work is unsafe: a global allocator and the C calls that tune it
// (each block says why it is sound).
#![allow(unsafe_code)]

use std::alloc::{GlobalAlloc, Layout};
use std::ffi::c_void;

use libmimalloc_sys as mi;

/// What `mi_malloc` guarantees on 64-bit targets (`MI_MAX_ALIGN_SIZE`).
const ALIGNED: usize = 16;

pub struct MiMalloc;

/// Gives freed memory back to the system soon, rather than after mimalloc's default
/// second, and commits arena memory as it is used, rather than up front. Peak memory
/// then follows what is alive: a short run such as W(100k, 10) frees the world it read
/// before its engine peaks, and with mimalloc's defaults that memory would stay resident
/// for the whole run. The price is a little time (docs/BENCHMARKS.md has the trade).
/// `MIMALLOC_PURGE_DELAY` and `MIMALLOC_ARENA_EAGER_COMMIT` in the environment still win.
///
/// Call it before `main` (the binary's `ctor`): the first arena is made at the first
/// allocation, before `main`, and takes the commit option it finds then. It only reads the
/// environment and sets two options: nothing that needs the standard library to be ready,
/// and nothing that allocates.
pub fn tune() {
    const PURGE_DELAY_MS: std::ffi::c_long = 10;
    // SAFETY: plain setters of mimalloc's option table, with valid option ids.
    unsafe {
        if !in_environment(c"MIMALLOC_PURGE_DELAY") {
            mi::mi_option_set(PURGE_DELAY, PURGE_DELAY_MS);
        }
        if !in_environment(c"MIMALLOC_ARENA_EAGER_COMMIT") {
            mi::mi_option_set(ARENA_EAGER_COMMIT, 0);
        }
    }
}

/// For a command that ends within a second or so (`check`, `fmt`): memory freed is kept
/// for reuse rather than given back after the purge delay. Given back, it is faulted in
/// again page by page when the next stage allocates, a cost that shows on a long mission;
/// the process ends soon, and gives it all back then.
/// `MIMALLOC_PURGE_DELAY` in the environment still wins.
pub fn short_lived() {
    if !in_environment(c"MIMALLOC_PURGE_DELAY") {
        // SAFETY: a plain setter of mimalloc's option table, with a valid option id; the
        // delay is read when a purge is scheduled, so a change takes effect from here on.
        unsafe { mi::mi_option_set(PURGE_DELAY, -1) }
    }
}

/// Gives the memory freed so far back to the system now, not after the purge delay:
/// for a point where much has just been freed and much is about to be allocated (the
/// world's text dropped while the fleet is built), so that the two are not resident
/// together.
pub fn give_back() {
    // SAFETY: mimalloc's own collection of free memory, callable at any time.
    unsafe { mi::mi_collect(true) }
}

/// Whether the variable is set, without allocating (this runs before the allocator is
/// ready for Rust's own use).
fn in_environment(name: &std::ffi::CStr) -> bool {
    // SAFETY: a NUL-terminated name; the result is only compared with null, and nothing
    // changes the environment before `main`.
    !unsafe { libc::getenv(name.as_ptr()) }.is_null()
}

// Ids in mimalloc v3's `mi_option_e` (its `mimalloc.h`, the version this crate builds);
// the crate names only v2's, whose order differs.
const ARENA_EAGER_COMMIT: mi::mi_option_t = 4;
const PURGE_DELAY: mi::mi_option_t = 15;

// SAFETY: every block comes from mimalloc with at least the layout's alignment (16
// bytes by default, else asked for) and goes back to it through `mi_free`, which takes
// blocks of either kind.
unsafe impl GlobalAlloc for MiMalloc {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if layout.align() <= ALIGNED {
            mi::mi_malloc(layout.size()).cast()
        } else {
            mi::mi_malloc_aligned(layout.size(), layout.align()).cast()
        }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        if layout.align() <= ALIGNED {
            mi::mi_zalloc(layout.size()).cast()
        } else {
            mi::mi_zalloc_aligned(layout.size(), layout.align()).cast()
        }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, _layout: Layout) {
        mi::mi_free(ptr.cast::<c_void>());
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if layout.align() <= ALIGNED {
            mi::mi_realloc(ptr.cast(), new_size).cast()
        } else {
            mi::mi_realloc_aligned(ptr.cast(), new_size, layout.align()).cast()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_options_set_are_the_ones_meant() {
        tune();
        // SAFETY: getters of mimalloc's option table.
        let (purge, eager, errors) = unsafe {
            (
                mi::mi_option_get(PURGE_DELAY),
                mi::mi_option_get(ARENA_EAGER_COMMIT),
                mi::mi_option_get(mi::mi_option_show_errors),
            )
        };
        if std::env::var_os("MIMALLOC_PURGE_DELAY").is_none() {
            assert_eq!(purge, 10);
        }
        if std::env::var_os("MIMALLOC_ARENA_EAGER_COMMIT").is_none() {
            assert_eq!(eager, 0);
        }
        assert_eq!(errors, 0, "an option near them is untouched");
    }
}
