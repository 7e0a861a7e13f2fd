//! `tumble.Batch`: W copies of a world stepped together on the engine's thread pool
//! (`tumble::Batch`), with every world's state as numpy arrays (W, N, 3) and (W, N, 4),
//! per-world forces, joint targets and resets, and `simulate` recording (T, W, N, ·)
//! (stored world by world; see `Frames`), into new arrays or an earlier run's (`out`).
//!
//! The binding converts and shapes; the engine checks values (naming the world and the
//! row: `worlds[2].velocities[1]: ...`) and is all or nothing. Loops run with the
//! interpreter's lock released, in chunks of steps between which Ctrl-C is looked for.

use std::sync::{Mutex, MutexGuard, TryLockError};
use std::time::{Duration, Instant};

use numpy::{
    AllowTypeChange, PyArrayDyn, PyArrayLike1, PyArrayLike3, PyArrayMethods, PyReadwriteArrayDyn,
    PyUntypedArrayMethods,
};
use pyo3::exceptions::{PyKeyError, PyRuntimeError};
use pyo3::intern;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyBytes, PyDict, PySlice, PyString};
use tumble::{Batch, BodyKind, BodyStates, JointTarget, Quat, Real, StepFailure, Vec3, World};
use tumble_scene::RunPlan;

use crate::convert::wrong_type;
use crate::convert::{engine, failed_step, invalid, not_real, real, scene, unreal_dtype, wide};
use crate::sim::{array, push3, push4, Trajectory};
use crate::world::{Inner, PyWorld};

/// The batch and what its Python side keeps beside it.
struct BatchInner {
    batch: Batch,
    /// Default step of `step` and `simulate` (s): the scene's `dt`, else 0.01.
    dt: Real,
    /// Default length of `simulate` (s).
    duration: Real,
    names: Vec<Option<String>>,
    /// Per body, whether it is dynamic (what `randomize` perturbs).
    dynamic: Vec<bool>,
    /// The initial state's positions, velocities and angular velocities (`randomize`).
    start: [Vec<Vec3>; 3],
}

/// W independent copies of a world, stepped together across threads.
///
/// Batch(scene, copies, threads=None): `scene` is a tumble.World (copied as it is now), a
/// scene as a dict, a scene or model file's path, or a built-in scene's name
/// (tumble.SCENES); `copies` the number of worlds W (an int >= 1); `threads` how many
/// threads step them (default TUMBLE_THREADS, else every core). Each world steps on one
/// thread, so its run is bit-identical to the same world stepped alone, whatever
/// `threads` is. A World with force callbacks or a contact filter or modifier (code) is
/// refused.
#[pyclass(module = "tumble", name = "Batch", frozen)]
pub struct PyBatch {
    inner: Mutex<BatchInner>,
}

impl PyBatch {
    fn lock(&self) -> PyResult<MutexGuard<'_, BatchInner>> {
        match self.inner.try_lock() {
            Ok(g) => Ok(g),
            Err(TryLockError::Poisoned(p)) => Ok(p.into_inner()),
            Err(TryLockError::WouldBlock) => Err(PyRuntimeError::new_err(
                "the batch is busy: another thread is stepping it",
            )),
        }
    }
}

/// The batch of `copies` copies of a Python scene argument, with the scene's `dt` and
/// `duration`. A World is copied as it is, under its lock (so the engine sees its
/// callbacks and contact hooks, and refuses them); the caller keeps it.
fn batch_of(
    obj: &Bound<'_, PyAny>,
    copies: usize,
    threads: Option<usize>,
) -> PyResult<(Batch, Real, Real)> {
    let py = obj.py();
    let loaded = if let Ok(w) = obj.cast::<PyWorld>() {
        let g: MutexGuard<'_, Inner> = w.get().lock()?;
        let batch = Batch::new(&g.world, copies, threads).map_err(engine)?;
        return Ok((batch, g.dt, g.duration));
    } else if obj.is_instance_of::<PyDict>() {
        let json = py.import(intern!(py, "json"))?;
        let text: String = json.call_method1("dumps", (obj,))?.extract()?;
        tumble_scene::load_str(&text)
    } else if obj.is_instance_of::<PyString>() || obj.hasattr("__fspath__")? {
        let os = py.import(intern!(py, "os"))?;
        let path: String = os.call_method1("fspath", (obj,))?.extract()?;
        tumble_scene::load(&path)
    } else {
        return Err(wrong_type(
            "scene",
            "a tumble.World, a scene dict, a file path or a built-in scene's name",
            obj,
        ));
    };
    let s = loaded.map_err(scene)?;
    let batch = Batch::new(&s.world, copies, threads).map_err(engine)?;
    Ok((batch, s.dt, s.duration))
}

/// A world's index from Python, refused past the batch's last.
fn index(obj: &Bound<'_, PyAny>, worlds: usize) -> PyResult<usize> {
    let i = whole(obj, "world")?;
    usize::try_from(i)
        .ok()
        .filter(|&i| i < worlds)
        .ok_or_else(|| {
            invalid(
                "world",
                format!("index {i} out of range for a batch of {worlds} worlds"),
            )
        })
}

/// An int argument (not a bool, not a float), as Python's `operator.index` takes it.
fn whole(obj: &Bound<'_, PyAny>, field: &str) -> PyResult<i64> {
    if obj.is_instance_of::<PyBool>() || obj.hasattr("__index__").ok() != Some(true) {
        return Err(wrong_type(field, "an int", obj));
    }
    obj.extract::<i64>()
        .map_err(|_| invalid(field, "must fit in 64 bits"))
}

fn thread_count(obj: Option<&Bound<'_, PyAny>>) -> PyResult<Option<usize>> {
    let Some(obj) = obj.filter(|o| !o.is_none()) else {
        return Ok(None);
    };
    let n = whole(obj, "threads")?;
    let most = tumble::threads::MAX_THREADS;
    usize::try_from(n)
        .map(Some)
        .map_err(|_| invalid("threads", format!("must be between 1 and {most}, got {n}")))
}

