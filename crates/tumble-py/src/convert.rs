//! Python values in, Python values out: numbers, vectors and quaternions as sequences or
//! numpy arrays, errors as ValueError/TypeError naming the field.

use numpy::{PyArray1, PyArrayMethods};
use pyo3::exceptions::{PyRuntimeError, PyTypeError, PyValueError};
use pyo3::intern;
use pyo3::prelude::*;
use pyo3::types::{PyFloat, PyInt, PyList, PyTuple};
use tumble::{Mat3, Quat, Real, Vec3};

/// A Python float as the core's number type.
// With the default f64 build the cast is the identity; it narrows under `tumble/f32`.
#[allow(clippy::unnecessary_cast)]
pub fn real(x: f64) -> Real {
    x as Real
}

/// A core number as a Python float.
#[allow(clippy::unnecessary_cast)]
pub fn wide(x: Real) -> f64 {
    x as f64
}

pyo3::create_exception!(
    tumble,
    SimulationError,
    PyRuntimeError,
    "A step whose result was not finite or faster than the world's speed limits; the step \
     was undone, so the world is as it was after the last good step. The message names the \
     step, the time, the body and the quantity (`step 41 (t = 0.683 s): bodies[7] \"pelvis\": \
     velocity is not finite`); so do the attributes `step`, `time` (s), `body` (index in \
     creation order), `name`, `quantity` and `problem`. From `simulate`, `trajectory` is the \
     run recorded up to the last good step (None elsewhere)."
);

/// The core's refusal, whose text already names the field (`shape.radius: must be > 0`);
/// a step that broke the finite-state invariant is a SimulationError, not bad input.
pub fn engine(e: tumble::Error) -> PyErr {
    match e {
        e if e.is_step_failure() => Python::attach(|py| failed_step(py, &e, None)),
        other => PyValueError::new_err(other.to_string()),
    }
}

/// A SimulationError carrying where and when the step failed, as attributes as well as in
/// its one-line message, so a caller can react (smaller dt, that body) without parsing. A
/// step past `max_contacts` has `quantity` "contacts" and no body.
pub fn failed_step(py: Python<'_>, e: &tumble::Error, trajectory: Option<Py<PyAny>>) -> PyErr {
    let err = SimulationError::new_err(e.to_string());
    let set = || -> PyResult<()> {
        let v = err.value(py);
        match e {
            tumble::Error::Unstable(u) => {
                v.setattr("step", u.step)?;
                v.setattr("time", wide(u.time))?;
                v.setattr("body", u.index)?;
                v.setattr("name", u.name.as_deref())?;
                v.setattr("quantity", u.quantity)?;
                v.setattr("problem", u.problem.as_str())?;
            }
            tumble::Error::TooManyContacts(c) => {
                v.setattr("step", c.step)?;
                v.setattr("time", wide(c.time))?;
                v.setattr("body", py.None())?;
                v.setattr("name", py.None())?;
                v.setattr("quantity", "contacts")?;
                let problem = format!("more than max_contacts = {} manifolds", c.limit);
                v.setattr("problem", problem)?;
            }
            _ => {}
        }
        v.setattr("trajectory", trajectory)
    };
    match set() {
        Ok(()) => err,
        Err(e) => e,
    }
}

/// The scene loader's refusal, `bodies[3].shape.radius: must be > 0`.
pub fn scene(e: tumble_scene::SceneError) -> PyErr {
    PyValueError::new_err(e.to_string())
}

/// A ValueError in the engine's `field: reason` form.
pub fn invalid(field: &str, reason: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(format!("{field}: {reason}"))
}

/// A TypeError in the same form.
pub fn wrong_type(field: &str, expected: &str, got: &Bound<'_, PyAny>) -> PyErr {
    let type_name = got
        .get_type()
        .name()
        .map(|n| n.to_string())
        .unwrap_or_else(|_| "?".into());
    PyTypeError::new_err(format!("{field}: expected {expected}, got {type_name}"))
}

/// What a numpy array's or scalar's dtype holds when it is not real numbers (`complex
/// numbers (complex128)`), or None for real numbers and for anything that is not numpy's.
/// numpy casts complex to float by dropping the imaginary part and strings to float by
/// parsing them; a position given as either is a mistake to report, not to guess at.
pub fn unreal_dtype(obj: &Bound<'_, PyAny>) -> Option<String> {
    let dtype = obj.getattr(intern!(obj.py(), "dtype")).ok()?;
    let kind: String = dtype
        .getattr(intern!(obj.py(), "kind"))
        .ok()?
        .extract()
        .ok()?;
    let what = match kind.as_str() {
        // bool, signed and unsigned integers, floats: numbers as Python's int and float are.
        "b" | "i" | "u" | "f" => return None,
        "c" => "complex numbers",
        "U" | "S" => "strings",
        "O" => "Python objects",
        "M" | "m" => "dates or times",
        _ => "raw data",
    };
    let name = dtype.str().map(|s| s.to_string()).unwrap_or(kind);
    Some(format!("{what} ({name})"))
}

/// A TypeError for a value holding `what` (from [`unreal_dtype`]) where numbers belong.
pub fn not_real(field: &str, expected: &str, what: &str) -> PyErr {
    PyTypeError::new_err(format!("{field}: expected {expected}, got {what}"))
}

