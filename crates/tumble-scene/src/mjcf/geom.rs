//! `<geom>` and `<inertial>`: a geom's Tumble shape and pose in its body's frame, its
//! mass properties (MuJoCo's closed forms: the same as Tumble's for spheres, boxes,
//! cylinders and capsules; an ellipsoid's exact, its collision shape a hull) and its
//! contact settings.

use tumble::{MassProperties, Mat3, Quat, Real, Shape, Vec3};

use super::frame::{self, vec3, Compiler};
use super::mesh::Meshes;
use super::parse::View;
use super::Warnings;
use crate::error::{printable, Result};

/// MuJoCo's default density (kg/m³): water.
const DEFAULT_DENSITY: Real = 1000.0;

/// A geom read from the file, in its MJCF body's frame.
#[derive(Debug, Clone)]
pub(crate) struct Geom {
    /// The collision shape; `None` for a plane (kept in `plane`).
    pub shape: Option<Shape>,
    /// A plane's unit normal and offset in the body frame (static bodies only).
    pub plane: Option<(Vec3, Real)>,
    /// Pose of the shape's frame in the body frame.
    pub position: Vec3,
    pub orientation: Quat,
    /// Mass properties in the body frame.
    pub mass: MassProperties,
    pub contype: u32,
    pub conaffinity: u32,
    /// The sliding friction coefficient (the first of MuJoCo's three).
    pub friction: Real,
    /// The torsional (m) and rolling (m) friction coefficients, the second and third,
    /// where the geom's `condim` reaches them (4 and 6), else 0.
    pub torsional: Real,
    pub rolling: Real,
    pub rgb: Option<[u8; 3]>,
    /// A colliding mesh geom of a static body: its triangles in the geom's frame.
    pub triangles: Option<super::mesh::Triangles>,
    /// `file:line: <geom>`, for errors met when the body is created.
    pub label: String,
}

/// Geom attributes with physics the import does not map (contact softness, margins,
/// fluid forces), warned about when a geom or its class sets them.
const UNREAD: [&str; 7] = [
    "solref",
    "solimp",
    "solmix",
    "margin",
    "gap",
    "priority",
    "fluidshape",
];

/// Tumble's round shapes run along y, MuJoCo's along z: the turn taking y to z.
fn y_to_z() -> Quat {
    Quat::from_axis_angle(Vec3::X, std::f64::consts::FRAC_PI_2 as Real)
}

/// Where a geom goes: the file's meshes, and whether its body moves.
pub(crate) struct Target<'a> {
    pub meshes: &'a mut Meshes,
    pub dynamic: bool,
}

/// A geom, or `None` for the kinds the import does not read (warned about once).
pub(crate) fn geom(
    v: &View<'_>,
    c: &Compiler,
    target: Target<'_>,
    warn: &mut Warnings,
) -> Result<Option<Geom>> {
    let kind = v.get("type").unwrap_or("sphere");
    if matches!(kind, "hfield" | "sdf") {
        warn.add(v.elem, &format!("{kind} geoms: not yet read (skipped)"));
        return Ok(None);
    }
    for key in UNREAD {
        if v.get(key).is_some() {
            warn.add(v.elem, &format!("geom {key}: not read"));
        }
    }
    let f = friction(v, warn)?;
    if kind == "mesh" {
        return mesh_geom(v, c, target, f).map(Some);
    }
    if v.get("mesh").is_some() {
        warn.add(
            v.elem,
            &format!("geom mesh on a {kind} geom (a primitive fitted to a mesh): not read, its size used"),
        );
    }
    let size = v.reals("size", &[])?.unwrap_or_default();
    let (mut position, mut orientation) = frame::frame(v, c)?;
    let fromto = v.reals("fromto", &[6])?;
    let mut size = size;
    if let Some(ft) = &fromto {
        let (a, b) = (vec3(&ft[..3]), vec3(&ft[3..]));
        if !matches!(kind, "capsule" | "cylinder" | "box" | "ellipsoid") {
            return Err(v.err("fromto", format!("not allowed on a {kind} geom")));
        }
        let axis = (b - a)
            .try_normalize()
            .ok_or_else(|| v.err("fromto", "the two points must differ"))?;
        position = 0.5 * (a + b);
        orientation = Quat::from_rotation_arc(Vec3::Z, axis);
        let half = 0.5 * (b - a).length();
        size = match kind {
            "capsule" | "cylinder" => vec![first(v, &size)?, half],
            _ => vec![
                first(v, &size)?,
                size.get(1).copied().unwrap_or(size[0]),
                half,
            ],
        };
    }
    let (shape, plane, unit) = shape_of(v, kind, &size)?;
    let local = match plane {
        Some(_) => Quat::IDENTITY,
        None if matches!(kind, "capsule" | "cylinder") => y_to_z(),
        None => Quat::IDENTITY,
    };
    let mass = geom_mass(v, &unit)?.transformed(position, orientation * local);
    Ok(Some(Geom {
        shape,
        plane: plane.map(|_| (orientation * Vec3::Z, (orientation * Vec3::Z).dot(position))),
        position,
        orientation: orientation * local,
        mass,
        contype: v.bits("contype", 1)?,
        conaffinity: v.bits("conaffinity", 1)?,
        friction: f.slide,
        torsional: f.torsional,
        rolling: f.rolling,
        rgb: rgb(v)?,
        triangles: None,
        label: v.elem.label(),
    }))
}

