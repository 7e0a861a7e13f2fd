//! Each joint kind described once, as data: what it locks ([`LinearLock`],
//! [`AngularLock`]), its free coordinate ([`FreeAxis`]) and the options it takes
//! ([`JointOption`], with units), in the table [`JOINT_KINDS`]; and the one place where a
//! [`JointKind`] variant meets its description ([`JointKind::options`],
//! [`JointKind::from_options`]). The solver's rows, the checks, the scene reader's keys and
//! the Python binding's keywords are all derived from this table.

use super::{JointKind, JointSpring, Motor, Servo};
use crate::error::{Error, Result};
use crate::math::Real;

/// The relative translations a kind forbids: its linear hard rows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LinearLock {
    /// None: the anchors may separate (a distance joint acts on its free axis only).
    Free,
    /// The anchors coincide: three rows, one per world axis.
    Point,
    /// The anchors stay on the line of `axis` through `body`'s anchor: two rows across it.
    AcrossAxis,
}

/// The relative rotations a kind forbids: its angular hard rows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AngularLock {
    /// None.
    Free,
    /// `axis` and `other_axis` stay aligned: two rows about the directions across them.
    AcrossAxis,
    /// No relative rotation at all: three rows, towards the orientation at creation.
    All,
}

/// The coordinate a kind leaves free, on which its limits, motor and spring act.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FreeAxis {
    /// Rotation about `axis` (rad): a hinge's angle.
    Rotation,
    /// Rotation about the bisector of the two axes (rad): a ball joint's twist. Measured
    /// only while limited: an unlimited ball has no twist row.
    Twist,
    /// Translation of the anchors along `axis` (m).
    Translation,
    /// The anchors' distance (m), along the line between them; with no limits and no
    /// spring it is held at the rest length (a rod).
    Distance,
}

impl FreeAxis {
    /// The key of a motor's force bound in scene files: a torque about rotations.
    pub fn motor_limit_key(self) -> &'static str {
        match self {
            FreeAxis::Rotation | FreeAxis::Twist => "max_torque",
            FreeAxis::Translation | FreeAxis::Distance => "max_force",
        }
    }
}

/// An option a kind may take, by the key scene files and Python keywords use.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JointOption {
    /// `cone`: largest swing angle between `axis` and `other_axis`, ≥ 0.
    Cone,
    /// `twist`: [lower, upper] twist about the axes (the limits of [`FreeAxis::Twist`]).
    Twist,
    /// `limits`: [lower, upper] of the free coordinate.
    Limits,
    /// `motor`: a [`Motor`] on the free coordinate.
    Motor,
    /// `spring`: a [`JointSpring`] on the free coordinate.
    Spring,
    /// `servo`: a [`Servo`] on the free coordinate.
    Servo,
    /// `length`: rest length, > 0; left out, the anchors' distance at creation.
    Length,
    /// `min`: shortest distance, ≥ 0.
    Min,
    /// `max`: longest distance, > 0 and ≥ `min`.
    Max,
}

/// The shape of an option's value.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OptionShape {
    /// A number.
    Real,
    /// `[lower, upper]`.
    Range,
    /// A [`Motor`].
    Motor,
    /// A [`JointSpring`].
    Spring,
    /// A [`Servo`].
    Servo,
}

impl JointOption {
    /// Every option, in the order option errors report them.
    pub const ALL: [JointOption; 9] = [
        JointOption::Cone,
        JointOption::Twist,
        JointOption::Limits,
        JointOption::Motor,
        JointOption::Spring,
        JointOption::Servo,
        JointOption::Length,
        JointOption::Min,
        JointOption::Max,
    ];

    /// The key in scene files, the Python keyword and the field in error messages.
    pub fn key(self) -> &'static str {
        match self {
            JointOption::Cone => "cone",
            JointOption::Twist => "twist",
            JointOption::Limits => "limits",
            JointOption::Motor => "motor",
            JointOption::Spring => "spring",
            JointOption::Servo => "servo",
            JointOption::Length => "length",
            JointOption::Min => "min",
            JointOption::Max => "max",
        }
    }

    /// What the option's value is.
    pub fn shape(self) -> OptionShape {
        match self {
            JointOption::Cone | JointOption::Length | JointOption::Min | JointOption::Max => {
                OptionShape::Real
            }
            JointOption::Twist | JointOption::Limits => OptionShape::Range,
            JointOption::Motor => OptionShape::Motor,
            JointOption::Spring => OptionShape::Spring,
            JointOption::Servo => OptionShape::Servo,
        }
    }
}

