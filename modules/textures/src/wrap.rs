//! Wrap modes: what a lookup outside the image's texels reads.

use serde::Deserialize;

/// How texel indices outside the image are mapped back into it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum WrapMode {
    /// Tile the image (period 1 in u and v).
    #[default]
    Repeat,
    /// Extend the border texels.
    Clamp,
    /// Tile with every other copy mirrored (period 2).
    Mirror,
}

impl WrapMode {
    /// Maps texel index `i` into 0..`n` (`n` ≥ 1).
    #[inline]
    pub fn apply(self, i: i64, n: i64) -> usize {
        (match self {
            WrapMode::Repeat => modulo(i, n),
            WrapMode::Clamp => i.clamp(0, n - 1),
            WrapMode::Mirror => {
                let k = modulo(i, 2 * n);
                if k >= n { 2 * n - 1 - k } else { k }
            }
        }) as usize
    }
}

/// `i.rem_euclid(n)` (`n` ≥ 1) without a division where `i` lies within
/// one period of 0..`n`, as nearly every lookup's does (a bilinear
/// lookup's neighbours step at most one texel outside); a 64-bit division
/// takes tens of cycles, and a bilinear lookup wraps eight indices.
#[inline(always)]
fn modulo(i: i64, n: i64) -> i64 {
    if (0..n).contains(&i) {
        i
    } else if (-n..0).contains(&i) {
        i + n
    } else if (n..2 * n).contains(&i) {
        i - n
    } else {
        i.rem_euclid(n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_modulo_without_division_is_rem_euclid() {
        for n in [1, 2, 3, 7, 1024] {
            for i in (-3 * n - 2..3 * n + 2).chain([i64::MIN / 4, i64::MAX / 4]) {
                assert_eq!(modulo(i, n), i.rem_euclid(n), "{i} mod {n}");
            }
        }
    }

    #[test]
    fn indices_map_into_the_image() {
        let n = 4;
        let idx = |m: WrapMode| (-5..9).map(|i| m.apply(i, n)).collect::<Vec<_>>();
        assert_eq!(
            idx(WrapMode::Repeat),
            [3, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3, 0]
        );
        assert_eq!(
            idx(WrapMode::Clamp),
            [0, 0, 0, 0, 0, 0, 1, 2, 3, 3, 3, 3, 3, 3]
        );
        assert_eq!(
            idx(WrapMode::Mirror),
            [3, 3, 2, 1, 0, 0, 1, 2, 3, 3, 2, 1, 0, 0]
        );
        assert_eq!(WrapMode::Repeat.apply(i64::MIN, 3), 1);
        assert_eq!(WrapMode::Mirror.apply(i64::MAX, 3), 1);
    }
}