/// A numpy array of real numbers as float64 from anything array-like (complex, strings
/// and objects refused with a TypeError naming `field`).
fn real_array<'py>(
    value: &Bound<'py, PyAny>,
    field: &str,
    expected: &str,
) -> PyResult<Bound<'py, PyAny>> {
    if value.is_instance_of::<PyString>() {
        return Err(wrong_type(field, expected, value));
    }
    let py = value.py();
    let arr = py
        .import(intern!(py, "numpy"))?
        .call_method1(intern!(py, "asarray"), (value,))
        .map_err(|_| wrong_type(field, expected, value))?;
    if let Some(got) = unreal_dtype(&arr) {
        return Err(not_real(
            field,
            &format!("{expected} of real numbers"),
            &got,
        ));
    }
    Ok(arr)
}

/// A (worlds, bodies, width) array as rows per world, float64.
fn per_world(
    value: &Bound<'_, PyAny>,
    field: &str,
    shape: [usize; 3],
) -> PyResult<Vec<Vec<[f64; 4]>>> {
    let [w, n, width] = shape;
    let expected = format!("an array of shape ({w}, {n}, {width})");
    let arr = real_array(value, field, &expected)?;
    let got: Vec<usize> = arr.getattr(intern!(arr.py(), "shape"))?.extract()?;
    if got != shape {
        return Err(invalid(
            field,
            format!("expected {expected} (worlds, bodies, {width}), got {got:?}"),
        ));
    }
    let arr: PyArrayLike3<'_, f64, AllowTypeChange> = arr
        .extract()
        .map_err(|_| wrong_type(field, &expected, value))?;
    let view = arr.as_array();
    Ok(view
        .outer_iter()
        .map(|world| {
            world
                .outer_iter()
                .map(|r| {
                    let mut row = [0.0; 4];
                    row[..width].copy_from_slice(&r.to_vec());
                    row
                })
                .collect()
        })
        .collect())
}

fn vectors(rows: Vec<Vec<[f64; 4]>>) -> Vec<Vec<Vec3>> {
    let v = |r: &[f64; 4]| Vec3::new(real(r[0]), real(r[1]), real(r[2]));
    rows.iter().map(|w| w.iter().map(v).collect()).collect()
}

fn quaternions(rows: Vec<Vec<[f64; 4]>>) -> Vec<Vec<Quat>> {
    let q = |r: &[f64; 4]| Quat::from_xyzw(real(r[0]), real(r[1]), real(r[2]), real(r[3]));
    rows.iter().map(|w| w.iter().map(q).collect()).collect()
}

/// Per-world arrays given to a setter, `reset` or `randomize`, converted.
#[derive(Default)]
struct Given {
    positions: Option<Vec<Vec<Vec3>>>,
    orientations: Option<Vec<Vec<Quat>>>,
    velocities: Option<Vec<Vec<Vec3>>>,
    angular_velocities: Option<Vec<Vec<Vec3>>>,
}

impl Given {
    /// The arrays given for `k` worlds of `n` bodies, converted (shapes checked).
    fn of(k: usize, n: usize, arrays: [Option<&Bound<'_, PyAny>>; 4]) -> PyResult<Given> {
        let [p, o, v, w] = arrays;
        let three = |a: Option<&Bound<'_, PyAny>>, field| {
            a.filter(|a| !a.is_none())
                .map(|a| per_world(a, field, [k, n, 3]).map(vectors))
                .transpose()
        };
        Ok(Given {
            positions: three(p, "positions")?,
            orientations: o
                .filter(|a| !a.is_none())
                .map(|a| per_world(a, "orientations", [k, n, 4]).map(quaternions))
                .transpose()?,
            velocities: three(v, "velocities")?,
            angular_velocities: three(w, "angular_velocities")?,
        })
    }

    fn is_empty(&self) -> bool {
        self.positions.is_none()
            && self.orientations.is_none()
            && self.velocities.is_none()
            && self.angular_velocities.is_none()
    }

    /// One BodyStates per world.
    fn states(&self, k: usize) -> Vec<BodyStates<'_>> {
        (0..k)
            .map(|i| BodyStates {
                positions: self.positions.as_ref().map(|a| &a[i][..]),
                orientations: self.orientations.as_ref().map(|a| &a[i][..]),
                velocities: self.velocities.as_ref().map(|a| &a[i][..]),
                angular_velocities: self.angular_velocities.as_ref().map(|a| &a[i][..]),
            })
            .collect()
    }
}

/// The world indices a `worlds=` argument names (None: every world), as ints.
fn world_list(obj: Option<&Bound<'_, PyAny>>) -> PyResult<Option<Vec<usize>>> {
    let Some(obj) = obj.filter(|o| !o.is_none()) else {
        return Ok(None);
    };
    let mut out = Vec::new();
    for (k, item) in obj
        .try_iter()
        .map_err(|_| wrong_type("worlds", "a sequence of world indices", obj))?
        .enumerate()
    {
        let item = item?;
        let field = format!("worlds[{k}]");
        let i = whole(&item, &field)?;
        out.push(usize::try_from(i).map_err(|_| invalid(&field, "must be >= 0"))?);
    }
    Ok(Some(out))
}

/// A failed step as Python sees it: SimulationError with the world's step's attributes,
/// its message prefixed with the world (`worlds[3]: step 41 ...`) and `world` set.
fn failure(py: Python<'_>, f: &StepFailure, trajectory: Option<Py<PyAny>>) -> PyErr {
    if !f.error.is_step_failure() {
        return engine(f.error.clone());
    }
    let err = failed_step(py, &f.error, trajectory);
    let v = err.value(py);
    let set = v
        .setattr("args", (f.to_string(),))
        .and_then(|()| v.setattr("world", f.world));
    match set {
        Ok(()) => err,
        Err(e) => e,
    }
}

/// Why a batch's loop stopped early.
enum Stop {
    Failed(StepFailure),
    Python(PyErr),
}

/// How often a running loop looks for Ctrl-C (see `steps.rs`).
const SIGNAL_INTERVAL: Duration = Duration::from_millis(5);

