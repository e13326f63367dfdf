//! The tool's allocator: the system's, and where an allocation fails (under an address-space
//! limit the memory budget's prediction did not foresee), a way out that allocates nothing:
//! a preformatted message on standard error, the temporaries removed, exit 3 (SPEC.md: running
//! out of memory is never an abort). `src/main.rs` installs it.

use std::alloc::{GlobalAlloc, Layout, System};

/// [`System`] with the failure path of the module's documentation.
pub struct Guarded;

// SAFETY: every call is forwarded to the system allocator unchanged; only a null result is
// acted upon, and that path never returns
unsafe impl GlobalAlloc for Guarded {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // SAFETY: forwarded with the caller's guarantees
        let p = unsafe { System.alloc(layout) };
        if p.is_null() {
            out_of_memory(layout.size());
        }
        p
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        // SAFETY: forwarded with the caller's guarantees
        let p = unsafe { System.alloc_zeroed(layout) };
        if p.is_null() {
            out_of_memory(layout.size());
        }
        p
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: forwarded with the caller's guarantees
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        // SAFETY: forwarded with the caller's guarantees
        let p = unsafe { System.realloc(ptr, layout, new_size) };
        if p.is_null() {
            out_of_memory(new_size);
        }
        p
    }
}

/// Writes the message (the size in decimal, into a stack buffer), removes the temporaries and
/// ends the process with exit 3, allocating nothing.
fn out_of_memory(size: usize) -> ! {
    const HEAD: &[u8] = b"error: not enough memory: an allocation of ";
    const TAIL: &[u8] = b" bytes failed (the memory budget's prediction did not foresee it: give a larger \
--memory-limit or ulimit -v, or a smaller input); no output was written\n";
    let mut buf = [0u8; 20];
    let digits = crate::io::decimal(size, &mut buf);
    #[cfg(unix)]
    // SAFETY: writes of static and stack buffers to standard error, then the process ends
    unsafe {
        libc::write(2, HEAD.as_ptr().cast(), HEAD.len());
        libc::write(2, digits.as_ptr().cast(), digits.len());
        libc::write(2, TAIL.as_ptr().cast(), TAIL.len());
        crate::io::staging::remove_temporaries_unallocated();
        libc::_exit(crate::error::ErrorKind::Memory.exit_code());
    }
    #[cfg(not(unix))]
    std::process::abort()
}
