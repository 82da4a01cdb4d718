//! Long work (a run, a sweep) off the Python thread: on a thread of its own, on a rayon pool
//! created for it, while the Python thread waits without the GIL and checks for signals.
//!
//! - **Ctrl-C**: every 100 ms the waiting thread takes the GIL and runs Python's signal
//!   handlers; a `KeyboardInterrupt` sets the work's interrupt flag (which a `World` and a
//!   sweep check between steps), waits for the work to stop, and is raised.
//! - **Fork**: rayon's global pool is not copied into a child forked after it started (as
//!   `multiprocessing` and `gymnasium.vector.AsyncVectorEnv` fork on Linux), and a child
//!   that uses it waits forever. A pool built here, in the current process, has its threads.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Condvar, Mutex};
use std::time::Duration;

use pyo3::prelude::*;

use crate::errors::BindingError;

/// How often the waiting thread looks for signals.
const SIGNAL_POLL: Duration = Duration::from_millis(100);

/// A rayon pool of `threads` threads (`None`: one per core), created now, in this process.
pub(crate) fn fresh_pool(threads: Option<usize>) -> PyResult<Arc<rayon::ThreadPool>> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build()
        .map(Arc::new)
        .map_err(|e| BindingError::Run(format!("cannot start worker threads: {e}")).into())
}

/// Runs `work(interrupt)` on a pool of `threads` created for it, without the GIL; a signal
/// handler that raises (Ctrl-C: `KeyboardInterrupt`) sets `interrupt`, and its exception is
/// returned once the work has stopped.
pub(crate) fn run_interruptible<T, F>(
    py: Python<'_>,
    threads: Option<usize>,
    work: F,
) -> PyResult<T>
where
    T: Send,
    F: FnOnce(Arc<AtomicBool>) -> T + Send,
{
    let pool = fresh_pool(threads)?;
    let interrupt = Arc::new(AtomicBool::new(false));
    let flag = interrupt.clone();
    // Set (and notified) by the worker when the work has returned.
    let done = (Mutex::new(false), Condvar::new());
    std::thread::scope(|scope| {
        let worker = scope.spawn(|| {
            let result = pool.install(|| work(flag));
            *done
                .0
                .lock()
                .unwrap_or_else(std::sync::PoisonError::into_inner) = true;
            done.1.notify_all();
            result
        });
        let mut raised = None;
        loop {
            let finished = py.detach(|| {
                let guard = done
                    .0
                    .lock()
                    .unwrap_or_else(std::sync::PoisonError::into_inner);
                let (guard, _) = done
                    .1
                    .wait_timeout_while(guard, SIGNAL_POLL, |finished| !*finished)
                    .unwrap_or_else(std::sync::PoisonError::into_inner);
                *guard
            });
            // A panicking worker never sets the flag: is_finished() ends the wait then.
            if finished || worker.is_finished() {
                break;
            }
            if raised.is_none()
                && let Err(e) = py.check_signals()
            {
                interrupt.store(true, Ordering::Relaxed);
                raised = Some(e);
            }
        }
        let result = py
            .detach(|| worker.join())
            .map_err(|_| PyErr::from(BindingError::Run("the simulation panicked".into())))?;
        match raised {
            Some(e) => Err(e),
            None => Ok(result),
        }
    })
}
