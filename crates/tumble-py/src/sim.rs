//! Runs: `World.simulate` (the loop in Rust, the interpreter's lock released, Ctrl-C
//! looked for between steps) and its `Trajectory`. A recording that could not fit in the
//! machine's memory is refused before anything is allocated.

use numpy::{PyArray1, PyArrayMethods};
use pyo3::exceptions::PyMemoryError;
use pyo3::intern;
use pyo3::prelude::*;
use tumble::{Quat, Real, Vec3, World};
use tumble_scene::RunPlan;

use crate::convert::{failed_step, invalid, real, scene, wide, wrong_type};
use crate::steps::Stop;
use crate::world::{Inner, PyWorld};

/// A recorded run: step 0, every `every`-th step and the last. `time` (T,) in s;
/// `position` (T, N, 3) of each body frame's origin in m; `orientation` (T, N, 4) as
/// [x, y, z, w]; `velocity` (T, N, 3) in m/s; `angular_velocity` (T, N, 3) in rad/s, all
/// world frame, bodies in creation order (`names`). With `diagnostics=True`, also
/// `kinetic`, `potential`, `total` (T,) in J, `linear_momentum` and `angular_momentum`
/// (T, 3); otherwise those are None.
#[pyclass(module = "tumble", name = "Trajectory", frozen, get_all)]
pub struct Trajectory {
    /// Times of the recorded frames (s), (T,).
    time: Py<PyAny>,
    /// Each body frame's origin (m), (T, N, 3).
    position: Py<PyAny>,
    /// Orientations as quaternions [x, y, z, w], (T, N, 4).
    orientation: Py<PyAny>,
    /// Centre-of-mass velocities (m/s), (T, N, 3).
    velocity: Py<PyAny>,
    /// Angular velocities (rad/s, world frame), (T, N, 3).
    angular_velocity: Py<PyAny>,
    /// Kinetic energy (J), (T,); None unless simulate(diagnostics=True).
    kinetic: Option<Py<PyAny>>,
    /// Potential energy (J), (T,); None unless diagnostics=True.
    potential: Option<Py<PyAny>>,
    /// Total energy (J), (T,); None unless diagnostics=True.
    total: Option<Py<PyAny>>,
    /// Linear momentum (kg·m/s), (T, 3); None unless diagnostics=True.
    linear_momentum: Option<Py<PyAny>>,
    /// Angular momentum about the origin (kg·m²/s), (T, 3); None unless diagnostics=True.
    angular_momentum: Option<Py<PyAny>>,
    /// The bodies' names (None if unnamed), in the arrays' order.
    names: Vec<Option<String>>,
}

#[pymethods]
impl Trajectory {
    fn __len__(&self, py: Python<'_>) -> PyResult<usize> {
        self.time.bind(py).len()
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        Ok(format!(
            "<tumble.Trajectory: {} frames of {} bodies>",
            self.time.bind(py).len()?,
            self.names.len()
        ))
    }
}

impl Trajectory {
    /// A trajectory of these arrays of time, position, orientation, velocity and angular
    /// velocity, without diagnostics.
    pub(crate) fn of_arrays(arrays: [Py<PyAny>; 5], names: Vec<Option<String>>) -> Trajectory {
        let [time, position, orientation, velocity, angular_velocity] = arrays;
        Trajectory {
            time,
            position,
            orientation,
            velocity,
            angular_velocity,
            kinetic: None,
            potential: None,
            total: None,
            linear_momentum: None,
            angular_momentum: None,
            names,
        }
    }

    /// Its bodies' names.
    pub(crate) fn names(&self) -> &[Option<String>] {
        &self.names
    }

    /// Its arrays of time, position, orientation, velocity and angular velocity.
    pub(crate) fn arrays(&self) -> [&Py<PyAny>; 5] {
        [
            &self.time,
            &self.position,
            &self.orientation,
            &self.velocity,
            &self.angular_velocity,
        ]
    }
}

/// What a run records, in flat f64 buffers.
#[derive(Default)]
struct Recording {
    time: Vec<f64>,
    position: Vec<f64>,
    orientation: Vec<f64>,
    velocity: Vec<f64>,
    angular_velocity: Vec<f64>,
    energy: [Vec<f64>; 3],
    linear_momentum: Vec<f64>,
    angular_momentum: Vec<f64>,
}

