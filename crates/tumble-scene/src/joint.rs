//! Joints: one entry of the `joints` array. Bodies are referred to by name; `other`
//! omitted or null joins `body` to the world.

use tumble::{BodyId, JointDef, JointKind, JointSpring, Motor, Quat, Real, Vec3, World};

use crate::error::{printable, Result};
use crate::reader::{Node, Obj};

/// Every joint type, in the order the documentation lists them.
pub const JOINT_TYPES: [&str; 5] = ["ball", "hinge", "slider", "fixed", "distance"];

const COMMON_KEYS: [&str; 10] = [
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
];

/// Reads one joint, resolving body names in `world`. Numbers are checked by the engine
/// in `World::create_joint`, which names the same keys.
pub(crate) fn joint(node: &Node<'_>, world: &World) -> Result<JointDef> {
    let obj = node.object()?;
    let kind_name = obj.required("type")?.str()?;
    let (kind, extra): (JointKind, &[&str]) = match kind_name {
        "ball" => (
            JointKind::Ball {
                cone: obj.real("cone")?,
                twist: range(&obj, "twist")?,
            },
            &["cone", "twist"],
        ),
        "hinge" => (
            JointKind::Hinge {
                limits: range(&obj, "limits")?,
                motor: motor(&obj, "max_torque")?,
                spring: spring(&obj)?,
            },
            &["limits", "motor", "spring"],
        ),
        "slider" => (
            JointKind::Slider {
                limits: range(&obj, "limits")?,
                motor: motor(&obj, "max_force")?,
                spring: spring(&obj)?,
            },
            &["limits", "motor", "spring"],
        ),
        "fixed" => (JointKind::Fixed, &[]),
        "distance" => (
            JointKind::Distance {
                length: obj.real("length")?,
                min: obj.real("min")?,
                max: obj.real("max")?,
                spring: spring(&obj)?,
            },
            &["length", "min", "max", "spring"],
        ),
        other => {
            return Err(obj.err_at(
                "type",
                format!(
                    "unknown joint type '{}' (expected one of: {})",
                    printable(other),
                    JOINT_TYPES.join(", ")
                ),
            ))
        }
    };
    let allowed: Vec<&str> = COMMON_KEYS.iter().chain(extra).copied().collect();
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
        name: obj.str("name")?.map(str::to_string),
        kind,
        body,
        anchor,
        axis,
        other,
        other_anchor,
        other_axis,
        collide_connected: obj.bool("collide_connected")?.unwrap_or(false),
        break_force: obj.real("break_force")?,
    })
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
fn motor(obj: &Obj<'_>, limit_key: &str) -> Result<Option<Motor>> {
    let Some(node) = obj.get("motor") else {
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
fn spring(obj: &Obj<'_>) -> Result<Option<JointSpring>> {
    let Some(node) = obj.get("spring") else {
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

/// The body a name refers to.
fn named_body(node: Node<'_>, world: &World) -> Result<BodyId> {
    let name = node.str()?;
    world
        .find_body(name)
        .ok_or_else(|| node.err(format!("no body named '{}'", printable(name))))
}