/// An option of a kind, with the unit of its value.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct OptionSpec {
    /// Which option.
    pub option: JointOption,
    /// Its unit (a motor's: speed, then force bound; a spring's: its target's).
    pub unit: &'static str,
}

/// The description of a joint kind, from which its rows, checks and accepted keys follow.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct KindSpec {
    /// The name in scene files, Python and [`JointKind::name`].
    pub name: &'static str,
    /// The translations it forbids.
    pub linear: LinearLock,
    /// The rotations it forbids.
    pub angular: AngularLock,
    /// The coordinate it leaves free for limits, motor and spring, if any.
    pub free: Option<FreeAxis>,
    /// The options it takes, in the order they are read and checked.
    pub options: &'static [OptionSpec],
}

const fn opt(option: JointOption, unit: &'static str) -> OptionSpec {
    OptionSpec { option, unit }
}

/// Every joint kind, in the order the documentation lists them.
pub const JOINT_KINDS: [KindSpec; 5] = [
    KindSpec {
        name: "ball",
        linear: LinearLock::Point,
        angular: AngularLock::Free,
        free: Some(FreeAxis::Twist),
        options: &[
            opt(JointOption::Cone, "rad"),
            opt(JointOption::Twist, "rad"),
        ],
    },
    KindSpec {
        name: "hinge",
        linear: LinearLock::Point,
        angular: AngularLock::AcrossAxis,
        free: Some(FreeAxis::Rotation),
        options: &[
            opt(JointOption::Limits, "rad"),
            opt(JointOption::Motor, "rad/s, N·m"),
            opt(JointOption::Spring, "rad"),
            opt(JointOption::Servo, "rad, N·m/rad, N·m·s/rad, N·m"),
        ],
    },
    KindSpec {
        name: "slider",
        linear: LinearLock::AcrossAxis,
        angular: AngularLock::All,
        free: Some(FreeAxis::Translation),
        options: &[
            opt(JointOption::Limits, "m"),
            opt(JointOption::Motor, "m/s, N"),
            opt(JointOption::Spring, "m"),
            opt(JointOption::Servo, "m, N/m, N·s/m, N"),
        ],
    },
    KindSpec {
        name: "fixed",
        linear: LinearLock::Point,
        angular: AngularLock::All,
        free: None,
        options: &[],
    },
    KindSpec {
        name: "distance",
        linear: LinearLock::Free,
        angular: AngularLock::Free,
        free: Some(FreeAxis::Distance),
        options: &[
            opt(JointOption::Length, "m"),
            opt(JointOption::Min, "m"),
            opt(JointOption::Max, "m"),
            opt(JointOption::Spring, "m"),
        ],
    },
];

impl KindSpec {
    /// The kind called `name`.
    pub fn named(name: &str) -> Option<&'static KindSpec> {
        JOINT_KINDS.iter().find(|k| k.name == name)
    }

    /// Whether the kind takes `option`.
    pub fn takes(&self, option: JointOption) -> bool {
        self.options.iter().any(|o| o.option == option)
    }

    /// Whether the kind locks its bodies' relative rotation in some direction (hinge,
    /// slider, fixed).
    pub fn locks_rotation(&self) -> bool {
        self.angular != AngularLock::Free
    }

    /// The option keys it takes, in order.
    pub fn keys(&self) -> impl Iterator<Item = &'static str> + '_ {
        self.options.iter().map(|o| o.option.key())
    }

    /// The key of its motor's force bound (`max_torque` or `max_force`).
    pub fn motor_limit_key(&self) -> &'static str {
        self.free.map_or("max_force", FreeAxis::motor_limit_key)
    }
}

/// One option's value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum OptionValue {
    /// For [`OptionShape::Real`].
    Real(Real),
    /// For [`OptionShape::Range`].
    Range([Real; 2]),
    /// For [`OptionShape::Motor`].
    Motor(Motor),
    /// For [`OptionShape::Spring`].
    Spring(JointSpring),
    /// For [`OptionShape::Servo`].
    Servo(Servo),
}

/// Every option's value, `None` where not given: a kind's settings in one shape.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[allow(missing_docs)] // One field per `JointOption`, documented there.
pub struct JointOptions {
    pub cone: Option<Real>,
    pub twist: Option<[Real; 2]>,
    pub limits: Option<[Real; 2]>,
    pub motor: Option<Motor>,
    pub spring: Option<JointSpring>,
    pub servo: Option<Servo>,
    pub length: Option<Real>,
    pub min: Option<Real>,
    pub max: Option<Real>,
}