/// A mesh geom: its frame moved to the mesh's centre of mass (MuJoCo's `geom_pos`); the
/// mesh's convex hull on a moving body, its triangles on a static one.
fn mesh_geom(v: &View<'_>, c: &Compiler, target: Target<'_>, f: Friction) -> Result<Geom> {
    let name = v
        .get("mesh")
        .ok_or_else(|| v.err("mesh", "missing on a mesh geom"))?;
    if v.get("fromto").is_some() {
        return Err(v.err("fromto", "not allowed on a mesh geom"));
    }
    let (position, orientation) = frame::frame(v, c)?;
    let (contype, conaffinity) = (v.bits("contype", 1)?, v.bits("conaffinity", 1)?);
    let colliding = contype | conaffinity != 0;
    let (mesh, hull) = target.meshes.get(v, name, colliding && target.dynamic)?;
    let position = position + orientation * mesh.center;
    let triangles = (colliding && !target.dynamic)
        .then(|| std::rc::Rc::new(super::mesh::nondegenerate(&mesh.points, &mesh.triangles)));
    let mass = geom_mass(v, &mesh.unit)?.transformed(position, orientation);
    Ok(Geom {
        shape: hull,
        plane: None,
        position,
        orientation,
        mass,
        contype,
        conaffinity,
        friction: f.slide,
        torsional: f.torsional,
        rolling: f.rolling,
        rgb: rgb(v)?,
        triangles,
        label: v.elem.label(),
    })
}

fn first(v: &View<'_>, size: &[Real]) -> Result<Real> {
    size.first()
        .copied()
        .ok_or_else(|| v.err("size", "missing (the radius)"))
}

/// The size entries a kind needs, each > 0.
fn sizes(v: &View<'_>, kind: &str, size: &[Real], n: usize) -> Result<Vec<Real>> {
    if size.len() < n {
        return Err(v.err(
            "size",
            format!("a {kind} needs {n} numbers, got {}", size.len()),
        ));
    }
    if let Some(bad) = size[..n].iter().find(|x| **x <= 0.0) {
        return Err(v.err("size", format!("must be > 0, got {bad}")));
    }
    Ok(size[..n].to_vec())
}

type ShapeParts = (Option<Shape>, Option<()>, MassProperties);

