//! `tumble.World.from_mjcf`: a world from an MJCF (MuJoCo XML) model, through
//! `tumble_scene::mjcf`. What the file has that the import does not read comes out as
//! Python warnings (UserWarning), one per kind, each naming the file, line and element.

use std::ffi::CString;
use std::path::PathBuf;

use pyo3::exceptions::PyUserWarning;
use pyo3::prelude::*;

use crate::convert::scene;
use crate::world::{Inner, PyWorld};

#[pymethods]
impl PyWorld {
    /// Loads an MJCF model (MuJoCo's XML: dm_control, Gymnasium). The world gets the
    /// file's `<option>` gravity (default (0, 0, -9.81): MJCF is z-up) and integrator;
    /// its timestep becomes `simulate`'s default `dt`. Bodies and joints keep the file's
    /// names (`world.joint("elbow")`), and a hinge's or slide's `position` is MuJoCo's
    /// qpos minus the joint's `ref` (0 unless the file sets it). Bad files raise
    /// ValueError naming the file, line and element, e.g.
    /// `arm.xml:12: <geom name="upper">: size: must be > 0, got -0.1`.
    #[staticmethod]
    fn from_mjcf(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        let (s, model) = tumble_scene::mjcf::load_scene(&path).map_err(scene)?;
        let category = py.get_type::<PyUserWarning>();
        for w in &model.warnings {
            let text = CString::new(w.to_string().replace('\0', "\\0"))?;
            PyErr::warn(py, &category, &text, 1)?;
        }
        Ok(PyWorld::new_inner(Inner {
            world: s.world,
            dt: s.dt,
            duration: s.duration,
            callbacks: None,
        }))
    }
}
