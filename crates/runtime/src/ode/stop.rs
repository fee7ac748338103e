//! A request to stop every integration in the process, as Ctrl-C in a
//! notebook makes it: each stepping loop (every method, the batch lanes,
//! double-double Taylor) looks at it before each step and ends with
//! [`OdeError::Stopped`](super::OdeError::Stopped). An analysis then ends
//! early however it treats a failed orbit, since every orbit after fails at
//! its first step. Nothing in the library sets it; the Python module does.

use std::sync::atomic::{AtomicBool, Ordering};

static STOP: AtomicBool = AtomicBool::new(false);

/// Asks every integration running or started from now on to stop.
pub fn request_stop() {
    STOP.store(true, Ordering::Relaxed);
}

/// Withdraws the request (before a new call).
pub fn clear_stop() {
    STOP.store(false, Ordering::Relaxed);
}

/// Whether a stop has been requested.
#[inline]
pub fn stop_requested() -> bool {
    STOP.load(Ordering::Relaxed)
}