/// Worlds a thread is handed per block (see `run`).
const WORLDS_PER_THREAD: usize = 8;

/// Steps the batch through steps 1..=`steps` of `plan` with the interpreter released,
/// recording into `frames` (when given) step 0's state, every `every`-th step's and the
/// last's.
///
/// Each world takes its steps of a chunk in a row, a block of worlds at a time (a few per
/// thread), so that a tiny world's data stays in the cache: stepping all 1,024 cart-poles
/// once before stepping any again ran them at half the speed of one alone. The chunk of
/// steps doubles while a block takes well under the signal interval, so that Ctrl-C is
/// looked for every few ms; at the end of a chunk every world (but a failed one) stands
/// at the same step, and a failure stops the run there, keeping the frames before that
/// chunk.
fn run(
    py: Python<'_>,
    batch: &mut Batch,
    plan: &RunPlan,
    mut frames: Option<&mut Frames<'_>>,
) -> Result<(), Stop> {
    py.detach(|| {
        let w = batch.len();
        let block = w.min(WORLDS_PER_THREAD * batch.threads());
        let (mut k, mut chunk) = (0u64, 1u64);
        let mut last_check = Instant::now();
        let dt = |j: u64| {
            if j == plan.steps {
                plan.last_dt
            } else {
                plan.dt
            }
        };
        while k < plan.steps {
            let n = chunk.min(plan.steps - k);
            let (mut slowest, mut failed) = (Duration::ZERO, None);
            for first in (0..w).step_by(block) {
                let b = block.min(w - first);
                let began = Instant::now();
                let steps = k + 1..k + n + 1;
                let outcome = match frames.as_deref_mut() {
                    Some(f) => {
                        let mut each = f.slots(first, b, f.frames_of(k, n));
                        batch.step_worlds(first, &mut each, steps, dt, |s, j, world| {
                            s.record(j, world)
                        })
                    }
                    None => batch.step_worlds(first, &mut vec![(); b], steps, dt, |_, _, _| ()),
                };
                slowest = slowest.max(began.elapsed());
                if let Err(e) = outcome {
                    failed.get_or_insert(e);
                }
                if last_check.elapsed() >= SIGNAL_INTERVAL {
                    last_check = Instant::now();
                    Python::attach(|py| py.check_signals()).map_err(Stop::Python)?;
                }
            }
            if let Some(e) = failed {
                if let Some(f) = frames.as_deref_mut() {
                    f.keep_until(k);
                }
                return Err(Stop::Failed(e));
            }
            k += n;
            if slowest < SIGNAL_INTERVAL / 4 && chunk < 1 << 20 {
                chunk *= 2;
            } else if slowest > SIGNAL_INTERVAL * 2 {
                chunk = (chunk / 2).max(1);
            }
        }
        Ok(())
    })
}

/// Every world's bodies' `f`, as one (W, N, width) array.
fn read_all(
    py: Python<'_>,
    g: &BatchInner,
    width: usize,
    f: impl Fn(&tumble::Body, &mut Vec<f64>),
) -> PyResult<Py<PyAny>> {
    let (w, n) = (g.batch.len(), g.batch.body_ids().len());
    let mut out = Vec::with_capacity(w * n * width);
    for (i, world) in g.batch.worlds().iter().enumerate() {
        if world.body_ids() != g.batch.body_ids() {
            return Err(invalid(
                &format!("worlds[{i}]"),
                "its bodies were added or removed since the batch was made; reset it",
            ));
        }
        for (_, b) in world.bodies() {
            f(b, &mut out);
        }
    }
    array(py, out, &[w, n, width])
}

impl PyBatch {
    /// Sets the arrays given in every world at once (all or nothing).
    fn set(&self, arrays: [Option<&Bound<'_, PyAny>>; 4]) -> PyResult<()> {
        let (w, n) = {
            let g = self.lock()?;
            (g.batch.len(), g.batch.body_ids().len())
        };
        let given = Given::of(w, n, arrays)?;
        let mut g = self.lock()?;
        g.batch.set_states(None, &given.states(w)).map_err(engine)
    }
}

#[pymethods]
impl PyBatch {
    #[new]
    #[pyo3(signature = (scene, copies, threads = None))]
    fn py_new(
        scene: &Bound<'_, PyAny>,
        copies: &Bound<'_, PyAny>,
        threads: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let copies = whole(copies, "copies")?;
        if copies < 1 {
            return Err(invalid("copies", format!("must be >= 1, got {copies}")));
        }
        let threads = thread_count(threads)?;
        let copies = usize::try_from(copies).map_err(|_| invalid("copies", "too many"))?;
        let (batch, dt, duration) = batch_of(scene, copies, threads)?;
        // Every copy starts as world 0 does.
        let world = batch.world(0).map_err(engine)?;
        let bodies = || world.bodies().map(|(_, b)| b);
        let start = [
            bodies().map(|b| b.position()).collect(),
            bodies().map(|b| b.linear_velocity()).collect(),
            bodies().map(|b| b.angular_velocity()).collect(),
        ];
        let names = bodies().map(|b| b.name().map(str::to_string)).collect();
        let dynamic = bodies().map(|b| b.kind() == BodyKind::Dynamic).collect();
        Ok(PyBatch {
            inner: Mutex::new(BatchInner {
                batch,
                dt,
                duration,
                names,
                dynamic,
                start,
            }),
        })
    }

    /// The number of worlds W.
    fn __len__(&self) -> PyResult<usize> {
        Ok(self.lock()?.batch.len())
    }

    /// The number of worlds W.
    #[getter]
    fn copies(&self) -> PyResult<usize> {
        Ok(self.lock()?.batch.len())
    }

    /// How many threads step the worlds (1 to 256); assignable. Results are bit-identical
    /// for every count.
    #[getter]
    fn threads(&self) -> PyResult<usize> {
        Ok(self.lock()?.batch.threads())
    }

