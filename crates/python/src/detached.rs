//! Long calls run without the GIL, on a thread of their own, while the
//! calling thread checks for Ctrl-C every 50 ms until they end: a
//! KeyboardInterrupt raises the `stop` flag, which the analyses that take
//! a callback read between blocks of orbits, and asks every integration
//! to stop (`mechlab::ode::stop`), so that every analysis ends at its
//! integrators' next step. The KeyboardInterrupt is raised in Python once
//! the work has returned.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, RecvTimeoutError};
use std::time::Duration;

use pyo3::prelude::*;

/// Set once Python has asked the work to stop.
pub struct Stop(AtomicBool);

impl Stop {
    pub fn requested(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }
}

/// `work` run off the GIL; Ctrl-C stops it where it looks at its [`Stop`].
/// The calling thread wakes when the work ends (a channel), or every 50 ms
/// to check for signals: a call of a millisecond takes a millisecond.
pub fn detached<T: Send>(py: Python<'_>, work: impl FnOnce(&Stop) -> T + Send) -> PyResult<T> {
    let stop = Stop(AtomicBool::new(false));
    let mut interrupt = None;
    mechlab::ode::stop::clear_stop();
    let result = py.detach(|| {
        std::thread::scope(|scope| {
            let (done, finished) = mpsc::channel::<()>();
            let stop = &stop;
            let handle = scope.spawn(move || {
                let value = work(stop);
                // (A panic drops `done` instead: the wait ends too.)
                let _ = done.send(());
                value
            });
            while let Err(RecvTimeoutError::Timeout) =
                finished.recv_timeout(Duration::from_millis(50))
            {
                if interrupt.is_none() {
                    if let Err(e) = Python::attach(|py| py.check_signals()) {
                        stop.0.store(true, Ordering::Relaxed);
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
