//! `tumble.World.from_mjcf`: a world from an MJCF (MuJoCo XML) model, through
//! `tumble_scene::mjcf`, and its actuators' controls (`actuators`, `set_control`,
//! `control`). What the file has that the import does not read comes out as
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
    /// qpos minus the joint's `ref` (0 unless the file sets it). The file's actuators are
    /// kept: `world.actuators`, `world.set_control(name, value)`. Bad files raise
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
            mjcf: Some(model),
        }))
    }

    /// The names of the actuators of the MJCF model the world was loaded from
    /// (`from_mjcf`), in file order; empty for other worlds.
    #[getter]
    fn actuators(&self) -> PyResult<Vec<String>> {
        let g = self.lock()?;
        Ok(g.mjcf
            .iter()
            .flat_map(|m| m.actuators.iter().map(|a| a.name.clone()))
            .collect())
    }

    /// Sets the control (MuJoCo's `ctrl`) of the actuator called `name` in the MJCF file,
    /// clamped to its `ctrlrange` as MuJoCo does: a motor's torque gear·ctrl, a position
    /// servo's target, a velocity servo's speed. Wakes the joint's bodies. An unknown
    /// name or a value that is not finite raises ValueError (`actuator 'x': ...`) and
    /// changes nothing.
    fn set_control(&self, name: &str, value: f64) -> PyResult<()> {
        let mut g = self.lock()?;
        let Inner { world, mjcf, .. } = &mut *g;
        let Some(model) = mjcf.as_mut() else {
            return Err(scene(tumble_scene::SceneError::new(
                format!("actuator '{}'", tumble_scene::printable(name)),
                "no such actuator (the world was not loaded from an MJCF file)",
            )));
        };
        model
            .set_control(world, name, crate::convert::real(value))
            .map_err(scene)
    }

    /// The control of actuator `name` as last set (after clamping to `ctrlrange`); 0
    /// until set. ValueError for an unknown name.
    fn control(&self, name: &str) -> PyResult<f64> {
        let g = self.lock()?;
        g.mjcf
            .iter()
            .flat_map(|m| m.actuators.iter())
            .find(|a| a.name == name)
            .map(|a| crate::convert::wide(a.control))
            .ok_or_else(|| {
                scene(tumble_scene::SceneError::new(
                    format!("actuator '{}'", tumble_scene::printable(name)),
                    "no such actuator",
                ))
            })
    }
}