    #[setter]
    fn set_threads(&self, value: &Bound<'_, PyAny>) -> PyResult<()> {
        let n = thread_count(Some(value))?
            .ok_or_else(|| invalid("threads", "must be between 1 and 256"))?;
        self.lock()?.batch.set_threads(n).map_err(engine)
    }

    /// Every body's name (None if unnamed), in the order of the arrays' second axis.
    #[getter]
    fn body_names(&self) -> PyResult<Vec<Option<String>>> {
        Ok(self.lock()?.names.clone())
    }

    /// The index along the arrays' body axis of the body called `name` (KeyError if none).
    fn body_index(&self, name: &str) -> PyResult<usize> {
        self.lock()?
            .names
            .iter()
            .position(|n| n.as_deref() == Some(name))
            .ok_or_else(|| PyKeyError::new_err(format!("no body named '{name}'")))
    }

    /// The default step of `step` and `simulate` (s): the scene's `dt`, else 0.01.
    #[getter]
    fn dt(&self) -> PyResult<f64> {
        Ok(wide(self.lock()?.dt))
    }

    /// Each world's simulated time (s), float64 array (W,).
    #[getter]
    fn time(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        let g = self.lock()?;
        let t: Vec<f64> = g.batch.worlds().iter().map(|w| wide(w.time())).collect();
        let w = t.len();
        array(py, t, &[w])
    }

    /// Each world's steps taken, a list of W ints.
    #[getter]
    fn step_counts(&self) -> PyResult<Vec<u64>> {
        Ok(self
            .lock()?
            .batch
            .worlds()
            .iter()
            .map(World::step_count)
            .collect())
    }

    /// Every world's body frame origins (m), float64 array (W, N, 3); assignable with
    /// any (W, N, 3) array of real numbers (checked whole, every world, before any
    /// changes; wakes the bodies).
    #[getter]
    fn positions(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        read_all(py, &*self.lock()?, 3, |b, o| push3(o, b.position()))
    }

    #[setter]
    fn set_positions(&self, value: &Bound<'_, PyAny>) -> PyResult<()> {
        self.set([Some(value), None, None, None])
    }

    /// Every body's orientation [x, y, z, w], float64 array (W, N, 4); assignable.
    #[getter]
    fn orientations(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        read_all(py, &*self.lock()?, 4, |b, o| push4(o, b.orientation()))
    }

    #[setter]
    fn set_orientations(&self, value: &Bound<'_, PyAny>) -> PyResult<()> {
        self.set([None, Some(value), None, None])
    }

    /// Every body's centre-of-mass velocity (m/s), float64 array (W, N, 3); assignable.
    #[getter]
    fn velocities(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        read_all(py, &*self.lock()?, 3, |b, o| push3(o, b.linear_velocity()))
    }

    #[setter]
    fn set_velocities(&self, value: &Bound<'_, PyAny>) -> PyResult<()> {
        self.set([None, None, Some(value), None])
    }

    /// Every body's angular velocity (rad/s, world frame), float64 array (W, N, 3);
    /// assignable.
    #[getter]
    fn angular_velocities(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        read_all(py, &*self.lock()?, 3, |b, o| push3(o, b.angular_velocity()))
    }

    #[setter]
    fn set_angular_velocities(&self, value: &Bound<'_, PyAny>) -> PyResult<()> {
        self.set([None, None, None, Some(value)])
    }

    /// Steps every world `steps` times by `dt` (default: the scene's, else 0.01), with
    /// the interpreter's lock released; Ctrl-C stops it within a few ms (the worlds may
    /// then stand at different steps: `step_counts`). A world whose step fails (not
    /// finite, too fast) stays at its last good step while the others finish the chunk
    /// of steps under way and stop together; SimulationError then names it (`worlds[3]:
    /// step 41 ...`, and the attribute `world`).
    #[pyo3(signature = (dt = None, steps = None))]
    fn step(
        &self,
        py: Python<'_>,
        dt: Option<f64>,
        steps: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let steps = steps.map_or(Ok(1), |s| whole(s, "steps"))?;
        let steps = u64::try_from(steps).map_err(|_| invalid("steps", "must be >= 0"))?;
        let mut g = self.lock()?;
        let dt = dt.map_or(g.dt, real);
        let plan = RunPlan::from_steps(steps, dt).map_err(scene)?;
        match run(py, &mut g.batch, &plan, None) {
            Ok(()) => Ok(()),
            Err(Stop::Failed(f)) => Err(failure(py, &f, None)),
            Err(Stop::Python(e)) => Err(e),
        }
    }

    /// Sets constant forces (N, world frame, at each centre of mass) and torques (N·m),
    /// arrays (W, N, 3), acting at every step from now on until the next `apply_forces`
    /// or `clear_forces`: they persist, as `World.add_force`'s constant forces do (they
    /// are such force elements, one per body pushed). All or nothing; wakes the bodies.
    /// Resetting a world drops its forces.
    #[pyo3(signature = (forces, torques = None))]
    fn apply_forces(
        &self,
        forces: &Bound<'_, PyAny>,
        torques: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let (w, n) = {
            let g = self.lock()?;
            (g.batch.len(), g.batch.body_ids().len())
        };
        let flat = |rows: Vec<Vec<Vec3>>| rows.into_iter().flatten().collect::<Vec<_>>();
        let f = flat(vectors(per_world(forces, "forces", [w, n, 3])?));
        let t = torques
            .filter(|t| !t.is_none())
            .map(|t| per_world(t, "torques", [w, n, 3]).map(|r| flat(vectors(r))))
            .transpose()?;
        self.lock()?
            .batch
            .set_forces(&f, t.as_deref())
            .map_err(engine)
    }

