//! Stopping a run from another thread, and progress reports.
//!
//! Python delivers Ctrl-C to its main thread only, while solvers run in worker threads (one per
//! cable) with the GIL released. The main thread sets a [`StopFlag`]; the solver loops read it
//! after every step (one atomic load) through a [`Poller`], which also calls the progress
//! callback and checks Python's signals (for runs on the main thread) every `every` steps or
//! every [`POLL_INTERVAL`] of wall time, whichever comes first.
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use pyo3::exceptions::PyKeyboardInterrupt;
use pyo3::prelude::*;

/// Why a run stopped when its stop flag was set or Ctrl-C arrived.
pub const INTERRUPTED: &str = "interrupted";

/// Longest wall time between two calls of the progress callback and signal checks.
pub const POLL_INTERVAL: Duration = Duration::from_millis(50);

/// A flag shared between the thread that wants a run stopped and the solver threads.
#[pyclass(module = "cablelife._core", frozen)]
#[derive(Default)]
pub struct StopFlag(Arc<AtomicBool>);

#[pymethods]
impl StopFlag {
    #[new]
    fn new() -> Self {
        Self::default()
    }

    /// Asks every run polling this flag to stop after its current step.
    fn set(&self) {
        self.0.store(true, Ordering::Relaxed);
    }

    /// Withdraws the request.
    fn clear(&self) {
        self.0.store(false, Ordering::Relaxed);
    }

    /// Whether a stop was requested.
    #[getter]
    fn is_set(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }

    fn __repr__(&self) -> String {
        format!("StopFlag(is_set={})", self.is_set())
    }
}

impl StopFlag {
    /// The shared flag itself (for kernels that read it directly).
    pub(crate) fn flag(&self) -> Arc<AtomicBool> {
        self.0.clone()
    }
}

/// Polled by a solver loop after each step.
pub struct Poller {
    stop: Option<Arc<AtomicBool>>,
    progress: Option<Py<PyAny>>,
    every: usize,
    total: usize,
    last: Instant,
}

impl Poller {
    pub fn new(
        stop: Option<&Bound<'_, StopFlag>>,
        progress: Option<Py<PyAny>>,
        every: usize,
        total: usize,
    ) -> Self {
        Poller {
            stop: stop.map(|s| s.get().0.clone()),
            progress,
            every: every.max(1),
            total,
            last: Instant::now(),
        }
    }

    /// After `done` of `total` steps: why to stop, if so. The stop flag is read every call;
    /// Python (signals, progress callback) is called every `every` steps, every
    /// [`POLL_INTERVAL`], and at the last step.
    pub fn poll(&mut self, done: usize) -> Option<String> {
        if self
            .stop
            .as_ref()
            .is_some_and(|s| s.load(Ordering::Relaxed))
        {
            return Some(INTERRUPTED.to_string());
        }
        if !done.is_multiple_of(self.every)
            && done < self.total
            && self.last.elapsed() < POLL_INTERVAL
        {
            return None;
        }
        self.last = Instant::now();
        let total = self.total;
        let progress = &self.progress;
        Python::attach(|py| {
            if let Err(e) = py.check_signals() {
                return Some(stopped_by(py, e));
            }
            if let Some(cb) = progress {
                if let Err(e) = cb.call1(py, (done, total)) {
                    if e.is_instance_of::<PyKeyboardInterrupt>(py) {
                        return Some(stopped_by(py, e));
                    }
                    return Some(format!("progress callback failed: {e}"));
                }
            }
            None
        })
    }
}

/// Why the run stops after Python raised `e` in the solver thread (its signal check or the
/// progress callback: Ctrl-C arrives there when the run is a direct call on the main thread,
/// as in `cablelife modes`). The run stops with what it computed; a KeyboardInterrupt is raised
/// again, so that the caller still gets it when the call returns.
fn stopped_by(py: Python<'_>, e: PyErr) -> String {
    if e.is_instance_of::<PyKeyboardInterrupt>(py) {
        // SAFETY: the GIL is held; the call only sets Python's pending-signal flag.
        unsafe { pyo3::ffi::PyErr_SetInterrupt() };
    }
    INTERRUPTED.to_string()
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<StopFlag>()?;
    m.add("INTERRUPTED", INTERRUPTED)?;
    Ok(())
}
