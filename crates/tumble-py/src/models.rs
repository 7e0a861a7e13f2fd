//! Model files: `World.from_urdf` and `World.add_urdf` over `tumble_scene::urdf`, and
//! `tumble.Model`, what a file became (its bodies and joints by the file's names).

use pyo3::prelude::*;
use pyo3::types::PyDict;
use tumble::{World, WorldDef};
use tumble_scene::urdf::{self, Imported, UrdfOptions};

use crate::convert::{engine, quat_or, scene, vec3_or};
use crate::joints::joint_handle;
use crate::world::{Inner, PyWorld};

/// What a model file became in a world: its `name`, `bodies` (a dict from each link's
/// name in the file to its tumble.Body; links merged by fixed joints share one),
/// `joints` (a dict from each joint's name to its tumble.Joint, whose `position` is the
/// file's joint coordinate) and `warnings` (what was read but not built as written).
#[pyclass(module = "tumble", name = "Model", frozen, get_all)]
pub struct PyModel {
    /// The file's model name (URDF's <robot name>).
    name: String,
    /// Each link by its name in the file: its tumble.Body (links merged by fixed joints
    /// share one).
    bodies: Py<PyDict>,
    /// Each joint by its name in the file: its tumble.Joint, whose `position` is the
    /// file's joint coordinate.
    joints: Py<PyDict>,
    /// What was read but not built as written, one line each.
    warnings: Vec<String>,
}

#[pymethods]
impl PyModel {
    fn __repr__(&self, py: Python<'_>) -> String {
        format!(
            "<tumble.Model '{}': {} links, {} joints>",
            self.name,
            self.bodies.bind(py).len(),
            self.joints.bind(py).len()
        )
    }
}

fn model<'py>(world: &Bound<'py, PyWorld>, m: Imported) -> PyResult<PyModel> {
    let py = world.py();
    let bodies = PyDict::new(py);
    for (name, id) in m.bodies {
        bodies.set_item(name, crate::body::handle(world, id)?)?;
    }
    let joints = PyDict::new(py);
    for (name, id) in m.joints {
        joints.set_item(name, joint_handle(world, id)?)?;
    }
    Ok(PyModel {
        name: m.name,
        bodies: bodies.unbind(),
        joints: joints.unbind(),
        warnings: m.warnings,
    })
}

fn options(
    fixed_base: bool,
    position: Option<&Bound<'_, PyAny>>,
    orientation: Option<&Bound<'_, PyAny>>,
    merge_fixed: bool,
    prefix: Option<String>,
    self_collision: bool,
) -> PyResult<UrdfOptions> {
    Ok(UrdfOptions {
        fixed_base,
        position: vec3_or(position, "position", tumble::Vec3::ZERO)?,
        orientation: quat_or(orientation, "orientation")?,
        merge_fixed,
        prefix: prefix.unwrap_or_default(),
        self_collision,
    })
}

#[pymethods]
impl PyWorld {
    /// A world holding the URDF model at `path`, with `gravity` (m/s², default z-up
    /// (0, 0, −9.81): URDF models are z-up and are never turned). `fixed_base` makes the
    /// root link static; `position` (m) and `orientation` [x, y, z, w] place it;
    /// `merge_fixed` makes links joined by fixed joints one body (else welds);
    /// `self_collision` makes the model's links that no joint connects collide with each
    /// other (default False, as PyBullet's: they still collide with everything else).
    /// Bodies and joints are named as in the file (`world.body("upper")`,
    /// `world.joint("elbow")`). What the file has that is not built as written (an impossible
    /// inertia taken from the geometry, say) comes out as Python warnings (UserWarning), as
    /// `add_urdf` lists it. A bad file raises ValueError naming file, line and element.
    #[staticmethod]
    #[pyo3(signature = (path, *, fixed_base = true, gravity = None, position = None,
        orientation = None, merge_fixed = true, self_collision = false))]
    // The keyword arguments of a Python constructor, and the interpreter for its warnings.
    #[allow(clippy::too_many_arguments)]
    fn from_urdf(
        py: Python<'_>,
        path: std::path::PathBuf,
        fixed_base: bool,
        gravity: Option<&Bound<'_, PyAny>>,
        position: Option<&Bound<'_, PyAny>>,
        orientation: Option<&Bound<'_, PyAny>>,
        merge_fixed: bool,
        self_collision: bool,
    ) -> PyResult<Self> {
        let def = WorldDef {
            gravity: vec3_or(gravity, "gravity", urdf::GRAVITY)?,
            ..WorldDef::default()
        };
        let opts = options(
            fixed_base,
            position,
            orientation,
            merge_fixed,
            None,
            self_collision,
        )?;
        let mut world = World::try_new(&def).map_err(engine)?;
        let model = urdf::load(&path, &mut world, &opts).map_err(scene)?;
        // What was read but not built as written, as `add_urdf` lists it in `warnings`.
        let category = py.get_type::<pyo3::exceptions::PyUserWarning>();
        for w in &model.warnings {
            let text = std::ffi::CString::new(w.replace('\0', "\\0"))?;
            PyErr::warn(py, &category, &text, 1)?;
        }
        Ok(PyWorld::new_inner(Inner {
            world,
            dt: tumble_scene::DEFAULT_DT,
            duration: tumble_scene::DEFAULT_DURATION,
            callbacks: None,
            mjcf: None,
        }))
    }

    /// Adds the URDF model at `path` to this world and returns a tumble.Model (its bodies
    /// and joints by the file's names). Keywords as `from_urdf`'s, and `prefix`, put
    /// before every body and joint name in the world (the Model's keys stay the file's)
    /// so that one file can be added twice (the copies collide with each other whatever
    /// `self_collision` says). All or nothing: a bad file raises ValueError and adds
    /// nothing.
    #[pyo3(signature = (path, *, position = None, orientation = None, fixed_base = true,
        merge_fixed = true, prefix = None, self_collision = false))]
    #[allow(clippy::too_many_arguments)]
    fn add_urdf<'py>(
        slf: &Bound<'py, Self>,
        path: std::path::PathBuf,
        position: Option<&Bound<'py, PyAny>>,
        orientation: Option<&Bound<'py, PyAny>>,
        fixed_base: bool,
        merge_fixed: bool,
        prefix: Option<String>,
        self_collision: bool,
    ) -> PyResult<PyModel> {
        let opts = options(
            fixed_base,
            position,
            orientation,
            merge_fixed,
            prefix,
            self_collision,
        )?;
        let imported = {
            let mut g = slf.get().lock()?;
            urdf::load(&path, &mut g.world, &opts).map_err(scene)?
        };
        model(slf, imported)
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyModel>()
}
