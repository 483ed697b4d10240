//! Requests of a stage ordered by the light they concern, so that each
//! light module is called once per stage on a contiguous slice (as `path`
//! groups its light samples). The caller builds each call's inputs in
//! this order, calls the light per range and reads the answers back in
//! the same order, mapping each to its request through [`ByLight::order`].

use crate::integrators::sort::sort_by_key;

/// Request indices sorted by light, with each light's range; reused.
#[derive(Default)]
pub(super) struct ByLight {
    /// Request indices, by light (stable).
    pub order: Vec<u32>,
    scratch: Vec<u32>,
    cursor: Vec<u32>,
    offsets: Vec<u32>,
}

impl ByLight {
    /// Sorts the requests 0 .. `n` by `light(request)`, one of `lights`.
    pub(super) fn sort(&mut self, n: usize, lights: usize, light: impl Fn(u32) -> u32) {
        self.order.clear();
        self.order.extend(0..n as u32);
        sort_by_key(
            &mut self.order,
            &mut self.scratch,
            &mut self.cursor,
            &mut self.offsets,
            lights,
            light,
        );
    }

    /// Each light with the positions in [`ByLight::order`] of its
    /// requests, where it has any.
    pub(super) fn ranges(&self) -> impl Iterator<Item = (usize, std::ops::Range<usize>)> + '_ {
        self.offsets.windows(2).enumerate().filter_map(|(l, w)| {
            let (a, b) = (w[0] as usize, w[1] as usize);
            (a < b).then_some((l, a..b))
        })
    }
}
