//! Python callables used by the core (section functions, rest strains and curvatures, tendon
//! offsets, chamber areas, distributed loads), and the one way the binding runs a computation.
//!
//! The core calls a callable as a plain function of `s`; the binding's closure re-acquires the
//! GIL, calls it and converts the result. An exception it raises (or a result that does not
//! convert) cannot cross the core: it is kept in the *error slot of the computation running on
//! this thread*, the callable returns NaN, and [`run`] raises the kept exception once the core
//! returns, as a `ParameterError` naming the callable's parameter with the original exception
//! as `__cause__`. The slot belongs to one computation (one call of [`run`]), not to the
//! callable: one callable shared by many threads reports each error to the computation that
//! caused it. Parallel computations (workspace maps) run on a thread pool of their own whose
//! threads report to the computation's slot.
//!
//! [`run`] also catches a Rust panic (a defect of softrod) and raises `InternalError` instead
//! of letting it cross into Python.

use std::cell::RefCell;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::{Arc, Mutex};

use pyo3::prelude::*;

use crate::errors::{describe, internal_err, param_err, to_py_err};

/// Where the first exception of a computation's callables waits until the core returns.
#[derive(Clone, Default)]
pub(crate) struct ErrorSlot(Arc<Mutex<Option<PyErr>>>);

impl ErrorSlot {
    fn keep(&self, err: PyErr) {
        if let Ok(mut slot) = self.0.lock() {
            if slot.is_none() {
                *slot = Some(err);
            }
        }
    }
    fn take(&self) -> Option<PyErr> {
        self.0.lock().ok().and_then(|mut s| s.take())
    }
}

thread_local! {
    /// The slot of the computation running on this thread, if any.
    static CURRENT: RefCell<Option<ErrorSlot>> = const { RefCell::new(None) };
}

/// Runs `f` with `slot` as this thread's current slot (restoring the previous one after).
fn with_slot<R>(slot: &ErrorSlot, f: impl FnOnce() -> R) -> R {
    let previous = CURRENT.with(|c| c.replace(Some(slot.clone())));
    struct Restore(Option<ErrorSlot>);
    impl Drop for Restore {
        fn drop(&mut self) {
            let prev = self.0.take();
            CURRENT.with(|c| *c.borrow_mut() = prev);
        }
    }
    let _restore = Restore(previous);
    f()
}

/// A Python callable of the arc length `s`, named by the parameter it was given as.
pub(crate) struct Callback {
    f: Py<PyAny>,
    what: &'static str,
    label: &'static str,
}

impl Callback {
    /// The callable `f` given as the parameter `what` (e.g. `rest_curvature`), described in
    /// messages as `label` (e.g. "the rest curvature").
    pub(crate) fn new(f: Py<PyAny>, what: &'static str, label: &'static str) -> Self {
        Self { f, what, label }
    }

