//! `tumble.World`: construction (keywords or a scene file), bodies, force elements,
//! stepping, settings and diagnostics.

use std::sync::{Mutex, MutexGuard, TryLockError};

use numpy::PyArray1;
use pyo3::exceptions::{PyKeyError, PyRuntimeError};
use pyo3::gc::PyVisit;
use pyo3::prelude::*;
use pyo3::PyTraverseError;
use tumble::limits::ContactLimits;
use tumble::{
    AppliedForce, BodyDef, BodyId, BodyKind, Drag, Force, ForceId, InertiaSpec, MassSpec, Real,
    SolverSettings, SpeedLimits, Spring, SpringEnd, Vec3, World, WorldDef,
};

use crate::body::{handle, PyBody};
use crate::convert::{
    engine, invalid, layer_bits, mat3_rows, numbers, quat_or, real, scene, vec3, vec3_or, vec3_out,
    wide, wrong_type,
};
use crate::shapes::shape_of;

/// The world and the run settings a scene file brings along.
pub struct Inner {
    pub world: World,
    /// Default step of `simulate` (s): the scene's `dt`, else 0.01.
    pub dt: Real,
    /// Default length of `simulate` (s): the scene's `duration`, else 1.
    pub duration: Real,
    /// The world's Python force callbacks (`callbacks.rs`); `None` while it has none.
    pub callbacks: Option<crate::callbacks::Callbacks>,
    /// What `World.from_mjcf` read (the actuators `set_control` drives); `None` for
    /// worlds made otherwise.
    pub mjcf: Option<tumble_scene::mjcf::ImportedMjcf>,
}

/// A simulated world: bodies, force elements, joints, and the step that advances them.
///
/// World(*, gravity=(0, -9.8, 0), integrator="symplectic_euler", solver="soft_step",
/// substeps=4, iterations=1, contact_hertz=60.0, contact_damping_ratio=10.0,
/// joint_hertz=1000.0, joint_damping_ratio=0.5, baumgarte=0.2, joint_trees="maximal",
/// length_unit=1.0, sleep=True, max_speed=None, max_angular_speed=None, max_contacts=None,
/// max_contacts_per_body=None, max_push_speed=None, threads=None). SI units throughout; quaternions
/// are [x, y, z, w].
/// `max_speed` (m/s) and `max_angular_speed` (rad/s) bound every body's speed (defaults
/// 1e4·length_unit and 1e5): a step that exceeds them, or whose result is not finite, is
/// undone and raises SimulationError; so is one needing more than `max_contacts` contact
/// manifolds (default 1,048,576). `max_contacts_per_body` (default 16) is how many other
/// bodies a body may be sunk into before two such crowded bodies are no longer paired.
/// `max_push_speed` (m/s, default 3·length_unit) is the fastest contacts push
/// overlapping bodies apart. `threads` is how many threads a step runs on (default
/// TUMBLE_THREADS, else every core); results are bit-identical for every count.
#[pyclass(module = "tumble", name = "World", frozen)]
pub struct PyWorld {
    // A Mutex rather than PyO3's borrow flag: the engine's World is Send but not Sync
    // (it owns FnMut force callbacks), and a frozen class over a Mutex is Sync. The lock
    // is only ever tried, never waited for, so a thread holding the interpreter cannot
    // deadlock against one stepping without it.
    inner: Mutex<Inner>,
}

impl PyWorld {
    pub fn new_inner(inner: Inner) -> PyWorld {
        PyWorld {
            inner: Mutex::new(inner),
        }
    }

    /// The world, or a RuntimeError while another thread is stepping it.
    pub fn lock(&self) -> PyResult<MutexGuard<'_, Inner>> {
        match self.inner.try_lock() {
            Ok(guard) => Ok(guard),
            // The engine does not panic on input; if something did, the state it left is
            // still a valid world (every edit is checked before it is made).
            Err(TryLockError::Poisoned(p)) => Ok(p.into_inner()),
            Err(TryLockError::WouldBlock) => Err(PyRuntimeError::new_err(
                "the world is busy: another thread is stepping or simulating it",
            )),
        }
    }
}

/// A body argument: a `tumble.Body` of this world, or a body's name.
pub fn body_arg(
    world: &Bound<'_, PyWorld>,
    inner: &Inner,
    obj: &Bound<'_, PyAny>,
    field: &str,
) -> PyResult<BodyId> {
    if let Ok(b) = obj.cast::<PyBody>() {
        let b = b.get();
        if b.world.as_ptr() != world.as_ptr() {
            return Err(invalid(field, "this body belongs to another world"));
        }
        inner
            .world
            .body(b.id)
            .map_err(|_| invalid(field, "this body was removed"))?;
        return Ok(b.id);
    }
    if let Ok(name) = obj.extract::<String>() {
        return inner
            .world
            .find_body(&name)
            .ok_or_else(|| invalid(field, format!("no body named '{name}'")));
    }
    Err(wrong_type(field, "a tumble.Body or a body's name", obj))
}

