//! Joints: one entry of the `joints` array. Bodies are referred to by name; `other`
//! omitted or null joins `body` to the world.
//!
//! The keys a `"type"` accepts are the common keys and its options, as its description in
//! `tumble::joint::JOINT_KINDS` lists them; each option is read by its shape (a number,
//! `[lower, upper]`, a motor object, a spring object). Nothing here names a kind.

use tumble::joint::{JointOptions, KindSpec, OptionShape, OptionValue, JOINT_KINDS};
use tumble::{BodyId, JointDef, JointKind, JointSpring, Motor, Quat, Real, Servo, Vec3, World};

use crate::error::{printable, Result};
use crate::reader::{Node, Obj};

/// Every joint type, in the order the documentation lists them.
pub const JOINT_TYPES: [&str; JOINT_KINDS.len()] = {
    let mut names = [""; JOINT_KINDS.len()];
    let mut i = 0;
    while i < names.len() {
        names[i] = JOINT_KINDS[i].name;
        i += 1;
    }
    names
};

const COMMON_KEYS: [&str; 11] = [
    "type",
    "name",
    "body",
    "anchor",
    "other",
    "other_anchor",
    "axis",
    "other_axis",
    "collide_connected",
    "break_force",
    "armature",
];

/// Reads one joint, resolving body names in `world`. Numbers are checked by the engine
/// in `World::create_joint`, which names the same keys.
pub(crate) fn joint(node: &Node<'_>, world: &World) -> Result<JointDef> {
    let obj = node.object()?;
    let kind_name = obj.required("type")?.str()?;
    let Some(spec) = KindSpec::named(kind_name) else {
        return Err(obj.err_at(
            "type",
            format!(
                "unknown joint type '{}' (expected one of: {})",
                printable(kind_name),
                JOINT_TYPES.join(", ")
            ),
        ));
    };
    let kind = options(&obj, spec)?;
    let allowed: Vec<&str> = COMMON_KEYS.iter().copied().chain(spec.keys()).collect();
    obj.only(&allowed)?;
    let body = named_body(obj.required("body")?, world)?;
    let other = match obj.get("other") {
        Some(node) if !node.is_null() => Some(named_body(node, world)?),
        _ => None,
    };
    let anchor = obj.vec3("anchor")?.unwrap_or(Vec3::ZERO);
    let axis = obj.vec3("axis")?.unwrap_or(Vec3::X);
    // Left out, the other end is where `body`'s anchor and axis are now, seen from
    // `other` (or the world): the joint starts exactly satisfied.
    let (pose_a, pose_b) = (pose(world, Some(body)), pose(world, other));
    let world_anchor = pose_a.0 + pose_a.1 * anchor;
    let other_anchor = match obj.vec3("other_anchor")? {
        Some(p) => p,
        None => pose_b.1.inverse() * (world_anchor - pose_b.0),
    };
    let other_axis = match obj.vec3("other_axis")? {
        Some(a) => a,
        None => pose_b.1.inverse() * (pose_a.1 * axis),
    };
    Ok(JointDef {
        name: crate::body::name(&obj, "joints")?,
        kind,
        body,
        anchor,
        axis,
        other,
        other_anchor,
        other_axis,
        collide_connected: obj.bool("collide_connected")?.unwrap_or(false),
        break_force: obj.real("break_force")?,
        armature: obj.real("armature")?.unwrap_or(0.0),
    })
}

/// The kind's options, each read by its shape, in the description's order.
fn options(obj: &Obj<'_>, spec: &KindSpec) -> Result<JointKind> {
    let mut options = JointOptions::default();
    for option in spec.options.iter().map(|o| o.option) {
        let key = option.key();
        let value = match option.shape() {
            OptionShape::Real => obj.real(key)?.map(OptionValue::Real),
            OptionShape::Range => range(obj, key)?.map(OptionValue::Range),
            OptionShape::Motor => motor(obj, key, spec.motor_limit_key())?.map(OptionValue::Motor),
            OptionShape::Spring => spring(obj, key)?.map(OptionValue::Spring),
            OptionShape::Servo => servo(obj, key, spec.motor_limit_key())?.map(OptionValue::Servo),
        };
        if let Some(value) = value {
            // Each value was read by its option's own shape.
            options
                .set(option, value)
                .expect("a value of its option's shape");
        }
    }
    Ok(JointKind::from_options(spec.name, &options).expect("a kind of JOINT_KINDS"))
}

/// A body's frame (origin and rotation); the world's is the identity.
fn pose(world: &World, id: Option<BodyId>) -> (Vec3, Quat) {
    id.and_then(|id| world.body(id).ok())
        .map(|b| (b.pose().position, b.pose().rotation))
        .unwrap_or((Vec3::ZERO, Quat::IDENTITY))
}

/// `[lower, upper]`, if present.
fn range(obj: &Obj<'_>, key: &str) -> Result<Option<[Real; 2]>> {
    obj.get(key)
        .map(|n| n.reals::<2>("[lower, upper]"))
        .transpose()
}

/// `{"speed": .., "max_torque" | "max_force": ..}`.
fn motor(obj: &Obj<'_>, key: &str, limit_key: &str) -> Result<Option<Motor>> {
    let Some(node) = obj.get(key) else {
        return Ok(None);
    };
    let m = node.object()?;
    m.only(&["speed", limit_key])?;
    let limit = m.required(limit_key)?;
    let max_force = limit.real()?;
    if max_force < 0.0 {
        return Err(limit.err("must be >= 0"));
    }
    Ok(Some(Motor {
        speed: m.required("speed")?.real()?,
        max_force,
    }))
}

/// `{"hertz": .., "damping_ratio": .., "target": ..}`.
fn spring(obj: &Obj<'_>, key: &str) -> Result<Option<JointSpring>> {
    let Some(node) = obj.get(key) else {
        return Ok(None);
    };
    let s = node.object()?;
    s.only(&["hertz", "damping_ratio", "target"])?;
    Ok(Some(JointSpring {
        hertz: s.required("hertz")?.real()?,
        damping_ratio: s.real("damping_ratio")?.unwrap_or(1.0),
        target: s.real("target")?.unwrap_or(0.0),
    }))
}

/// `{"target": .., "stiffness": .., "damping": .., "max_torque" | "max_force": ..}`;
/// `damping` defaults to 0. The numbers are checked by the engine.
fn servo(obj: &Obj<'_>, key: &str, limit_key: &str) -> Result<Option<Servo>> {
    let Some(node) = obj.get(key) else {
        return Ok(None);
    };
    let s = node.object()?;
    s.only(&["target", "stiffness", "damping", limit_key])?;
    Ok(Some(Servo {
        target: s.required("target")?.real()?,
        stiffness: s.required("stiffness")?.real()?,
        damping: s.real("damping")?.unwrap_or(0.0),
        max_force: s.required(limit_key)?.real()?,
    }))
}

/// The body a name (or an index into `bodies`) refers to.
fn named_body(node: Node<'_>, world: &World) -> Result<BodyId> {
    crate::body::reference(&node, world)
}
