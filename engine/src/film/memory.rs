//! What a frame's film costs in memory, checked before it is taken: the
//! film's weighted sums and the developed image are reserved with
//! `try_reserve`, so a frame too large for the machine (or for a `ulimit`)
//! is a [`FrameTooLarge`] error that says what it needed and what would
//! fit, never an allocation abort.

use radiant_core::Rgb;
use std::fmt;

/// Bytes per pixel of the film's weighted sums (RGB and weight, f32).
pub const SUM_BYTES: u64 = 16;
/// Bytes per pixel of the developed image (RGB, f32).
pub const IMAGE_BYTES: u64 = std::mem::size_of::<Rgb>() as u64;

/// A frame whose film could not be allocated.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub struct FrameTooLarge {
    /// Frame width in pixels.
    pub width: u32,
    /// Frame height in pixels.
    pub height: u32,
    /// Memory available to the process when the allocation failed, where
    /// the system says (Linux: the smaller of `MemAvailable` and the
    /// address-space limit left).
    pub available: Option<u64>,
}

impl FrameTooLarge {
    /// The error for a `width`×`height` frame, with the memory available
    /// now.
    pub fn new(width: u32, height: u32) -> Self {
        Self {
            width,
            height,
            available: available_memory(),
        }
    }

    /// Bytes the frame needs: its sums and its developed image.
    pub fn needed(&self) -> u64 {
        self.width as u64 * self.height as u64 * (SUM_BYTES + IMAGE_BYTES)
    }
}

impl fmt::Display for FrameTooLarge {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let pixels = self.width as u64 * self.height as u64;
        write!(
            f,
            "a {}×{} frame needs {} of memory ({} for the film's weighted sums, {} for the \
             finished image) and it could not be allocated",
            self.width,
            self.height,
            gib(self.needed()),
            gib(pixels * SUM_BYTES),
            gib(pixels * IMAGE_BYTES)
        )?;
        if let Some(available) = self.available {
            let rows = available / (self.width as u64 * (SUM_BYTES + IMAGE_BYTES)).max(1);
            write!(
                f,
                "; about {} is available, enough for {} rows at this width",
                gib(available),
                rows
            )?;
        }
        write!(
            f,
            ": render a smaller frame or on a machine with more memory"
        )
    }
}

/// `bytes` in GiB, two decimals.
fn gib(bytes: u64) -> String {
    format!("{:.2} GiB", bytes as f64 / (1u64 << 30) as f64)
}

/// A vector of `len` copies of `value`, or `None` where the memory cannot
/// be reserved.
pub fn try_filled<T: Clone>(len: usize, value: T) -> Option<Vec<T>> {
    let mut v = Vec::new();
    v.try_reserve_exact(len).ok()?;
    v.resize(len, value);
    Some(v)
}

/// Memory the process may still take: the smaller of the system's
/// available memory and what its address-space limit leaves (Linux;
/// `None` elsewhere or where `/proc` cannot be read).
pub fn available_memory() -> Option<u64> {
    let field = |text: &str, key: &str| -> Option<u64> {
        let line = text.lines().find(|l| l.starts_with(key))?;
        line[key.len()..].split_whitespace().next()?.parse().ok()
    };
    let meminfo = std::fs::read_to_string("/proc/meminfo").ok()?;
    let mut available = field(&meminfo, "MemAvailable:")? * 1024;
    let limits = std::fs::read_to_string("/proc/self/limits").ok();
    let status = std::fs::read_to_string("/proc/self/status").ok();
    if let (Some(limits), Some(status)) = (limits, status)
        && let Some(limit) = field(&limits, "Max address space")
        && let Some(used) = field(&status, "VmSize:")
    {
        available = available.min(limit.saturating_sub(used * 1024));
    }
    Some(available)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_message_gives_the_need_and_what_fits() {
        let e = FrameTooLarge {
            width: 32768,
            height: 32768,
            available: Some(4 << 30),
        };
        assert_eq!(e.needed(), 32768 * 32768 * 28);
        let shown = e.to_string();
        assert!(
            shown.starts_with("a 32768×32768 frame needs 28.00 GiB"),
            "{shown}"
        );
        assert!(
            shown.contains("16.00 GiB for the film's weighted sums"),
            "{shown}"
        );
        assert!(
            shown.contains("enough for 4681 rows at this width"),
            "{shown}"
        );
    }

    #[test]
    fn impossible_reservations_are_none() {
        assert!(try_filled(usize::MAX / 2, 0u64).is_none());
        assert_eq!(try_filled(3, 7u8), Some(vec![7, 7, 7]));
    }
}
