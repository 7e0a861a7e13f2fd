//! Loops of steps that Ctrl-C can stop: `World.step(dt, steps=N)` and `World.simulate`.
//!
//! A long loop runs in Rust with the interpreter's lock released, where Python's own
//! signal handling cannot reach it: CPython's SIGINT handler only sets a flag that the
//! interpreter acts on when it next runs Python code, so `step(dt, steps=10**10)` would
//! ignore Ctrl-C for hours. The loop therefore looks at that flag itself
//! (`PyErr_CheckSignals`, taking the lock for the moment it needs) every few milliseconds,
//! between two steps, and stops with the handler's exception (KeyboardInterrupt): the
//! world is then exactly at the last step completed, as if `steps` had been that count.

use std::time::{Duration, Instant};

use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use tumble::{Real, World};

use crate::world::Inner;

/// How often a running loop looks for a signal: often enough that Ctrl-C feels immediate,
/// rarely enough that taking the interpreter's lock costs nothing measurable (a check is
/// about a microsecond; a 5 ms interval makes it 0.02 % of the run).
const SIGNAL_INTERVAL: Duration = Duration::from_millis(5);

/// Why a loop stopped before its last step.
pub enum Stop {
    /// A step was refused or undone (bad dt, an unstable step): the engine's error.
    Engine(tumble::Error),
    /// A signal handler raised (KeyboardInterrupt for Ctrl-C), or another Python error.
    Python(PyErr),
}

impl From<Stop> for PyErr {
    fn from(stop: Stop) -> PyErr {
        match stop {
            Stop::Engine(e) => crate::convert::engine(e),
            Stop::Python(e) => e,
        }
    }
}

/// Steps the world `steps` times, the k-th (from 1) of length `dt(k)`, calling `after(k,
/// world)` after each; stops at the first refusal, raised signal or exception in a force
/// callback (that exception, not the engine's `CallbackFailed`). With `release` the
/// interpreter's lock is released for the run (worth it for long runs only: releasing and
/// retaking it costs about what a step of an empty world does); a world with a Python
/// force callback always releases it, as the callback may run on another thread.
pub fn run(
    py: Python<'_>,
    inner: &mut Inner,
    steps: u64,
    release: bool,
    dt: impl Fn(u64) -> Real + Send,
    after: impl FnMut(u64, &World) + Send,
) -> Result<(), Stop> {
    let release = release || inner.callbacks.is_some();
    match run_world(py, &mut inner.world, steps, release, dt, after) {
        Err(Stop::Engine(tumble::Error::CallbackFailed(failed))) => {
            let kept = inner
                .callbacks
                .as_ref()
                .and_then(|c| c.ctx.borrow_mut(py).take_error());
            // Only a Python callback fails a step here, and it keeps its exception.
            Err(Stop::Python(kept.unwrap_or_else(|| {
                let e = tumble::Error::CallbackFailed(failed);
                PyRuntimeError::new_err(e.to_string())
            })))
        }
        outcome => outcome,
    }
}

fn run_world(
    py: Python<'_>,
    world: &mut World,
    steps: u64,
    release: bool,
    dt: impl Fn(u64) -> Real + Send,
    after: impl FnMut(u64, &World) + Send,
) -> Result<(), Stop> {
    if release {
        py.detach(|| {
            checked_loop(world, steps, dt, after, || {
                Python::attach(|py| py.check_signals())
            })
        })
    } else {
        checked_loop(world, steps, dt, after, || py.check_signals())
    }
}

fn checked_loop(
    world: &mut World,
    steps: u64,
    dt: impl Fn(u64) -> Real,
    mut after: impl FnMut(u64, &World),
    check_signals: impl Fn() -> PyResult<()>,
) -> Result<(), Stop> {
    if steps == 1 {
        // One step returns at once, and the interpreter acts on a pending signal as soon
        // as it runs again: no clock is read, so a single step costs what it did.
        world.step(dt(1)).map_err(Stop::Engine)?;
        after(1, world);
        return Ok(());
    }
    let mut clock = Clock::new();
    for k in 1..=steps {
        world.step(dt(k)).map_err(Stop::Engine)?;
        after(k, world);
        if clock.due(k) {
            check_signals().map_err(Stop::Python)?;
        }
    }
    Ok(())
}

/// When to look for a signal, reading the clock only every `stride` steps: a clock read
/// costs about 30 ns, a sixth of an empty world's step. The stride doubles while a
/// stride of steps takes well under the interval and halves when one takes over twice
/// it, so the wait for Ctrl-C stays near the interval however long a step is, and
/// follows a world whose steps grow slower.
struct Clock {
    last: Instant,
    stride: u64,
    next: u64,
}

impl Clock {
    fn new() -> Clock {
        Clock {
            last: Instant::now(),
            stride: 1,
            next: 1,
        }
    }

    /// Whether to look for a signal after step `k`.
    fn due(&mut self, k: u64) -> bool {
        if k < self.next {
            return false;
        }
        let elapsed = self.last.elapsed();
        if elapsed > 2 * SIGNAL_INTERVAL {
            self.stride = (self.stride / 2).max(1);
        } else if elapsed < SIGNAL_INTERVAL / 8 && self.stride < 1024 {
            self.stride *= 2;
        }
        self.next = k.saturating_add(self.stride);
        if elapsed < SIGNAL_INTERVAL {
            return false;
        }
        self.last = Instant::now();
        true
    }
}