    /// Removes the forces of `apply_forces` from every world (waking their bodies).
    fn clear_forces(&self) -> PyResult<()> {
        self.lock()?.batch.clear_forces();
        Ok(())
    }
}

impl PyBatch {
    /// What `set_joint_targets` drives on joint `name` when `kind` is not given.
    fn target_kind(g: &BatchInner, name: &str, kind: Option<&str>) -> PyResult<JointTarget> {
        let world = g.batch.world(0).map_err(engine)?;
        let id = world
            .find_joint(name)
            .ok_or_else(|| invalid("name", format!("no joint named '{name}'")))?;
        let options = world.joint(id).map_err(engine)?.kind().options();
        use tumble::joint::JointOption;
        let motor = options.get(JointOption::Motor).is_some();
        let servo = options.get(JointOption::Servo).is_some();
        match (kind, motor, servo) {
            (Some("velocity"), ..) => Ok(JointTarget::Velocity),
            (Some("position"), ..) => Ok(JointTarget::Position),
            (Some(other), ..) => Err(invalid(
                "kind",
                format!("expected 'velocity' (a motor's speed) or 'position' (a servo's target), got '{other}'"),
            )),
            (None, true, false) => Ok(JointTarget::Velocity),
            (None, false, true) => Ok(JointTarget::Position),
            (None, true, true) => Err(invalid(
                "kind",
                format!("joint '{name}' has a motor and a servo: give kind='velocity' or 'position'"),
            )),
            (None, false, false) => Err(invalid(
                "name",
                format!("joint '{name}' has neither a motor nor a servo to set the target of"),
            )),
        }
    }
}

#[pymethods]
impl PyBatch {
    /// Sets the target of the joint called `name` in every world from `values`, shape
    /// (W,): its motor's speed (rad/s or m/s) or its servo's target (rad or m), the
    /// motor's or servo's other settings kept, as setting `Joint.motor`/`Joint.servo`
    /// would (both bodies woken). `kind` is "velocity" or "position"; by default what the
    /// joint has. An unknown name is a ValueError naming the joint; all or nothing.
    #[pyo3(signature = (name, values, *, kind = None))]
    fn set_joint_targets(
        &self,
        name: &str,
        values: &Bound<'_, PyAny>,
        kind: Option<&str>,
    ) -> PyResult<()> {
        let w = self.lock()?.batch.len();
        let expected = format!("an array of shape ({w},) (one value per world)");
        let arr = real_array(values, "values", &expected)?;
        let got: Vec<usize> = arr.getattr(intern!(arr.py(), "shape"))?.extract()?;
        if got != [w] {
            return Err(invalid(
                "values",
                format!("expected {expected}, got {got:?}"),
            ));
        }
        let arr: PyArrayLike1<'_, f64, AllowTypeChange> = arr
            .extract()
            .map_err(|_| wrong_type("values", &expected, values))?;
        let view = arr.as_array();
        let v: Vec<Real> = view.iter().map(|&x| real(x)).collect();
        let mut g = self.lock()?;
        let target = PyBatch::target_kind(&g, name, kind)?;
        g.batch.set_joint_targets(name, target, &v).map_err(engine)
    }

    /// Returns worlds to the state the batch was made from (or with `snapshot`, bytes
    /// from `World.snapshot` or `Batch.snapshot`, to that state; it must hold the same
    /// bodies): every world, or those listed in `worlds`. Then sets any of `positions`,
    /// `orientations`, `velocities`, `angular_velocities` given, arrays (K, N, 3) or
    /// (K, N, 4) for the K worlds reset. All or nothing; drops the worlds' applied forces.
    #[pyo3(signature = (worlds = None, snapshot = None, *, positions = None,
        orientations = None, velocities = None, angular_velocities = None))]
    #[allow(clippy::too_many_arguments)]
    fn reset(
        &self,
        worlds: Option<&Bound<'_, PyAny>>,
        snapshot: Option<&Bound<'_, PyAny>>,
        positions: Option<&Bound<'_, PyAny>>,
        orientations: Option<&Bound<'_, PyAny>>,
        velocities: Option<&Bound<'_, PyAny>>,
        angular_velocities: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let list = world_list(worlds)?;
        let snapshot: Option<Vec<u8>> = snapshot
            .filter(|s| !s.is_none())
            .map(|s| {
                s.cast::<PyBytes>()
                    .map(|b| b.as_bytes().to_vec())
                    .map_err(|_| wrong_type("snapshot", "bytes (from snapshot())", s))
            })
            .transpose()?;
        let (w, n) = {
            let g = self.lock()?;
            (g.batch.len(), g.batch.body_ids().len())
        };
        let k = list.as_ref().map_or(w, Vec::len);
        let arrays = [positions, orientations, velocities, angular_velocities];
        let given = Given::of(k, n, arrays)?;
        let states = (!given.is_empty()).then(|| given.states(k));
        self.lock()?
            .batch
            .reset_with_states(list.as_deref(), snapshot.as_deref(), states.as_deref())
            .map_err(engine)
    }

    /// Resets worlds (every world, or those in `worlds`) to the initial state with each
    /// dynamic body's position, velocity and angular velocity moved by independent
    /// uniform noise in [-s, s] per component, s = `positions` (m), `velocities` (m/s),
    /// `angular_velocities` (rad/s). The noise is drawn from `rng` (a
    /// numpy.random.Generator) as rng.uniform(-s, s, size=(K, N, 3)) in that order, one
    /// draw per non-zero scale: the same seed gives the same worlds. Joints pull bodies
    /// moved apart back together in the first steps.
    #[pyo3(signature = (rng, *, worlds = None, positions = 0.0, velocities = 0.0,
        angular_velocities = 0.0))]
    fn randomize(
        &self,
        rng: &Bound<'_, PyAny>,
        worlds: Option<&Bound<'_, PyAny>>,
        positions: f64,
        velocities: f64,
        angular_velocities: f64,
    ) -> PyResult<()> {
        if !rng.hasattr("uniform")? {
            return Err(wrong_type("rng", "a numpy.random.Generator", rng));
        }
        let list = world_list(worlds)?;
        let (k, n, dynamic, start) = {
            let g = self.lock()?;
            let k = list.as_ref().map_or(g.batch.len(), Vec::len);
            (
                k,
                g.batch.body_ids().len(),
                g.dynamic.clone(),
                g.start.clone(),
            )
        };
        let scales = [
            ("positions", positions),
            ("velocities", velocities),
            ("angular_velocities", angular_velocities),
        ];
        let mut noisy: Vec<Vec<Vec<Vec3>>> = Vec::new();
        for ((field, s), base) in scales.into_iter().zip(&start) {
            if !(s.is_finite() && s >= 0.0) {
                return Err(invalid(
                    field,
                    format!("must be a finite number >= 0, got {s}"),
                ));
            }
            let mut rows: Vec<Vec<Vec3>> = vec![base.clone(); k];
            if s > 0.0 {
                let draw = rng.call_method1("uniform", (-s, s, (k, n, 3)))?;
                let noise = vectors(per_world(&draw, field, [k, n, 3])?);
                for (world, noise) in rows.iter_mut().zip(noise) {
                    for ((row, d), &dyn_) in world.iter_mut().zip(noise).zip(&dynamic) {
                        if dyn_ {
                            *row += d;
                        }
                    }
                }
            }
            noisy.push(rows);
        }
        let given = Given {
            positions: Some(noisy.remove(0)),
            orientations: None,
            velocities: Some(noisy.remove(0)),
            angular_velocities: Some(noisy.remove(0)),
        };
        self.lock()?
            .batch
            .reset_with_states(list.as_deref(), None, Some(&given.states(k)))
            .map_err(engine)
    }

    /// World `i`'s whole state as bytes (as `World.snapshot`).
    fn snapshot<'py>(
        &self,
        py: Python<'py>,
        i: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyBytes>> {
        let g = self.lock()?;
        let i = index(i, g.batch.len())?;
        let bytes = g.batch.world(i).map_err(engine)?.snapshot();
        Ok(PyBytes::new(py, &bytes))
    }

    /// A new tumble.World continuing world `i` (a copy: changing it leaves the batch).
    fn world(&self, i: &Bound<'_, PyAny>) -> PyResult<PyWorld> {
        let g = self.lock()?;
        let i = index(i, g.batch.len())?;
        let bytes = g.batch.world(i).map_err(engine)?.snapshot();
        Ok(PyWorld::new_inner(Inner {
            world: World::from_snapshot(&bytes).map_err(engine)?,
            dt: g.dt,
            duration: g.duration,
            callbacks: None,
            mjcf: None,
        }))
    }

    fn __repr__(&self) -> PyResult<String> {
        let g = self.lock()?;
        Ok(format!(
            "<tumble.Batch: {} worlds of {} bodies, {} threads>",
            g.batch.len(),
            g.batch.body_ids().len(),
            g.batch.threads()
        ))
    }
}

