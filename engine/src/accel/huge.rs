//! Arrays in huge pages: the memory that traversal reads at random.
//!
//! A ray's walk through a hierarchy touches nodes and primitive packets
//! scattered over megabytes. With the usual 4 KiB pages each of those
//! touches also needs a page-table entry that the CPU's translation
//! caches rarely hold (a few thousand entries cover 8 MiB), so a walk
//! waits on page walks as well as on the data. [`HugeArray`] keeps an
//! array of 2 MiB or more in an anonymous mapping advised for transparent
//! huge pages (`MADV_HUGEPAGE`, which Embree advises for its hierarchies
//! too), where one translation covers 2 MiB. Smaller arrays stay on the
//! heap. Where the kernel grants no huge pages the mapping works as any
//! other memory.
//!
//! Arrays are written here directly, up to a capacity known in advance
//! (a bound such as one packet per primitive costs address space only:
//! untouched pages take no memory). The wide hierarchy's nodes are built
//! in a `Vec` and copied here.

use std::fmt;
use std::ops::{Deref, DerefMut};
use std::ptr::NonNull;

/// The huge page size (x86-64 and AArch64 with 4 KiB base pages), and the
/// least array size that is mapped on its own.
const HUGE_PAGE: usize = 2 << 20;

/// An array of `T` whose whole 2 MiB stretches live in huge pages when
/// it may grow to at least [`HUGE_PAGE`]; it dereferences to a slice. It
/// grows only up to the capacity it was made with (beyond, it moves to
/// the heap).
pub struct HugeArray<T: Copy> {
    /// The first value (dangling while nothing was ever stored), so that
    /// reading the array is one pointer and one length, whatever holds it.
    first: NonNull<T>,
    len: usize,
    storage: Storage<T>,
}

/// What holds a [`HugeArray`]'s values.
enum Storage<T> {
    /// Below [`HUGE_PAGE`] (or where mapping failed, or the capacity was
    /// exceeded): a `Vec` as long as the array.
    Heap(Vec<T>),
    /// A mapping with room for `capacity` values from a huge page
    /// boundary on. Pages beyond the values are never touched, so they
    /// take no memory.
    Mapped {
        /// Held for its drop, which unmaps it; read through `first`.
        _map: memmap2::MmapMut,
        capacity: usize,
    },
}

// SAFETY: a `HugeArray` owns its values as a `Vec` would (the pointer is
// into its own storage), so it may move to and be shared between threads
// as a `Vec<T>` can.
unsafe impl<T: Copy + Send> Send for HugeArray<T> {}
// SAFETY: as above.
unsafe impl<T: Copy + Sync> Sync for HugeArray<T> {}

impl<T: Copy> HugeArray<T> {
    // A huge page boundary is aligned for any `T` that can be.
    const ALIGNED: () = assert!(std::mem::align_of::<T>() <= HUGE_PAGE);

    /// The array held by `values`.
    fn on_heap(mut values: Vec<T>) -> Self {
        Self {
            first: NonNull::new(values.as_mut_ptr()).unwrap_or(NonNull::dangling()),
            len: values.len(),
            storage: Storage::Heap(values),
        }
    }

    /// An empty array with room for `capacity` values, in huge pages if
    /// they would take at least 2 MiB. Only the memory that values are
    /// pushed into is ever taken (rounded up to the huge page).
    pub fn with_capacity(capacity: usize) -> Self {
        let () = Self::ALIGNED;
        let bytes = capacity.saturating_mul(std::mem::size_of::<T>());
        if bytes >= HUGE_PAGE
            && let Some((mut map, start)) = map_huge(bytes)
        {
            // SAFETY: `start` lies inside the mapping (`map_huge`).
            let first = unsafe { map.as_mut_ptr().add(start) }.cast::<T>();
            return Self {
                first: NonNull::new(first).unwrap_or(NonNull::dangling()),
                len: 0,
                storage: Storage::Mapped {
                    _map: map,
                    capacity,
                },
            };
        }
        Self::on_heap(Vec::with_capacity(capacity))
    }

    /// Appends `value`.
    #[inline]
    pub fn push(&mut self, value: T) {
        if let Storage::Mapped { capacity, .. } = self.storage
            && self.len == capacity
        {
            *self = Self::on_heap(self.to_vec());
        }
        match &mut self.storage {
            Storage::Mapped { .. } => {
                // SAFETY: `len` is below the capacity (above), so the slot
                // lies in the mapping's room for `capacity` values from
                // `first` (a huge page boundary, aligned for `T`).
                unsafe { self.first.add(self.len).write(value) };
                self.len += 1;
            }
            Storage::Heap(values) => {
                values.push(value);
                self.first = NonNull::new(values.as_mut_ptr()).unwrap_or(NonNull::dangling());
                self.len = values.len();
            }
        }
    }