impl JointOptions {
    /// The value of `option`, if given.
    pub fn get(&self, option: JointOption) -> Option<OptionValue> {
        match option {
            JointOption::Cone => self.cone.map(OptionValue::Real),
            JointOption::Twist => self.twist.map(OptionValue::Range),
            JointOption::Limits => self.limits.map(OptionValue::Range),
            JointOption::Motor => self.motor.map(OptionValue::Motor),
            JointOption::Spring => self.spring.map(OptionValue::Spring),
            JointOption::Servo => self.servo.map(OptionValue::Servo),
            JointOption::Length => self.length.map(OptionValue::Real),
            JointOption::Min => self.min.map(OptionValue::Real),
            JointOption::Max => self.max.map(OptionValue::Real),
        }
    }

    /// Sets `option`; an error (`cone: expected a number`) for a value of another shape.
    pub fn set(&mut self, option: JointOption, value: OptionValue) -> Result<()> {
        match (option, value) {
            (JointOption::Cone, OptionValue::Real(x)) => self.cone = Some(x),
            (JointOption::Twist, OptionValue::Range(r)) => self.twist = Some(r),
            (JointOption::Limits, OptionValue::Range(r)) => self.limits = Some(r),
            (JointOption::Motor, OptionValue::Motor(m)) => self.motor = Some(m),
            (JointOption::Spring, OptionValue::Spring(s)) => self.spring = Some(s),
            (JointOption::Servo, OptionValue::Servo(s)) => self.servo = Some(s),
            (JointOption::Length, OptionValue::Real(x)) => self.length = Some(x),
            (JointOption::Min, OptionValue::Real(x)) => self.min = Some(x),
            (JointOption::Max, OptionValue::Real(x)) => self.max = Some(x),
            _ => {
                let expected = match option.shape() {
                    OptionShape::Real => "a number",
                    OptionShape::Range => "[lower, upper]",
                    OptionShape::Motor => "a motor",
                    OptionShape::Spring => "a spring",
                    OptionShape::Servo => "a servo",
                };
                return Err(Error::invalid(option.key(), format!("expected {expected}")));
            }
        }
        Ok(())
    }
}

impl JointKind {
    /// The name used in scene files.
    pub fn name(&self) -> &'static str {
        self.spec().name
    }

    /// The kind's description.
    pub fn spec(&self) -> &'static KindSpec {
        self.parts().0
    }

    /// The kind's settings as options (those it does not take are `None`).
    pub fn options(&self) -> JointOptions {
        self.parts().1
    }

    fn parts(&self) -> (&'static KindSpec, JointOptions) {
        let none = JointOptions::default();
        match *self {
            JointKind::Ball { cone, twist } => (
                &JOINT_KINDS[0],
                JointOptions {
                    cone,
                    twist,
                    ..none
                },
            ),
            JointKind::Hinge {
                limits,
                motor,
                spring,
                servo,
            } => (
                &JOINT_KINDS[1],
                JointOptions {
                    limits,
                    motor,
                    spring,
                    servo,
                    ..none
                },
            ),
            JointKind::Slider {
                limits,
                motor,
                spring,
                servo,
            } => (
                &JOINT_KINDS[2],
                JointOptions {
                    limits,
                    motor,
                    spring,
                    servo,
                    ..none
                },
            ),
            JointKind::Fixed => (&JOINT_KINDS[3], none),
            JointKind::Distance {
                length,
                min,
                max,
                spring,
            } => (
                &JOINT_KINDS[4],
                JointOptions {
                    length,
                    min,
                    max,
                    spring,
                    ..none
                },
            ),
        }
    }

    /// The kind called `name` with the options it takes from `o` (others are ignored);
    /// `None` for an unknown name.
    pub fn from_options(name: &str, o: &JointOptions) -> Option<JointKind> {
        Some(match name {
            "ball" => JointKind::Ball {
                cone: o.cone,
                twist: o.twist,
            },
            "hinge" => JointKind::Hinge {
                limits: o.limits,
                motor: o.motor,
                spring: o.spring,
                servo: o.servo,
            },
            "slider" => JointKind::Slider {
                limits: o.limits,
                motor: o.motor,
                spring: o.spring,
                servo: o.servo,
            },
            "fixed" => JointKind::Fixed,
            "distance" => JointKind::Distance {
                length: o.length,
                min: o.min,
                max: o.max,
                spring: o.spring,
            },
            _ => return None,
        })
    }
}
