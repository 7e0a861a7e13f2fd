//! Every body's state as one numpy array, readable and settable without a Python loop:
//! `World.positions`, `orientations`, `velocities`, `angular_velocities`,
//! `angular_momenta` and `set_state`.
//!
//! A set is all or nothing. The arrays are converted first (a wrong type or shape is
//! refused before anything else is looked at), then handed to the engine's
//! `World::set_states` in one call, which checks every row of every array before it
//! changes any body: a refused call leaves the world bit-identical, whichever array and
//! row is wrong.

use numpy::{AllowTypeChange, PyArrayLike2};
use pyo3::intern;
use pyo3::prelude::*;
use pyo3::types::PyString;
use tumble::{Body, BodyStates, Quat, Vec3, World};

use crate::convert::{engine, invalid, not_real, real, unreal_dtype, wrong_type};
use crate::sim::{array, push3, push4};
use crate::world::PyWorld;

/// Rows of a bulk array given for every body: (n, width) real numbers, as float64.
///
/// numpy reads the value first as it is (`asarray` without a dtype), so that complex
/// numbers, strings and objects are seen for what they are and refused (TypeError),
/// rather than cast to float64 by dropping the imaginary part or parsing the text. The
/// values are not checked here: the engine checks every row before it changes any body,
/// with the same rules and messages as its single setters.
fn rows(value: &Bound<'_, PyAny>, field: &str, n: usize, width: usize) -> PyResult<Vec<Vec<f64>>> {
    let expected = format!("an array of shape (N, {width})");
    if value.is_instance_of::<PyString>() {
        return Err(wrong_type(field, &expected, value));
    }
    let py = value.py();
    let arr = py
        .import(intern!(py, "numpy"))?
        .call_method1(intern!(py, "asarray"), (value,))
        .map_err(|_| wrong_type(field, &expected, value))?;
    if let Some(got) = unreal_dtype(&arr) {
        return Err(not_real(
            field,
            &format!("{expected} of real numbers"),
            &got,
        ));
    }
    let arr: PyArrayLike2<'_, f64, AllowTypeChange> = arr
        .extract()
        .map_err(|_| wrong_type(field, &expected, value))?;
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
    Ok(view.rows().into_iter().map(|r| r.to_vec()).collect())
}

fn vectors(value: Option<&Bound<'_, PyAny>>, field: &str, n: usize) -> PyResult<Option<Vec<Vec3>>> {
    let v3 = |r: &Vec<f64>| Vec3::new(real(r[0]), real(r[1]), real(r[2]));
    value
        .map(|v| Ok(rows(v, field, n, 3)?.iter().map(v3).collect()))
        .transpose()
}

fn quaternions(value: Option<&Bound<'_, PyAny>>, n: usize) -> PyResult<Option<Vec<Quat>>> {
    let quat = |r: &Vec<f64>| Quat::from_xyzw(real(r[0]), real(r[1]), real(r[2]), real(r[3]));
    value
        .map(|v| Ok(rows(v, "orientations", n, 4)?.iter().map(quat).collect()))
        .transpose()
}

/// The bulk arrays given to `set_state` or to one of the bulk setters (None: not given).
#[derive(Default)]
struct Given<'a, 'py> {
    positions: Option<&'a Bound<'py, PyAny>>,
    orientations: Option<&'a Bound<'py, PyAny>>,
    velocities: Option<&'a Bound<'py, PyAny>>,
    angular_velocities: Option<&'a Bound<'py, PyAny>>,
}

