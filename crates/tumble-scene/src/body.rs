//! Bodies: one entry of the `bodies` array, read into a `BodyDef` and a `Shape`.

use tumble::{BodyDef, BodyId, BodyKind, InertiaSpec, MassSpec, Mat3, Quat, Shape, Vec3, World};

use crate::error::{printable, Result};
use crate::reader::{Node, Obj};

const BODY_KEYS: [&str; 26] = [
    "name",
    "kind",
    "shape",
    "mass",
    "density",
    "inertia",
    "center_of_mass",
    "position",
    "orientation",
    "velocity",
    "angular_velocity",
    "planar",
    "collision_group",
    "collision_mask",
    "collision_owner",
    "friction",
    "restitution",
    "rolling_resistance",
    "torsional_friction",
    "bullet",
    "color",
    "linear_damping",
    "angular_damping",
    "gravity_scale",
    "sensor",
    "one_way",
];

/// A body's `color`, `"#rrggbb"`: for pictures and the viewer only, never for physics.
pub(crate) fn color(node: &Node<'_>) -> Result<Option<[u8; 3]>> {
    let obj = node.object()?;
    let Some(text) = obj.str("color")? else {
        return Ok(None);
    };
    let hex = text
        .strip_prefix('#')
        .filter(|h| h.len() == 6 && h.is_ascii());
    let channel = |i: usize| hex.and_then(|h| u8::from_str_radix(&h[i..i + 2], 16).ok());
    match (channel(0), channel(2), channel(4)) {
        (Some(r), Some(g), Some(b)) => Ok(Some([r, g, b])),
        _ => Err(obj.err_at(
            "color",
            format!("expected \"#rrggbb\", got '{}'", printable(text)),
        )),
    }
}

/// The body kinds, as scene files name them.
pub const BODY_KINDS: [&str; 3] = ["static", "kinematic", "dynamic"];

/// Reads one body. Values are only checked for form here; the engine checks the rules
/// (positive mass, non-zero quaternion, plausible inertia) in `World::create_body`.
pub(crate) fn body(node: &Node<'_>) -> Result<(BodyDef, Shape)> {
    let obj = node.object()?;
    obj.only(&BODY_KEYS)?;
    let def = BodyDef {
        name: name(&obj, "bodies")?,
        kind: kind(&obj)?,
        position: obj.vec3("position")?.unwrap_or(Vec3::ZERO),
        orientation: obj.quat("orientation")?.unwrap_or(Quat::IDENTITY),
        linear_velocity: obj.vec3("velocity")?.unwrap_or(Vec3::ZERO),
        angular_velocity: obj.vec3("angular_velocity")?.unwrap_or(Vec3::ZERO),
        mass: mass(&obj)?,
        inertia: obj.get("inertia").map(|n| inertia(&n)).transpose()?,
        center_of_mass: obj.vec3("center_of_mass")?,
        planar: obj.bool("planar")?.unwrap_or(false),
        collision_group: bits(&obj, "collision_group")?.unwrap_or(1),
        collision_mask: bits(&obj, "collision_mask")?.unwrap_or(u32::MAX),
        collision_owner: bits(&obj, "collision_owner")?.unwrap_or(0),
        friction: obj.real("friction")?.unwrap_or(BodyDef::default().friction),
        restitution: obj.real("restitution")?.unwrap_or(0.0),
        rolling_resistance: obj.real("rolling_resistance")?.unwrap_or(0.0),
        torsional_friction: obj.real("torsional_friction")?.unwrap_or(0.0),
        bullet: obj.bool("bullet")?.unwrap_or(false),
        linear_damping: obj.real("linear_damping")?.unwrap_or(0.0),
        angular_damping: obj.real("angular_damping")?.unwrap_or(0.0),
        gravity_scale: obj.real("gravity_scale")?.unwrap_or(1.0),
        sensor: obj.bool("sensor")?.unwrap_or(false),
        one_way: obj.vec3("one_way")?,
    };
    let shape = crate::shape::shape(&obj.required("shape")?)?;
    Ok((def, shape))
}

/// A 32-bit layer mask.
fn bits(obj: &Obj<'_>, key: &str) -> Result<Option<u32>> {
    obj.get(key)
        .map(|n| n.whole(u32::MAX as u64).map(|v| v as u32))
        .transpose()
}