/// The shape (in its own frame, round shapes along y) and its unit-density mass
/// properties in the geom's frame (along z).
fn shape_of(v: &View<'_>, kind: &str, size: &[Real]) -> Result<ShapeParts> {
    let s = |n| sizes(v, kind, size, n);
    let unit = |shape: &Shape, turn: Quat| shape.mass_properties(1.0).transformed(Vec3::ZERO, turn);
    let out = match kind {
        "sphere" => {
            let shape = Shape::sphere(s(1)?[0]);
            (unit(&shape, Quat::IDENTITY), shape)
        }
        "capsule" | "cylinder" => {
            let r = s(2)?;
            let shape = if kind == "capsule" {
                Shape::capsule(r[0], r[1])
            } else {
                Shape::cylinder(r[0], r[1])
            };
            // Mass properties in the shape's own (y) frame; the geom's pose adds the turn.
            (unit(&shape, Quat::IDENTITY), shape)
        }
        "box" => {
            let h = s(3)?;
            let shape = Shape::cuboid(vec3(&h));
            (unit(&shape, Quat::IDENTITY), shape)
        }
        "ellipsoid" => return ellipsoid(v, &s(3)?),
        "plane" => {
            // MuJoCo's planes are infinite for collision (size only draws them).
            return Ok((None, Some(()), MassProperties::diagonal(0.0, Vec3::ZERO)));
        }
        other => return Err(v.err("type", format!("unknown geom type '{}'", printable(other)))),
    };
    Ok((Some(out.1), None, out.0))
}

/// An ellipsoid: exact mass properties (m = ρ 4/3 π abc, I_x = m (b² + c²)/5, ...), and as
/// a collision shape the hull of 12 × 24 points on its surface.
fn ellipsoid(v: &View<'_>, r: &[Real]) -> Result<ShapeParts> {
    let (a, b, c) = (r[0], r[1], r[2]);
    let pi = std::f64::consts::PI as Real;
    let mass = 4.0 / 3.0 * pi * a * b * c;
    let unit = MassProperties::diagonal(
        mass,
        Vec3::new(b * b + c * c, a * a + c * c, a * a + b * b) * (mass / 5.0),
    );
    let mut points = vec![Vec3::new(0.0, 0.0, c), Vec3::new(0.0, 0.0, -c)];
    for i in 1..12 {
        let theta = pi * i as Real / 12.0;
        for j in 0..24 {
            let phi = 2.0 * pi * j as Real / 24.0;
            let (st, ct) = theta.sin_cos();
            let (sp, cp) = phi.sin_cos();
            points.push(Vec3::new(a * st * cp, b * st * sp, c * ct));
        }
    }
    let shape = Shape::convex_hull(&points).map_err(|e| v.err("size", e.to_string()))?;
    Ok((Some(shape), None, unit))
}

/// The geom's mass properties in its own frame: `mass` if given, else `density` × volume.
fn geom_mass(v: &View<'_>, unit: &MassProperties) -> Result<MassProperties> {
    if let Some(m) = v.real("mass")? {
        if m < 0.0 {
            return Err(v.err("mass", format!("must be >= 0, got {m}")));
        }
        if unit.mass <= 0.0 || m == 0.0 {
            return Ok(MassProperties::diagonal(0.0, Vec3::ZERO));
        }
        return Ok(unit.with_mass(m));
    }
    let density = v.real("density")?.unwrap_or(DEFAULT_DENSITY);
    if density < 0.0 {
        return Err(v.err("density", format!("must be >= 0, got {density}")));
    }
    Ok(MassProperties {
        mass: unit.mass * density,
        center: unit.center,
        inertia: unit.inertia * density,
    })
}

/// A geom's friction as its `condim` makes it act (see [`friction`]).
struct Friction {
    slide: Real,
    torsional: Real,
    rolling: Real,
}

/// MuJoCo's friction triple (sliding; torsional and rolling, in metres: the torque's cap
/// per newton of normal force), `1 0.005 0.0001` where not given, and the part of it the
/// geom's `condim` switches on: torsional from 4, rolling at 6. A pair's coefficients
/// are each the larger of its two geoms' (MuJoCo's rule at equal priority, and Tumble's
/// for torsional friction and rolling resistance). `condim 1` (frictionless) holds only
/// between two such geoms in MuJoCo, which one body's friction cannot say: warned.
fn friction(v: &View<'_>, warn: &mut Warnings) -> Result<Friction> {
    let given = v.reals("friction", &[1, 2, 3])?.unwrap_or_default();
    let mut f = [1.0, 0.005, 0.0001];
    for (k, x) in given.into_iter().enumerate() {
        if !x.is_finite() || x < 0.0 {
            return Err(v.err("friction", format!("must be finite and >= 0, got {x}")));
        }
        f[k] = x;
    }
    let condim = v.bits("condim", 3)?;
    if !matches!(condim, 1 | 3 | 4 | 6) {
        return Err(v.err("condim", format!("must be 1, 3, 4 or 6, got {condim}")));
    }
    if condim == 1 {
        warn.add(
            v.elem,
            "geom condim 1 (frictionless): not read, friction kept",
        );
    }
    Ok(Friction {
        slide: f[0],
        torsional: if condim >= 4 { f[1] } else { 0.0 },
        rolling: if condim == 6 { f[2] } else { 0.0 },
    })
}

