//! Joints: `World.add_joint` for ball, hinge, slider, fixed and distance joints, with
//! their limits, motors and springs, and `tumble.Joint` handles that read the reaction.

use numpy::PyArray1;
use pyo3::exceptions::{PyKeyError, PyTypeError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use tumble::joint::{JointOption, JointOptions, KindSpec, OptionShape, OptionValue};
use tumble::{BodyId, JointDef, JointId, JointKind, Quat, Vec3};

use crate::body::{handle, PyBody};
use crate::convert::{engine, invalid, numbers, real, vec3, vec3_out, wrong_type};
use crate::world::{body_arg, checked_name, Inner, PyWorld};

/// A velocity motor on a hinge or slider: drive the joint at `speed` (rad/s or m/s) with
/// at most `max_force` (N·m for hinges, N for sliders).
#[pyclass(module = "tumble", name = "Motor", frozen, get_all)]
pub struct PyMotor {
    /// Target speed (rad/s for hinges, m/s for sliders).
    pub(crate) speed: f64,
    /// Largest torque (N·m) or force (N) the motor may exert.
    pub(crate) max_force: f64,
}

#[pymethods]
impl PyMotor {
    #[new]
    fn new(speed: f64, max_force: f64) -> Self {
        PyMotor { speed, max_force }
    }

    fn __repr__(&self) -> String {
        format!("tumble.Motor({}, {})", self.speed, self.max_force)
    }
}

/// A spring on a joint's free coordinate: natural frequency `hertz` (Hz), `damping_ratio`
/// (1 = critical) and rest angle or position `target` (rad or m; a distance joint's rest
/// length is its `length`).
#[pyclass(module = "tumble", name = "JointSpring", frozen, get_all)]
pub struct PyJointSpring {
    /// Natural frequency (Hz).
    pub(crate) hertz: f64,
    /// Damping ratio (1 = critical).
    pub(crate) damping_ratio: f64,
    /// Rest angle (rad) or position (m).
    pub(crate) target: f64,
}

#[pymethods]
impl PyJointSpring {
    #[new]
    #[pyo3(signature = (hertz, damping_ratio = 1.0, target = 0.0))]
    fn new(hertz: f64, damping_ratio: f64, target: f64) -> Self {
        PyJointSpring {
            hertz,
            damping_ratio,
            target,
        }
    }

    fn __repr__(&self) -> String {
        format!(
            "tumble.JointSpring({}, damping_ratio={}, target={})",
            self.hertz, self.damping_ratio, self.target
        )
    }
}

/// A position servo on a hinge or slider: drives the joint towards `target` (rad or m)
/// as a spring of `stiffness` (N·m/rad or N/m) and a damper of `damping` (N·m·s/rad or
/// N·s/m) would, with at most `max_force` (N·m or N); solved implicitly, stable at any
/// stiffness.
#[pyclass(module = "tumble", name = "Servo", frozen, get_all)]
pub struct PyServo {
    /// Target angle (rad) or position (m).
    pub(crate) target: f64,
    /// Stiffness (N·m/rad or N/m).
    pub(crate) stiffness: f64,
    /// Damping (N·m·s/rad or N·s/m).
    pub(crate) damping: f64,
    /// Largest torque (N·m) or force (N).
    pub(crate) max_force: f64,
}

#[pymethods]
impl PyServo {
    #[new]
    fn new(target: f64, stiffness: f64, damping: f64, max_force: f64) -> Self {
        PyServo {
            target,
            stiffness,
            damping,
            max_force,
        }
    }

    fn __repr__(&self) -> String {
        format!(
            "tumble.Servo({}, {}, {}, {})",
            self.target, self.stiffness, self.damping, self.max_force
        )
    }
}

/// A joint in a world: its `name`, `kind`, `body` and `other` (None: the world), whether it
/// is `broken`, and the `reaction_force` (N) and `reaction_torque` (N·m) it applied to
/// `other` over the last step (`body` felt the opposite).
#[pyclass(module = "tumble", name = "Joint", frozen)]
pub struct PyJoint {
    pub(crate) world: Py<PyWorld>,
    pub(crate) id: JointId,
}

impl PyJoint {
    pub(crate) fn read<R>(&self, f: impl FnOnce(&tumble::Joint) -> R) -> PyResult<R> {
        let g = self.world.get().lock()?;
        Ok(f(g.world.joint(self.id).map_err(engine)?))
    }
}

#[pymethods]
impl PyJoint {
    // The world, for the garbage collector (see `PyBody::__traverse__`).
    fn __traverse__(&self, visit: pyo3::gc::PyVisit<'_>) -> Result<(), pyo3::PyTraverseError> {
        visit.call(&self.world)
    }

    /// The joint's name, or None.
    #[getter]
    fn name(&self) -> PyResult<Option<String>> {
        self.read(|j| j.name().map(str::to_string))
    }

    /// "ball", "hinge", "slider", "fixed" or "distance".
    #[getter]
    fn kind(&self) -> PyResult<&'static str> {
        self.read(|j| j.kind().name())
    }

    /// The first body.
    #[getter]
    fn body<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyBody>> {
        let id = self.read(|j| j.body())?;
        handle(self.world.bind(py), id)
    }

    /// The second body, or None when the joint holds `body` to the world.
    #[getter]
    fn other<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyBody>>> {
        let id = self.read(|j| j.other())?;
        id.map(|id| handle(self.world.bind(py), id)).transpose()
    }

    /// Whether the joint broke (its reaction exceeded `break_force`); a broken joint
    /// holds nothing.
    #[getter]
    fn broken(&self) -> PyResult<bool> {
        self.read(|j| j.is_broken())
    }

    /// Force the joint applied to `other` over the last step (N, world frame), array (3,);
    /// the force on `body` is its opposite.
    #[getter]
    fn reaction_force<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(vec3_out(py, self.read(|j| j.reaction_force())?))
    }

    /// Torque the joint applied to `other` about its anchor over the last step (N·m, world
    /// frame), array (3,).
    #[getter]
    fn reaction_torque<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(vec3_out(py, self.read(|j| j.reaction_torque())?))
    }

    /// Whether the joint still exists in its world.
    #[getter]
    fn alive(&self) -> PyResult<bool> {
        Ok(self.world.get().lock()?.world.joint(self.id).is_ok())
    }

    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other.cast::<PyJoint>().is_ok_and(|o| {
            let o = o.get();
            o.id == self.id && o.world.as_ptr() == self.world.as_ptr()
        })
    }

    fn __hash__(&self) -> u64 {
        (u64::from(self.id.generation) << 32) | u64::from(self.id.index)
    }

    fn __repr__(&self) -> String {
        match self.read(|j| (j.kind().name(), j.name().map(str::to_string))) {
            Ok((kind, Some(name))) => format!("<tumble.Joint {kind} '{name}'>"),
            Ok((kind, None)) => format!("<tumble.Joint {kind} #{}>", self.id.index),
            Err(_) => "<tumble.Joint (removed)>".into(),
        }
    }
}