pub fn push3(out: &mut Vec<f64>, v: Vec3) {
    out.extend_from_slice(&[wide(v.x), wide(v.y), wide(v.z)]);
}

pub fn push4(out: &mut Vec<f64>, q: Quat) {
    out.extend_from_slice(&[wide(q.x), wide(q.y), wide(q.z), wide(q.w)]);
}

impl Recording {
    /// Buffers for the whole run, reserved up front so that recording allocates nothing; a
    /// reservation the allocator refuses is an error here, where `Vec::with_capacity`
    /// would abort the interpreter.
    fn with_capacity(
        frames: usize,
        bodies: usize,
        diagnostics: bool,
    ) -> Result<Self, std::collections::TryReserveError> {
        let per = frames.saturating_mul(bodies);
        let d = if diagnostics { frames } else { 0 };
        let mut rec = Recording::default();
        rec.time.try_reserve_exact(frames)?;
        rec.position.try_reserve_exact(per.saturating_mul(3))?;
        rec.orientation.try_reserve_exact(per.saturating_mul(4))?;
        rec.velocity.try_reserve_exact(per.saturating_mul(3))?;
        rec.angular_velocity
            .try_reserve_exact(per.saturating_mul(3))?;
        for e in &mut rec.energy {
            e.try_reserve_exact(d)?;
        }
        rec.linear_momentum.try_reserve_exact(d.saturating_mul(3))?;
        rec.angular_momentum
            .try_reserve_exact(d.saturating_mul(3))?;
        Ok(rec)
    }

    fn frame(&mut self, world: &World, time: Real, diagnostics: bool) {
        self.time.push(wide(time));
        for (_, b) in world.bodies() {
            push3(&mut self.position, b.position());
            push4(&mut self.orientation, b.orientation());
            push3(&mut self.velocity, b.linear_velocity());
            push3(&mut self.angular_velocity, b.angular_velocity());
        }
        if diagnostics {
            let d = world.diagnostics();
            self.energy[0].push(wide(d.kinetic));
            self.energy[1].push(wide(d.potential));
            self.energy[2].push(wide(d.total));
            push3(&mut self.linear_momentum, d.linear_momentum);
            push3(&mut self.angular_momentum, d.angular_momentum);
        }
    }
}

/// The frames a run of `steps` records with `every`: step 0, every `every`-th step, the
/// last.
pub(crate) fn frame_count(steps: u64, every: u64) -> u64 {
    steps / every + 1 + u64::from(steps % every != 0)
}

/// Bytes a recording of `frames` frames of `bodies` bodies takes: per frame its time, 13
/// numbers per body (position 3, orientation 4, velocity 3, angular velocity 3) and with
/// diagnostics 9 more (three energies, two momenta), 8 bytes each. In u128, so that no
/// request, however absurd, overflows on its way to being refused.
fn recording_bytes(frames: u64, bodies: usize, diagnostics: bool) -> u128 {
    let per_frame = 1 + 13 * bodies as u128 + if diagnostics { 9 } else { 0 };
    frames as u128 * per_frame * 8
}

/// The machine's physical memory (bytes), or None where Python's `os.sysconf` cannot say
/// (Windows); there a recording too large is left to the allocator (MemoryError).
fn physical_memory(py: Python<'_>) -> Option<u128> {
    let os = py.import(intern!(py, "os")).ok()?;
    let sysconf = |name: &str| -> Option<u128> {
        let v: i64 = os.call_method1("sysconf", (name,)).ok()?.extract().ok()?;
        u128::try_from(v).ok()
    };
    Some(sysconf("SC_PHYS_PAGES")? * sysconf("SC_PAGE_SIZE")?)
}

/// A size in bytes as people say it: `52.8 GB`.
fn size(bytes: u128) -> String {
    let b = bytes as f64;
    if b >= 1e12 {
        format!("{:.1} TB", b / 1e12)
    } else if b >= 1e9 {
        format!("{:.1} GB", b / 1e9)
    } else {
        format!("{:.1} MB", b / 1e6)
    }
}

