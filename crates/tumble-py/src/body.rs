//! `tumble.Body`: a handle that reads and writes one body's live state in its world.

use std::hash::{Hash, Hasher};

use numpy::PyArray1;
use pyo3::prelude::*;
use tumble::{Body, BodyId, BodyKind};

use crate::convert::{engine, layer_bits, mat3_out, quat, quat_out, real, vec3, vec3_out, wide};
use crate::world::{Inner, PyWorld};

/// A body in a world. Its properties read the live state (arrays are fresh copies); the
/// assignable ones (position, orientation, velocity, angular_velocity, friction,
/// restitution, collision_group, collision_mask, collision_owner, linear_damping, angular_damping,
/// gravity_scale, sensor, one_way) edit it, checked as `add_body` checks them, and wake it. Handles of
/// a removed body raise ValueError. Two handles of the same body compare equal.
#[pyclass(module = "tumble", name = "Body", frozen)]
pub struct PyBody {
    pub world: Py<PyWorld>,
    pub id: BodyId,
}

/// The handle of body `id` of `world`.
pub fn handle<'py>(world: &Bound<'py, PyWorld>, id: BodyId) -> PyResult<Bound<'py, PyBody>> {
    Bound::new(
        world.py(),
        PyBody {
            world: world.clone().unbind(),
            id,
        },
    )
}

impl PyBody {
    fn read<R>(&self, f: impl FnOnce(&Body) -> R) -> PyResult<R> {
        let g = self.world.get().lock()?;
        let body = g.world.body(self.id).map_err(engine)?;
        Ok(f(body))
    }

    fn edit(&self, f: impl FnOnce(&mut Inner, BodyId) -> tumble::Result<()>) -> PyResult<()> {
        let mut g = self.world.get().lock()?;
        f(&mut g, self.id).map_err(engine)
    }
}

#[pymethods]
impl PyBody {
    /// The world this body is in.
    #[getter]
    fn world(&self, py: Python<'_>) -> Py<PyWorld> {
        self.world.clone_ref(py)
    }

    /// The body's name, or None.
    #[getter]
    fn name(&self) -> PyResult<Option<String>> {
        self.read(|b| b.name().map(str::to_string))
    }