pub(crate) fn joint_handle<'py>(
    world: &Bound<'py, PyWorld>,
    id: JointId,
) -> PyResult<Bound<'py, PyJoint>> {
    Bound::new(
        world.py(),
        PyJoint {
            world: world.clone().unbind(),
            id,
        },
    )
}

/// The option `key` of a joint, if given and not None.
fn given<'py>(
    options: Option<&Bound<'py, PyDict>>,
    key: &str,
) -> PyResult<Option<Bound<'py, PyAny>>> {
    let Some(options) = options else {
        return Ok(None);
    };
    Ok(options.get_item(key)?.filter(|v| !v.is_none()))
}

/// Refuses an option the kind does not take: the first of `JointOption::ALL` given, then
/// any key that is no option at all.
fn check_keys(spec: &KindSpec, options: Option<&Bound<'_, PyDict>>) -> PyResult<()> {
    let known = JointOption::ALL.iter().map(|o| o.key());
    let mut bad = None;
    for key in known {
        if !spec.keys().any(|k| k == key) && given(options, key)?.is_some() {
            bad = Some(key.to_string());
            break;
        }
    }
    if bad.is_none() {
        for (key, value) in options.iter().flat_map(|o| o.iter()) {
            let key: String = key.extract()?;
            if !value.is_none() && !spec.keys().any(|k| k == key) {
                bad = Some(key);
                break;
            }
        }
    }
    match bad {
        None => Ok(()),
        Some(key) => {
            let allowed: Vec<&str> = spec.keys().collect();
            Err(PyTypeError::new_err(format!(
                "{key}: not an option of a {} joint (its options: {})",
                spec.name,
                if allowed.is_empty() {
                    "none".to_string()
                } else {
                    allowed.join(", ")
                }
            )))
        }
    }
}

