//! `tumble.CharacterController`: the engine's character controller over a world, and
//! `tumble.Push`, an impulse it gave a body.

use std::sync::{Mutex, MutexGuard, TryLockError};

use numpy::PyArray1;
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use tumble::{CharacterController, CharacterDef, Ground, QueryFilter, Real, Vec3};

use crate::body::{handle, PyBody};
use crate::convert::{
    engine, invalid, layer_bits, real, vec3, vec3_or, vec3_out, wide, wrong_type,
};
use crate::world::{body_arg, PyWorld};

/// A character controller: a kinematic capsule that walks in `world`.
///
/// CharacterController(world, *, radius=0.3, half_height=0.6, position=(0, 0, 0),
/// max_slope=π/4, step_height=0.3, skin=0.02, snap_distance=0.3, max_push_force=1000.0,
/// up=(0, 1, 0), collision_mask=0xFFFFFFFF, exclude=None).
/// `move(displacement, dt)` moves it by `displacement` (m) over `dt` (s): it slides along
/// walls, climbs slopes up to `max_slope` (rad) and steps up to `step_height` (m), follows
/// the ground down slopes and stairs (by up to `snap_distance`), keeps `skin` (m) from
/// every surface, never passes through one however fast, and pushes dynamic bodies in its
/// way with impulses of at most `max_push_force`·dt. Gravity is the caller's: add it to
/// the displacement while `on_ground` is False. It is not a body: other bodies do not
/// collide with it. Bodies whose collision_group meets `collision_mask` block it, less
/// `exclude` (a Body or a body's name). Bad values raise ValueError naming the field
/// (`character.radius: must be > 0`).
#[pyclass(module = "tumble", name = "CharacterController", frozen)]
pub struct PyCharacter {
    world: Py<PyWorld>,
    // As World's: a frozen class over a Mutex, only ever tried.
    controller: Mutex<CharacterController>,
}

/// An impulse a move gave a dynamic body: the `body`, the `impulse` (N·s, world) and the
/// `point` (m, world) it was applied at.
#[pyclass(module = "tumble", name = "Push", frozen, get_all)]
pub struct PyPush {
    /// The body pushed.
    body: Py<PyBody>,
    /// The impulse (N·s, world), (3,); no longer than max_push_force·dt.
    impulse: Py<PyArray1<f64>>,
    /// Where it was applied (m, world), (3,).
    point: Py<PyArray1<f64>>,
}

#[pymethods]
impl PyPush {
    fn __repr__(&self, py: Python<'_>) -> String {
        format!("<tumble.Push impulse={}>", self.impulse.bind(py))
    }
}

impl PyCharacter {
    fn lock(&self) -> PyResult<MutexGuard<'_, CharacterController>> {
        match self.controller.try_lock() {
            Ok(guard) => Ok(guard),
            Err(TryLockError::Poisoned(p)) => Ok(p.into_inner()),
            Err(TryLockError::WouldBlock) => Err(PyRuntimeError::new_err(
                "the character is busy: another thread is moving it",
            )),
        }
    }

    fn read<R>(&self, f: impl FnOnce(&CharacterController) -> R) -> PyResult<R> {
        let guard = self.lock()?;
        Ok(f(&guard))
    }
}

