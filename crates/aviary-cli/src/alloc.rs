//! The process's allocator: mimalloc rather than glibc's malloc. The engine makes and
//! frees many small objects per step and the world reader many small strings; with glibc
//! W(100k, 10) took 1.7 times as long (docs/BENCHMARKS.md). The `mimalloc` crate's
//! allocator asks for the alignment on every call (`mi_malloc_aligned`), a slower path
//! that showed in the profile; mimalloc aligns every block to 16 bytes anyway, so only
//! larger alignments take it here.

use std::alloc::{GlobalAlloc, Layout};
use std::ffi::c_void;

use libmimalloc_sys as mi;

/// What `mi_malloc` guarantees on 64-bit targets (`MI_MAX_ALIGN_SIZE`).
const ALIGNED: usize = 16;

pub struct MiMalloc;

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
