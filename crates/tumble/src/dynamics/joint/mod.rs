//! Joints: ball, hinge, slider, fixed and distance constraints between two bodies, or a
//! body and the world, with limits, motors and springs.
//!
//! A joint is defined, like a body, by a plain [`JointDef`] with defaults; the world checks
//! it and keeps a [`Joint`], which also carries what the solver reports back (the reaction
//! force and torque) and whether the joint has broken. The constraint rows live in
//! `dynamics/solver/joint*.rs`; the kinds' descriptions in `kinds.rs`.
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
use crate::limits::MAX_COORDINATE;

pub(crate) mod coords;
mod kinds;
use crate::math::{orthonormal_basis, Quat, Real, Vec3};
pub use coords::JointCoordinate;
pub use kinds::{
    AngularLock, FreeAxis, JointOption, JointOptions, KindSpec, LinearLock, OptionShape,
    OptionSpec, OptionValue, JOINT_KINDS,
};

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

/// A position servo: drives the joint's free coordinate towards `target` as a spring of
/// `stiffness` and a damper of `damping` would (τ = −k (q − target) − c q̇), solved
/// implicitly in each substep (stable at any stiffness), with at most `max_force`. Unlike
/// a [`JointSpring`], whose stiffness follows from a frequency and the bodies' masses,
/// the gains are given as torque (force) per radian (metre): a load τ holds the joint
/// off its target by about τ / k (less, by up to half, as the solver's passes share the
/// load with the joint's other rows; see `solver/joint_1d.rs`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Servo {
    /// Target angle (rad) or position (m) of the free coordinate.
    pub target: Real,
    /// Stiffness k (N·m/rad for hinges, N/m for sliders), ≥ 0.
    pub stiffness: Real,
    /// Damping c (N·m·s/rad for hinges, N·s/m for sliders), ≥ 0; k and c not both 0.
    pub damping: Real,
    /// Largest torque (N·m) or force (N) the servo may exert, ≥ 0.
    pub max_force: Real,
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
        /// Position servo about the axis.
        servo: Option<Servo>,
    },
    /// No relative rotation; the anchors move apart only along the axis.
    Slider {
        /// Lower and upper translation along the axis (m).
        limits: Option<[Real; 2]>,
        /// Drive along the axis.
        motor: Option<Motor>,
        /// Spring along the axis.
        spring: Option<JointSpring>,
        /// Position servo along the axis.
        servo: Option<Servo>,
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

// Adding a kind: its variant above, its `KindSpec` in `JOINT_KINDS` and its arms in
// `JointKind::parts` and `JointKind::from_options` (kinds.rs); new rows only if its locks
// or free axis are new (`dynamics/solver/joint_rows.rs`).

/// Everything needed to create a joint.
#[derive(Debug, PartialEq)]
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
    /// Armature (rotor inertia) of a hinge's or slider's coordinate: kg m² about a hinge's
    /// axis, kg along a slider's (MuJoCo's `armature`, a geared motor's reflected rotor).
    /// The coordinate's acceleration meets a generalised force −a q̈, acting equally and
    /// oppositely on the two bodies, as if the joint's own mass matrix were larger by a.
    /// Finite and ≥ 0; other kinds take none. Default 0: none, at no cost.
    pub armature: Real,
}

// Clone by hand for `clone_from` in place: the world copies its joints every step (to
// undo a failed one), and the derived `clone_from` cloned each name, an allocation a
// named joint a step. Every field but the name is `Copy`.
impl Clone for JointDef {
    fn clone(&self) -> Self {
        JointDef {
            name: self.name.clone(),
            ..*self
        }
    }

    fn clone_from(&mut self, source: &Self) {
        let mut name = self.name.take();
        name.clone_from(&source.name);
        *self = JointDef { name, ..*source };
    }
}

impl Clone for Joint {
    fn clone(&self) -> Self {
        Joint {
            def: self.def.clone(),
            ..*self
        }
    }

    fn clone_from(&mut self, source: &Self) {
        let placeholder = JointDef::new(source.def.kind, source.def.body);
        let mut def = std::mem::replace(&mut self.def, placeholder);
        def.clone_from(&source.def);
        *self = Joint { def, ..*source };
    }
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
            armature: 0.0,
        }
    }
}

