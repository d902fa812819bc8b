//! Memory a row needs, against what the machine has: a row too large is
//! refused with the estimate before anything is allocated.

use super::InputError;

/// Which engine runs the row (their memory per block differs by 50×).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EngineKind {
    /// The reference engine (`crate::reference`).
    Reference,
    /// A Rapier world (topple's impacts or Rapier's own; either precision).
    Rapier,
}

/// Bytes per block of a row, an upper estimate: about twice the growth of the
/// peak resident size of `topple chain` (Domino X, s/h 0.3) between rows of
/// 10⁴ and 10⁵ blocks: the reference
/// engine keeps the state, frozen flags and hit times of each block (about
/// 40 B measured); a Rapier world keeps a rigid body, a collider, broad-phase
/// and contact-graph entries per block (about 3 KiB measured).
fn bytes_per_block(engine: EngineKind) -> u64 {
    match engine {
        EngineKind::Reference => 256,
        EngineKind::Rapier => 8 * 1024,
    }
}

/// Fixed cost of a run besides its blocks (the binary, Rapier's pipeline).
const BASE_BYTES: u64 = 64 << 20;

/// Estimated peak memory (bytes) of a row of `n` blocks.
///
/// ```
/// use topple::validate::{memory_estimate, EngineKind};
/// assert!(memory_estimate(1_000_000_000, EngineKind::Reference) > 200 << 30);
/// assert!(memory_estimate(40, EngineKind::Rapier) < 100 << 20);
/// ```
pub fn memory_estimate(n: usize, engine: EngineKind) -> u64 {
    BASE_BYTES.saturating_add((n as u64).saturating_mul(bytes_per_block(engine)))
}

/// Memory this process may still use (bytes): `MemAvailable` of
/// `/proc/meminfo` on Linux; `None` where that is unknown.
pub fn available_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb.saturating_mul(1024))
}

fn gib(bytes: u64) -> String {
    format!("{:.2} GiB", bytes as f64 / (1u64 << 30) as f64)
}

/// Refuses a row whose estimated memory exceeds `available` bytes (the
/// machine's available memory if `None` is given and it is known).
///
/// ```
/// use topple::validate::{check_memory, EngineKind};
/// let e = check_memory("--n", 1_000_000_000, EngineKind::Reference, Some(8 << 30)).unwrap_err();
/// assert!(e.to_string().contains("needs about"));
/// assert!(check_memory("--n", 40, EngineKind::Reference, Some(8 << 30)).is_ok());
/// ```
pub fn check_memory(
    field: &str,
    n: usize,
    engine: EngineKind,
    available: Option<u64>,
) -> Result<(), InputError> {
    let Some(available) = available.or_else(available_memory) else {
        return Ok(());
    };
    let need = memory_estimate(n, engine);
    if need <= available {
        return Ok(());
    }
    let most = (available.saturating_sub(BASE_BYTES) / bytes_per_block(engine)) as usize;
    Err(InputError::new(
        field,
        n,
        format!(
            "{field} ≤ {most} on this machine (the row needs about {} and {} is available)",
            gib(need),
            gib(available)
        ),
    ))
}
