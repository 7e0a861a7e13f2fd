//! Snapshots from Python (issue 18): `world.snapshot()` → bytes, `world.restore(data)`,
//! `tumble.World.from_snapshot(data)`, and through them `pickle` and `copy.deepcopy` of a
//! world. The bytes are the engine's (`World::snapshot`): continuing from them is
//! bit-identical to never having stopped.

use pyo3::prelude::*;
use pyo3::types::PyBytes;
use tumble::{Real, World};

use crate::convert::{engine, real, wide};
use crate::world::{Inner, PyWorld};

fn restored(data: &[u8], dt: Real, duration: Real) -> PyResult<PyWorld> {
    let world = World::from_snapshot(data).map_err(engine)?;
    Ok(PyWorld::new_inner(Inner {
        world,
        dt,
        duration,
        callbacks: None,
        mjcf: None,
    }))
}

#[pymethods]
impl PyWorld {
    /// The world's whole state as bytes (a compact, versioned format with a checksum):
    /// `restore` or `World.from_snapshot` continue it bit-identically. Force callbacks,
    /// the contact filter and the contact modifier are code and not saved: a world
    /// restored into keeps its own, and must have as many force callbacks as were saved.
    fn snapshot<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyBytes>> {
        let bytes = self.lock()?.world.snapshot();
        Ok(PyBytes::new(py, &bytes))
    }

    /// Replaces the world's state with `data` (from `snapshot`). A bad snapshot
    /// (truncated, changed, another version or precision, or force callbacks that do not
    /// match) raises ValueError `snapshot: ...` and changes nothing.
    fn restore(&self, data: &[u8]) -> PyResult<()> {
        self.lock()?.world.restore(data).map_err(engine)
    }

    /// A new world continuing `data` (from `snapshot`), with the default step and run
    /// length of `simulate`. A snapshot of a world with force callbacks is refused: make
    /// a World, add as many callbacks, then `restore`.
    #[staticmethod]
    fn from_snapshot(data: &[u8]) -> PyResult<PyWorld> {
        restored(
            data,
            tumble_scene::DEFAULT_DT,
            tumble_scene::DEFAULT_DURATION,
        )
    }

    /// For pickle: the snapshot plus `simulate`'s default step and run length.
    #[staticmethod]
    fn _from_pickle(data: &[u8], dt: f64, duration: f64) -> PyResult<PyWorld> {
        restored(data, real(dt), real(duration))
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyAny>> {
        let py = slf.py();
        let (bytes, dt, duration) = {
            let g = slf.get().lock()?;
            (g.world.snapshot(), wide(g.dt), wide(g.duration))
        };
        let make = slf.get_type().getattr("_from_pickle")?;
        (make, (PyBytes::new(py, &bytes), dt, duration))
            .into_pyobject(py)
            .map(|t| t.into_any())
    }

    fn __deepcopy__(&self, _memo: &Bound<'_, PyAny>) -> PyResult<PyWorld> {
        self.__copy__()
    }

    /// Writes the world as a scene file (docs/scene-format.md) at `path`: every body,
    /// force and joint as scene keys, `simulate`'s default `dt` and `duration`, and with
    /// `state=True` (the default) the world's snapshot as the `"state"` section, so that
    /// `World.from_scene(path)` continues it bit-identically. Without it the file is a
    /// fresh scene at the current poses and velocities.
    #[pyo3(signature = (path, *, state = true))]
    fn save_scene(&self, path: std::path::PathBuf, state: bool) -> PyResult<()> {
        let text = {
            let g = self.lock()?;
            let options = tumble_scene::SaveOptions {
                dt: g.dt,
                duration: g.duration,
                state,
                ..Default::default()
            };
            tumble_scene::save_with(&g.world, &options)
        };
        std::fs::write(&path, text).map_err(PyErr::from)
    }

    /// A copy is a deep one: the world's state through a snapshot.
    fn __copy__(&self) -> PyResult<PyWorld> {
        let g = self.lock()?;
        restored(&g.world.snapshot(), g.dt, g.duration)
    }
}
