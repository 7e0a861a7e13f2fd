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

use pyo3::prelude::*;
use tumble::{Real, World};

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

/// Steps `world` `steps` times, the k-th (from 1) of length `dt(k)`, calling `after(k,
/// world)` after each; stops at the first refusal or raised signal. With `release` the
/// interpreter's lock is released for the run (worth it for long runs only: releasing and
/// retaking it costs about what a step of an empty world does).
pub fn run(
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
    let mut checked = Instant::now();
    for k in 1..=steps {
        world.step(dt(k)).map_err(Stop::Engine)?;
        after(k, world);
        if checked.elapsed() >= SIGNAL_INTERVAL {
            check_signals().map_err(Stop::Python)?;
            checked = Instant::now();
        }
    }
    Ok(())
}