/// A batch's recording: position, orientation, velocity and angular velocity, each
/// stored world by world, (W, T, N, ·), and seen by Python as (T, W, N, ·) (the first two
/// axes swapped: a view, no copy). Each world writes its rows as it steps, one after
/// another in its own stretch of each array, on the thread stepping it.
///
/// Why so: the first version gathered a chunk's rows per world and copied them into
/// time-major (T, W, N, ·) arrays; writing straight into those, every step of a world
/// stored into four new cache lines 48 kB apart, and two threads recording 1,024
/// cart-poles ran at 0.8 of their speed unrecorded. MuJoCo's rollout writes (W, T, ·).
struct Frames<'a> {
    /// Every `every`-th step is recorded, and the last (`steps`).
    every: u64,
    steps: u64,
    bodies: usize,
    /// Frames of the run; after a failed run, the frames recorded whole.
    count: usize,
    /// The frames each world has room for (`count` before a failure).
    room: usize,
    arrays: [&'a mut [f64]; 4],
}

/// Numbers a body takes in each of a recording's arrays.
const WIDTHS: [usize; 4] = [3, 4, 3, 3];

impl<'a> Frames<'a> {
    /// A recording into `arrays` (W, T, N, ·) of a run of `plan` of `batch`, step 0's
    /// filled in.
    fn new(batch: &Batch, plan: &RunPlan, every: u64, arrays: [&'a mut [f64]; 4]) -> Self {
        let count = crate::sim::frame_count(plan.steps, every) as usize;
        let mut f = Frames {
            every,
            steps: plan.steps,
            bodies: batch.body_ids().len(),
            count,
            room: count,
            arrays,
        };
        for (s, world) in f.slots(0, batch.len(), 0..1).iter_mut().zip(batch.worlds()) {
            s.record(0, world);
        }
        f
    }

    /// The frames that steps `k + 1..=k + n` are recorded in: the step k + 1 falls in
    /// or after up to the one of step k + n (the last frame, when that is the last step).
    fn frames_of(&self, k: u64, n: u64) -> std::ops::Range<usize> {
        let end = if k + n >= self.steps {
            self.room
        } else {
            ((k + n) / self.every + 1) as usize
        };
        ((k / self.every + 1) as usize).min(end)..end
    }

    /// Worlds `first..first + b`'s rows of `frames`, one `Slots` a world.
    fn slots(&mut self, first: usize, b: usize, frames: std::ops::Range<usize>) -> Vec<Slots<'_>> {
        let (n, room, start) = (self.bodies, self.room, frames.start);
        let (every, steps) = (self.every, self.steps);
        let mut each: Vec<Slots<'_>> = (0..b)
            .map(|_| Slots {
                first: start,
                every,
                steps,
                bodies: n,
                rows: Default::default(),
            })
            .collect();
        for (c, (array, width)) in self.arrays.iter_mut().zip(WIDTHS).enumerate() {
            let per = n * width;
            if per == 0 {
                continue;
            }
            let worlds = array.chunks_mut(room * per).skip(first).take(b);
            for (s, world) in each.iter_mut().zip(worlds) {
                s.rows[c] = &mut world[frames.start * per..frames.end * per];
            }
        }
        each
    }

    /// Keeps the frames of steps 0..=`k` only.
    fn keep_until(&mut self, k: u64) {
        self.count = self.count.min((k / self.every + 1) as usize);
    }
}