/// A joint as the world keeps it.
#[derive(Debug, PartialEq)]
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
    /// Cleared by `World::set_joint_enabled(id, false)`: a disabled joint is not solved and
    /// keeps no pair from colliding, as a broken one.
    pub(crate) enabled: bool,
    pub(crate) reaction_force: Vec3,
    pub(crate) reaction_torque: Vec3,
    /// Impulses of the last substep, to warm-start the next.
    pub(crate) impulses: JointImpulses,
    /// A hinge's angle as last read (rad): at creation, after every step and when set.
    /// Its reading counts whole turns from here (`coords::position`), as MuJoCo's qpos
    /// and PyBullet's joint states do; 0 for other kinds.
    pub(crate) angle: Real,
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
    pub servo: Real,
    /// Rigid distance row.
    pub axial: Real,
    /// What the coordinate's armature (see [`JointDef::armature`]) pushed on the bodies
    /// along the free row in the last substep; warm started with the rest.
    pub armature: Real,
    /// How far the armature's flywheel (see `solver/joint_armature.rs`) ran ahead of the
    /// coordinate's rate at the end of the last substep: the coupling's unsolved rest.
    pub flywheel_lag: Real,
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
    /// Whether the joint is enabled (see `World::set_joint_enabled`).
    pub fn is_enabled(&self) -> bool {
        self.enabled
    }
    /// Whether the joint acts: enabled and not broken.
    pub(crate) fn acts(&self) -> bool {
        self.enabled && !self.broken
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

/// Checks an armature for a joint of `kind`: finite, ≥ 0, and on a hinge or a slider.
pub(crate) fn check_armature(armature: Real, kind: &JointKind) -> Result<()> {
    check::non_negative("armature", armature)?;
    let free = matches!(kind, JointKind::Hinge { .. } | JointKind::Slider { .. });
    if armature > 0.0 && !free {
        return Err(Error::invalid(
            "armature",
            "only hinge and slider joints take one",
        ));
    }
    Ok(())
}

/// Checks a definition's numbers; field paths are relative to the def (`limits`, `axis`).
pub(crate) fn validate(def: &JointDef) -> Result<()> {
    check::vec3_at_most("anchor", def.anchor, MAX_COORDINATE, "m")?;
    check::vec3_at_most("other_anchor", def.other_anchor, MAX_COORDINATE, "m")?;
    for (field, axis) in [("axis", def.axis), ("other_axis", def.other_axis)] {
        check::vec3(field, axis)?;
        if axis.length() < 1e-9 {
            return Err(Error::invalid(field, "must be a non-zero direction"));
        }
    }
    if let Some(f) = def.break_force {
        check::positive("break_force", f)?;
    }
    check_armature(def.armature, &def.kind)?;
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
        (_, OptionValue::Servo(sv)) => check_servo(key, &sv),
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
    let (hertz, ratio) = (format!("{field}.hertz"), format!("{field}.damping_ratio"));
    check::positive(&hertz, s.hertz)?;
    check::at_most(&hertz, s.hertz, crate::limits::MAX_HERTZ, "Hz")?;
    check::non_negative(&ratio, s.damping_ratio)?;
    check::at_most(
        &ratio,
        s.damping_ratio,
        crate::limits::MAX_DAMPING_RATIO,
        "",
    )?;
    check::finite(&format!("{field}.target"), s.target)
}

fn check_servo(field: &str, s: &Servo) -> Result<()> {
    check::finite(&format!("{field}.target"), s.target)?;
    let stiffness = format!("{field}.stiffness");
    check::non_negative(&stiffness, s.stiffness)?;
    check::non_negative(&format!("{field}.damping"), s.damping)?;
    check::non_negative(&format!("{field}.max_force"), s.max_force)?;
    if s.stiffness == 0.0 && s.damping == 0.0 {
        return Err(Error::invalid(stiffness, "must be > 0 when damping is 0"));
    }
    Ok(())
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
    let mut joint = Joint {
        def: def.clone(),
        axis,
        other_axis,
        reference,
        other_reference,
        relative_rotation: qa.inverse() * qb,
        length,
        broken: false,
        enabled: true,
        reaction_force: Vec3::ZERO,
        reaction_torque: Vec3::ZERO,
        impulses: JointImpulses::default(),
        angle: 0.0,
    };
    if joint.def.kind.spec().free == Some(FreeAxis::Rotation) {
        // Zero unless the limits' window lies elsewhere (see `coords::angle_window`).
        joint.angle = coords::hinge_angle(&joint, qa, qb);
    }
    joint
}

crate::codec::codec_struct!(Motor { speed, max_force });
crate::codec::codec_struct!(JointSpring {
    hertz,
    damping_ratio,
    target
});
crate::codec::codec_struct!(Servo {
    target,
    stiffness,
    damping,
    max_force
});
crate::codec::codec_struct!(JointDef {
    name,
    kind,
    body,
    anchor,
    axis,
    other,
    other_anchor,
    other_axis,
    collide_connected,
    break_force,
    armature
});
crate::codec::codec_struct!(Joint {
    def,
    axis,
    other_axis,
    reference,
    other_reference,
    relative_rotation,
    length,
    broken,
    enabled,
    reaction_force,
    reaction_torque,
    impulses,
    angle
});
crate::codec::codec_struct!(JointImpulses {
    hard,
    lower,
    upper,
    cone,
    motor,
    spring,
    servo,
    axial,
    armature,
    flywheel_lag
});

impl crate::codec::Code for JointKind {
    fn put(&self, w: &mut crate::codec::Writer) {
        match *self {
            JointKind::Ball { cone, twist } => (0u8, (cone, twist)).put(w),
            JointKind::Hinge {
                limits,
                motor,
                spring,
                servo,
            } => (1u8, (limits, motor, spring, servo)).put(w),
            JointKind::Slider {
                limits,
                motor,
                spring,
                servo,
            } => (2u8, (limits, motor, spring, servo)).put(w),
            JointKind::Fixed => 3u8.put(w),
            JointKind::Distance {
                length,
                min,
                max,
                spring,
            } => (4u8, (length, min, max, spring)).put(w),
        }
    }

    fn get(r: &mut crate::codec::Reader<'_>) -> crate::codec::Decoded<Self> {
        use crate::codec::Code;
        Ok(match u8::get(r)? {
            0 => {
                let (cone, twist) = Code::get(r)?;
                JointKind::Ball { cone, twist }
            }
            tag @ (1 | 2) => {
                let (limits, motor, spring, servo) = Code::get(r)?;
                if tag == 1 {
                    JointKind::Hinge {
                        limits,
                        motor,
                        spring,
                        servo,
                    }
                } else {
                    JointKind::Slider {
                        limits,
                        motor,
                        spring,
                        servo,
                    }
                }
            }
            3 => JointKind::Fixed,
            4 => {
                let (length, min, max, spring) = Code::get(r)?;
                JointKind::Distance {
                    length,
                    min,
                    max,
                    spring,
                }
            }
            t => return Err(r.bad_tag("joint kind", t)),
        })
    }
}