/// A body's or joint's name (`of`: "bodies" or "joints"), refused as a scene file refuses
/// it (`name: must not be empty`): names label output rows, where the unnamed are labelled
/// by their index, so the rule is the scene format's, from its own function.
pub fn checked_name(name: Option<String>, of: &str) -> PyResult<Option<String>> {
    if let Some(n) = &name {
        tumble_scene::check_name(n, of).map_err(|reason| invalid("name", reason))?;
    }
    Ok(name)
}

/// The speed limits given, each defaulting to the engine's for `length_unit`, or `None`
/// (all the engine's defaults) when neither is given, as in a scene file.
fn speed_limits(
    max_speed: Option<f64>,
    max_angular_speed: Option<f64>,
    length_unit: f64,
) -> Option<SpeedLimits> {
    if max_speed.is_none() && max_angular_speed.is_none() {
        return None;
    }
    // A bad length_unit is refused by the engine before the limits are looked at.
    let default = SpeedLimits::for_length_unit(real(length_unit));
    Some(SpeedLimits {
        max_speed: max_speed.map_or(default.max_speed, real),
        max_angular_speed: max_angular_speed.map_or(default.max_angular_speed, real),
    })
}

/// The contact limits given, each defaulting to the engine's.
fn contact_limits(per_step: Option<i64>, per_body: Option<i64>) -> PyResult<ContactLimits> {
    let d = ContactLimits::default();
    Ok(ContactLimits {
        per_step: per_step.map_or(Ok(d.per_step), |v| count(v, "max_contacts"))?,
        per_body: per_body.map_or(Ok(d.per_body), |v| count(v, "max_contacts_per_body"))?,
    })
}

/// A count such as `substeps`, at least 1.
fn count(value: i64, field: &str) -> PyResult<u32> {
    if value < 1 {
        return Err(invalid(field, "must be >= 1"));
    }
    u32::try_from(value).map_err(|_| invalid(field, format!("must be at most {}", u32::MAX)))
}

/// Solver settings: `kind` ("soft_step" or "pgs"), `substeps` and `iterations` per step,
/// contact stiffness `contact_hertz` (Hz) and `contact_damping_ratio`, `baumgarte` (PGS's
/// fraction of error corrected per substep), the joints' `joint_hertz` (Hz) and
/// `joint_damping_ratio`, and `joint_trees` ("maximal" or "reduced": joint trees solved in
/// reduced coordinates). Read with `world.solver_settings`, change a copy, assign it back.
#[pyclass(module = "tumble", name = "SolverSettings", get_all, set_all)]
#[derive(Clone)]
pub struct PySolverSettings {
    /// "soft_step" or "pgs".
    kind: String,
    /// Solver substeps per step (>= 1).
    substeps: i64,
    /// Solve (and relax) passes per substep (>= 1).
    iterations: i64,
    /// Contact stiffness (Hz), capped at a quarter of the substep rate.
    contact_hertz: f64,
    /// Damping ratio of the contact spring.
    contact_damping_ratio: f64,
    /// PGS's fraction of the position error corrected per substep.
    baumgarte: f64,
    /// Stiffness of the joints' drift correction (Hz).
    joint_hertz: f64,
    /// Damping ratio of the joints' drift correction.
    joint_damping_ratio: f64,
    /// "maximal" or "reduced": how joint trees are solved.
    joint_trees: String,
}

impl PySolverSettings {
    fn of(s: &SolverSettings) -> Self {
        PySolverSettings {
            kind: s.kind.name().to_string(),
            substeps: i64::from(s.substeps),
            iterations: i64::from(s.iterations),
            contact_hertz: wide(s.contact_hertz),
            contact_damping_ratio: wide(s.contact_damping_ratio),
            baumgarte: wide(s.baumgarte),
            joint_hertz: wide(s.joint_hertz),
            joint_damping_ratio: wide(s.joint_damping_ratio),
            joint_trees: s.joint_trees.name().to_string(),
        }
    }

    fn to_core(&self) -> PyResult<SolverSettings> {
        Ok(SolverSettings {
            kind: tumble_scene::parse_solver(&self.kind).map_err(scene)?,
            substeps: count(self.substeps, "substeps")?,
            iterations: count(self.iterations, "iterations")?,
            contact_hertz: real(self.contact_hertz),
            contact_damping_ratio: real(self.contact_damping_ratio),
            baumgarte: real(self.baumgarte),
            joint_hertz: real(self.joint_hertz),
            joint_damping_ratio: real(self.joint_damping_ratio),
            joint_trees: tumble_scene::parse_joint_trees(&self.joint_trees).map_err(scene)?,
        })
    }
}

