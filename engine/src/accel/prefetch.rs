//! Software prefetch: starting the loads of data that a batch stage will
//! read a few items later.
//!
//! The wavefront resolves a batch of hits one after the other, and each
//! hit reads records (its primitive, its instance's placement, its vertex
//! normals) at places in memory that no hardware prefetcher can guess. The
//! addresses are known from the batch's hit array long before they are
//! needed, so a stage asks for them a few hits ahead
//! ([`crate::accel::Accel::prefetch_instance`],
//! [`crate::accel::Accel::prefetch_primitive`]), and the misses overlap
//! instead of stalling one by one.

/// Bytes per cache line.
const LINE: usize = 64;

/// Starts loading every cache line of `value` into the first-level data
/// cache, without waiting for it (a hint: it changes no result, and does
/// nothing on targets without a prefetch instruction).
///
/// One prefetch per 64 bytes of the value from its start, and one at its
/// last byte: that reaches every line the value touches, wherever it
/// starts, with a number of instructions fixed by its type (no loop over
/// its alignment at run time).
#[inline(always)]
pub fn prefetch<T>(value: &T) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        let start = std::ptr::from_ref(value).cast::<i8>();
        let size = std::mem::size_of::<T>();
        let mut offset = 0;
        while offset < size {
            // SAFETY: prefetching reads nothing and never faults.
            unsafe { _mm_prefetch::<_MM_HINT_T0>(start.wrapping_add(offset)) };
            offset += LINE;
        }
        if size > 1 {
            // SAFETY: as above.
            unsafe { _mm_prefetch::<_MM_HINT_T0>(start.wrapping_add(size - 1)) };
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = value;
}