/// A body's or joint's `name` (`bodies`, `joints` say which, for the message), checked.
pub(crate) fn name(obj: &Obj<'_>, of: &str) -> Result<Option<String>> {
    let Some(name) = obj.str("name")? else {
        return Ok(None);
    };
    check_name(name, of).map_err(|reason| obj.err_at("name", reason))?;
    Ok(Some(name.to_string()))
}

/// Whether `name` is digits only (and not empty): what an unnamed body's or joint's label
/// looks like.
pub(crate) fn is_plain_number(name: &str) -> bool {
    !name.is_empty() && name.bytes().all(|b| b.is_ascii_digit())
}

/// Why `name` cannot name one of `of` (`"bodies"` or `"joints"`), or `Ok`. Names label
/// CSV rows and messages, where unnamed bodies and joints are labelled by their index: a
/// name of digits could be mistaken for another's index, an empty one reads as a missing
/// field, and a control character would break the one-line rows and errors. Python's
/// `add_body` and `add_joint` call this too, so a name is refused the same everywhere.
pub fn check_name(name: &str, of: &str) -> std::result::Result<(), String> {
    if name.is_empty() {
        return Err("must not be empty".into());
    }
    if name.chars().any(char::is_control) {
        return Err("must not contain control characters".into());
    }
    if is_plain_number(name) {
        return Err(format!(
            "must not be a plain number (unnamed {of} are labelled by their index)"
        ));
    }
    Ok(())
}

fn kind(obj: &Obj<'_>) -> Result<BodyKind> {
    let Some(kind) = obj.str("kind")? else {
        return Ok(BodyKind::Dynamic);
    };
    BodyKind::from_name(kind).ok_or_else(|| {
        obj.err_at(
            "kind",
            format!(
                "unknown kind '{}' (expected one of: {})",
                printable(kind),
                BODY_KINDS.join(", ")
            ),
        )
    })
}

fn mass(obj: &Obj<'_>) -> Result<MassSpec> {
    match (obj.real("mass")?, obj.real("density")?) {
        (Some(_), Some(_)) => Err(obj.err_at(
            "density",
            "cannot be given together with mass (give one of mass, density)",
        )),
        (Some(m), None) => Ok(MassSpec::Mass(m)),
        (None, Some(d)) => Ok(MassSpec::Density(d)),
        (None, None) => Ok(MassSpec::default()),
    }
}

/// Three principal moments `[Ixx, Iyy, Izz]` or a full tensor as three rows.
fn inertia(node: &Node<'_>) -> Result<InertiaSpec> {
    if !node.is_array_of_arrays() {
        let [x, y, z] = node.reals::<3>("[Ixx, Iyy, Izz] (or a 3x3 matrix of rows)")?;
        return Ok(InertiaSpec::Principal(Vec3::new(x, y, z)));
    }
    let rows = node.array()?;
    let [a, b, c] = rows.as_slice() else {
        return Err(node.err("expected a 3x3 matrix [[..], [..], [..]] (or 3 principal moments)"));
    };
    let rows = [a, b, c].map(|r| r.reals::<3>("(a matrix row)"));
    let [a, b, c] = rows;
    // Rows in, columns in glam: the transpose (a no-op for the symmetric tensors the
    // engine accepts, but an asymmetric one should be reported as given).
    Ok(InertiaSpec::Tensor(
        Mat3::from_cols_array_2d(&[a?, b?, c?]).transpose(),
    ))
}

/// The body a force or joint refers to: by name, or by its index in `bodies` (how a saved
/// scene names a body that has no name).
pub(crate) fn reference(node: &Node<'_>, world: &World) -> Result<BodyId> {
    if node.is_number() {
        let i = node.whole(u64::MAX)?;
        let ids = world.body_ids();
        return usize::try_from(i)
            .ok()
            .and_then(|i| ids.get(i).copied())
            .ok_or_else(|| node.err(format!("no body at index {i} (there are {})", ids.len())));
    }
    let name = node.str()?;
    world
        .find_body(name)
        .ok_or_else(|| node.err(format!("no body named '{}'", printable(name))))
}