    /// "dynamic", "kinematic" or "static".
    #[getter]
    fn kind(&self) -> PyResult<&'static str> {
        self.read(|b| match b.kind() {
            BodyKind::Dynamic => "dynamic",
            BodyKind::Kinematic => "kinematic",
            BodyKind::Static => "static",
        })
    }

    /// The shape's kind ("sphere", "box", ...).
    #[getter]
    fn shape_kind(&self) -> PyResult<&'static str> {
        self.read(|b| b.shape().kind_name())
    }

    /// Whether the body still exists in its world.
    #[getter]
    fn alive(&self) -> PyResult<bool> {
        Ok(self.world.get().lock()?.world.body(self.id).is_ok())
    }

    /// Mass (kg).
    #[getter]
    fn mass(&self) -> PyResult<f64> {
        self.read(|b| wide(b.mass()))
    }

    /// Inertia tensor about the centre of mass in body axes (kg·m²), array (3, 3).
    #[getter]
    fn inertia<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let m = self.read(|b| b.inertia_local())?;
        mat3_out(py, m)
    }

    /// Inertia tensor about the centre of mass in world axes (kg·m²), array (3, 3).
    #[getter]
    fn inertia_world<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let m = self.read(|b| b.inertia_world())?;
        mat3_out(py, m)
    }

    /// World position of the body frame's origin (m), array (3,); assignable.
    #[getter]
    fn position<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(vec3_out(py, self.read(Body::position)?))
    }

    #[setter]
    fn set_position(&self, value: &Bound<'_, PyAny>) -> PyResult<()> {
        let p = vec3(value, "position")?;
        self.edit(|g, id| g.world.set_position(id, p))
    }

    /// World position of the centre of mass (m), array (3,).
    #[getter]
    fn center_of_mass<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(vec3_out(py, self.read(Body::center_of_mass)?))
    }

    /// Orientation, body frame to world, as a unit quaternion [x, y, z, w]; assignable
    /// (any non-zero quaternion, normalised; turns the body about its frame's origin).
    #[getter]
    fn orientation<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(quat_out(py, self.read(Body::orientation)?))
    }

    #[setter]
    fn set_orientation(&self, value: &Bound<'_, PyAny>) -> PyResult<()> {
        let q = quat(value, "orientation")?;
        self.edit(|g, id| g.world.set_orientation(id, q))
    }

    /// Velocity of the centre of mass (m/s, world frame), array (3,); assignable.
    #[getter]
    fn velocity<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(vec3_out(py, self.read(Body::linear_velocity)?))
    }

    #[setter]
    fn set_velocity(&self, value: &Bound<'_, PyAny>) -> PyResult<()> {
        let v = vec3(value, "velocity")?;
        self.edit(|g, id| g.world.set_linear_velocity(id, v))
    }

    /// Angular velocity (rad/s, world frame), array (3,); assignable (the angular
    /// momentum follows as L = I_world ω).
    #[getter]
    fn angular_velocity<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(vec3_out(py, self.read(Body::angular_velocity)?))
    }

    #[setter]
    fn set_angular_velocity(&self, value: &Bound<'_, PyAny>) -> PyResult<()> {
        let w = vec3(value, "angular_velocity")?;
        self.edit(|g, id| g.world.set_angular_velocity(id, w))
    }

    /// Linear momentum m v (kg·m/s), array (3,).
    #[getter]
    fn linear_momentum<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(vec3_out(py, self.read(Body::linear_momentum)?))
    }

    /// Angular momentum about the centre of mass (kg·m²/s, world frame), array (3,): what
    /// a torque-free body keeps.
    #[getter]
    fn angular_momentum<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(vec3_out(py, self.read(Body::angular_momentum)?))
    }

    /// Kinetic energy, translational plus rotational (J).
    #[getter]
    fn kinetic_energy(&self) -> PyResult<f64> {
        self.read(|b| wide(b.kinetic_energy()))
    }

    /// Whether the body is awake (False while its island sleeps).
    #[getter]
    fn awake(&self) -> PyResult<bool> {
        self.read(Body::is_awake)
    }

    /// Whether the body is confined to the xy plane.
    #[getter]
    fn planar(&self) -> PyResult<bool> {
        self.read(Body::is_planar)
    }

    /// Coulomb friction coefficient (>= 0; a pair uses √(μ_a μ_b)); assignable.
    #[getter]
    fn friction(&self) -> PyResult<f64> {
        self.read(|b| wide(b.friction()))
    }

    #[setter]
    fn set_friction(&self, value: f64) -> PyResult<()> {
        self.edit(|g, id| g.world.set_friction(id, real(value)))
    }

    /// Coefficient of restitution (in [0, 1]; a pair uses the larger); assignable.
    #[getter]
    fn restitution(&self) -> PyResult<f64> {
        self.read(|b| wide(b.restitution()))
    }

    #[setter]
    fn set_restitution(&self, value: f64) -> PyResult<()> {
        self.edit(|g, id| g.world.set_restitution(id, real(value)))
    }

    /// Collision layers the body is in (32-bit set); assignable.
    #[getter]
    fn collision_group(&self) -> PyResult<u32> {
        self.read(|b| b.collision_filter().0)
    }

    #[setter]
    fn set_collision_group(&self, value: i64) -> PyResult<()> {
        let group = layer_bits(value, "collision_group")?;
        self.edit(|g, id| {
            let (_, mask) = g.world.body(id)?.collision_filter();
            g.world.set_collision_filter(id, group, mask)
        })
    }

    /// Layers the body collides with (32-bit set); assignable.
    #[getter]
    fn collision_mask(&self) -> PyResult<u32> {
        self.read(|b| b.collision_filter().1)
    }

    #[setter]
    fn set_collision_mask(&self, value: i64) -> PyResult<()> {
        let mask = layer_bits(value, "collision_mask")?;
        self.edit(|g, id| {
            let (group, _) = g.world.body(id)?.collision_filter();
            g.world.set_collision_filter(id, group, mask)
        })
    }

    /// Collision owner (0: none): bodies with the same non-zero owner never collide with
    /// each other whatever their groups and masks (an imported URDF model's links share
    /// one unless `self_collision=True`); assignable.
    #[getter]
    fn collision_owner(&self) -> PyResult<u32> {
        self.read(|b| b.collision_owner())
    }

    #[setter]
    fn set_collision_owner(&self, value: i64) -> PyResult<()> {
        let owner = layer_bits(value, "collision_owner")?;
        self.edit(|g, id| g.world.set_collision_owner(id, owner))
    }

    /// Linear damping (1/s, >= 0): dv/dt = −c v besides the forces; assignable.
    #[getter]
    fn linear_damping(&self) -> PyResult<f64> {
        self.read(|b| wide(b.linear_damping()))
    }

    #[setter]
    fn set_linear_damping(&self, value: f64) -> PyResult<()> {
        self.edit(|g, id| g.world.set_linear_damping(id, real(value)))
    }

    /// Angular damping (1/s, >= 0): dL/dt = −c L besides the torques; assignable.
    #[getter]
    fn angular_damping(&self) -> PyResult<f64> {
        self.read(|b| wide(b.angular_damping()))
    }

    #[setter]
    fn set_angular_damping(&self, value: f64) -> PyResult<()> {
        self.edit(|g, id| g.world.set_angular_damping(id, real(value)))
    }

    /// Multiplier of the world's gravity for this body; assignable.
    #[getter]
    fn gravity_scale(&self) -> PyResult<f64> {
        self.read(|b| wide(b.gravity_scale()))
    }

    #[setter]
    fn set_gravity_scale(&self, value: f64) -> PyResult<()> {
        self.edit(|g, id| g.world.set_gravity_scale(id, real(value)))
    }

    /// Whether the body is a sensor (reports overlaps, no contact response); assignable.
    #[getter]
    fn sensor(&self) -> PyResult<bool> {
        self.read(Body::is_sensor)
    }

    #[setter]
    fn set_sensor(&self, value: bool) -> PyResult<()> {
        self.edit(|g, id| g.world.set_sensor(id, value))
    }

    /// A one-way body's unit normal (body frame), or None; assignable (any non-zero
    /// length, normalised; None makes it an ordinary body).
    #[getter]
    fn one_way<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyArray1<f64>>>> {
        Ok(self.read(Body::one_way)?.map(|n| vec3_out(py, n)))
    }

    #[setter]
    fn set_one_way(&self, value: Option<&Bound<'_, PyAny>>) -> PyResult<()> {
        let normal = value
            .filter(|n| !n.is_none())
            .map(|n| vec3(n, "one_way"))
            .transpose()?;
        self.edit(|g, id| g.world.set_one_way(id, normal))
    }

    /// Makes a kinematic body arrive exactly at `position` (m, its frame's origin) and
    /// `orientation` ([x, y, z, w]; default: as it is) at the end of the next step, whose
    /// dt sets its velocities; it keeps them afterwards. ValueError for a body that is
    /// not kinematic.
    #[pyo3(signature = (position, orientation = None))]
    fn set_kinematic_target(
        &self,
        position: &Bound<'_, PyAny>,
        orientation: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let p = vec3(position, "position")?;
        let q = match orientation {
            Some(q) => quat(q, "orientation")?,
            None => self.read(Body::orientation)?,
        };
        self.edit(|g, id| g.world.set_kinematic_target(id, p, q))
    }

    /// Rolling resistance coefficient (dimensionless): rolling torque at most μ_r r N.
    #[getter]
    fn rolling_resistance(&self) -> PyResult<f64> {
        self.read(|b| wide(b.rolling_resistance()))
    }

    /// Torsional friction (m): spinning torque about the contact normal at most μ_t N.
    #[getter]
    fn torsional_friction(&self) -> PyResult<f64> {
        self.read(|b| wide(b.torsional_friction()))
    }

    /// Applies an impulse (N·s, world frame) at a world point (m; default the centre of
    /// mass): Δp = J, ΔL = (point − x) × J. Ignored for static and kinematic bodies.
    #[pyo3(signature = (impulse, point = None))]
    fn apply_impulse(
        &self,
        impulse: &Bound<'_, PyAny>,
        point: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let j = vec3(impulse, "impulse")?;
        let p = match point {
            Some(p) => vec3(p, "point")?,
            None => self.read(Body::center_of_mass)?,
        };
        self.edit(|g, id| g.world.apply_impulse(id, j, p))
    }

    /// Wakes the body's island (and the islands touching it).
    fn wake(&self) -> PyResult<()> {
        self.edit(|g, id| g.world.wake_body(id))
    }

    // The world, for the garbage collector: a force callback that holds a body of its
    // world makes a cycle through it (see `callbacks.rs`).
    fn __traverse__(&self, visit: pyo3::gc::PyVisit<'_>) -> Result<(), pyo3::PyTraverseError> {
        visit.call(&self.world)
    }

    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other.cast::<PyBody>().is_ok_and(|o| {
            let o = o.get();
            o.id == self.id && o.world.as_ptr() == self.world.as_ptr()
        })
    }

    fn __hash__(&self) -> u64 {
        let mut h = std::collections::hash_map::DefaultHasher::new();
        (
            self.world.as_ptr() as usize,
            self.id.index,
            self.id.generation,
        )
            .hash(&mut h);
        h.finish()
    }

    fn __repr__(&self) -> String {
        match self.read(|b| b.name().map(str::to_string)) {
            Ok(Some(name)) => format!("<tumble.Body '{name}'>"),
            Ok(None) => format!("<tumble.Body #{}>", self.id.index),
            Err(_) => "<tumble.Body (removed)>".to_string(),
        }
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyBody>()
}