/// Converts every array given, then sets them all in one engine call. The arrays are read
/// without the world's lock held, so that an `__array__` of the caller's that looks at the
/// world does not find it busy.
fn set_given(w: &PyWorld, given: Given<'_, '_>) -> PyResult<()> {
    let n = w.lock()?.world.body_count();
    let positions = vectors(given.positions, "positions", n)?;
    let orientations = quaternions(given.orientations, n)?;
    let velocities = vectors(given.velocities, "velocities", n)?;
    let omegas = vectors(given.angular_velocities, "angular_velocities", n)?;
    let states = BodyStates {
        positions: positions.as_deref(),
        orientations: orientations.as_deref(),
        velocities: velocities.as_deref(),
        angular_velocities: omegas.as_deref(),
    };
    // Another thread may have added a body meanwhile: the engine counts the rows again.
    w.lock()?.world.set_states(&states).map_err(engine)
}

/// One (N, width) array of every body's `f`, in creation order.
fn read_all(
    w: &PyWorld,
    py: Python<'_>,
    width: usize,
    f: impl Fn(&Body, &mut Vec<f64>),
) -> PyResult<Py<PyAny>> {
    let g = w.lock()?;
    let world: &World = &g.world;
    let mut out = Vec::with_capacity(world.body_count() * width);
    for (_, b) in world.bodies() {
        f(b, &mut out);
    }
    array(py, out, &[world.body_count(), width])
}

#[pymethods]
impl PyWorld {
    /// Every body frame's origin (m), float64 array (N, 3) in creation order; assignable
    /// with any (N, 3) array of real numbers (checked whole before anything changes).
    #[getter]
    fn positions(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        read_all(self, py, 3, |b, o| push3(o, b.position()))
    }

    #[setter]
    fn set_positions(&self, value: &Bound<'_, PyAny>) -> PyResult<()> {
        let given = Given {
            positions: Some(value),
            ..Default::default()
        };
        set_given(self, given)
    }

    /// Every body's orientation [x, y, z, w], float64 array (N, 4); assignable (each row
    /// any non-zero quaternion, normalised).
    #[getter]
    fn orientations(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        read_all(self, py, 4, |b, o| push4(o, b.orientation()))
    }

    #[setter]
    fn set_orientations(&self, value: &Bound<'_, PyAny>) -> PyResult<()> {
        let given = Given {
            orientations: Some(value),
            ..Default::default()
        };
        set_given(self, given)
    }

    /// Every body's centre-of-mass velocity (m/s), float64 array (N, 3); assignable.
    #[getter]
    fn velocities(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        read_all(self, py, 3, |b, o| push3(o, b.linear_velocity()))
    }

    #[setter]
    fn set_velocities(&self, value: &Bound<'_, PyAny>) -> PyResult<()> {
        let given = Given {
            velocities: Some(value),
            ..Default::default()
        };
        set_given(self, given)
    }

    /// Every body's angular velocity (rad/s, world frame), float64 array (N, 3);
    /// assignable.
    #[getter]
    fn angular_velocities(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        read_all(self, py, 3, |b, o| push3(o, b.angular_velocity()))
    }

    #[setter]
    fn set_angular_velocities(&self, value: &Bound<'_, PyAny>) -> PyResult<()> {
        let given = Given {
            angular_velocities: Some(value),
            ..Default::default()
        };
        set_given(self, given)
    }

    /// Every body's angular momentum about its centre of mass (kg·m²/s, world frame),
    /// float64 array (N, 3).
    #[getter]
    fn angular_momenta(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        read_all(self, py, 3, |b, o| push3(o, b.angular_momentum()))
    }

    /// Sets any of the bulk arrays at once, in the order positions, orientations,
    /// velocities, angular velocities (so ω is turned into L with the new orientation).
    /// All or nothing: every row of every array is checked before any body changes.
    #[pyo3(signature = (*, positions = None, orientations = None, velocities = None, angular_velocities = None))]
    fn set_state(
        &self,
        positions: Option<&Bound<'_, PyAny>>,
        orientations: Option<&Bound<'_, PyAny>>,
        velocities: Option<&Bound<'_, PyAny>>,
        angular_velocities: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let given = Given {
            positions,
            orientations,
            velocities,
            angular_velocities,
        };
        set_given(self, given)
    }
}
