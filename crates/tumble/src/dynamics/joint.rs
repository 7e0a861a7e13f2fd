//! Joints: ball, hinge, slider, fixed and distance constraints between two bodies, or a
//! body and the world, with limits, motors and springs.
//!
//! A joint is defined, like a body, by a plain [`JointDef`] with defaults; the world checks
//! it and keeps a [`Joint`], which also carries what the solver reports back (the reaction
//! force and torque) and whether the joint has broken. The constraint rows live in
//! `solver/joint*.rs`.
//!
//! Frames: `anchor` and `axis` are in the frame of `body` (its origin, not its centre of
//! mass); `other_anchor` and `other_axis` in the frame of `other`, or in world coordinates
//! when `other` is `None` (the world). Angles of hinges and twists are measured from the
//! pose the bodies have when the joint is created, which counts as zero.
//!
//! Each kind is described once, as data, by its [`KindSpec`] in [`JOINT_KINDS`]: what it
//! locks ([`LinearLock`], [`AngularLock`]), its free coordinate ([`FreeAxis`]) and the
//! options it takes ([`JointOption`], with units). Everything else is derived from that
//! table: the solver's rows, the checks in `validate`, the keys a scene file's joint
//! accepts and the Python binding's keywords. A kind's settings travel between its
//! [`JointKind`] variant and the uniform [`JointOptions`] through [`JointKind::options`]
//! and [`JointKind::from_options`], the one place a variant meets its description.

use crate::error::{check, Error, Result};
use crate::id::BodyId;
pub use crate::id::JointId;
use crate::math::{orthonormal_basis, Quat, Real, Vec3};

/// A velocity motor: drives the joint's free coordinate at `speed` (rad/s or m/s) with at
/// most `max_force` (N·m for hinges, N for sliders).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Motor {
    /// Target speed (rad/s for hinges, m/s for sliders).
    pub speed: Real,
    /// Largest torque (N·m) or force (N) the motor may exert.
    pub max_force: Real,
}

/// A spring on the joint's free coordinate: a soft constraint towards `target` with the
/// given frequency and damping ratio (for a distance joint, towards its rest length).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointSpring {
    /// Natural frequency (Hz); the stiffness follows from the bodies' effective mass.
    pub hertz: Real,
    /// Damping ratio (1 = critical).
    pub damping_ratio: Real,
    /// Rest angle (rad) or position (m) of the free coordinate.
    pub target: Real,
}

/// What a joint constrains, with the settings particular to each kind.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum JointKind {
    /// The anchors coincide; rotation is free, within optional limits: the angle between
    /// the two axes at most `cone` (rad), the twist about them within `twist` (rad).
    Ball {
        /// Largest swing angle between `axis` and `other_axis` (rad).
        cone: Option<Real>,
        /// Lower and upper twist angle about the axes (rad).
        twist: Option<[Real; 2]>,
    },
    /// The anchors coincide and the axes stay aligned; rotation about them is free.
    Hinge {
        /// Lower and upper angle (rad).
        limits: Option<[Real; 2]>,
        /// Drive about the axis.
        motor: Option<Motor>,
        /// Spring about the axis.
        spring: Option<JointSpring>,
    },
    /// No relative rotation; the anchors move apart only along the axis.
    Slider {
        /// Lower and upper translation along the axis (m).
        limits: Option<[Real; 2]>,
        /// Drive along the axis.
        motor: Option<Motor>,
        /// Spring along the axis.
        spring: Option<JointSpring>,
    },
    /// No relative motion at all (a weld).
    Fixed,
    /// The anchors keep their distance: a rod when `min == max == length`, a rope with
    /// only `max`, and a spring when `spring` is set (limits still hold).
    Distance {
        /// Rest length (m); `None` takes the distance at creation.
        length: Option<Real>,
        /// Shortest allowed distance (m); `None`: no lower limit beyond the rod's.
        min: Option<Real>,
        /// Longest allowed distance (m).
        max: Option<Real>,
        /// A soft spring towards `length` instead of a rigid rod.
        spring: Option<JointSpring>,
    },
}

// ---------------------------------------------------------------------------------------
// The kinds as data. Adding a kind: its variant above, its `KindSpec` in `JOINT_KINDS`,
// its arms in `JointKind::options` and `JointKind::from_options`; new rows only if its
// locks or free axis are new (`solver/joint_rows.rs`).
// ---------------------------------------------------------------------------------------

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
}