#[pymethods]
impl PySolverSettings {
    #[new]
    #[pyo3(signature = (*, kind = "soft_step".to_string(), substeps = 4, iterations = 1,
        contact_hertz = 60.0, contact_damping_ratio = 10.0, baumgarte = 0.2,
        joint_hertz = 1000.0, joint_damping_ratio = 0.5, joint_trees = "maximal".to_string()))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        kind: String,
        substeps: i64,
        iterations: i64,
        contact_hertz: f64,
        contact_damping_ratio: f64,
        baumgarte: f64,
        joint_hertz: f64,
        joint_damping_ratio: f64,
        joint_trees: String,
    ) -> PyResult<Self> {
        let s = PySolverSettings {
            kind,
            substeps,
            iterations,
            contact_hertz,
            contact_damping_ratio,
            baumgarte,
            joint_hertz,
            joint_damping_ratio,
            joint_trees,
        };
        s.to_core()?;
        Ok(s)
    }

    fn __repr__(&self) -> String {
        format!(
            "tumble.SolverSettings(kind={:?}, substeps={}, iterations={}, contact_hertz={}, \
             contact_damping_ratio={}, baumgarte={}, joint_hertz={}, joint_damping_ratio={}, \
             joint_trees={:?})",
            self.kind,
            self.substeps,
            self.iterations,
            self.contact_hertz,
            self.contact_damping_ratio,
            self.baumgarte,
            self.joint_hertz,
            self.joint_damping_ratio,
            self.joint_trees
        )
    }
}

/// Energies and momenta of a state, over the dynamic bodies: `kinetic`, `potential`
/// (gravity, zero at the origin, plus springs) and `total` in J; `linear_momentum`
/// (kg·m/s) and `angular_momentum` about the world origin (kg·m²/s) as arrays (3,).
#[pyclass(module = "tumble", name = "Diagnostics", frozen, get_all)]
pub struct PyDiagnostics {
    /// Kinetic energy (J).
    kinetic: f64,
    /// Potential energy (J): gravity, zero at the origin, plus springs.
    potential: f64,
    /// Kinetic plus potential (J).
    total: f64,
    /// Linear momentum (kg·m/s), (3,).
    linear_momentum: Py<PyArray1<f64>>,
    /// Angular momentum about the world origin (kg·m²/s), (3,).
    angular_momentum: Py<PyArray1<f64>>,
}

#[pymethods]
impl PyDiagnostics {
    fn __repr__(&self) -> String {
        format!(
            "tumble.Diagnostics(kinetic={}, potential={}, total={}, ...)",
            self.kinetic, self.potential, self.total
        )
    }
}

fn spring_end(
    slf: &Bound<'_, PyWorld>,
    g: &Inner,
    body: BodyId,
    world_point: Option<&Bound<'_, PyAny>>,
    other: Option<&Bound<'_, PyAny>>,
    other_anchor: Option<&Bound<'_, PyAny>>,
) -> PyResult<SpringEnd> {
    match (world_point, other) {
        (Some(p), None) => {
            if other_anchor.is_some() {
                return Err(invalid("other_anchor", "only with other"));
            }
            Ok(SpringEnd::World(vec3(p, "world_point")?))
        }
        (None, Some(o)) => {
            let id = body_arg(slf, g, o, "other")?;
            if id == body {
                return Err(invalid("other", "must be a different body than body"));
            }
            Ok(SpringEnd::Body {
                body: id,
                anchor: vec3_or(other_anchor, "other_anchor", Vec3::ZERO)?,
            })
        }
        (Some(_), Some(_)) => Err(invalid(
            "other",
            "cannot be given together with world_point (give exactly one of world_point, other)",
        )),
        (None, None) => Err(invalid(
            "world_point",
            "a spring needs world_point or other (give exactly one)",
        )),
    }
}

/// A thread count from Python: negative counts get the engine's message for them.
fn thread_count(n: i64) -> PyResult<usize> {
    let most = tumble::threads::MAX_THREADS;
    usize::try_from(n)
        .map_err(|_| invalid("threads", format!("must be between 1 and {most}, got {n}")))
}

#[pymethods]
impl PyWorld {
    // Tells the garbage collector what the world holds (see `callbacks.rs`). A world that
    // is stepping (its lock held) reports nothing: it is in use, so not garbage.
    fn __traverse__(&self, visit: PyVisit<'_>) -> Result<(), PyTraverseError> {
        match self.inner.try_lock() {
            Ok(g) => g.callbacks.as_ref().map_or(Ok(()), |c| c.traverse(&visit)),
            Err(_) => Ok(()),
        }
    }