/// The frame step `k` of a run of `steps` steps recording every `every`-th is recorded in,
/// if it is.
fn frame_of(k: u64, every: u64, steps: u64) -> Option<usize> {
    if k % every == 0 {
        Some((k / every) as usize)
    } else if k == steps {
        Some((k / every + 1) as usize)
    } else {
        None
    }
}

/// One world's rows from frame `first` on, in each of the four arrays: frame after frame,
/// N bodies a frame.
struct Slots<'a> {
    first: usize,
    every: u64,
    steps: u64,
    bodies: usize,
    rows: [&'a mut [f64]; 4],
}

/// Row `t` of `per` numbers of `rows`, if it has one.
fn row(rows: &mut [f64], t: usize, per: usize) -> Option<&mut [f64]> {
    rows.get_mut(t * per..(t + 1) * per)
}

impl Slots<'_> {
    /// Writes `world`'s bodies into the frame of step `k`, if that step is recorded.
    fn record(&mut self, k: u64, world: &World) {
        let Some(t) = frame_of(k, self.every, self.steps).and_then(|f| f.checked_sub(self.first))
        else {
            return;
        };
        let n = self.bodies;
        let [p, q, v, a] = &mut self.rows;
        let (Some(p), Some(q), Some(v), Some(a)) = (
            row(p, t, n * 3),
            row(q, t, n * 4),
            row(v, t, n * 3),
            row(a, t, n * 3),
        ) else {
            return;
        };
        let rows = p.chunks_exact_mut(3).zip(q.chunks_exact_mut(4));
        let rates = v.chunks_exact_mut(3).zip(a.chunks_exact_mut(3));
        for ((_, b), ((p, q), (v, a))) in world.bodies().zip(rows.zip(rates)) {
            let (x, o) = (b.position(), b.orientation());
            let (u, w) = (b.linear_velocity(), b.angular_velocity());
            p.copy_from_slice(&[wide(x.x), wide(x.y), wide(x.z)]);
            q.copy_from_slice(&[wide(o.x), wide(o.y), wide(o.z), wide(o.w)]);
            v.copy_from_slice(&[wide(u.x), wide(u.y), wide(u.z)]);
            a.copy_from_slice(&[wide(w.x), wide(w.y), wide(w.z)]);
        }
    }
}

#[pymethods]
impl PyBatch {
    /// Runs every world for `duration` seconds (default: the scene's) in steps of `dt`
    /// (default: the scene's, else 0.01), or exactly `steps` steps, as World.simulate
    /// does, and returns a tumble.Trajectory whose arrays have a world axis: `time` (T,)
    /// (from the start of this run), `position` (T, W, N, 3), `orientation` (T, W, N, 4),
    /// `velocity` and `angular_velocity` (T, W, N, 3); step 0, every `every`-th step and
    /// the last are recorded. The four body arrays are stored world by world (each is a
    /// (W, T, N, ·) array seen with its first two axes swapped, so `a[:, i]` is one
    /// contiguous run); np.ascontiguousarray makes a time-major copy. Given `out`, a
    /// Trajectory of an earlier Batch.simulate with the arrays this run records (same T,
    /// W and N), its arrays are overwritten and it is returned: a loop of rollouts
    /// allocates nothing (as MuJoCo's rollout writes into the `state` array it is
    /// given); no other thread may touch those arrays meanwhile.
    /// The loop runs with the interpreter's lock released. A failed step raises
    /// SimulationError naming the world, whose `trajectory` holds the frames recorded
    /// before it (views of `out`'s arrays when given).
    #[pyo3(signature = (duration = None, dt = None, *, steps = None, every = None, out = None))]
    fn simulate(
        &self,
        py: Python<'_>,
        duration: Option<f64>,
        dt: Option<f64>,
        steps: Option<&Bound<'_, PyAny>>,
        every: Option<&Bound<'_, PyAny>>,
        out: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Py<Trajectory>> {
        let every = u64::try_from(every.map_or(Ok(1), |e| whole(e, "every"))?)
            .ok()
            .filter(|&e| e >= 1)
            .ok_or_else(|| invalid("every", "must be >= 1"))?;
        let mut g = self.lock()?;
        let dt = dt.map_or(g.dt, real);
        let (plan, field) = match (steps.filter(|s| !s.is_none()), duration) {
            (Some(_), Some(_)) => {
                return Err(invalid("steps", "cannot be given together with duration"))
            }
            (Some(s), None) => {
                let s = u64::try_from(whole(s, "steps")?)
                    .map_err(|_| invalid("steps", "must be >= 0"))?;
                (RunPlan::from_steps(s, dt).map_err(scene)?, "steps")
            }
            (None, d) => (
                RunPlan::from_duration(d.map_or(g.duration, real), dt).map_err(scene)?,
                "duration",
            ),
        };
        let run = Recorded { plan, every };
        match out.filter(|o| !o.is_none()) {
            Some(out) => run.into_out(py, &mut g, out),
            None => {
                let (w, n) = (g.batch.len(), g.batch.body_ids().len());
                let frames = crate::sim::frame_count(plan.steps, every);
                crate::sim::check_fits(py, field, frames, w.saturating_mul(n), false)?;
                run.into_new(py, &mut g)
            }
        }
    }
}

/// A recorded run of `Batch.simulate`.
struct Recorded {
    plan: RunPlan,
    every: u64,
}

impl Recorded {
    /// (T, W, N): the frames, worlds and bodies recorded.
    fn lead(&self, g: &BatchInner) -> [usize; 3] {
        [self.lead_frames(), g.batch.len(), g.batch.body_ids().len()]
    }

    /// T, the frames of the whole run.
    fn lead_frames(&self) -> usize {
        crate::sim::frame_count(self.plan.steps, self.every) as usize
    }

    /// The time of each of the first `count` frames, from the start of the run.
    fn times(&self, count: usize) -> impl Iterator<Item = f64> + '_ {
        let (plan, every) = (&self.plan, self.every);
        (0..count as u64).map(move |t| wide(plan.time_after((t * every).min(plan.steps))))
    }

