//! Long work with the GIL released, stoppable: it runs on a thread of its
//! own while the calling thread waits, waking every few tens of
//! milliseconds to let Python handle signals (Ctrl+C in a terminal,
//! "interrupt kernel" in a notebook) and to ask the caller's cancel hook.
//! Either sets a flag the work polls (the renderer's `PassWatch`, asked
//! before each tile), and the caller gets the exception once the work has
//! stopped, so nothing keeps running behind Python's back.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Condvar, Mutex, PoisonError};
use std::time::Duration;

use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;

use crate::errors::Cancelled;

/// How often the waiting thread looks at signals and the cancel hook: a
/// cancelled render stops within this plus one tile per thread. A render
/// that finishes wakes the waiter at once, so this adds nothing to it.
const POLL: Duration = Duration::from_millis(50);

/// Runs `work` on its own thread with the GIL released. `stop` is raised
/// when Python reports a signal's exception (KeyboardInterrupt) or
/// `cancel.is_set()` answers true; `work` must then return soon. Returns
/// what `work` returned, or that exception (for the hook,
/// `glint.Cancelled`).
pub fn run_stoppable<T: Send>(
    py: Python<'_>,
    cancel: Option<&Bound<'_, PyAny>>,
    stop: &AtomicBool,
    work: impl FnOnce() -> T + Send,
) -> PyResult<T> {
    let finished = (Mutex::new(false), Condvar::new());
    std::thread::scope(|scope| {
        let worker = scope.spawn(|| {
            let out = work();
            *finished.0.lock().unwrap_or_else(PoisonError::into_inner) = true;
            finished.1.notify_all();
            out
        });
        loop {
            let done = py.detach(|| {
                let guard = finished.0.lock().unwrap_or_else(PoisonError::into_inner);
                let (guard, _) = finished
                    .1
                    .wait_timeout_while(guard, POLL, |done| !*done)
                    .unwrap_or_else(PoisonError::into_inner);
                // A worker that panicked never says it finished.
                *guard || worker.is_finished()
            });
            if done {
                break;
            }
            // A hook that raises stops the work too, with its exception.
            let stopped = py.check_signals().err().or_else(|| {
                let hook = cancel?;
                match hook.call_method0("is_set").and_then(|r| r.is_truthy()) {
                    Ok(true) => Some(Cancelled::new_err("cancelled by its cancel hook")),
                    Ok(false) => None,
                    Err(e) => Some(e),
                }
            });
            if let Some(error) = stopped {
                stop.store(true, Ordering::Relaxed);
                // Wait for the work to stop; what it returns is dropped.
                let _ = py.detach(|| worker.join());
                return Err(error);
            }
        }
        py.detach(|| worker.join())
            .map_err(|_| PyRuntimeError::new_err("glint's worker thread panicked"))
    })
}
