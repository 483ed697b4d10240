//! The per-path arrays of the wavefront ([`super::path`]).
//!
//! A batch's stages keep one array per quantity (hit, throughput, BSDF
//! sample, light sample, shadow ray, …), and most of them are as long as
//! the paths still alive at the current bounce: a thousand camera paths,
//! a few hundred after the first bounce, a handful at the last. The next
//! batch grows them back to a thousand. A `Vec` shrunk by `truncate` and
//! grown by `resize` writes a default into every element it grows by,
//! although each stage overwrites the elements it uses: about 300 KB of
//! stores per batch, 2.3 % of the instructions of a render of
//! `scenes/bench/spot-point.yaml`. A [`Buffer`] keeps every element it
//! ever held, so that shrinking and growing back writes nothing.

use std::ops::{Deref, DerefMut};

/// An array whose length can drop and grow back without its elements
/// being re-initialised: the first [`len`](slice::len) of the elements it
/// has ever held are its contents (it dereferences to them), and the rest
/// keep whatever they last held.
#[derive(Debug, Clone, Default)]
pub struct Buffer<T> {
    /// Every element the buffer has been grown to.
    held: Vec<T>,
    /// How many of them are the contents; never more than `held.len()`.
    len: usize,
}

impl<T: Clone + Default> Buffer<T> {
    /// Gives the buffer length `n` for a stage that writes every element
    /// before it reads one: the elements it grows by hold what they held
    /// when it last shrank (the default where it never reached them).
    #[inline]
    pub fn fit(&mut self, n: usize) {
        if self.held.len() < n {
            self.held.resize(n, T::default());
        }
        self.len = n;
    }

    /// Gives the buffer length `n`, every element `T::default()`.
    #[inline]
    pub fn zeroed(&mut self, n: usize) {
        self.fit(n);
        self.fill(T::default());
    }
}

impl<T> Buffer<T> {
    /// Shortens the buffer to `n` elements (no change where it is not
    /// longer); the elements past `n` are kept for regrowth.
    #[inline]
    pub fn truncate(&mut self, n: usize) {
        self.len = self.len.min(n);
    }
}

impl<T> Deref for Buffer<T> {
    type Target = [T];

    #[inline]
    fn deref(&self) -> &[T] {
        // SAFETY: `len <= held.len()` (`fit` and `truncate` keep it so).
        unsafe { self.held.get_unchecked(..self.len) }
    }
}

impl<T> DerefMut for Buffer<T> {
    #[inline]
    fn deref_mut(&mut self) -> &mut [T] {
        // SAFETY: as in `deref`.
        unsafe { self.held.get_unchecked_mut(..self.len) }
    }
}

impl<'a, T> IntoIterator for &'a Buffer<T> {
    type Item = &'a T;
    type IntoIter = std::slice::Iter<'a, T>;

    #[inline]
    fn into_iter(self) -> Self::IntoIter {
        self.iter()
    }
}

impl<'a, T> IntoIterator for &'a mut Buffer<T> {
    type Item = &'a mut T;
    type IntoIter = std::slice::IterMut<'a, T>;

    #[inline]
    fn into_iter(self) -> Self::IntoIter {
        self.iter_mut()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shrinking_keeps_elements_for_regrowth() {
        let mut b = Buffer::<u32>::default();
        b.fit(4);
        assert_eq!(&b[..], &[0, 0, 0, 0]);
        b.copy_from_slice(&[1, 2, 3, 4]);
        b.truncate(1);
        assert_eq!(&b[..], &[1]);
        // Growing back writes nothing: a stage overwrites what it uses.
        b.fit(3);
        assert_eq!(&b[..], &[1, 2, 3]);
        // Past what it ever held, the default.
        b.fit(6);
        assert_eq!(&b[..], &[1, 2, 3, 4, 0, 0]);
        // Truncating to more than the length changes nothing.
        b.truncate(10);
        assert_eq!(b.len(), 6);
    }

    #[test]
    fn zeroed_writes_every_element() {
        let mut b = Buffer::<f32>::default();
        b.fit(3);
        b.fill(7.0);
        b.zeroed(2);
        assert_eq!(&b[..], &[0.0, 0.0]);
        b.fit(3);
        assert_eq!(&b[..], &[0.0, 0.0, 7.0]);
    }
}