/// Refuses, before anything is allocated, a recording larger than the machine's memory.
/// Reserving it would abort the interpreter (Rust aborts when an allocation fails) or,
/// under overcommit, succeed and end in the out-of-memory killer far into the run.
/// `field` is the argument that asked for the run (`steps` or `duration`).
pub(crate) fn check_fits(
    py: Python<'_>,
    field: &str,
    frames: u64,
    bodies: usize,
    diagnostics: bool,
) -> PyResult<()> {
    let bytes = recording_bytes(frames, bodies, diagnostics);
    match physical_memory(py) {
        Some(memory) if bytes > memory => Err(invalid(
            field,
            format!(
                "recording {frames} frames of {bodies} bodies would take {}, more than this \
                 machine's {} of memory; record every k-th step with every=k, or simulate \
                 in shorter runs",
                size(bytes),
                size(memory)
            ),
        )),
        _ => Ok(()),
    }
}

/// Steps `world` through `plan` into `rec`, recording step 0, every `every`-th step and the
/// last, with the interpreter's lock released and Ctrl-C looked for between steps. When
/// it stops early, `rec` holds every frame up to the last good step.
fn run(
    py: Python<'_>,
    inner: &mut Inner,
    plan: RunPlan,
    every: u64,
    diagnostics: bool,
    rec: &mut Recording,
) -> Result<(), Stop> {
    let start = inner.world.time();
    rec.frame(&inner.world, start, diagnostics);
    let dt = |k| plan.step_dt(k);
    let record = |k: u64, world: &World| {
        if k % every == 0 || k == plan.steps {
            // k·dt from the start rather than the world's running sum, as the CLI reports.
            rec.frame(world, start + plan.time_after(k), diagnostics);
        }
    };
    crate::steps::run(py, inner, plan.steps, true, dt, record)
}

/// `run` with a controller: `controller(world, t)` is called before every step with the
/// Python world (unlocked, so that it can read joints and set motors) and the time the
/// step starts from (s). Its exception stops the run before that step, and is raised.
/// It may change the world but not which bodies it has: the recording's bodies are fixed.
fn run_controlled(
    world: &Bound<'_, PyWorld>,
    controller: &Bound<'_, PyAny>,
    plan: RunPlan,
    (every, diagnostics): (u64, bool),
    rec: &mut Recording,
) -> Result<(), Stop> {
    let py = world.py();
    let lock = || world.get().lock().map_err(Stop::Python);
    let (start, ids) = {
        let g = lock()?;
        rec.frame(&g.world, g.world.time(), diagnostics);
        (g.world.time(), g.world.body_ids().to_vec())
    };
    for k in 1..=plan.steps {
        let t = wide(lock()?.world.time());
        controller.call1((world, t)).map_err(Stop::Python)?;
        let mut g = lock()?;
        if g.world.body_ids() != ids.as_slice() {
            let reason = "added or removed a body; simulate records a fixed set of bodies";
            return Err(Stop::Python(invalid("controller", reason)));
        }
        // One step at a time: releasing the interpreter's lock pays only for large worlds
        // (and always with a Python force callback: see `steps::run`).
        let release = g.world.body_count() >= 64;
        let dt = plan.step_dt(k);
        let record = |_, w: &World| {
            if k % every == 0 || k == plan.steps {
                rec.frame(w, start + plan.time_after(k), diagnostics);
            }
        };
        crate::steps::run(py, &mut g, 1, release, |_| dt, record)?;
        drop(g);
        // The interpreter runs Python's signal handlers only between its own bytecodes:
        // a controller that returns at once would leave Ctrl-C to the end of the run.
        py.check_signals().map_err(Stop::Python)?;
    }
    Ok(())
}

pub fn array(py: Python<'_>, data: Vec<f64>, shape: &[usize]) -> PyResult<Py<PyAny>> {
    Ok(PyArray1::from_vec(py, data)
        .reshape(shape)?
        .into_any()
        .unbind())
}

/// A recording as the Trajectory Python sees, its bodies called `names`.
fn trajectory(
    py: Python<'_>,
    rec: Recording,
    names: Vec<Option<String>>,
    diagnostics: bool,
) -> PyResult<Trajectory> {
    let (t, n) = (rec.time.len(), names.len());
    let diag = |data: Vec<f64>, shape: &[usize]| -> PyResult<Option<Py<PyAny>>> {
        diagnostics.then(|| array(py, data, shape)).transpose()
    };
    let [kinetic, potential, total] = rec.energy;
    Ok(Trajectory {
        time: array(py, rec.time, &[t])?,
        position: array(py, rec.position, &[t, n, 3])?,
        orientation: array(py, rec.orientation, &[t, n, 4])?,
        velocity: array(py, rec.velocity, &[t, n, 3])?,
        angular_velocity: array(py, rec.angular_velocity, &[t, n, 3])?,
        kinetic: diag(kinetic, &[t])?,
        potential: diag(potential, &[t])?,
        total: diag(total, &[t])?,
        linear_momentum: diag(rec.linear_momentum, &[t, 3])?,
        angular_momentum: diag(rec.angular_momentum, &[t, 3])?,
        names,
    })
}

