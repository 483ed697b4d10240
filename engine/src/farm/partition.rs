//! Sample partitions (`--partition K/N`): the K-th of N disjoint, adjacent
//! ranges of a frame's sample indices. Every sampler draws sample `i` of a
//! pixel from (seed, pixel, `i`) alone, so the partitions of a frame are
//! disjoint sampler streams whose union is the whole frame's samples. They
//! start on block boundaries ([`BLOCK`]), so their exact film sums add up to
//! the single render's bit for bit.

use crate::film::exact::BLOCK;
use std::fmt;
use std::ops::Range;
use std::str::FromStr;

/// The `index`-th (from 1) of `count` sample partitions.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Partition {
    index: u32,
    count: u32,
}

/// Why a partition is not valid.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum PartitionError {
    /// The text is not `K/N` with numbers.
    #[error("`{0}` is not a partition; expected K/N, as in 3/16 (the 3rd of 16)")]
    Syntax(String),
    /// `K` is outside 1..=N.
    #[error("partition {index}/{count} does not exist: K must lie between 1 and {count}")]
    OutOfRange {
        /// K.
        index: u32,
        /// N.
        count: u32,
    },
    /// More partitions than blocks of samples, so some would be empty.
    #[error(
        "{count} partitions of {spp} samples per pixel would leave some empty (partitions hold whole blocks of {BLOCK} samples): use at most {} partitions or more samples (--spp)", spp.div_ceil(BLOCK)
    )]
    TooMany {
        /// N.
        count: u32,
        /// Samples per pixel of the frame.
        spp: u32,
    },
}

impl Partition {
    /// The `index`-th (from 1) of `count` partitions.
    pub fn new(index: u32, count: u32) -> Result<Self, PartitionError> {
        if index == 0 || index > count {
            return Err(PartitionError::OutOfRange { index, count });
        }
        Ok(Self { index, count })
    }

    /// K, from 1.
    pub fn index(self) -> u32 {
        self.index
    }

    /// N.
    pub fn count(self) -> u32 {
        self.count
    }

    /// The sample indices of this partition of a frame of `spp` samples per
    /// pixel, in whole blocks of [`BLOCK`] samples: of the B = ⌈spp/4⌉
    /// blocks, partition K of N takes blocks ⌊(K−1)·B/N⌋ .. ⌊K·B/N⌋ (the
    /// last one ending at `spp`), so the N ranges are adjacent, disjoint and
    /// cover 0..spp, and their sizes differ by at most a block.
    pub fn samples(self, spp: u32) -> Result<Range<u32>, PartitionError> {
        let blocks = spp.div_ceil(BLOCK);
        if self.count > blocks {
            return Err(PartitionError::TooMany {
                count: self.count,
                spp,
            });
        }
        let bound = |k: u32| {
            let block = u64::from(k) * u64::from(blocks) / u64::from(self.count);
            (block * u64::from(BLOCK)).min(u64::from(spp)) as u32
        };
        Ok(bound(self.index - 1)..bound(self.index))
    }
}

impl FromStr for Partition {
    type Err = PartitionError;

    fn from_str(text: &str) -> Result<Self, Self::Err> {
        let syntax = || PartitionError::Syntax(text.to_string());
        let (k, n) = text.split_once('/').ok_or_else(syntax)?;
        let number = |s: &str| s.trim().parse::<u32>().map_err(|_| syntax());
        Self::new(number(k)?, number(n)?)
    }
}

impl fmt::Display for Partition {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_k_of_n() {
        let p: Partition = "3/16".parse().expect("valid");
        assert_eq!((p.index(), p.count()), (3, 16));
        assert_eq!(p.to_string(), "3/16");
        assert_eq!(" 1 / 1 ".parse::<Partition>(), Partition::new(1, 1));
        for bad in ["3", "a/b", "3/", "/16", "-1/4", "3/16/2", ""] {
            assert!(
                matches!(bad.parse::<Partition>(), Err(PartitionError::Syntax(_))),
                "{bad}"
            );
        }
        for (k, n) in [(0, 16), (17, 16), (1, 0)] {
            assert_eq!(
                format!("{k}/{n}").parse::<Partition>(),
                Err(PartitionError::OutOfRange { index: k, count: n })
            );
        }
    }

    #[test]
    fn partitions_tile_the_samples_in_whole_blocks() {
        for (spp, n) in [(4096, 16), (10, 3), (7, 2), (1, 1), (37, 9), (u32::MAX, 5)] {
            let mut next = 0;
            let blocks = spp.div_ceil(BLOCK);
            for k in 1..=n {
                let r = Partition::new(k, n)
                    .expect("valid")
                    .samples(spp)
                    .expect("enough samples");
                assert_eq!(r.start, next, "adjacent");
                assert_eq!(r.start % BLOCK, 0, "starts on a block");
                assert!(!r.is_empty());
                let size = r.end.div_ceil(BLOCK) - r.start / BLOCK;
                assert!(size >= blocks / n && size <= blocks / n + 1, "{spp} {n}");
                next = r.end;
            }
            assert_eq!(next, spp, "complete");
        }
        assert_eq!(
            Partition::new(3, 16).expect("valid").samples(4096),
            Ok(512..768)
        );
        assert_eq!(Partition::new(3, 3).expect("valid").samples(10), Ok(8..10));
        assert_eq!(
            Partition::new(1, 3).expect("valid").samples(8),
            Err(PartitionError::TooMany { count: 3, spp: 8 })
        );
        assert!(
            PartitionError::TooMany { count: 3, spp: 8 }
                .to_string()
                .contains("use at most 2 partitions")
        );
    }
}
