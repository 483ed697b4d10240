//! Batch queries that trace two rays at once, their traversals
//! interleaved node visit by node visit.
//!
//! A traversal is a chain of dependent loads: a node's box test decides
//! which node to load next, so a ray whose next node is not cached waits
//! for it, and a batch loop's next ray would start only once it is done.
//! [`interleave`] keeps [`WALKS`] rays in lanes, each with its query and
//! its walk ([`super::wide::Walk`]), and steps them in turn: while one
//! ray's node is on its way the other's visit runs. What a step is —
//! a visit of one bottom level (`blas/interleave.rs`), or, for shadow
//! rays, of a top level and the instances it leads into (`instanced.rs`)
//! — is the query's [`Walks`].
//!
//! Two lanes, measured: renders of the speed suite's scenes (meshes that
//! mostly stay cached) run 2–4 % faster than one ray at a time, three or
//! four lanes' bookkeeping costs what they gain, and incoherent rays or
//! scenes far larger than the caches gain more (see
//! `engine/benches/ANIMATION.md`).

/// Rays a batch query traces at once.
pub(super) const WALKS: usize = 2;

/// What a batch query does with its lanes ([`interleave`]).
pub(super) trait Walks {
    /// A lane: one ray's query and traversal.
    type Lane;
    /// A ray's answer.
    type Answer;

    /// An idle lane.
    fn lane(&self) -> Self::Lane;

    /// Sets `lane` up for ray `i`; or returns the ray's answer where it
    /// needs no traversal.
    fn start(&self, lane: &mut Self::Lane, i: usize) -> Option<Self::Answer>;

    /// One step of `lane`'s traversal (about one node visit); whether it
    /// goes on.
    fn step(&self, lane: &mut Self::Lane) -> bool;

    /// The answer of `lane`, whose traversal is over.
    fn finish(&self, lane: &Self::Lane) -> Self::Answer;
}

/// Answers the rays `rays` into `out` with `walks`, [`WALKS`] rays at a
/// time whose traversals take a step each in turn. Each ray gets the
/// answer of its own traversal, whatever order the rays finish in.
#[inline(always)]
pub(super) fn interleave<W: Walks>(
    walks: &W,
    mut rays: impl Iterator<Item = usize>,
    out: &mut [W::Answer],
) {
    let mut lanes: [W::Lane; WALKS] = std::array::from_fn(|_| walks.lane());
    let mut of: [Option<usize>; WALKS] = [None; WALKS];
    let mut busy = 0;
    loop {
        for (lane, ray) in lanes.iter_mut().zip(&mut of) {
            if let Some(i) = *ray {
                if walks.step(lane) {
                    continue;
                }
                out[i] = walks.finish(lane);
                *ray = None;
                busy -= 1;
            }
            for i in rays.by_ref() {
                match walks.start(lane, i) {
                    Some(answer) => out[i] = answer,
                    None => {
                        *ray = Some(i);
                        busy += 1;
                        break;
                    }
                }
            }
        }
        if busy == 0 {
            return;
        }
    }
}