    /// Runs the batch, recording into `arrays`; the frames recorded whole.
    fn record(
        &self,
        py: Python<'_>,
        g: &mut BatchInner,
        arrays: [&mut [f64]; 4],
    ) -> (Result<(), Stop>, usize) {
        let mut rec = Frames::new(&g.batch, &self.plan, self.every, arrays);
        let outcome = run(py, &mut g.batch, &self.plan, Some(&mut rec));
        (outcome, rec.count)
    }

    /// The run recorded into fresh arrays, returned as a new Trajectory.
    fn into_new(self, py: Python<'_>, g: &mut BatchInner) -> PyResult<Py<Trajectory>> {
        let [t, w, n] = self.lead(g);
        let mut arrays = WIDTHS.map(|width| vec![0.0; w * t * n * width]);
        let (outcome, kept) = self.record(py, g, arrays.each_mut().map(|a| a.as_mut_slice()));
        let [p, q, v, a] = arrays;
        let seen = |data: Vec<f64>, width: usize| -> PyResult<Py<PyAny>> {
            let stored = array(py, data, &[w, t, n, width])?;
            let swapped = stored
                .bind(py)
                .call_method1(intern!(py, "swapaxes"), (0, 1))?;
            Ok(swapped.unbind())
        };
        let time = array(py, self.times(t).collect(), &[t])?;
        let arrays = [time, seen(p, 3)?, seen(q, 4)?, seen(v, 3)?, seen(a, 3)?];
        let traj = Trajectory::of_arrays(arrays, g.names.clone());
        self.finish(py, outcome, kept, traj.into_pyobject(py)?)
    }

    /// The run recorded into the arrays of `out`, a Trajectory of the same shapes,
    /// returned.
    fn into_out(
        self,
        py: Python<'_>,
        g: &mut BatchInner,
        out: &Bound<'_, PyAny>,
    ) -> PyResult<Py<Trajectory>> {
        let traj = out
            .cast::<Trajectory>()
            .map_err(|_| wrong_type("out", "a tumble.Trajectory from Batch.simulate", out))?;
        let [t, w, n] = self.lead(g);
        let [time, p, q, v, a] = traj.get().arrays();
        let mut time = writable(py, time, "out.time", &[t])?;
        let shape = |width| [t, w, n, width];
        let mut p = writable(py, p, "out.position", &shape(3))?;
        let mut q = writable(py, q, "out.orientation", &shape(4))?;
        let mut v = writable(py, v, "out.velocity", &shape(3))?;
        let mut a = writable(py, a, "out.angular_velocity", &shape(3))?;
        for (to, from) in slice(&mut time)?.iter_mut().zip(self.times(t)) {
            *to = from;
        }
        let arrays = [
            slice(&mut p)?,
            slice(&mut q)?,
            slice(&mut v)?,
            slice(&mut a)?,
        ];
        let (outcome, kept) = self.record(py, g, arrays);
        drop((time, p, q, v, a));
        self.finish(py, outcome, kept, traj.clone())
    }

    /// The run's trajectory `traj`, or the failure it ended in carrying the frames
    /// recorded whole (the first `kept`, views of `traj`'s arrays).
    fn finish(
        &self,
        py: Python<'_>,
        outcome: Result<(), Stop>,
        kept: usize,
        traj: Bound<'_, Trajectory>,
    ) -> PyResult<Py<Trajectory>> {
        let t = self.lead_frames();
        let traj = if kept < t {
            let head = |a: &Py<PyAny>| -> PyResult<Py<PyAny>> {
                let frames = PySlice::new(py, 0, kept as isize, 1);
                Ok(a.bind(py).get_item(frames)?.unbind())
            };
            let [time, p, q, v, a] = traj.get().arrays();
            let arrays = [head(time)?, head(p)?, head(q)?, head(v)?, head(a)?];
            Trajectory::of_arrays(arrays, traj.get().names().to_vec()).into_pyobject(py)?
        } else {
            traj
        };
        match outcome {
            Ok(()) => Ok(traj.unbind()),
            Err(Stop::Failed(f)) => Err(failure(py, &f, Some(traj.into_any().unbind()))),
            Err(Stop::Python(e)) => Err(e),
        }
    }
}

/// `array`, to be written by a run: a writable float64 array of `shape` (T, ...) as
/// `Batch.simulate` makes them, stored with its first two axes swapped (a (T,) array as
/// it is), else refused naming `field`. Returns the stored array, borrowed for writing.
fn writable<'py>(
    py: Python<'py>,
    array: &Py<PyAny>,
    field: &str,
    shape: &[usize],
) -> PyResult<PyReadwriteArrayDyn<'py, f64>> {
    let text = |s: &[usize]| match s {
        [one] => format!("({one},)"),
        _ => format!(
            "({})",
            s.iter()
                .map(|d| d.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
    };
    let refuse = |got: String| {
        invalid(
            field,
            format!(
                "must be a writable float64 array of shape {}, laid out as Batch.simulate \
                 makes it, for the frames this run records; got {got}",
                text(shape)
            ),
        )
    };
    let Ok(a) = array.bind(py).cast::<PyArrayDyn<f64>>() else {
        return Err(refuse("an array of another type".into()));
    };
    if a.shape() != shape {
        return Err(refuse(format!("shape {}", text(a.shape()))));
    }
    let stored = if shape.len() > 1 {
        let swapped = a.call_method1(intern!(py, "swapaxes"), (0, 1))?;
        swapped
            .cast_into::<PyArrayDyn<f64>>()
            .map_err(PyErr::from)?
    } else {
        a.clone()
    };
    if !stored.is_c_contiguous() {
        return Err(refuse("an array laid out otherwise".into()));
    }
    stored
        .try_readwrite()
        .map_err(|_| refuse("an array that is read-only or borrowed".into()))
}

/// A writable array's numbers (checked C-contiguous by `writable`).
fn slice<'b>(array: &'b mut PyReadwriteArrayDyn<'_, f64>) -> PyResult<&'b mut [f64]> {
    array
        .as_slice_mut()
        .map_err(|_| invalid("out", "its arrays must be C-contiguous"))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyBatch>()
}