/// One option's value, read by its shape.
pub(crate) fn option_value(option: JointOption, o: &Bound<'_, PyAny>) -> PyResult<OptionValue> {
    let key = option.key();
    Ok(match option.shape() {
        OptionShape::Real => {
            let x: f64 = o.extract().map_err(|_| wrong_type(key, "a number", o))?;
            OptionValue::Real(real(x))
        }
        OptionShape::Range => {
            let v = numbers(o, key, 2, "[lower, upper]")?;
            OptionValue::Range([real(v[0]), real(v[1])])
        }
        OptionShape::Motor => {
            let m = o
                .cast::<PyMotor>()
                .map_err(|_| wrong_type(key, "a tumble.Motor(speed, max_force)", o))?;
            let m = m.get();
            OptionValue::Motor(tumble::Motor {
                speed: real(m.speed),
                max_force: real(m.max_force),
            })
        }
        OptionShape::Spring => {
            let s = o
                .cast::<PyJointSpring>()
                .map_err(|_| wrong_type(key, "a tumble.JointSpring(hertz, ...)", o))?;
            let s = s.get();
            OptionValue::Spring(tumble::JointSpring {
                hertz: real(s.hertz),
                damping_ratio: real(s.damping_ratio),
                target: real(s.target),
            })
        }
        OptionShape::Servo => {
            let s = o.cast::<PyServo>().map_err(|_| {
                wrong_type(
                    key,
                    "a tumble.Servo(target, stiffness, damping, max_force)",
                    o,
                )
            })?;
            let s = s.get();
            OptionValue::Servo(tumble::Servo {
                target: real(s.target),
                stiffness: real(s.stiffness),
                damping: real(s.damping),
                max_force: real(s.max_force),
            })
        }
    })
}

/// The joint kind called `name` with the keyword options given, as its description
/// (`tumble::joint::JOINT_KINDS`) lists them.
fn kind_of(name: &str, options: Option<&Bound<'_, PyDict>>) -> PyResult<JointKind> {
    let Some(spec) = KindSpec::named(name) else {
        return Err(invalid(
            "kind",
            format!(
                "unknown joint type '{name}' (expected one of: {})",
                tumble_scene::JOINT_TYPES.join(", ")
            ),
        ));
    };
    check_keys(spec, options)?;
    let mut values = JointOptions::default();
    for option in spec.options.iter().map(|o| o.option) {
        if let Some(o) = given(options, option.key())? {
            values
                .set(option, option_value(option, &o)?)
                .map_err(engine)?;
        }
    }
    JointKind::from_options(spec.name, &values)
        .ok_or_else(|| invalid("kind", format!("unknown joint type '{name}'")))
}

/// A body's frame (origin and rotation); the world's is the identity.
fn frame(g: &Inner, id: Option<BodyId>) -> (Vec3, Quat) {
    id.and_then(|id| g.world.body(id).ok())
        .map(|b| (b.pose().position, b.pose().rotation))
        .unwrap_or((Vec3::ZERO, Quat::IDENTITY))
}

