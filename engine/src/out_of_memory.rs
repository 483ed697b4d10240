//! The last line of defence against running out of memory: the binary's
//! global allocator is the system's, except that where an allocation fails
//! — one that no estimate foresaw, after the checks made before a film, a
//! mesh, a BVH or a texture is taken — the process says so on stderr and
//! exits with status 1, as for any other error, instead of aborting
//! (status 134), removing the temporary files of outputs not yet complete.
//! It allocates nothing itself: the message is formatted on the stack.
//!
//! The `radiant` binary installs it, and so can any binary built on the
//! library (a module crate's own `radiant`, for one):
//!
//! ```no_run,standalone_crate
//! #[global_allocator]
//! static ALLOCATOR: radiant::out_of_memory::ExitOnFailure = radiant::out_of_memory::ExitOnFailure;
//! # fn main() {}
//! ```

use std::alloc::{GlobalAlloc, Layout, System};
use std::io::Write;

/// [`System`], exiting with a message where an allocation fails.
pub struct ExitOnFailure;

// SAFETY: every method forwards to `System` with the same arguments and
// returns its result unchanged; where that is null (failure), the process
// exits instead of returning.
unsafe impl GlobalAlloc for ExitOnFailure {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // SAFETY: the caller's contract for `alloc` is `System`'s.
        checked(unsafe { System.alloc(layout) }, layout.size())
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        // SAFETY: as for `alloc`.
        checked(unsafe { System.alloc_zeroed(layout) }, layout.size())
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: `ptr` came from `System` with this layout.
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        // SAFETY: `ptr` came from `System` with this layout.
        checked(unsafe { System.realloc(ptr, layout, new_size) }, new_size)
    }
}

/// `ptr`, or (where it is null) a message on stderr and exit status 1.
fn checked(ptr: *mut u8, size: usize) -> *mut u8 {
    if !ptr.is_null() {
        return ptr;
    }
    let mut message = [0u8; 320];
    let mut out = &mut message[..];
    let _ = writeln!(
        out,
        "Error: out of memory: an allocation of {size} bytes failed, past the checks made \
         before the film, meshes, BVHs and textures were taken; render a smaller frame or \
         scene, or give the process more memory"
    );
    let len = 320 - out.len();
    let _ = std::io::stderr().write_all(&message[..len]);
    // No half-written output is left behind.
    crate::film::output::remove_unfinished_outputs();
    std::process::exit(1)
}