#[pymethods]
impl PyCharacter {
    #[new]
    #[pyo3(signature = (world, *, radius=0.3, half_height=0.6, position=None,
        max_slope=std::f64::consts::FRAC_PI_4, step_height=0.3, skin=0.02,
        snap_distance=0.3, max_push_force=1000.0, up=None, collision_mask=0xFFFF_FFFF,
        exclude=None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        world: &Bound<'_, PyWorld>,
        radius: f64,
        half_height: f64,
        position: Option<&Bound<'_, PyAny>>,
        max_slope: f64,
        step_height: f64,
        skin: f64,
        snap_distance: f64,
        max_push_force: f64,
        up: Option<&Bound<'_, PyAny>>,
        collision_mask: i64,
        exclude: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let inner = world.get().lock()?;
        let exclude = exclude
            .map(|b| body_arg(world, &inner, b, "character.exclude"))
            .transpose()?;
        let def = CharacterDef {
            position: vec3_or(position, "character.position", Vec3::ZERO)?,
            radius: real(radius),
            half_height: real(half_height),
            up: vec3_or(up, "character.up", Vec3::Y)?,
            max_slope: real(max_slope),
            step_height: real(step_height),
            skin: real(skin),
            snap_distance: real(snap_distance),
            max_push_force: real(max_push_force),
            filter: QueryFilter {
                mask: layer_bits(collision_mask, "character.collision_mask")?,
                exclude,
            },
        };
        let controller = CharacterController::new(&inner.world, &def).map_err(engine)?;
        drop(inner);
        Ok(PyCharacter {
            world: world.clone().unbind(),
            controller: Mutex::new(controller),
        })
    }

    /// Moves the character by `displacement` (m, world) over `dt` (s): see the class.
    /// Refused, nothing changed, for a displacement not finite or a dt not > 0.
    #[pyo3(name = "move")]
    fn move_by(&self, displacement: &Bound<'_, PyAny>, dt: f64) -> PyResult<()> {
        let d = vec3(displacement, "displacement")?;
        let mut inner = self.world.get().lock()?;
        let mut c = self.lock()?;
        c.move_by(&mut inner.world, d, real(dt)).map_err(engine)
    }

    /// The world it walks in.
    #[getter]
    fn world(&self, py: Python<'_>) -> Py<PyWorld> {
        self.world.clone_ref(py)
    }

    /// The capsule's centre (m, world), (3,); assignable (placed there, not swept).
    #[getter]
    fn position<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(vec3_out(py, self.read(|c| c.position())?))
    }

    #[setter]
    fn set_position(&self, value: &Bound<'_, PyAny>) -> PyResult<()> {
        let p = vec3(value, "position")?;
        let inner = self.world.get().lock()?;
        self.lock()?.set_position(&inner.world, p).map_err(engine)
    }

    /// Whether the last move (or the start) left it on walkable ground.
    #[getter]
    fn on_ground(&self) -> PyResult<bool> {
        self.read(|c| c.on_ground())
    }

    /// The unit normal of the ground it stands on, (3,), or None in the air.
    #[getter]
    fn ground_normal<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyArray1<f64>>>> {
        Ok(self.read(|c| c.ground_normal())?.map(|n| vec3_out(py, n)))
    }

    /// The body it stands on, or None in the air.
    #[getter]
    fn ground_body<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyBody>>> {
        let id = self.read(|c| c.ground_body())?;
        id.map(|id| handle(self.world.bind(py), id)).transpose()
    }

    /// The last move's displacement over its dt (m/s), (3,): what it did.
    #[getter]
    fn velocity<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(vec3_out(py, self.read(|c| c.velocity())?))
    }

    /// The impulses the last move gave dynamic bodies, a list of tumble.Push.
    #[getter]
    fn pushes(&self, py: Python<'_>) -> PyResult<Vec<PyPush>> {
        let pushes = self.read(|c| c.pushes().to_vec())?;
        let world = self.world.bind(py);
        pushes
            .into_iter()
            .map(|p| {
                Ok(PyPush {
                    body: handle(world, p.body)?.unbind(),
                    impulse: vec3_out(py, p.impulse).unbind(),
                    point: vec3_out(py, p.point).unbind(),
                })
            })
            .collect()
    }

    /// The capsule's radius (m).
    #[getter]
    fn radius(&self) -> PyResult<f64> {
        self.setting(|d| d.radius)
    }

    /// Half the length of the segment between its sphere centres (m).
    #[getter]
    fn half_height(&self) -> PyResult<f64> {
        self.setting(|d| d.half_height)
    }

    /// The steepest slope it walks up (rad).
    #[getter]
    fn max_slope(&self) -> PyResult<f64> {
        self.setting(|d| d.max_slope)
    }

    /// The highest step it climbs (m).
    #[getter]
    fn step_height(&self) -> PyResult<f64> {
        self.setting(|d| d.step_height)
    }

    /// The gap it keeps to every surface (m).
    #[getter]
    fn skin(&self) -> PyResult<f64> {
        self.setting(|d| d.skin)
    }

    /// How far down it follows the ground (m).
    #[getter]
    fn snap_distance(&self) -> PyResult<f64> {
        self.setting(|d| d.snap_distance)
    }

    /// The largest force it pushes a body with (N).
    #[getter]
    fn max_push_force(&self) -> PyResult<f64> {
        self.setting(|d| d.max_push_force)
    }

    /// Its unit up direction, (3,).
    #[getter]
    fn up<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(vec3_out(py, self.read(|c| c.def().up)?))
    }

    /// What the character carries from one move to the next, as a dict: `position` and
    /// `velocity` (3,) arrays and `ground` (None in the air, else a dict of `body` (a
    /// Body), `point` and `normal`). With `World.snapshot`, what a saved run needs: after
    /// `world.restore(snap)`, `restore(state)` puts the character back, and its next move
    /// goes on as it would have.
    fn state<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let (position, velocity, ground) =
            self.read(|c| (c.position(), c.velocity(), c.ground()))?;
        let d = PyDict::new(py);
        d.set_item("position", vec3_out(py, position))?;
        d.set_item("velocity", vec3_out(py, velocity))?;
        let ground = match ground {
            None => None,
            Some(g) => {
                let gd = PyDict::new(py);
                gd.set_item("body", handle(self.world.bind(py), g.body)?)?;
                gd.set_item("point", vec3_out(py, g.point))?;
                gd.set_item("normal", vec3_out(py, g.normal))?;
                Some(gd)
            }
        };
        d.set_item("ground", ground)?;
        Ok(d)
    }

    /// Puts the character back to `state` (a dict as `state()` returns; `velocity` and
    /// `ground` may be left out: zero, in the air). Refused, nothing changed, with the
    /// key named (`state.ground.body: this body was removed`) for a value of the wrong
    /// type or shape, a position beyond the world's range, a ground body the world does
    /// not hold or a ground normal that is not a unit vector.
    fn restore<'py>(&self, state: &Bound<'py, PyAny>) -> PyResult<()> {
        fn item<'py>(d: &Bound<'py, PyDict>, key: &str) -> Option<Bound<'py, PyAny>> {
            d.get_item(key).ok().flatten()
        }
        let state = state
            .cast::<PyDict>()
            .map_err(|_| wrong_type("state", "a dict", state))?;
        let known = ["position", "velocity", "ground"];
        for key in state.keys() {
            let name: String = key.extract().unwrap_or_else(|_| key.to_string());
            if !known.contains(&name.as_str()) {
                return Err(invalid(&format!("state.{name}"), "unknown key"));
            }
        }
        let position = item(state, "position")
            .ok_or_else(|| invalid("state.position", "required"))
            .and_then(|p| vec3(&p, "state.position"))?;
        let velocity = vec3_or(
            item(state, "velocity").as_ref(),
            "state.velocity",
            Vec3::ZERO,
        )?;
        let world = self.world.get();
        let inner = world.lock()?;
        let ground = match item(state, "ground").filter(|g| !g.is_none()) {
            None => None,
            Some(g) => {
                let g = g
                    .cast::<PyDict>()
                    .map_err(|_| wrong_type("state.ground", "a dict or None", &g))?;
                let field = |key: &str| {
                    item(g, key).ok_or_else(|| invalid(&format!("state.ground.{key}"), "required"))
                };
                let body = field("body")?;
                let bound = self.world.bind(g.py());
                Some(Ground {
                    body: body_arg(bound, &inner, &body, "state.ground.body")?,
                    point: vec3(&field("point")?, "state.ground.point")?,
                    normal: vec3(&field("normal")?, "state.ground.normal")?,
                })
            }
        };
        let mut c = self.lock()?;
        c.restore(&inner.world, position, ground, velocity)
            .map_err(|e| engine(e.within("state")))
    }

    fn __repr__(&self) -> PyResult<String> {
        let (p, ground) = self.read(|c| (c.position(), c.on_ground()))?;
        Ok(format!(
            "<tumble.CharacterController at [{}, {}, {}], on_ground={}>",
            wide(p.x),
            wide(p.y),
            wide(p.z),
            if ground { "True" } else { "False" }
        ))
    }
}

impl PyCharacter {
    fn setting(&self, f: impl FnOnce(&CharacterDef) -> Real) -> PyResult<f64> {
        self.read(|c| wide(f(&c.def())))
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyCharacter>()?;
    m.add_class::<PyPush>()?;
    Ok(())
}
