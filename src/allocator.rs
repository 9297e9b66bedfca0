//! The global allocator: mimalloc. Every stage allocates small per-face buffers on rayon's
//! threads and frees them on others, where glibc's malloc contends; mimalloc serves that pattern
//! well and gives the same output bytes.
//!
//! Most of Rust's requests ask no more alignment than every block of their size has; those go
//! to mimalloc's plain entry points, which skip the checks its aligned ones make on each call
//! (the rule std's own `System` allocator follows for `malloc`).

use libmimalloc_sys::{
    mi_free, mi_malloc, mi_malloc_aligned, mi_realloc, mi_realloc_aligned, mi_zalloc,
    mi_zalloc_aligned,
};
use std::alloc::{GlobalAlloc, Layout};
use std::ffi::c_void;

/// The alignment mimalloc gives every block at least as large as it (`MI_MAX_ALIGN_SIZE` on
/// x86-64); smaller blocks are aligned to their size's power of two.
const PLAIN_ALIGN: usize = 16;

pub struct MiMalloc;

/// Whether every block of `size` is aligned to `align`: mimalloc's plain entry points serve it.
fn plain(align: usize, size: usize) -> bool {
    align <= PLAIN_ALIGN && align <= size
}

/// `plain_alloc(size)` when every block of `size` meets `align` ([`plain`]), else
/// `aligned(size, align)`.
///
/// # Safety
/// Both must be mimalloc's allocation functions of one kind.
#[inline(always)]
unsafe fn by_alignment(
    size: usize,
    align: usize,
    plain_alloc: unsafe extern "C" fn(usize) -> *mut c_void,
    aligned: unsafe extern "C" fn(usize, usize) -> *mut c_void,
) -> *mut u8 {
    // SAFETY: the caller passes mimalloc's functions; the plain one only gets sizes whose
    // every block is aligned at least as asked.
    unsafe {
        if plain(align, size) {
            plain_alloc(size).cast()
        } else {
            aligned(size, align).cast()
        }
    }
}

// SAFETY: each call passes the layout's size and alignment to the mimalloc function that
// honours them (the plain ones only where every block of that size is aligned so), and frees
// with `mi_free`, which takes blocks from all of them.
unsafe impl GlobalAlloc for MiMalloc {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // SAFETY: see the impl.
        unsafe { by_alignment(layout.size(), layout.align(), mi_malloc, mi_malloc_aligned) }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        // SAFETY: see the impl.
        unsafe { by_alignment(layout.size(), layout.align(), mi_zalloc, mi_zalloc_aligned) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, _layout: Layout) {
        // SAFETY: see the impl.
        unsafe { mi_free(ptr.cast::<c_void>()) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let (ptr, align) = (ptr.cast::<c_void>(), layout.align());
        // SAFETY: see the impl.
        unsafe {
            if plain(align, new_size) {
                mi_realloc(ptr, new_size).cast()
            } else {
                mi_realloc_aligned(ptr, new_size, align).cast()
            }
        }
    }
}
