//! Long calls run without the GIL, on a thread of their own, while the
//! calling thread checks for Ctrl-C every 50 ms until they end: a
//! KeyboardInterrupt asks every integration to stop (`mechlab::ode::stop`),
//! so that every analysis ends at its integrators' next step (a chaos map
//! also skips the blocks of rows not yet started). The KeyboardInterrupt
//! is raised in Python once the work has returned.

use std::sync::mpsc::{self, RecvTimeoutError};
use std::time::Duration;

use pyo3::prelude::*;

/// `work` run off the GIL; Ctrl-C stops its integrations.
/// The calling thread wakes when the work ends (a channel), or every 50 ms
/// to check for signals: a call of a millisecond takes a millisecond.
pub fn detached<T: Send>(py: Python<'_>, work: impl FnOnce() -> T + Send) -> PyResult<T> {
    let mut interrupt = None;
    mechlab::ode::stop::clear_stop();
    let result = py.detach(|| {
        std::thread::scope(|scope| {
            let (done, finished) = mpsc::channel::<()>();
            let handle = scope.spawn(move || {
                let value = work();
                // (A panic drops `done` instead: the wait ends too.)
                let _ = done.send(());
                value
            });
            while let Err(RecvTimeoutError::Timeout) =
                finished.recv_timeout(Duration::from_millis(50))
            {
                if interrupt.is_none() {
                    if let Err(e) = Python::attach(|py| py.check_signals()) {
                        mechlab::ode::stop::request_stop();
                        interrupt = Some(e);
                    }
                }
            }
            handle.join()
        })
    });
    match (result, interrupt) {
        (_, Some(e)) => Err(e),
        (Ok(value), None) => Ok(value),
        (Err(panic), None) => std::panic::resume_unwind(panic),
    }
}

/// A progress bar on stderr (what a notebook shows under its cell) of
/// `total` steps named `what`.
pub fn progress(total: u64, what: &str) -> indicatif::ProgressBar {
    let bar = indicatif::ProgressBar::new(total);
    if let Ok(style) = indicatif::ProgressStyle::with_template(
        "{msg} {bar:30} {pos}/{len} ({elapsed}, {eta} left)",
    ) {
        bar.set_style(style);
    }
    bar.set_message(what.to_string());
    bar
}