impl JointOption {
    /// Every option, in the order option errors report them.
    pub const ALL: [JointOption; 8] = [
        JointOption::Cone,
        JointOption::Twist,
        JointOption::Limits,
        JointOption::Motor,
        JointOption::Spring,
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
            (JointOption::Length, OptionValue::Real(x)) => self.length = Some(x),
            (JointOption::Min, OptionValue::Real(x)) => self.min = Some(x),
            (JointOption::Max, OptionValue::Real(x)) => self.max = Some(x),
            _ => {
                let expected = match option.shape() {
                    OptionShape::Real => "a number",
                    OptionShape::Range => "[lower, upper]",
                    OptionShape::Motor => "a motor",
                    OptionShape::Spring => "a spring",
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
            } => (
                &JOINT_KINDS[1],
                JointOptions {
                    limits,
                    motor,
                    spring,
                    ..none
                },
            ),
            JointKind::Slider {
                limits,
                motor,
                spring,
            } => (
                &JOINT_KINDS[2],
                JointOptions {
                    limits,
                    motor,
                    spring,
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
            },
            "slider" => JointKind::Slider {
                limits: o.limits,
                motor: o.motor,
                spring: o.spring,
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

/// Everything needed to create a joint.
#[derive(Debug, Clone, PartialEq)]
pub struct JointDef {
    /// An optional unique name (scene files refer to joints by it).
    pub name: Option<String>,
    /// What the joint constrains.
    pub kind: JointKind,
    /// The first body.
    pub body: BodyId,
    /// Anchor in `body`'s frame (m).
    pub anchor: Vec3,
    /// Axis in `body`'s frame (hinge, slider, ball limits); normalised on creation.
    pub axis: Vec3,
    /// The second body, or `None` for the world.
    pub other: Option<BodyId>,
    /// Anchor in `other`'s frame, or a world point (m).
    pub other_anchor: Vec3,
    /// Axis in `other`'s frame, or a world direction.
    pub other_axis: Vec3,
    /// Whether the two bodies still collide with each other.
    pub collide_connected: bool,
    /// Reaction force (N) beyond which the joint breaks; `None`: unbreakable.
    pub break_force: Option<Real>,
}

impl JointDef {
    /// A joint of `kind` on `body`, anchored at its origin, to the world at the origin,
    /// with both axes along x.
    pub fn new(kind: JointKind, body: BodyId) -> JointDef {
        JointDef {
            name: None,
            kind,
            body,
            anchor: Vec3::ZERO,
            axis: Vec3::X,
            other: None,
            other_anchor: Vec3::ZERO,
            other_axis: Vec3::X,
            collide_connected: false,
            break_force: None,
        }
    }
}

/// A joint as the world keeps it.
#[derive(Debug, Clone, PartialEq)]
pub struct Joint {
    pub(crate) def: JointDef,
    /// Unit axes in each frame (other: world frame when joined to the world).
    pub(crate) axis: Vec3,
    pub(crate) other_axis: Vec3,
    /// Unit vectors perpendicular to each axis that coincide at creation: angles about
    /// the axis are measured between them.
    pub(crate) reference: Vec3,
    pub(crate) other_reference: Vec3,
    /// Orientation of `other` relative to `body` at creation (`q_body⁻¹ q_other`), the
    /// target of fixed and slider joints.
    pub(crate) relative_rotation: Quat,
    /// Rest length of a distance joint (m).
    pub(crate) length: Real,
    pub(crate) broken: bool,
    pub(crate) reaction_force: Vec3,
    pub(crate) reaction_torque: Vec3,
    /// Impulses of the last substep, to warm-start the next.
    pub(crate) impulses: JointImpulses,
}

/// Accumulated impulses of a joint's rows.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct JointImpulses {
    /// The hard rows solved as one block (point, across-axis, angular lock; at most six),
    /// in the order `solver/joint_rows.rs` builds them (linear lock, then angular lock).
    pub hard: [Real; 6],
    /// Lower and upper limit on the free coordinate (hinge/slider/twist/distance).
    pub lower: Real,
    pub upper: Real,
    /// Cone limit of a ball joint.
    pub cone: Real,
    pub motor: Real,
    pub spring: Real,
    /// Rigid distance row.
    pub axial: Real,
}

impl Joint {
    /// The joint's definition, as given (axes not normalised).
    pub fn def(&self) -> &JointDef {
        &self.def
    }
    /// What the joint constrains.
    pub fn kind(&self) -> &JointKind {
        &self.def.kind
    }
    /// The first body.
    pub fn body(&self) -> BodyId {
        self.def.body
    }
    /// The second body, `None` for the world.
    pub fn other(&self) -> Option<BodyId> {
        self.def.other
    }
    /// The joint's name, if any.
    pub fn name(&self) -> Option<&str> {
        self.def.name.as_deref()
    }
    /// Whether the reaction passed `break_force`: a broken joint no longer acts.
    pub fn is_broken(&self) -> bool {
        self.broken
    }
    /// The force the joint applied to `other` over the last step (N, world frame); the
    /// force on `body` is its opposite.
    pub fn reaction_force(&self) -> Vec3 {
        self.reaction_force
    }
    /// The torque the joint applied to `other` about its anchor over the last step (N·m).
    pub fn reaction_torque(&self) -> Vec3 {
        self.reaction_torque
    }
}

/// Checks a definition's numbers; field paths are relative to the def (`limits`, `axis`).
pub(crate) fn validate(def: &JointDef) -> Result<()> {
    check::vec3("anchor", def.anchor)?;
    check::vec3("other_anchor", def.other_anchor)?;
    for (field, axis) in [("axis", def.axis), ("other_axis", def.other_axis)] {
        check::vec3(field, axis)?;
        if axis.length() < 1e-9 {
            return Err(Error::invalid(field, "must be a non-zero direction"));
        }
    }
    if let Some(f) = def.break_force {
        check::positive("break_force", f)?;
    }
    if def.other == Some(def.body) {
        return Err(Error::invalid("other", "must differ from body"));
    }
    let spec = def.kind.spec();
    let options = def.kind.options();
    for option in spec.options.iter().map(|o| o.option) {
        if let Some(value) = options.get(option) {
            check_option(option, value, &options)?;
        }
    }
    Ok(())
}

/// Checks one option's value (`options`: the others, for the pairs that must agree).
fn check_option(option: JointOption, value: OptionValue, options: &JointOptions) -> Result<()> {
    let key = option.key();
    match (option, value) {
        (JointOption::Cone | JointOption::Min, OptionValue::Real(x)) => check::non_negative(key, x),
        (JointOption::Length, OptionValue::Real(x)) => check::positive(key, x),
        (JointOption::Max, OptionValue::Real(x)) => {
            check::positive(key, x)?;
            match options.min {
                Some(lo) if lo > x => Err(Error::invalid("min", "must be <= max")),
                _ => Ok(()),
            }
        }
        (_, OptionValue::Range(r)) => check_range(key, r),
        (_, OptionValue::Motor(m)) => {
            check::finite(&format!("{key}.speed"), m.speed)?;
            check::non_negative(&format!("{key}.max_force"), m.max_force)
        }
        (_, OptionValue::Spring(sp)) => check_spring(key, &sp),
        (_, OptionValue::Real(x)) => check::finite(key, x),
    }
}

fn check_range(field: &str, [lo, hi]: [Real; 2]) -> Result<()> {
    check::finite(field, lo)?;
    check::finite(field, hi)?;
    if lo > hi {
        return Err(Error::invalid(field, "lower must be <= upper"));
    }
    Ok(())
}

fn check_spring(field: &str, s: &JointSpring) -> Result<()> {
    check::positive(&format!("{field}.hertz"), s.hertz)?;
    check::non_negative(&format!("{field}.damping_ratio"), s.damping_ratio)?;
    check::finite(&format!("{field}.target"), s.target)
}

/// Builds the world's record of a checked definition, given the bodies' poses now
/// (`None`: the world, identity).
pub(crate) fn build(def: &JointDef, body: (Vec3, Quat), other: Option<(Vec3, Quat)>) -> Joint {
    let axis = def.axis.normalize();
    let other_axis = def.other_axis.normalize();
    let (pa, qa) = body;
    let (pb, qb) = other.unwrap_or((Vec3::ZERO, Quat::IDENTITY));
    let reference = orthonormal_basis(axis)[0];
    // The same direction in the other frame, made perpendicular to its axis.
    let seen = qb.inverse() * (qa * reference);
    let other_reference = (seen - other_axis * other_axis.dot(seen))
        .try_normalize()
        .unwrap_or_else(|| orthonormal_basis(other_axis)[0]);
    let world_a = pa + qa * def.anchor;
    let world_b = pb + qb * def.other_anchor;
    let length = match def.kind.options().length {
        Some(l) => l,
        None => (world_b - world_a).length(),
    };
    Joint {
        def: def.clone(),
        axis,
        other_axis,
        reference,
        other_reference,
        relative_rotation: qa.inverse() * qb,
        length,
        broken: false,
        reaction_force: Vec3::ZERO,
        reaction_torque: Vec3::ZERO,
        impulses: JointImpulses::default(),
    }
}
