//! `tumble._tumble`, the extension module behind Python's `import tumble`.
//!
//! Everything here is a thin layer over the Rust core and `tumble-scene`: the physics, the
//! validation and the error texts are theirs. What the binding adds is conversion (numbers
//! and numpy arrays in, numpy arrays out, f64 whatever `tumble::Real` is), handles that
//! read live state, and loops that run in Rust with the interpreter's lock released.
//!
//! The Python-facing names, signatures and docstrings are mirrored in
//! `python/tumble/_tumble.pyi`; keep the two in step.

mod batch;
mod body;
mod bulk;
mod callbacks;
mod character;
mod convert;
mod joint_control;
mod joints;
mod mjcf;
mod models;
mod query;
mod render;
mod scenes;
mod shapes;
mod sim;
mod snapshots;
mod steps;
mod world;

use pyo3::prelude::*;

/// Tumble, a rigid-body dynamics engine (Rust core).
#[pymodule]
#[pyo3(name = "_tumble")]
fn tumble_module(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add(
        "INTEGRATORS",
        tumble::Integrator::ALL
            .iter()
            .map(|i| i.name())
            .collect::<Vec<_>>(),
    )?;
    m.add("SCENES", tumble_scene::builtin_names())?;
    // Whether the core was built with f32 numbers; arrays are float64 either way.
    m.add("SINGLE_PRECISION", std::mem::size_of::<tumble::Real>() == 4)?;
    m.add(
        "SimulationError",
        m.py().get_type::<convert::SimulationError>(),
    )?;
    shapes::register(m)?;
    world::register(m)?;
    body::register(m)?;
    sim::register(m)?;
    query::register(m)?;
    joints::register(m)?;
    character::register(m)?;
    callbacks::register(m)?;
    models::register(m)?;
    batch::register(m)?;
    scenes::register(m)?;
    Ok(())
}