    /// The array of `len` values `value(0)`, `value(1)`, …, in huge pages
    /// if they take at least 2 MiB.
    pub fn from_fn(len: usize, value: impl FnMut(usize) -> T) -> Self {
        let mut array = Self::with_capacity(len);
        (0..len).map(value).for_each(|v| array.push(v));
        array
    }

    /// A copy of `values`, in huge pages if it takes at least 2 MiB.
    pub fn from_slice(values: &[T]) -> Self {
        Self::from_fn(values.len(), |i| values[i])
    }
}

/// An anonymous mapping with room for `bytes` from a huge page boundary
/// on, and that boundary's offset in it, advised for transparent huge
/// pages (the slack before the boundary is never touched). `None` if the
/// system refuses the mapping.
fn map_huge(bytes: usize) -> Option<(memmap2::MmapMut, usize)> {
    let room = bytes.checked_next_multiple_of(HUGE_PAGE)?;
    let map = memmap2::MmapOptions::new()
        .len(room.checked_add(HUGE_PAGE)?)
        .map_anon()
        .ok()?;
    let start = (map.as_ptr() as usize).next_multiple_of(HUGE_PAGE) - map.as_ptr() as usize;
    // Advice only: where it is refused the pages stay small.
    #[cfg(target_os = "linux")]
    let _ = map.advise_range(memmap2::Advice::HugePage, start, room);
    Some((map, start))
}

impl<T: Copy> Deref for HugeArray<T> {
    type Target = [T];

    #[inline(always)]
    fn deref(&self) -> &[T] {
        // SAFETY: `first` points at `len` values written into the storage,
        // which lives as long as `self` and moves only through `&mut self`
        // (which updates `first`); dangling only where `len` is 0.
        unsafe { std::slice::from_raw_parts(self.first.as_ptr(), self.len) }
    }
}

impl<T: Copy> DerefMut for HugeArray<T> {
    #[inline(always)]
    fn deref_mut(&mut self) -> &mut [T] {
        // SAFETY: as in `deref`, borrowed mutably through `self`.
        unsafe { std::slice::from_raw_parts_mut(self.first.as_ptr(), self.len) }
    }
}

impl<T: Copy> From<Vec<T>> for HugeArray<T> {
    /// The values of `values`: copied to huge pages if they take at least
    /// 2 MiB, else kept where they are.
    fn from(values: Vec<T>) -> Self {
        if std::mem::size_of_val(values.as_slice()) >= HUGE_PAGE {
            Self::from_slice(&values)
        } else {
            Self::on_heap(values)
        }
    }
}

impl<T: Copy> Default for HugeArray<T> {
    fn default() -> Self {
        Self::on_heap(Vec::new())
    }
}

impl<T: Copy> Clone for HugeArray<T> {
    fn clone(&self) -> Self {
        Self::from_slice(self)
    }
}

impl<T: Copy + fmt::Debug> fmt::Debug for HugeArray<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_list().entries(self.iter()).finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_and_large_arrays_keep_their_values() {
        for n in [0, 1, 1000, HUGE_PAGE / 12 + 7, 3 * HUGE_PAGE / 12] {
            let values: Vec<[u32; 3]> = (0..n as u32).map(|i| [i, i ^ 0x5555, !i]).collect();
            let mut array = HugeArray::from(values.clone());
            assert_eq!(&array[..], &values[..], "{n} values");
            assert_eq!(
                matches!(array.storage, Storage::Mapped { .. }),
                n * 12 >= HUGE_PAGE,
                "{n} values"
            );
            if let Some(last) = array.last_mut() {
                *last = [1, 2, 3];
            }
            let copy = array.clone();
            assert_eq!(&copy[..], &array[..]);
            assert_eq!(copy.last(), (n > 0).then_some(&[1, 2, 3]));
        }
    }

    #[test]
    fn pushing_past_the_capacity_moves_to_the_heap() {
        let n = HUGE_PAGE / 8;
        let mut array = HugeArray::with_capacity(n);
        assert!(matches!(array.storage, Storage::Mapped { .. }));
        for i in 0..n as u64 + 3 {
            array.push(i * 3);
        }
        assert!(matches!(array.storage, Storage::Heap(_)));
        assert!(array.iter().enumerate().all(|(i, &v)| v == i as u64 * 3));
        assert_eq!(array.len(), n + 3);
    }
}
