//! `bdpt`'s strategies by name and index, and the chunk's log of
//! camera-side contributions by strategy, for per-strategy images
//! ([`crate::integrators::strategies`]).
//!
//! A sample's camera-side strategies (s = 0, next-event estimation, the
//! connections) are summed into its radiance where the walk finds them;
//! where per-strategy images are asked for, each is also logged here with
//! its sample slot and strategy, and the worker splats the log at the
//! samples' film positions once the chunk is walked (leaving out samples
//! whose sum is not finite, which the image records as black). The t = 1
//! strategies land away from their sample and are splatted where they
//! land.

use radiant_core::Rgb;

/// The index of strategy (s, t) — a path of s + t − 1 segments, s light
/// and t camera vertices — among a render's strategies, ordered by path
/// length, then by s (so index 0 is (0, 2): an emitter seen directly).
#[inline]
pub(super) fn strategy_index(s: usize, t: usize) -> usize {
    let k = s + t - 1;
    (k - 1) * (k + 2) / 2 + s
}

/// The names of the strategies of paths of 1 to `max` segments
/// (`s{s}_t{t}`), in [`strategy_index`] order.
pub(super) fn strategy_names(max: usize) -> Vec<String> {
    (1..=max)
        .flat_map(|k| (0..=k).map(move |s| format!("s{s}_t{}", k + 1 - s)))
        .collect()
}

/// The chunk's camera-side contributions by strategy: (slot, strategy
/// index, weighted value), kept only where `on`.
#[derive(Default)]
pub(super) struct StrategyLog {
    /// Whether the render asks for per-strategy images.
    pub on: bool,
    /// The logged contributions, in the order the walk found them.
    pub entries: Vec<(u32, u32, Rgb)>,
}

impl StrategyLog {
    /// Logs slot `j`'s contribution `value` (weighted) by strategy (s, t),
    /// unless it is zero (a weight of 0, or another strategy than the one
    /// `strategy: [s, t]` renders).
    #[inline]
    pub(super) fn add(&mut self, j: usize, s: usize, t: usize, value: Rgb) {
        if self.on && value != Rgb::ZERO {
            self.entries
                .push((j as u32, strategy_index(s, t) as u32, value));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn indices_follow_the_names() {
        let names = strategy_names(5);
        // k + 1 strategies of each length k.
        assert_eq!(names.len(), 2 + 3 + 4 + 5 + 6);
        for k in 1..=5usize {
            for s in 0..=k {
                let t = k + 1 - s;
                assert_eq!(names[strategy_index(s, t)], format!("s{s}_t{t}"));
            }
        }
    }
}