    #[new]
    #[pyo3(signature = (*, gravity = None, integrator = "symplectic_euler".to_string(),
        solver = "soft_step".to_string(), substeps = 4, iterations = 1, contact_hertz = 60.0,
        contact_damping_ratio = 10.0, joint_hertz = 1000.0, joint_damping_ratio = 0.5,
        baumgarte = 0.2, joint_trees = "maximal".to_string(), length_unit = 1.0, sleep = true,
        max_speed = None,
        max_angular_speed = None, max_contacts = None, max_contacts_per_body = None,
        max_push_speed = None, threads = None))]
    #[allow(clippy::too_many_arguments)]
    fn py_new(
        gravity: Option<&Bound<'_, PyAny>>,
        integrator: String,
        solver: String,
        substeps: i64,
        iterations: i64,
        contact_hertz: f64,
        contact_damping_ratio: f64,
        joint_hertz: f64,
        joint_damping_ratio: f64,
        baumgarte: f64,
        joint_trees: String,
        length_unit: f64,
        sleep: bool,
        max_speed: Option<f64>,
        max_angular_speed: Option<f64>,
        max_contacts: Option<i64>,
        max_contacts_per_body: Option<i64>,
        max_push_speed: Option<f64>,
        threads: Option<i64>,
    ) -> PyResult<Self> {
        let settings = PySolverSettings {
            kind: solver,
            substeps,
            iterations,
            contact_hertz,
            contact_damping_ratio,
            baumgarte,
            joint_hertz,
            joint_damping_ratio,
            joint_trees,
        };
        let def = WorldDef {
            gravity: vec3_or(gravity, "gravity", Vec3::new(0.0, -9.8, 0.0))?,
            integrator: tumble_scene::parse_integrator(&integrator).map_err(scene)?,
            length_unit: real(length_unit),
            solver: settings.to_core()?,
            sleep,
            limits: speed_limits(max_speed, max_angular_speed, length_unit),
            contact_limits: contact_limits(max_contacts, max_contacts_per_body)?,
            max_push_speed: max_push_speed.map(real),
            threads: threads.map(thread_count).transpose()?,
        };
        let world = World::try_new(&def).map_err(engine)?;
        Ok(PyWorld::new_inner(Inner {
            world,
            dt: tumble_scene::DEFAULT_DT,
            duration: tumble_scene::DEFAULT_DURATION,
            callbacks: None,
            mjcf: None,
        }))
    }

    /// Loads a scene: a file path or a built-in scene's name (see `tumble.SCENES`). The
    /// scene's `dt` and `duration` become `simulate`'s defaults. Bad scenes raise
    /// ValueError naming the field, e.g. `bodies[3].shape.radius: must be > 0`.
    #[staticmethod]
    fn from_scene(path: std::path::PathBuf) -> PyResult<Self> {
        let text = path.to_string_lossy().into_owned();
        let s = tumble_scene::load(&text).map_err(scene)?;
        Ok(PyWorld::new_inner(Inner {
            world: s.world,
            dt: s.dt,
            duration: s.duration,
            callbacks: None,
            mjcf: None,
        }))
    }

    /// Loads a scene from JSON text (docs/scene-format.md); its relative paths (`models`
    /// files) are read from `folder`, else from the working directory.
    #[staticmethod]
    #[pyo3(signature = (text, folder = None))]
    fn from_json(text: String, folder: Option<std::path::PathBuf>) -> PyResult<Self> {
        let s = match folder {
            Some(dir) => tumble_scene::load_str_in(&text, &dir),
            None => tumble_scene::load_str(&text),
        }
        .map_err(scene)?;
        Ok(PyWorld::new_inner(Inner {
            world: s.world,
            dt: s.dt,
            duration: s.duration,
            callbacks: None,
            mjcf: None,
        }))
    }

    /// Adds a body and returns its handle.
    ///
    /// `mass` (kg) or `density` (kg/m³, default 1000) but not both; `position` (m) of the
    /// body frame's origin; `orientation` [x, y, z, w]; `velocity` (m/s) of the centre of
    /// mass and `angular_velocity` (rad/s), world frame; `kind` "dynamic", "kinematic" or
    /// "static"; `inertia` as 3 principal moments or a 3×3 matrix (kg·m², body axes) and
    /// `center_of_mass` (m, body frame) override the shape's; `planar` confines the body
    /// to the xy plane; `friction`, `restitution`, `rolling_resistance` (dimensionless:
    /// rolling torque at most μ_r r N) and `torsional_friction` (m: spinning torque at most
    /// μ_t N; a pair uses the larger of each), `collision_group`/`collision_mask`
    /// (32-bit layer sets), `collision_owner` (bodies with the same non-zero owner never
    /// collide with each other; 0: none), `bullet` (continuous collision against every body that is
    /// not a bullet), `linear_damping` and `angular_damping` (1/s: dv/dt = −c v,
    /// dL/dt = −c L besides the forces), `gravity_scale` (times the world's gravity),
    /// `sensor` (reports overlaps in `sensor_events()`, with no contact response) and
    /// `one_way` (a platform's normal, body frame: bodies from that side land on it, from
    /// below or the side pass through).
    #[pyo3(signature = (shape, *, mass = None, density = None, position = None,
        orientation = None, velocity = None, angular_velocity = None,
        kind = "dynamic".to_string(), name = None, planar = false, inertia = None,
        center_of_mass = None, friction = 0.6, restitution = 0.0, rolling_resistance = 0.0,
        torsional_friction = 0.0, collision_group = 1, collision_mask = 0xFFFF_FFFF,
        collision_owner = 0, bullet = false, linear_damping = 0.0, angular_damping = 0.0, gravity_scale = 1.0,
        sensor = false, one_way = None))]
    #[allow(clippy::too_many_arguments)]
    fn add_body<'py>(
        slf: &Bound<'py, Self>,
        shape: &Bound<'py, PyAny>,
        mass: Option<f64>,
        density: Option<f64>,
        position: Option<&Bound<'py, PyAny>>,
        orientation: Option<&Bound<'py, PyAny>>,
        velocity: Option<&Bound<'py, PyAny>>,
        angular_velocity: Option<&Bound<'py, PyAny>>,
        kind: String,
        name: Option<String>,
        planar: bool,
        inertia: Option<&Bound<'py, PyAny>>,
        center_of_mass: Option<&Bound<'py, PyAny>>,
        friction: f64,
        restitution: f64,
        rolling_resistance: f64,
        torsional_friction: f64,
        collision_group: i64,
        collision_mask: i64,
        collision_owner: i64,
        bullet: bool,
        linear_damping: f64,
        angular_damping: f64,
        gravity_scale: f64,
        sensor: bool,
        one_way: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyBody>> {
        let shape = shape_of(shape, "shape")?;
        let mass = match (mass, density) {
            (Some(_), Some(_)) => {
                return Err(invalid(
                    "density",
                    "cannot be given together with mass (give one of mass, density)",
                ))
            }
            (Some(m), None) => MassSpec::Mass(real(m)),
            (None, Some(d)) => MassSpec::Density(real(d)),
            (None, None) => MassSpec::default(),
        };
        let kind = BodyKind::from_name(&kind).ok_or_else(|| {
            invalid(
                "kind",
                format!("unknown body kind '{kind}' (expected one of: static, kinematic, dynamic)"),
            )
        })?;
        let inertia = inertia.map(inertia_spec).transpose()?;
        let def = BodyDef {
            name: checked_name(name, "bodies")?,
            kind,
            position: vec3_or(position, "position", Vec3::ZERO)?,
            orientation: quat_or(orientation, "orientation")?,
            linear_velocity: vec3_or(velocity, "velocity", Vec3::ZERO)?,
            angular_velocity: vec3_or(angular_velocity, "angular_velocity", Vec3::ZERO)?,
            mass,
            inertia,
            center_of_mass: center_of_mass
                .map(|c| vec3(c, "center_of_mass"))
                .transpose()?,
            planar,
            collision_group: layer_bits(collision_group, "collision_group")?,
            collision_mask: layer_bits(collision_mask, "collision_mask")?,
            collision_owner: layer_bits(collision_owner, "collision_owner")?,
            friction: real(friction),
            restitution: real(restitution),
            rolling_resistance: real(rolling_resistance),
            torsional_friction: real(torsional_friction),
            bullet,
            linear_damping: real(linear_damping),
            angular_damping: real(angular_damping),
            gravity_scale: real(gravity_scale),
            sensor,
            one_way: one_way
                .filter(|n| !n.is_none())
                .map(|n| vec3(n, "one_way"))
                .transpose()?,
        };
        let id = slf
            .get()
            .lock()?
            .world
            .create_body(&def, shape)
            .map_err(engine)?;
        handle(slf, id)
    }

    /// Removes a body (a handle or a name) with every force element and joint on it.
    fn remove_body(slf: &Bound<'_, Self>, body: &Bound<'_, PyAny>) -> PyResult<()> {
        let mut g = slf.get().lock()?;
        let id = body_arg(slf, &g, body, "body")?;
        g.world.remove_body(id).map_err(engine)
    }

    /// The body called `name` (KeyError if there is none).
    fn body<'py>(slf: &Bound<'py, Self>, name: String) -> PyResult<Bound<'py, PyBody>> {
        let id = slf.get().lock()?.world.find_body(&name);
        match id {
            Some(id) => handle(slf, id),
            None => Err(PyKeyError::new_err(format!("no body named '{name}'"))),
        }
    }

    /// Every body's handle, in creation order (the order of the bulk arrays).
    #[getter]
    fn bodies<'py>(slf: &Bound<'py, Self>) -> PyResult<Vec<Bound<'py, PyBody>>> {
        let ids = slf.get().lock()?.world.body_ids().to_vec();
        ids.into_iter().map(|id| handle(slf, id)).collect()
    }

    /// Every body's name (None for unnamed bodies), in creation order.
    #[getter]
    fn body_names(&self) -> PyResult<Vec<Option<String>>> {
        let g = self.lock()?;
        Ok(g.world
            .bodies()
            .map(|(_, b)| b.name().map(str::to_string))
            .collect())
    }

    fn __len__(&self) -> PyResult<usize> {
        Ok(self.lock()?.world.body_count())
    }

    /// Adds a Hookean spring with a parallel damper from `anchor` on `body` (m, its frame)
    /// to a fixed `world_point` (m) or to `other_anchor` on `other` (give exactly one of
    /// world_point and other). `stiffness` (N/m), `rest_length` (m), `damping` (N·s/m).
    /// Returns the force element's id.
    #[pyo3(signature = (body, *, stiffness, world_point = None, other = None, anchor = None,
        other_anchor = None, rest_length = 0.0, damping = 0.0))]
    #[allow(clippy::too_many_arguments)]
    fn add_spring(
        slf: &Bound<'_, Self>,
        body: &Bound<'_, PyAny>,
        stiffness: f64,
        world_point: Option<&Bound<'_, PyAny>>,
        other: Option<&Bound<'_, PyAny>>,
        anchor: Option<&Bound<'_, PyAny>>,
        other_anchor: Option<&Bound<'_, PyAny>>,
        rest_length: f64,
        damping: f64,
    ) -> PyResult<u64> {
        let mut g = slf.get().lock()?;
        let id = body_arg(slf, &g, body, "body")?;
        let end = spring_end(slf, &g, id, world_point, other, other_anchor)?;
        let spring = Spring {
            body: id,
            anchor: vec3_or(anchor, "anchor", Vec3::ZERO)?,
            other: end,
            stiffness: real(stiffness),
            rest_length: real(rest_length),
            damping: real(damping),
        };
        add(&mut g.world, Force::Spring(spring))
    }

    /// Adds air drag at `body`'s centre of mass: F = −linear·v − quadratic·|v|·v, with
    /// `linear` in N·s/m and `quadratic` in N·s²/m². Returns the force element's id.
    #[pyo3(signature = (body, *, linear = 0.0, quadratic = 0.0))]
    fn add_drag(
        slf: &Bound<'_, Self>,
        body: &Bound<'_, PyAny>,
        linear: f64,
        quadratic: f64,
    ) -> PyResult<u64> {
        let mut g = slf.get().lock()?;
        let id = body_arg(slf, &g, body, "body")?;
        let drag = Drag {
            body: id,
            linear: real(linear),
            quadratic: real(quadratic),
        };
        add(&mut g.world, Force::Drag(drag))
    }

    /// Adds a constant `force` (N, world frame) acting at `point` (m, body frame; default
    /// the centre of mass) and a constant `torque` (N·m, world frame). Returns its id.
    #[pyo3(signature = (body, *, force = None, point = None, torque = None))]
    fn add_force(
        slf: &Bound<'_, Self>,
        body: &Bound<'_, PyAny>,
        force: Option<&Bound<'_, PyAny>>,
        point: Option<&Bound<'_, PyAny>>,
        torque: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<u64> {
        let mut g = slf.get().lock()?;
        let id = body_arg(slf, &g, body, "body")?;
        let applied = AppliedForce {
            body: id,
            force: vec3_or(force, "force", Vec3::ZERO)?,
            point: point.map(|p| vec3(p, "point")).transpose()?,
            torque: vec3_or(torque, "torque", Vec3::ZERO)?,
        };
        add(&mut g.world, Force::Applied(applied))
    }

    /// Removes a force element by the id its `add_*` returned; False if there is none
    /// (never was, or removed already: ids are generational and never reused).
    fn remove_force(&self, id: u64) -> PyResult<bool> {
        let id = ForceId {
            index: id as u32,
            generation: (id >> 32) as u32,
        };
        Ok(self.lock()?.world.remove_force(id).is_ok())
    }

    /// Advances the world by `dt` seconds, `steps` times (default once). Long runs release
    /// the interpreter lock, so other Python threads go on meanwhile, and stop on Ctrl-C
    /// (KeyboardInterrupt) between two steps. A step whose result is not finite or too
    /// fast raises SimulationError with that step undone; either way the world is left at
    /// the last step completed (`step_count` says which).
    #[pyo3(signature = (dt, steps = 1))]
    fn step(&self, py: Python<'_>, dt: f64, steps: u64) -> PyResult<()> {
        let mut g = self.lock()?;
        let dt = real(dt);
        // Releasing and retaking the interpreter lock costs about what stepping an empty
        // world does, so a short step keeps it; counting an empty world as one body, so
        // that many steps of it (long, however cheap each) let other threads run.
        let release = (g.world.body_count().max(1) as u64).saturating_mul(steps) >= 64;
        crate::steps::run(py, &mut g, steps, release, |_| dt, |_, _| ())?;
        Ok(())
    }

    /// Simulated time (s).
    #[getter]
    fn time(&self) -> PyResult<f64> {
        Ok(wide(self.lock()?.world.time()))
    }

    /// Steps taken so far.
    #[getter]
    fn step_count(&self) -> PyResult<u64> {
        Ok(self.lock()?.world.step_count())
    }

    /// Gravitational acceleration (m/s²), an array (3,); assignable.
    #[getter]
    fn gravity<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(vec3_out(py, self.lock()?.world.gravity()))
    }

    #[setter]
    fn set_gravity(&self, value: &Bound<'_, PyAny>) -> PyResult<()> {
        let g = vec3(value, "gravity")?;
        self.lock()?.world.set_gravity(g).map_err(engine)
    }

    /// The integrator's name (one of `tumble.INTEGRATORS`); assignable.
    #[getter]
    fn integrator(&self) -> PyResult<&'static str> {
        Ok(self.lock()?.world.integrator().name())
    }

    #[setter]
    fn set_integrator(&self, name: String) -> PyResult<()> {
        let i = tumble_scene::parse_integrator(&name).map_err(scene)?;
        self.lock()?.world.set_integrator(i);
        Ok(())
    }

    /// Whether resting islands may fall asleep; assignable (False wakes every body).
    #[getter]
    fn sleep(&self) -> PyResult<bool> {
        Ok(self.lock()?.world.sleep_enabled())
    }

    #[setter]
    fn set_sleep(&self, on: bool) -> PyResult<()> {
        self.lock()?.world.set_sleep_enabled(on);
        Ok(())
    }

    /// The default step of `simulate` (s): the scene's `dt`, else 0.01; assignable.
    #[getter]
    fn dt(&self) -> PyResult<f64> {
        Ok(wide(self.lock()?.dt))
    }

    #[setter]
    fn set_dt(&self, dt: f64) -> PyResult<()> {
        if !(dt > 0.0 && dt.is_finite()) {
            return Err(invalid("dt", "must be > 0"));
        }
        self.lock()?.dt = real(dt);
        Ok(())
    }

    /// The default length of `simulate` (s): the scene's `duration`, else 1; assignable.
    #[getter]
    fn duration(&self) -> PyResult<f64> {
        Ok(wide(self.lock()?.duration))
    }

    #[setter]
    fn set_duration(&self, duration: f64) -> PyResult<()> {
        if !(duration >= 0.0 && duration.is_finite()) {
            return Err(invalid("duration", "must be >= 0"));
        }
        self.lock()?.duration = real(duration);
        Ok(())
    }

    /// A copy of the contact and joint solver's settings; assign a changed copy back.
    #[getter]
    fn solver_settings(&self) -> PyResult<PySolverSettings> {
        Ok(PySolverSettings::of(&self.lock()?.world.solver_settings()))
    }

    #[setter]
    fn set_solver_settings(&self, settings: PyRef<'_, PySolverSettings>) -> PyResult<()> {
        let s = settings.to_core()?;
        self.lock()?.world.set_solver_settings(s).map_err(engine)
    }

    /// The fastest a centre of mass may move (m/s; default 1e4 times `length_unit`): a body
    /// set faster is refused, a step that makes one faster raises SimulationError. Assignable
    /// (not below the speed of a body moving now).
    #[getter]
    fn max_speed(&self) -> PyResult<f64> {
        Ok(wide(self.lock()?.world.speed_limits().max_speed))
    }

    #[setter]
    fn set_max_speed(&self, value: f64) -> PyResult<()> {
        let mut g = self.lock()?;
        let limits = SpeedLimits {
            max_speed: real(value),
            ..g.world.speed_limits()
        };
        g.world.set_speed_limits(limits).map_err(engine)
    }

    /// The fastest a body may turn (rad/s; default 1e5), as `max_speed`; assignable.
    #[getter]
    fn max_angular_speed(&self) -> PyResult<f64> {
        Ok(wide(self.lock()?.world.speed_limits().max_angular_speed))
    }

    #[setter]
    fn set_max_angular_speed(&self, value: f64) -> PyResult<()> {
        let mut g = self.lock()?;
        let limits = SpeedLimits {
            max_angular_speed: real(value),
            ..g.world.speed_limits()
        };
        g.world.set_speed_limits(limits).map_err(engine)
    }

    /// Contact manifolds a step may hold (default 1,048,576, about 4 kB each): a step that
    /// needs more is undone and raises SimulationError. Assignable (at least 1).
    #[getter]
    fn max_contacts(&self) -> PyResult<u32> {
        Ok(self.lock()?.world.contact_limits().per_step)
    }

    #[setter]
    fn set_max_contacts(&self, value: i64) -> PyResult<()> {
        let mut g = self.lock()?;
        let limits = ContactLimits {
            per_step: count(value, "max_contacts")?,
            ..g.world.contact_limits()
        };
        g.world.set_contact_limits(limits).map_err(engine)
    }

    /// Other dynamic bodies a body may be sunk into before it counts as crowded (default
    /// 16): two crowded bodies are not paired, so bodies created inside each other keep
    /// contacts in proportion to their number. Assignable (at least 1).
    #[getter]
    fn max_contacts_per_body(&self) -> PyResult<u32> {
        Ok(self.lock()?.world.contact_limits().per_body)
    }

    #[setter]
    fn set_max_contacts_per_body(&self, value: i64) -> PyResult<()> {
        let mut g = self.lock()?;
        let limits = ContactLimits {
            per_body: count(value, "max_contacts_per_body")?,
            ..g.world.contact_limits()
        };
        g.world.set_contact_limits(limits).map_err(engine)
    }

    /// The fastest contacts push overlapping bodies apart (m/s; default 3 times
    /// `length_unit`), by depth correction and by the recovery of bodies created inside
    /// each other. Assignable (> 0).
    #[getter]
    fn max_push_speed(&self) -> PyResult<f64> {
        Ok(wide(self.lock()?.world.max_push_speed()))
    }

    #[setter]
    fn set_max_push_speed(&self, value: f64) -> PyResult<()> {
        let mut g = self.lock()?;
        g.world.set_max_push_speed(real(value)).map_err(engine)
    }

    /// How many threads a step runs on (1 to 256; default TUMBLE_THREADS, else every
    /// core). Assignable; results are bit-identical for every count.
    #[getter]
    fn threads(&self) -> PyResult<usize> {
        Ok(self.lock()?.world.threads())
    }

    #[setter]
    fn set_threads(&self, value: i64) -> PyResult<()> {
        let n = thread_count(value)?;
        self.lock()?.world.set_threads(n).map_err(engine)
    }

    /// Speculative contact distance (m): gaps narrower than this count as contacts.
    #[getter]
    fn contact_margin(&self) -> PyResult<f64> {
        Ok(wide(self.lock()?.world.contact_margin()))
    }

    /// Energies, momentum and angular momentum of the current state.
    fn diagnostics(&self, py: Python<'_>) -> PyResult<PyDiagnostics> {
        let d = self.lock()?.world.diagnostics();
        Ok(PyDiagnostics {
            kinetic: wide(d.kinetic),
            potential: wide(d.potential),
            total: wide(d.total),
            linear_momentum: vec3_out(py, d.linear_momentum).unbind(),
            angular_momentum: vec3_out(py, d.angular_momentum).unbind(),
        })
    }

    /// A hash of every body's state bits: equal hashes mean bit-identical states.
    fn state_hash(&self) -> PyResult<u64> {
        Ok(self.lock()?.world.state_hash())
    }

    fn __repr__(&self) -> PyResult<String> {
        let g = self.lock()?;
        Ok(format!(
            "<tumble.World: {} bodies, t = {} s, {}>",
            g.world.body_count(),
            g.world.time(),
            g.world.integrator().name()
        ))
    }
}

fn inertia_spec(obj: &Bound<'_, PyAny>) -> PyResult<InertiaSpec> {
    if obj.extract::<Vec<f64>>().is_ok() {
        let v = numbers(obj, "inertia", 3, "3 principal moments")?;
        return Ok(InertiaSpec::Principal(Vec3::new(
            real(v[0]),
            real(v[1]),
            real(v[2]),
        )));
    }
    mat3_rows(obj, "inertia").map(InertiaSpec::Tensor)
}

fn add(world: &mut World, force: Force) -> PyResult<u64> {
    world
        .add_force(force)
        .map(|id| (id.generation as u64) << 32 | id.index as u64)
        .map_err(engine)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyWorld>()?;
    m.add_class::<PySolverSettings>()?;
    m.add_class::<PyDiagnostics>()?;
    Ok(())
}