/// `n` numbers from any sequence or 1-D array.
pub fn numbers(obj: &Bound<'_, PyAny>, field: &str, n: usize, what: &str) -> PyResult<Vec<f64>> {
    let count = |got: usize| invalid(field, format!("expected {what}, got {got} numbers"));
    // A contiguous float64 vector (what numpy arithmetic gives) is read as it lies: item by
    // item, each a numpy scalar, costs a microsecond more (a force callback's vectors).
    if let Ok(array) = obj.cast::<PyArray1<f64>>() {
        if let Ok(view) = array.try_readonly() {
            if let Ok(v) = view.as_slice() {
                return if v.len() == n {
                    Ok(v.to_vec())
                } else {
                    Err(count(v.len()))
                };
            }
        }
    }
    if obj.is_instance_of::<pyo3::types::PyString>() {
        return Err(wrong_type(field, what, obj));
    }
    // Tuples and lists are read directly: they have no dtype to look for (looking would
    // raise and catch an AttributeError), and a general sequence is recognised by an
    // isinstance test against collections.abc.Sequence; together about a microsecond.
    // Their items are still checked one by one.
    let items: Vec<Bound<'_, PyAny>> = if let Ok(t) = obj.cast::<PyTuple>() {
        t.iter().collect()
    } else if let Ok(l) = obj.cast::<PyList>() {
        l.iter().collect()
    } else {
        if let Some(got) = unreal_dtype(obj) {
            return Err(not_real(field, what, &got));
        }
        obj.extract().map_err(|_| wrong_type(field, what, obj))?
    };
    let v = items
        .iter()
        .map(|x| {
            // Python's float and int are the common case, and numpy's float64 (a float
            // subclass, the items of a float64 array) is real too; anything else may be a
            // numpy scalar, whose complex kind would convert with its imaginary part
            // dropped. (The dtype look-up costs about 1 µs an item: a force callback's
            // `add_force(body, -k * ctx.position(body))` pays it on none.)
            if !(x.is_instance_of::<PyFloat>() || x.is_instance_of::<PyInt>()) {
                if let Some(got) = unreal_dtype(x) {
                    return Err(not_real(field, what, &got));
                }
            }
            x.extract::<f64>().map_err(|_| wrong_type(field, what, obj))
        })
        .collect::<PyResult<Vec<f64>>>()?;
    if v.len() != n {
        return Err(count(v.len()));
    }
    Ok(v)
}

/// `[x, y, z]`.
pub fn vec3(obj: &Bound<'_, PyAny>, field: &str) -> PyResult<Vec3> {
    let v = numbers(obj, field, 3, "3 numbers [x, y, z]")?;
    Ok(Vec3::new(real(v[0]), real(v[1]), real(v[2])))
}

/// `[x, y, z]`, or `default` when not given.
pub fn vec3_or(obj: Option<&Bound<'_, PyAny>>, field: &str, default: Vec3) -> PyResult<Vec3> {
    obj.map_or(Ok(default), |o| vec3(o, field))
}

/// A quaternion `[x, y, z, w]`; the engine checks it is non-zero and normalises it.
pub fn quat(obj: &Bound<'_, PyAny>, field: &str) -> PyResult<Quat> {
    let v = numbers(obj, field, 4, "a quaternion of 4 numbers [x, y, z, w]")?;
    Ok(Quat::from_xyzw(
        real(v[0]),
        real(v[1]),
        real(v[2]),
        real(v[3]),
    ))
}

/// A quaternion, or the identity when not given.
pub fn quat_or(obj: Option<&Bound<'_, PyAny>>, field: &str) -> PyResult<Quat> {
    obj.map_or(Ok(Quat::IDENTITY), |o| quat(o, field))
}

/// A list of points `[[x, y, z], ...]` or an (N, 3) array.
pub fn points(obj: &Bound<'_, PyAny>, field: &str) -> PyResult<Vec<Vec3>> {
    let expected = "an array of points of shape (N, 3)";
    if obj.is_instance_of::<pyo3::types::PyString>() {
        return Err(wrong_type(field, expected, obj));
    }
    let rows: Vec<Bound<'_, PyAny>> = obj
        .extract()
        .map_err(|_| wrong_type(field, expected, obj))?;
    rows.iter()
        .enumerate()
        .map(|(i, row)| vec3(row, &format!("{field}[{i}]")))
        .collect()
}

/// A 3×3 matrix given as three rows.
pub fn mat3_rows(obj: &Bound<'_, PyAny>, field: &str) -> PyResult<Mat3> {
    let rows = points(obj, field)?;
    if rows.len() != 3 {
        return Err(invalid(field, "expected 3 rows of 3 numbers"));
    }
    Ok(Mat3::from_cols(rows[0], rows[1], rows[2]).transpose())
}

/// A vector as a float64 array of shape (3,).
pub fn vec3_out<'py>(py: Python<'py>, v: Vec3) -> Bound<'py, PyArray1<f64>> {
    PyArray1::from_vec(py, vec![wide(v.x), wide(v.y), wide(v.z)])
}

/// A quaternion as a float64 array `[x, y, z, w]`.
pub fn quat_out<'py>(py: Python<'py>, q: Quat) -> Bound<'py, PyArray1<f64>> {
    PyArray1::from_vec(py, vec![wide(q.x), wide(q.y), wide(q.z), wide(q.w)])
}

/// A matrix as a float64 array of shape (3, 3), rows first.
pub fn mat3_out<'py>(py: Python<'py>, m: Mat3) -> PyResult<Bound<'py, PyAny>> {
    let rows = [m.row(0), m.row(1), m.row(2)];
    let flat: Vec<f64> = rows
        .iter()
        .flat_map(|r| [wide(r.x), wide(r.y), wide(r.z)])
        .collect();
    Ok(PyArray1::from_vec(py, flat).reshape([3, 3])?.into_any())
}

/// The bits of a collision layer mask, checked to fit 32 bits.
pub fn layer_bits(value: i64, field: &str) -> PyResult<u32> {
    u32::try_from(value).map_err(|_| invalid(field, "must be a whole number in [0, 2**32)"))
}
