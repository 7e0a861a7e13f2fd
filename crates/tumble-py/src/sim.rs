//! Runs and bulk state: `World.simulate` (the loop in Rust, the interpreter's lock
//! released), its `Trajectory`, and every body's state as one numpy array, readable and
//! settable without a Python loop.

use numpy::{AllowTypeChange, PyArray1, PyArrayLike2, PyArrayMethods};
use pyo3::prelude::*;
use tumble::{Body, BodyId, Quat, Real, Vec3, World};
use tumble_scene::RunPlan;

use crate::convert::{engine, invalid, real, scene, wide};
use crate::world::PyWorld;

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

fn push3(out: &mut Vec<f64>, v: Vec3) {
    out.extend_from_slice(&[wide(v.x), wide(v.y), wide(v.z)]);
}

fn push4(out: &mut Vec<f64>, q: Quat) {
    out.extend_from_slice(&[wide(q.x), wide(q.y), wide(q.z), wide(q.w)]);
}

impl Recording {
    fn with_capacity(frames: usize, bodies: usize, diagnostics: bool) -> Self {
        let per = frames * bodies;
        let d = if diagnostics { frames } else { 0 };
        Recording {
            time: Vec::with_capacity(frames),
            position: Vec::with_capacity(per * 3),
            orientation: Vec::with_capacity(per * 4),
            velocity: Vec::with_capacity(per * 3),
            angular_velocity: Vec::with_capacity(per * 3),
            energy: std::array::from_fn(|_| Vec::with_capacity(d)),
            linear_momentum: Vec::with_capacity(d * 3),
            angular_momentum: Vec::with_capacity(d * 3),
        }
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

/// Steps `world` through `plan`, recording step 0, every `every`-th step and the last.
fn run(
    world: &mut World,
    plan: &RunPlan,
    every: u64,
    diagnostics: bool,
) -> tumble::Result<Recording> {
    let frames = plan.steps / every + 1 + u64::from(plan.steps % every != 0);
    let mut rec = Recording::with_capacity(frames as usize, world.body_count(), diagnostics);
    let start = world.time();
    rec.frame(world, start, diagnostics);
    for k in 1..=plan.steps {
        world.step(plan.step_dt(k))?;
        if k % every == 0 || k == plan.steps {
            // k·dt from the start rather than the world's running sum, as the CLI reports.
            rec.frame(world, start + plan.time_after(k), diagnostics);
        }
    }
    Ok(rec)
}

fn array(py: Python<'_>, data: Vec<f64>, shape: &[usize]) -> PyResult<Py<PyAny>> {
    Ok(PyArray1::from_vec(py, data)
        .reshape(shape)?
        .into_any()
        .unbind())
}

/// Rows of a bulk array given for every body: (N, width), converted to float64.
fn rows<'py>(
    value: &Bound<'py, PyAny>,
    field: &str,
    n: usize,
    width: usize,
) -> PyResult<Vec<Vec<f64>>> {
    let arr: PyArrayLike2<'py, f64, AllowTypeChange> = value.extract().map_err(|_| {
        crate::convert::wrong_type(field, &format!("an array of shape (N, {width})"), value)
    })?;
    let view = arr.as_array();
    if view.shape() != [n, width] {
        return Err(invalid(
            field,
            format!(
                "expected an array of shape ({n}, {width}) (one row per body), got {:?}",
                view.shape()
            ),
        ));
    }
    let out: Vec<Vec<f64>> = view.rows().into_iter().map(|r| r.to_vec()).collect();
    // Checked whole before anything is written, so a refused array changes nothing.
    if let Some(i) = out.iter().position(|r| r.iter().any(|x| !x.is_finite())) {
        return Err(invalid(&format!("{field}[{i}]"), "must be finite numbers"));
    }
    if width == 4 {
        if let Some(i) = out.iter().position(|r| r.iter().all(|&x| x == 0.0)) {
            return Err(invalid(
                &format!("{field}[{i}]"),
                "must be a non-zero quaternion [x, y, z, w]",
            ));
        }
    }
    Ok(out)
}

fn v3(r: &[f64]) -> Vec3 {
    Vec3::new(real(r[0]), real(r[1]), real(r[2]))
}

fn read_all(world: &World, width: usize, f: impl Fn(&Body, &mut Vec<f64>)) -> Vec<f64> {
    let mut out = Vec::with_capacity(world.body_count() * width);
    for (_, b) in world.bodies() {
        f(b, &mut out);
    }
    out
}

type Setter = fn(&mut World, BodyId, &[f64]) -> tumble::Result<()>;

fn set_all(
    w: &PyWorld,
    value: &Bound<'_, PyAny>,
    field: &str,
    width: usize,
    set: Setter,
) -> PyResult<()> {
    let mut g = w.lock()?;
    let n = g.world.body_count();
    let data = rows(value, field, n, width)?;
    let ids = g.world.body_ids().to_vec();
    for (i, (id, r)) in ids.iter().zip(&data).enumerate() {
        set(&mut g.world, *id, r).map_err(|e| match e {
            tumble::Error::InvalidField { reason, .. } => invalid(&format!("{field}[{i}]"), reason),
            other => engine(other),
        })?;
    }
    Ok(())
}