/// The radius a geom rolls on, which turns MuJoCo's rolling friction (a length) into
/// Tumble's dimensionless rolling resistance μ_r (a torque of at most μ_r r N, r the
/// distance from the centre of mass to the contact plane): a round geom's radius, a box's
/// or hull's smallest half-width. Exact for a ball, MuJoCo's usual roller.
pub(crate) fn rolling_radius(shape: &Shape) -> Option<Real> {
    match shape {
        Shape::Sphere { radius } | Shape::Capsule { radius, .. } => Some(*radius),
        Shape::Cylinder { radius, .. } => Some(*radius),
        Shape::Box { half_extents } => Some(half_extents.min_element()),
        Shape::ConvexHull(_) => {
            let b = shape.aabb(&tumble::Pose::IDENTITY);
            Some((0.5 * (b.max - b.min)).min_element())
        }
        _ => None,
    }
}

fn rgb(v: &View<'_>) -> Result<Option<[u8; 3]>> {
    let Some(c) = v.reals("rgba", &[4])? else {
        return Ok(None);
    };
    let byte = |x: Real| (x.clamp(0.0, 1.0) * 255.0).round() as u8;
    Ok(Some([byte(c[0]), byte(c[1]), byte(c[2])]))
}

/// `<inertial>`: mass, centre (`pos`), and the tensor from `diaginertia` (in the frame
/// of `quat`/...) or `fullinertia` (ixx iyy izz ixy ixz iyz, body frame).
pub(crate) fn inertial(v: &View<'_>, c: &Compiler) -> Result<MassProperties> {
    let mass = v.real("mass")?.ok_or_else(|| v.err("mass", "missing"))?;
    if mass < 0.0 {
        return Err(v.err("mass", format!("must be >= 0, got {mass}")));
    }
    let (pos, rot) = frame::frame(v, c)?;
    let tensor = match (v.reals("diaginertia", &[3])?, v.reals("fullinertia", &[6])?) {
        (Some(d), None) => {
            let r = Mat3::from_quat(rot);
            r * Mat3::from_diagonal(vec3(&d)) * r.transpose()
        }
        (None, Some(f)) => Mat3::from_cols(
            Vec3::new(f[0], f[3], f[4]),
            Vec3::new(f[3], f[1], f[5]),
            Vec3::new(f[4], f[5], f[2]),
        ),
        (Some(_), Some(_)) => return Err(v.err("fullinertia", "diaginertia is given too")),
        (None, None) => return Err(v.err("diaginertia", "missing (or fullinertia)")),
    };
    check_tensor(v, tensor)?;
    Ok(MassProperties {
        mass,
        center: pos,
        inertia: tensor,
    })
}

/// A physical inertia: principal moments >= 0 and each at most the sum of the others.
fn check_tensor(v: &View<'_>, t: Mat3) -> Result<()> {
    let (m, _) = tumble::math::symmetric_eigen(t);
    let key = if v.get("fullinertia").is_some() {
        "fullinertia"
    } else {
        "diaginertia"
    };
    if m.min_element() < 0.0 {
        return Err(v.err(key, "principal moments must be >= 0"));
    }
    let tol = 1e-9 * m.max_element();
    if m.x + m.y + tol < m.z || m.y + m.z + tol < m.x || m.x + m.z + tol < m.y {
        return Err(v.err(
            key,
            "impossible inertia: each principal moment must be at most the sum of the other two",
        ));
    }
    Ok(())
}
