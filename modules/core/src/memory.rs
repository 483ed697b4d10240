//! Memory checked before it is taken. Loaders estimate what a large input
//! (a mesh, a texture, an acceleration structure, a film) will need before
//! they allocate it and compare that with what the process may still take
//! ([`available`]); too much is an [`OutOfMemory`] error that says what
//! needed how much, never an allocation abort halfway through.

use std::fmt;

/// Something that needs more memory than is available.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub struct OutOfMemory {
    /// What needs the memory: "the 16384×16384 texture `x.exr`".
    pub what: String,
    /// Bytes it needs (an estimate where it is taken before loading).
    pub needed: u64,
    /// Bytes available, where the system says.
    pub available: Option<u64>,
}

impl fmt::Display for OutOfMemory {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} needs about {} of memory",
            self.what,
            gib(self.needed)
        )?;
        match self.available {
            Some(available) => write!(f, " and about {} is available", gib(available)),
            None => write!(f, " and it could not be allocated"),
        }
    }
}

/// `Ok` where `needed` bytes for `what` fit in the memory available (or
/// that is unknown), else what needed how much against what there is.
pub fn check(needed: u64, what: impl FnOnce() -> String) -> Result<(), OutOfMemory> {
    match available() {
        Some(available) if needed > available => Err(OutOfMemory {
            what: what(),
            needed,
            available: Some(available),
        }),
        _ => Ok(()),
    }
}

/// `bytes` in GiB, two decimals.
pub fn gib(bytes: u64) -> String {
    format!("{:.2} GiB", bytes as f64 / (1u64 << 30) as f64)
}

/// Memory the process may still take: the smaller of the system's
/// available memory and what its address-space limit leaves (Linux;
/// `None` elsewhere or where `/proc` cannot be read).
pub fn available() -> Option<u64> {
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
    fn impossible_needs_are_refused_with_what_and_how_much() {
        let Err(e) = check(u64::MAX, || "the test's texture".into()) else {
            // Without /proc nothing can be checked.
            assert!(available().is_none());
            return;
        };
        let shown = e.to_string();
        assert!(
            shown.starts_with("the test's texture needs about"),
            "{shown}"
        );
        assert!(shown.contains("is available"), "{shown}");
        assert!(check(1, String::new).is_ok());
    }
}
