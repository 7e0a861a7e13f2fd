//! `tumble._tumble.builtin_scene(name)`: the JSON text of a built-in scene, so that Python
//! (tumble.sweep) can patch a built-in's document as it patches a file's.

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// The JSON text of the built-in scene `name` (ValueError naming the built-ins if none).
#[pyfunction]
fn builtin_scene(name: &str) -> PyResult<&'static str> {
    tumble_scene::builtin(name).ok_or_else(|| {
        PyValueError::new_err(format!(
            "scene: '{}' is not a built-in scene ({})",
            name.escape_default(),
            tumble_scene::builtin_names().join(", ")
        ))
    })
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(builtin_scene, m)?)
}