/// The run `simulate` was asked for, and the argument that asked (for its refusals).
fn plan_of(
    g: &crate::world::Inner,
    duration: Option<f64>,
    dt: Option<f64>,
    steps: Option<i64>,
) -> PyResult<(RunPlan, &'static str)> {
    let dt = dt.map_or(g.dt, real);
    match (steps, duration) {
        (Some(_), Some(_)) => Err(invalid("steps", "cannot be given together with duration")),
        (Some(s), None) => {
            let s = u64::try_from(s).map_err(|_| invalid("steps", "must be >= 0"))?;
            Ok((RunPlan::from_steps(s, dt).map_err(scene)?, "steps"))
        }
        (None, d) => {
            let plan = RunPlan::from_duration(d.map_or(g.duration, real), dt).map_err(scene)?;
            Ok((plan, "duration"))
        }
    }
}

#[pymethods]
impl PyWorld {
    /// Runs the world for `duration` seconds (default: the scene's) in steps of `dt`
    /// (default: the scene's, else 0.01), or for exactly `steps` steps, and returns the
    /// recorded Trajectory. The loop runs in Rust with the interpreter's lock released.
    /// As with the CLI, a duration that is not a whole number of steps ends with one
    /// shorter step; `every` records every k-th step (step 0 and the last always).
    /// A recording larger than the machine's memory is refused (ValueError) before the
    /// run; Ctrl-C stops the run between two steps (KeyboardInterrupt); a step that is
    /// not finite or too fast raises SimulationError, whose `trajectory` is the run up to
    /// the last good step. The world is left at the last step completed.
    ///
    /// `controller=fn` calls `fn(world, t)` before every step, with this World (it can
    /// read joint coordinates and set motors, servos, forces, states) and the time the
    /// step starts from (s); the loop then takes the interpreter's lock at every step.
    /// An exception in fn, or in a force callback, stops the run before or during that
    /// step, with the world as it was before the step, and is raised as it was.
    #[pyo3(signature = (duration = None, dt = None, *, steps = None, every = 1,
        diagnostics = false, controller = None))]
    #[allow(clippy::too_many_arguments)]
    fn simulate(
        slf: &Bound<'_, Self>,
        duration: Option<f64>,
        dt: Option<f64>,
        steps: Option<i64>,
        every: i64,
        diagnostics: bool,
        controller: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Trajectory> {
        let py = slf.py();
        let every = u64::try_from(every)
            .ok()
            .filter(|&e| e >= 1)
            .ok_or_else(|| invalid("every", "must be >= 1"))?;
        if let Some(c) = controller.filter(|c| !c.is_callable()) {
            return Err(wrong_type("controller", "a callable fn(world, t)", c));
        }
        let mut g = slf.get().lock()?;
        let (plan, field) = plan_of(&g, duration, dt, steps)?;
        let frames = frame_count(plan.steps, every);
        check_fits(py, field, frames, g.world.body_count(), diagnostics)?;
        let mut rec = Recording::with_capacity(frames as usize, g.world.body_count(), diagnostics)
            .map_err(|e| PyMemoryError::new_err(format!("{field}: the recording: {e}")))?;
        let outcome = match controller {
            None => run(py, &mut g, plan, every, diagnostics, &mut rec),
            Some(c) => {
                drop(g);
                let outcome = run_controlled(slf, c, plan, (every, diagnostics), &mut rec);
                g = slf.get().lock()?;
                outcome
            }
        };
        let names = g
            .world
            .bodies()
            .map(|(_, b)| b.name().map(str::to_string))
            .collect();
        drop(g);
        match outcome {
            Ok(()) => trajectory(py, rec, names, diagnostics),
            Err(Stop::Engine(e)) if e.is_step_failure() => {
                let partial = Py::new(py, trajectory(py, rec, names, diagnostics)?)?;
                Err(failed_step(py, &e, Some(partial.into_any())))
            }
            Err(stop) => Err(stop.into()),
        }
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Trajectory>()
}
