//! A joint's settings and coordinates as properties of `tumble.Joint`: `motor`, `servo`,
//! `limits`, `spring`, `enabled` and `break_force` read and set while the world runs, and
//! `position` and `velocity`, the joint's coordinate (settable: it poses the mechanism).
//! Every value is checked by the engine, whose field names these are; a refused value
//! changes nothing.

use pyo3::prelude::*;
use tumble::joint::{JointOption, OptionValue};
use tumble::{JointCoordinate, JointId, World};

use crate::convert::{engine, vec3, wide, wrong_type};
use crate::joints::{option_value, PyJoint, PyJointSpring, PyMotor, PyServo};

/// A coordinate as Python sees it: a float, or a 3-tuple for ball and fixed joints.
#[derive(IntoPyObject)]
enum Coordinate {
    Scalar(f64),
    Vector((f64, f64, f64)),
}

impl From<JointCoordinate> for Coordinate {
    fn from(c: JointCoordinate) -> Self {
        match c {
            JointCoordinate::Scalar(x) => Coordinate::Scalar(wide(x)),
            JointCoordinate::Vector(v) => Coordinate::Vector((wide(v.x), wide(v.y), wide(v.z))),
        }
    }
}

impl PyJoint {
    /// Runs an edit of the world on this joint, as one locked call.
    fn edit(&self, f: impl FnOnce(&mut World, JointId) -> tumble::Result<()>) -> PyResult<()> {
        let mut g = self.world.get().lock()?;
        f(&mut g.world, self.id).map_err(engine)
    }

    /// The option's value (None when not set or not an option of the kind).
    fn option(&self, option: JointOption) -> PyResult<Option<OptionValue>> {
        self.read(|j| j.kind().options().get(option))
    }

    /// Sets `option` from a Python value (None removes it).
    fn set_option(&self, option: JointOption, value: &Bound<'_, PyAny>) -> PyResult<()> {
        let value = if value.is_none() {
            None
        } else {
            Some(option_value(option, value)?)
        };
        self.edit(|w, id| w.set_joint_option(id, option, value))
    }
}

#[pymethods]
impl PyJoint {
    /// The hinge's or slider's velocity motor (tumble.Motor), or None; settable (None
    /// switches it off).
    #[getter]
    fn motor(&self) -> PyResult<Option<PyMotor>> {
        Ok(match self.option(JointOption::Motor)? {
            Some(OptionValue::Motor(m)) => Some(PyMotor {
                speed: wide(m.speed),
                max_force: wide(m.max_force),
            }),
            _ => None,
        })
    }

    #[setter]
    fn set_motor(&self, value: &Bound<'_, PyAny>) -> PyResult<()> {
        self.set_option(JointOption::Motor, value)
    }

    /// The hinge's or slider's position servo (tumble.Servo), or None; settable.
    #[getter]
    fn servo(&self) -> PyResult<Option<PyServo>> {
        Ok(match self.option(JointOption::Servo)? {
            Some(OptionValue::Servo(s)) => Some(PyServo {
                target: wide(s.target),
                stiffness: wide(s.stiffness),
                damping: wide(s.damping),
                max_force: wide(s.max_force),
            }),
            _ => None,
        })
    }

    #[setter]
    fn set_servo(&self, value: &Bound<'_, PyAny>) -> PyResult<()> {
        self.set_option(JointOption::Servo, value)
    }

    /// The hinge's or slider's limits (lower, upper) in rad or m, or None; settable.
    #[getter]
    fn limits(&self) -> PyResult<Option<(f64, f64)>> {
        Ok(match self.option(JointOption::Limits)? {
            Some(OptionValue::Range([lo, hi])) => Some((wide(lo), wide(hi))),
            _ => None,
        })
    }

    #[setter]
    fn set_limits(&self, value: &Bound<'_, PyAny>) -> PyResult<()> {
        self.set_option(JointOption::Limits, value)
    }

