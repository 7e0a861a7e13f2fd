//! Force elements: one entry of the `forces` array. Bodies are referred to by name.

use tumble::{AppliedForce, BodyId, Drag, Force, Spring, SpringEnd, Vec3, World};

use crate::error::{printable, Result};
use crate::reader::{Node, Obj};

/// Every force type, in the order the documentation lists them.
pub const FORCE_TYPES: [&str; 3] = ["spring", "drag", "force"];

const SPRING_KEYS: [&str; 9] = [
    "type",
    "body",
    "anchor",
    "world_point",
    "other",
    "other_anchor",
    "stiffness",
    "rest_length",
    "damping",
];
const DRAG_KEYS: [&str; 4] = ["type", "body", "linear", "quadratic"];
const APPLIED_KEYS: [&str; 5] = ["type", "body", "force", "point", "torque"];

/// Reads one force element, resolving body names in `world`. Values are checked by the
/// engine in `World::add_force`.
pub(crate) fn force(node: &Node<'_>, world: &World) -> Result<Force> {
    let obj = node.object()?;
    let kind = obj.required("type")?.str()?;
    match kind {
        "spring" => {
            obj.only(&SPRING_KEYS)?;
            spring(&obj, world).map(Force::Spring)
        }
        "drag" => {
            obj.only(&DRAG_KEYS)?;
            Ok(Force::Drag(Drag {
                body: body(&obj, "body", world)?,
                linear: obj.real("linear")?.unwrap_or(0.0),
                quadratic: obj.real("quadratic")?.unwrap_or(0.0),
            }))
        }
        "force" => {
            obj.only(&APPLIED_KEYS)?;
            Ok(Force::Applied(AppliedForce {
                body: body(&obj, "body", world)?,
                force: obj.vec3("force")?.unwrap_or(Vec3::ZERO),
                point: obj.vec3("point")?,
                torque: obj.vec3("torque")?.unwrap_or(Vec3::ZERO),
            }))
        }
        other => Err(obj.err_at(
            "type",
            format!(
                "unknown force type '{}' (expected one of: {})",
                printable(other),
                FORCE_TYPES.join(", ")
            ),
        )),
    }
}

/// A spring ends at a fixed `world_point` or at `other_anchor` on the body `other`:
/// exactly one of the two, since a silent preference would hide a mistake.
fn spring(obj: &Obj<'_>, world: &World) -> Result<Spring> {
    let a = body(obj, "body", world)?;
    let other = match (obj.has("world_point"), obj.has("other")) {
        (true, true) => return Err(obj.err_at(
            "other",
            "cannot be given together with world_point (give exactly one of world_point, other)",
        )),
        (false, false) => {
            return Err(obj
                .node()
                .err("a spring needs world_point or other (give exactly one)"))
        }
        (true, false) => {
            if obj.has("other_anchor") {
                return Err(obj.err_at("other_anchor", "only allowed together with other"));
            }
            SpringEnd::World(obj.required("world_point")?.vec3()?)
        }
        (false, true) => SpringEnd::Body {
            body: other_body(obj, a, world)?,
            anchor: obj.vec3("other_anchor")?.unwrap_or(Vec3::ZERO),
        },
    };
    Ok(Spring {
        body: a,
        anchor: obj.vec3("anchor")?.unwrap_or(Vec3::ZERO),
        other,
        stiffness: obj.required("stiffness")?.real()?,
        rest_length: obj.real("rest_length")?.unwrap_or(0.0),
        damping: obj.real("damping")?.unwrap_or(0.0),
    })
}

/// A spring from a body to itself exerts no net force and is surely a typo.
fn other_body(obj: &Obj<'_>, a: BodyId, world: &World) -> Result<BodyId> {
    let b = body(obj, "other", world)?;
    if b == a {
        return Err(obj.err_at("other", "must be a different body from body"));
    }
    Ok(b)
}

fn body(obj: &Obj<'_>, key: &str, world: &World) -> Result<BodyId> {
    crate::body::reference(&obj.required(key)?, world)
}