    /// Calls it at `s` and converts the result with `convert`; on failure reports to the
    /// current computation and returns `fallback`.
    pub(crate) fn call<T>(
        &self,
        s: f64,
        fallback: T,
        expected: &str,
        convert: impl FnOnce(&Bound<'_, PyAny>) -> Option<T>,
    ) -> T {
        Python::attach(|py| {
            let err = match self.f.bind(py).call1((s,)) {
                Ok(r) => match convert(&r) {
                    Some(v) => return v,
                    None => param_err(
                        self.what,
                        format!("<function> returning {} at s = {s} m", describe(&r)),
                        &format!("a function of s returning {expected} ({})", self.label),
                    ),
                },
                Err(original) => {
                    let text = crate::errors::one_line(&format!(
                        "invalid parameter `{}`: {} raised {} at s = {s} m",
                        self.what,
                        self.label,
                        original
                            .value(py)
                            .repr()
                            .map(|r| r.to_string())
                            .unwrap_or_else(|_| original.to_string())
                    ));
                    let e = crate::errors::ParameterError::new_err(text);
                    let _ = e.value(py).setattr("parameter", self.what);
                    e.set_cause(py, Some(original));
                    e
                }
            };
            let kept =
                CURRENT.with(|c| c.borrow().as_ref().map(|slot| slot.keep(err.clone_ref(py))));
            if kept.is_none() {
                // Called outside any computation (cannot happen through `run`): say so where
                // Python can see it rather than drop it.
                err.write_unraisable(py, None);
            }
            fallback
        })
    }

    /// `n` floats.
    pub(crate) fn floats<const N: usize>(&self, s: f64) -> [f64; N] {
        let expected = format!("{N} finite numbers");
        self.call(s, [f64::NAN; N], &expected, |r| {
            let v: Vec<f64> = r.extract().ok()?;
            <[f64; N]>::try_from(v.as_slice()).ok()
        })
    }

    /// One float.
    pub(crate) fn float(&self, s: f64) -> f64 {
        self.call(s, f64::NAN, "a finite number", |r| r.extract::<f64>().ok())
    }
}

/// Whether the user asked the computation running on this thread to stop: Python's signal
/// handlers run (with the GIL); an exception one raises (`KeyboardInterrupt` for Ctrl-C) is
/// kept in the computation's slot, raised when the core returns. For the core's
/// [`softrod::Interrupt`] checks, made between units of work (the starts of an inverse).
pub(crate) fn interrupted() -> bool {
    Python::attach(|py| match py.check_signals() {
        Ok(()) => false,
        Err(err) => {
            CURRENT.with(|c| {
                if let Some(slot) = c.borrow().as_ref() {
                    slot.keep(err);
                }
            });
            true
        }
    })
}

/// Runs a core computation with the GIL released: callable errors are raised (see the module
/// documentation), a panic becomes `InternalError`, a core error its Python exception.
pub(crate) fn run<T: Send>(
    py: Python<'_>,
    what: &str,
    f: impl FnOnce() -> softrod::Result<T> + Send,
) -> PyResult<T> {
    let slot = ErrorSlot::default();
    let out = py.detach(|| with_slot(&slot, || catch_unwind(AssertUnwindSafe(f))));
    finish(&slot, what, out)
}

/// As [`run`] with the GIL held (for cheap calls that are not worth releasing it).
pub(crate) fn run_attached<T>(what: &str, f: impl FnOnce() -> softrod::Result<T>) -> PyResult<T> {
    let slot = ErrorSlot::default();
    let out = with_slot(&slot, || catch_unwind(AssertUnwindSafe(f)));
    finish(&slot, what, out)
}

/// As [`run`] for a computation that runs in parallel (rayon): it runs on a pool whose threads
/// report to this computation's slot. `parallel` false (no Python callables involved) uses the
/// global pool.
pub(crate) fn run_parallel<T: Send>(
    py: Python<'_>,
    what: &str,
    parallel: bool,
    f: impl FnOnce() -> softrod::Result<T> + Send,
) -> PyResult<T> {
    if !parallel {
        return run(py, what, f);
    }
    let slot = ErrorSlot::default();
    let worker_slot = slot.clone();
    let pool = rayon::ThreadPoolBuilder::new()
        .start_handler(move |_| {
            CURRENT.with(|c| *c.borrow_mut() = Some(worker_slot.clone()));
        })
        .build()
        .map_err(|e| internal_err(&format!("{what}: thread pool: {e}")))?;
    let out = py.detach(|| with_slot(&slot, || catch_unwind(AssertUnwindSafe(|| pool.install(f)))));
    finish(&slot, what, out)
}

fn finish<T>(
    slot: &ErrorSlot,
    what: &str,
    out: std::thread::Result<softrod::Result<T>>,
) -> PyResult<T> {
    // A callable that failed is the cause of whatever the core made of its NaN.
    if let Some(err) = slot.take() {
        return Err(err);
    }
    match out {
        Ok(r) => r.map_err(to_py_err),
        Err(panic) => {
            let msg = panic
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| panic.downcast_ref::<String>().cloned())
                .unwrap_or_default();
            Err(internal_err(&format!("{what}: {msg}")))
        }
    }
}