    /// The spring (tumble.JointSpring) of a hinge, slider or distance joint, or None;
    /// settable.
    #[getter]
    fn spring(&self) -> PyResult<Option<PyJointSpring>> {
        Ok(match self.option(JointOption::Spring)? {
            Some(OptionValue::Spring(s)) => Some(PyJointSpring {
                hertz: wide(s.hertz),
                damping_ratio: wide(s.damping_ratio),
                target: wide(s.target),
            }),
            _ => None,
        })
    }

    #[setter]
    fn set_spring(&self, value: &Bound<'_, PyAny>) -> PyResult<()> {
        self.set_option(JointOption::Spring, value)
    }

    /// Whether the joint acts; settable. A disabled joint is not solved and its bodies
    /// collide as unjoined ones do.
    #[getter]
    fn enabled(&self) -> PyResult<bool> {
        self.read(|j| j.is_enabled())
    }

    #[setter]
    fn set_enabled(&self, value: &Bound<'_, PyAny>) -> PyResult<()> {
        let on: bool = value
            .extract()
            .map_err(|_| wrong_type("enabled", "True or False", value))?;
        self.edit(|w, id| w.set_joint_enabled(id, on))
    }

    /// The reaction force (N) beyond which the joint breaks, or None; settable.
    #[getter]
    fn break_force(&self) -> PyResult<Option<f64>> {
        self.read(|j| j.def().break_force.map(wide))
    }

    #[setter]
    fn set_break_force(&self, value: &Bound<'_, PyAny>) -> PyResult<()> {
        let force = if value.is_none() {
            None
        } else {
            let f: f64 = value
                .extract()
                .map_err(|_| wrong_type("break_force", "a number or None", value))?;
            Some(crate::convert::real(f))
        };
        self.edit(|w, id| w.set_joint_break_force(id, force))
    }

    /// A hinge's or slider's armature, the coordinate's rotor inertia (kg m² or kg);
    /// settable (finite, >= 0; only hinges and sliders take one above 0).
    #[getter]
    fn armature(&self) -> PyResult<f64> {
        self.read(|j| wide(j.def().armature))
    }

    #[setter]
    fn set_armature(&self, value: &Bound<'_, PyAny>) -> PyResult<()> {
        let a: f64 = value
            .extract()
            .map_err(|_| wrong_type("armature", "a number", value))?;
        self.edit(|w, id| w.set_joint_armature(id, crate::convert::real(a)))
    }

    /// The joint's coordinate, of `body` relative to `other`, zero at creation: hinge
    /// angle (rad, counting whole turns), slider offset (m), distance (m); a ball or fixed joint's
    /// rotation vector (rad, in `other`'s frame) as a 3-tuple. Settable (not on fixed
    /// joints): the side of `body` (or of `other`, when `body`'s is held by the world)
    /// moves rigidly to that coordinate, velocities turned with it.
    #[getter]
    fn position(&self) -> PyResult<Coordinate> {
        let g = self.world.get().lock()?;
        Ok(g.world.joint_position(self.id).map_err(engine)?.into())
    }

    #[setter]
    fn set_position(&self, value: &Bound<'_, PyAny>) -> PyResult<()> {
        let vector = self.read(|j| j.kind().spec().free.is_none() || j.kind().name() == "ball")?;
        let q = if vector {
            JointCoordinate::Vector(vec3(value, "position")?)
        } else {
            let x: f64 = value
                .extract()
                .map_err(|_| wrong_type("position", "a number", value))?;
            JointCoordinate::Scalar(crate::convert::real(x))
        };
        self.edit(|w, id| w.set_joint_position(id, q))
    }

    /// The joint's rate: hinge (rad/s), slider and distance (m/s); for ball and fixed
    /// joints the relative angular velocity (rad/s, in `other`'s frame) as a 3-tuple.
    #[getter]
    fn velocity(&self) -> PyResult<Coordinate> {
        let g = self.world.get().lock()?;
        Ok(g.world.joint_velocity(self.id).map_err(engine)?.into())
    }
}
