//! The memory a request may take for its results, checked before any work:
//! a mistyped knob (`periods=2000000000`) gets an error naming what was
//! asked for, not an allocation that aborts the process.

/// The most a run keeps in memory for its results (points of orbits,
/// pixels of maps). A laptop has 8 to 32 GiB; results beyond this one
/// should be written in parts (tiles) or asked for in fewer points.
pub const RESULT_BYTES: u128 = 4 << 30;

/// A request whose results would not fit in [`RESULT_BYTES`].
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error(
    "{what}: {count} × {bytes_each} bytes would keep {:.1} GiB of results in memory, over the {} GiB a run may take; ask for fewer",
    (*count as f64) * (*bytes_each as f64) / (1u64 << 30) as f64,
    RESULT_BYTES >> 30
)]
pub struct TooLarge {
    /// What was counted, e.g. "points of 24 orbits of 2000000001 periods".
    pub what: String,
    /// How many (saturated at u64::MAX).
    pub count: u64,
    pub bytes_each: usize,
}

/// Whether `count` results of `bytes_each` bytes fit; `what` names them
/// in the error.
pub fn check(
    what: impl FnOnce() -> String,
    count: u128,
    bytes_each: usize,
) -> Result<(), TooLarge> {
    match count.checked_mul(bytes_each as u128) {
        Some(bytes) if bytes <= RESULT_BYTES => Ok(()),
        _ => Err(TooLarge {
            what: what(),
            count: u64::try_from(count).unwrap_or(u64::MAX),
            bytes_each,
        }),
    }
}

/// A square map of `pixels` × `pixels` values of f64.
pub fn check_map(pixels: usize) -> Result<(), TooLarge> {
    check(
        || format!("a map of {pixels} × {pixels} pixels"),
        pixels as u128 * pixels as u128,
        std::mem::size_of::<f64>(),
    )
}