#[pymethods]
impl PyWorld {
    /// Adds a joint of `kind` ("ball", "hinge", "slider", "fixed" or "distance") between
    /// `body` and `other` (a body or name; None: the world) and returns its handle.
    ///
    /// `anchor` and `axis` are in `body`'s frame (m; axis default x); `other_anchor` and
    /// `other_axis` in `other`'s frame, or world coordinates when joined to the world; left
    /// out, they are where `body`'s anchor and axis are now, so the joint starts satisfied.
    /// Options by kind (keywords; None counts as left out): ball `cone` (rad) and `twist`
    /// [lo, hi] (rad); hinge and slider `limits` [lo, hi] (rad or m), `motor`
    /// (tumble.Motor), `spring` (tumble.JointSpring), `servo` (tumble.Servo); distance `length`, `min`, `max` (m)
    /// and `spring`. `collide_connected` lets the two bodies still collide; `break_force`
    /// (N) breaks the joint when exceeded; `armature` (hinge kg m², slider kg) is the
    /// coordinate's rotor inertia, MuJoCo's armature.
    #[pyo3(signature = (kind, body, other = None, *, anchor = None, axis = None,
        other_anchor = None, other_axis = None, name = None, collide_connected = false,
        break_force = None, armature = 0.0, **options))]
    #[allow(clippy::too_many_arguments)]
    fn add_joint<'py>(
        slf: &Bound<'py, Self>,
        kind: String,
        body: &Bound<'py, PyAny>,
        other: Option<&Bound<'py, PyAny>>,
        anchor: Option<&Bound<'py, PyAny>>,
        axis: Option<&Bound<'py, PyAny>>,
        other_anchor: Option<&Bound<'py, PyAny>>,
        other_axis: Option<&Bound<'py, PyAny>>,
        name: Option<String>,
        collide_connected: bool,
        break_force: Option<f64>,
        armature: f64,
        options: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, PyJoint>> {
        let kind = kind_of(&kind, options)?;
        let id = {
            let mut g = slf.get().lock()?;
            let a = body_arg(slf, &g, body, "body")?;
            let b = other.map(|o| body_arg(slf, &g, o, "other")).transpose()?;
            let anchor = anchor.map_or(Ok(Vec3::ZERO), |v| vec3(v, "anchor"))?;
            let axis = axis.map_or(Ok(Vec3::X), |v| vec3(v, "axis"))?;
            // As in scene files: a missing far end is where `body`'s anchor and axis are.
            let (pa, qa) = frame(&g, Some(a));
            let (pb, qb) = frame(&g, b);
            let other_anchor = match other_anchor {
                Some(v) => vec3(v, "other_anchor")?,
                None => qb.inverse() * (pa + qa * anchor - pb),
            };
            let other_axis = match other_axis {
                Some(v) => vec3(v, "other_axis")?,
                None => qb.inverse() * (qa * axis),
            };
            let def = JointDef {
                name: checked_name(name, "joints")?,
                kind,
                body: a,
                anchor,
                axis,
                other: b,
                other_anchor,
                other_axis,
                collide_connected,
                break_force: break_force.map(real),
                armature: real(armature),
            };
            g.world.create_joint(&def).map_err(engine)?
        };
        joint_handle(slf, id)
    }

    /// Removes a joint, waking the bodies it held; False if it was already gone.
    fn remove_joint(&self, joint: &Bound<'_, PyAny>) -> PyResult<bool> {
        let j = joint
            .cast::<PyJoint>()
            .map_err(|_| wrong_type("joint", "a tumble.Joint", joint))?;
        let id = j.get().id;
        // A stale handle is the engine's error; here it is the documented False.
        Ok(self.lock()?.world.remove_joint(id).is_ok())
    }

    /// The joint called `name` (KeyError if there is none).
    fn joint<'py>(slf: &Bound<'py, Self>, name: String) -> PyResult<Bound<'py, PyJoint>> {
        let id = slf.get().lock()?.world.find_joint(&name);
        match id {
            Some(id) => joint_handle(slf, id),
            None => Err(PyKeyError::new_err(format!("no joint named '{name}'"))),
        }
    }

    /// Every joint's handle, in creation order.
    #[getter]
    fn joints<'py>(slf: &Bound<'py, Self>) -> PyResult<Vec<Bound<'py, PyJoint>>> {
        let ids: Vec<JointId> = slf.get().lock()?.world.joints().map(|(id, _)| id).collect();
        ids.into_iter().map(|id| joint_handle(slf, id)).collect()
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyMotor>()?;
    m.add_class::<PyJointSpring>()?;
    m.add_class::<PyServo>()?;
    m.add_class::<PyJoint>()?;
    Ok(())
}