fn set_position(w: &mut World, id: BodyId, r: &[f64]) -> tumble::Result<()> {
    w.set_position(id, v3(r))
}
fn set_orientation(w: &mut World, id: BodyId, r: &[f64]) -> tumble::Result<()> {
    w.set_orientation(
        id,
        Quat::from_xyzw(real(r[0]), real(r[1]), real(r[2]), real(r[3])),
    )
}
fn set_velocity(w: &mut World, id: BodyId, r: &[f64]) -> tumble::Result<()> {
    w.set_linear_velocity(id, v3(r))
}
fn set_angular_velocity(w: &mut World, id: BodyId, r: &[f64]) -> tumble::Result<()> {
    w.set_angular_velocity(id, v3(r))
}

#[pymethods]
impl PyWorld {
    /// Runs the world for `duration` seconds (default: the scene's) in steps of `dt`
    /// (default: the scene's, else 0.01), or for exactly `steps` steps, and returns the
    /// recorded Trajectory. The loop runs in Rust with the interpreter's lock released.
    /// As with the CLI, a duration that is not a whole number of steps ends with one
    /// shorter step; `every` records every k-th step (step 0 and the last always).
    #[pyo3(signature = (duration = None, dt = None, *, steps = None, every = 1, diagnostics = false))]
    fn simulate(
        slf: &Bound<'_, Self>,
        duration: Option<f64>,
        dt: Option<f64>,
        steps: Option<i64>,
        every: i64,
        diagnostics: bool,
    ) -> PyResult<Trajectory> {
        let py = slf.py();
        if every < 1 {
            return Err(invalid("every", "must be >= 1"));
        }
        let mut g = slf.get().lock()?;
        let dt = dt.map_or(g.dt, real);
        let plan = match (steps, duration) {
            (Some(_), Some(_)) => {
                return Err(invalid("steps", "cannot be given together with duration"))
            }
            (Some(s), None) => {
                let s = u64::try_from(s).map_err(|_| invalid("steps", "must be >= 0"))?;
                RunPlan::from_steps(s, dt)
            }
            (None, d) => RunPlan::from_duration(d.map_or(g.duration, real), dt),
        }
        .map_err(scene)?;
        let world = &mut g.world;
        let rec = py
            .detach(|| run(world, &plan, every as u64, diagnostics))
            .map_err(engine)?;
        let names = g
            .world
            .bodies()
            .map(|(_, b)| b.name().map(str::to_string))
            .collect();
        let (t, n) = (rec.time.len(), g.world.body_count());
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

    /// Every body frame's origin (m), float64 array (N, 3) in creation order; assignable
    /// with any (N, 3) array (checked whole before anything changes).
    #[getter]
    fn positions(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        let g = self.lock()?;
        let data = read_all(&g.world, 3, |b, o| push3(o, b.position()));
        array(py, data, &[g.world.body_count(), 3])
    }

    #[setter]
    fn set_positions(&self, value: &Bound<'_, PyAny>) -> PyResult<()> {
        set_all(self, value, "positions", 3, set_position)
    }

    /// Every body's orientation [x, y, z, w], float64 array (N, 4); assignable.
    #[getter]
    fn orientations(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        let g = self.lock()?;
        let data = read_all(&g.world, 4, |b, o| push4(o, b.orientation()));
        array(py, data, &[g.world.body_count(), 4])
    }

    #[setter]
    fn set_orientations(&self, value: &Bound<'_, PyAny>) -> PyResult<()> {
        set_all(self, value, "orientations", 4, set_orientation)
    }

    /// Every body's centre-of-mass velocity (m/s), float64 array (N, 3); assignable.
    #[getter]
    fn velocities(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        let g = self.lock()?;
        let data = read_all(&g.world, 3, |b, o| push3(o, b.linear_velocity()));
        array(py, data, &[g.world.body_count(), 3])
    }

    #[setter]
    fn set_velocities(&self, value: &Bound<'_, PyAny>) -> PyResult<()> {
        set_all(self, value, "velocities", 3, set_velocity)
    }

    /// Every body's angular velocity (rad/s, world frame), float64 array (N, 3);
    /// assignable.
    #[getter]
    fn angular_velocities(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        let g = self.lock()?;
        let data = read_all(&g.world, 3, |b, o| push3(o, b.angular_velocity()));
        array(py, data, &[g.world.body_count(), 3])
    }

    #[setter]
    fn set_angular_velocities(&self, value: &Bound<'_, PyAny>) -> PyResult<()> {
        set_all(self, value, "angular_velocities", 3, set_angular_velocity)
    }

    /// Every body's angular momentum about its centre of mass (kg·m²/s, world frame),
    /// float64 array (N, 3).
    #[getter]
    fn angular_momenta(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        let g = self.lock()?;
        let data = read_all(&g.world, 3, |b, o| push3(o, b.angular_momentum()));
        array(py, data, &[g.world.body_count(), 3])
    }

    /// Sets any of the bulk arrays at once, in the order positions, orientations,
    /// velocities, angular velocities (so ω is turned into L with the new orientation).
    #[pyo3(signature = (*, positions = None, orientations = None, velocities = None, angular_velocities = None))]
    fn set_state(
        &self,
        positions: Option<&Bound<'_, PyAny>>,
        orientations: Option<&Bound<'_, PyAny>>,
        velocities: Option<&Bound<'_, PyAny>>,
        angular_velocities: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        if let Some(v) = positions {
            self.set_positions(v)?;
        }
        if let Some(v) = orientations {
            self.set_orientations(v)?;
        }
        if let Some(v) = velocities {
            self.set_velocities(v)?;
        }
        if let Some(v) = angular_velocities {
            self.set_angular_velocities(v)?;
        }
        Ok(())
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Trajectory>()
}
