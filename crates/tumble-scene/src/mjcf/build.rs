//! The element tree to a plan (every body, joint and actuator checked), then the plan to
//! Tumble bodies and joints. Nothing touches the world until the whole file has been
//! read, and a failure while creating undoes what was created.

use std::path::Path;

use tumble::{Integrator, JointKind, MassProperties, Quat, Real, Servo, Vec3, World};

use super::frame::{self, vec3, Compiler};
use super::geom::{self, Geom};
use super::mesh::{self, Meshes};
use super::parse::{Defaults, Elem, View, MAIN};
use super::{ImportedMjcf, MjcfOptions, Warning, Warnings};
use crate::error::{printable, Result};

/// A servo's force bound when nothing limits it (N·m or N): in effect none.
const UNLIMITED: Real = 1e12;
/// An intermediate body's mass and moments, as a fraction of the body it carries.
pub(crate) const LIGHT: Real = 1e-3;

/// A Tumble body to create.
#[derive(Debug)]
pub(crate) struct PlanBody {
    pub name: Option<String>,
    pub label: String,
    pub dynamic: bool,
    /// Pose of the body frame in the world.
    pub position: Vec3,
    pub orientation: Quat,
    pub geoms: Vec<Geom>,
    /// Mass properties of the parts welded into it, in its frame.
    pub mass: Vec<MassProperties>,
    /// Set on intermediate bodies: the body whose mass they take a fraction of.
    pub light_of: Option<usize>,
}

/// A Tumble joint to create.
#[derive(Debug)]
pub(crate) struct PlanJoint {
    pub name: String,
    pub label: String,
    pub kind: String,
    pub def: JointKind,
    pub body: usize,
    pub other: Option<usize>,
    /// Anchor and axis in `body`'s frame.
    pub anchor: Vec3,
    pub axis: Vec3,
    pub reference: Real,
    /// Passive spring k, its target (Tumble coordinate), damper c.
    pub spring: (Real, Real, Real),
    /// The coordinate's armature (hinge kg m², slide kg; 0 for a ball joint).
    pub armature: Real,
}

/// Everything read from the file, checked, before the world is touched.
pub(crate) struct Plan {
    pub model: Option<String>,
    pub bodies: Vec<PlanBody>,
    pub joints: Vec<PlanJoint>,
    /// Per joint, its servo at zero control.
    pub servos: Vec<Option<Servo>>,
    pub free: Vec<(String, usize)>,
    pub names: Vec<(String, usize)>,
    pub excluded: Vec<(usize, usize)>,
    pub actuators: Vec<PlanActuator>,
    pub settings: Settings,
    pub warnings: Vec<Warning>,
}

struct Ctx<'a> {
    defaults: &'a Defaults,
    compiler: Compiler,
    meshes: Meshes,
    warn: Warnings,
    bodies: Vec<PlanBody>,
    joints: Vec<PlanJoint>,
    free: Vec<(String, usize)>,
    names: Vec<(String, usize)>,
    /// Pairs that must not collide though no joint joins them directly.
    excluded: Vec<(usize, usize)>,
    unnamed_joints: usize,
    /// From `<option><flag>`: whether joint ranges limit, and springs and dampers act.
    limits: bool,
    passive: bool,
}

/// Reads the tree and builds it into `world`.
/// `dir`: the model file's folder, against which mesh files are found.
pub(crate) fn build(
    root: &Elem,
    dir: &Path,
    world: &mut World,
    options: &MjcfOptions,
) -> Result<ImportedMjcf> {
    let defaults = Defaults::collect(root)?;
    let mut ctx = Ctx {
        defaults: &defaults,
        compiler: Compiler::default(),
        meshes: Meshes::default(),
        warn: Warnings::default(),
        bodies: Vec::new(),
        joints: Vec::new(),
        free: Vec::new(),
        names: Vec::new(),
        excluded: Vec::new(),
        unnamed_joints: 0,
        limits: true,
        passive: true,
    };
    for c in root.kids("compiler") {
        ctx.compiler.read(&View::new(c, MAIN, &defaults)?)?;
    }
    let c = &ctx.compiler;
    let mesh_dir = mesh::mesh_dir(dir, c.meshdir.as_deref(), c.assetdir.as_deref());
    ctx.meshes = Meshes::collect(root, &defaults, &mesh_dir, c.strip_path, &mut ctx.warn)?;
    let settings = read_options(root, &defaults, &mut ctx.warn)?;
    ctx.limits = settings.limits;
    ctx.passive = settings.passive;
    ctx.bodies.push(PlanBody {
        name: Some("world".to_string()),
        label: "world".to_string(),
        dynamic: false,
        position: options.position,
        orientation: options.orientation.normalize(),
        geoms: Vec::new(),
        mass: Vec::new(),
        light_of: None,
    });
    let pose = (options.position, options.orientation.normalize());
    for wb in root.kids("worldbody") {
        body_contents(&mut ctx, wb, 0, pose, MAIN)?;
    }
    warn_unread_sections(root, &mut ctx.warn);
    exclusions(&mut ctx, root)?;
    let actuators = read_actuators(&mut ctx, root)?;
    let servos = servos(&ctx, &actuators);
    if let Some(total) = ctx.compiler.total_mass {
        scale_masses(&mut ctx.bodies, total);
    }
    let plan = Plan {
        model: root.own("model").map(str::to_string),
        bodies: ctx.bodies,
        joints: ctx.joints,
        servos,
        free: ctx.free,
        names: ctx.names,
        excluded: ctx.excluded,
        actuators,
        settings,
        warnings: ctx.warn.list,
    };
    super::create::create(plan, world, options)
}

/// `<compiler settotalmass>`: every moving body's mass and inertia times one factor, so
/// that they add up to `total`.
fn scale_masses(bodies: &mut [PlanBody], total: Real) {
    let now: Real = bodies
        .iter()
        .filter(|b| b.dynamic && b.light_of.is_none())
        .flat_map(|b| b.mass.iter().map(|m| m.mass))
        .sum();
    if now <= 0.0 {
        return;
    }
    let k = total / now;
    for b in bodies.iter_mut().filter(|b| b.dynamic) {
        for m in &mut b.mass {
            m.mass *= k;
            m.inertia *= k;
        }
    }
}

/// `<option>`: timestep, gravity, integrator.
pub(crate) struct Settings {
    pub timestep: Real,
    pub gravity: Vec3,
    pub integrator: Integrator,
    /// `<flag contact="disable">` (or `constraint`): no body collides with any other.
    pub contacts: bool,
    /// `<flag limit="disable">` (or `constraint`): joint ranges are not limits.
    pub limits: bool,
    /// `<flag passive="disable">`: no joint springs or dampers.
    pub passive: bool,
}

fn read_options(root: &Elem, defaults: &Defaults, warn: &mut Warnings) -> Result<Settings> {
    let mut s = Settings {
        timestep: 0.002,
        gravity: Vec3::new(0.0, 0.0, -9.81),
        integrator: Integrator::SymplecticEuler,
        contacts: true,
        limits: true,
        passive: true,
    };
    for o in root.kids("option") {
        let v = View::new(o, MAIN, defaults)?;
        if let Some(dt) = v.real("timestep")? {
            if dt <= 0.0 {
                return Err(v.err("timestep", format!("must be > 0, got {dt}")));
            }
            s.timestep = dt;
        }
        if let Some(g) = v.reals("gravity", &[3])? {
            s.gravity = vec3(&g);
        }
        // The nearest Tumble integrator: MuJoCo's Euler is semi-implicit (velocity first).
        s.integrator = match v.get("integrator") {
            None => s.integrator,
            Some("Euler") => Integrator::SymplecticEuler,
            Some("RK4") => Integrator::Rk4,
            Some("implicit" | "implicitfast") => Integrator::ImplicitEuler,
            Some(t) => {
                return Err(v.err(
                    "integrator",
                    format!(
                        "unknown integrator '{}' (expected Euler, RK4, implicit, implicitfast)",
                        printable(t)
                    ),
                ))
            }
        };
        for key in [
            "density",
            "viscosity",
            "wind",
            "magnetic",
            "o_margin",
            "cone",
            "impratio",
            "noslip_iterations",
        ] {
            if v.get(key).is_some() {
                warn.add(o, &format!("option {key}: not read"));
            }
        }
        for flag in o.kids("flag") {
            read_flags(flag, &mut s, warn);
        }
    }
    Ok(s)
}

/// `<option><flag>`: the switches that change what is simulated.
fn read_flags(flag: &Elem, s: &mut Settings, warn: &mut Warnings) {
    for (key, value) in &flag.attrs {
        let off = value == "disable";
        match key.as_str() {
            "contact" => s.contacts &= !off,
            "limit" => s.limits &= !off,
            "passive" => s.passive &= !off,
            "constraint" => {
                s.contacts &= !off;
                s.limits &= !off;
            }
            "gravity" if off => s.gravity = Vec3::ZERO,
            // Reporting and solver details with nothing to map to.
            "energy" | "warmstart" | "gravity" => {}
            other => warn.add(flag, &format!("option flag {other}: not read")),
        }
    }
}

/// Sections with no physics the import reads, or none at all.
fn warn_unread_sections(root: &Elem, warn: &mut Warnings) {
    const QUIET: [&str; 12] = [
        "compiler",
        "option",
        "default",
        "worldbody",
        "actuator",
        "contact",
        "asset",
        "visual",
        "statistic",
        "size",
        "keyframe",
        "extension",
    ];
    for kid in &root.children {
        if !QUIET.contains(&kid.tag.as_str()) {
            warn.add(kid, &format!("<{}>: not read", kid.tag));
        }
    }
}

/// Composes a child frame onto a parent's.
fn compose(parent: (Vec3, Quat), child: (Vec3, Quat)) -> (Vec3, Quat) {
    (
        parent.0 + parent.1 * child.0,
        (parent.1 * child.1).normalize(),
    )
}

/// The geoms, joints and child bodies of `elem` (a `<body>` or the `<worldbody>`), whose
/// parts go into plan body `target`; `pose` is `elem`'s frame in the world.
fn body_contents(
    ctx: &mut Ctx<'_>,
    elem: &Elem,
    target: usize,
    pose: (Vec3, Quat),
    class: &str,
) -> Result<()> {
    let defaults = ctx.defaults;
    let t = &ctx.bodies[target];
    // The element's frame relative to the body its parts join.
    let inv = t.orientation.inverse();
    let rel = (inv * (pose.0 - t.position), (inv * pose.1).normalize());
    let mut geoms = Vec::new();
    for g in elem.kids("geom") {
        let v = View::new(g, class, defaults)?;
        let place = geom::Target {
            meshes: &mut ctx.meshes,
            dynamic: ctx.bodies[target].dynamic,
        };
        if let Some(mut gm) = geom::geom(&v, &ctx.compiler, place, &mut ctx.warn)? {
            if gm.plane.is_some() && ctx.bodies[target].dynamic {
                return Err(v.err("type", "a plane must be part of the world body"));
            }
            place_geom(&mut gm, rel);
            geoms.push(gm);
        }
    }
    let mass = body_mass(ctx, elem, class, &geoms)?;
    let b = &mut ctx.bodies[target];
    b.mass.push(mass.transformed(rel.0, rel.1));
    b.geoms.extend(geoms);
    for kid in &elem.children {
        match kid.tag.as_str() {
            "body" => child_body(ctx, kid, target, pose, class)?,
            "frame" => frame_contents(ctx, kid, target, pose, class)?,
            "geom" | "joint" | "freejoint" | "inertial" => {}
            "site" | "camera" | "light" => {}
            other => ctx.warn.add(kid, &format!("<{other}>: not read")),
        }
    }
    Ok(())
}

/// `<frame>`: a pose (and `childclass`) for the geoms and bodies inside it, which belong
/// to the body around it.
fn frame_contents(
    ctx: &mut Ctx<'_>,
    elem: &Elem,
    target: usize,
    pose: (Vec3, Quat),
    class: &str,
) -> Result<()> {
    let defaults = ctx.defaults;
    let v = View::new(elem, class, defaults)?;
    let pose = compose(pose, frame::frame(&v, &ctx.compiler)?);
    let class = child_class(elem, &v, defaults, class)?;
    if elem.kids("joint").next().is_some() || elem.kids("freejoint").next().is_some() {
        return Err(v.err("joint", "joints belong in a <body>, not a <frame>"));
    }
    body_contents(ctx, elem, target, pose, class)
}

/// Moves a geom read in its element's frame into the frame `rel` of the body it joins.
fn place_geom(g: &mut Geom, rel: (Vec3, Quat)) {
    g.position = rel.0 + rel.1 * g.position;
    g.orientation = (rel.1 * g.orientation).normalize();
    g.plane = g.plane.map(|(n, _)| {
        let n = rel.1 * n;
        (n, n.dot(g.position))
    });
}

/// A body's own mass properties in its frame: `<inertial>`, or its geoms' (per the
/// compiler's `inertiafromgeom`).
fn body_mass(ctx: &Ctx<'_>, elem: &Elem, class: &str, geoms: &[Geom]) -> Result<MassProperties> {
    use frame::FromGeom;
    let inertial = elem.kids("inertial").next();
    let from_geoms = match (ctx.compiler.from_geom, inertial) {
        (FromGeom::Always, _) | (FromGeom::Auto, None) => true,
        (FromGeom::Never, _) | (FromGeom::Auto, Some(_)) => false,
    };
    if from_geoms {
        return Ok(sum(geoms.iter().map(|g| g.mass)));
    }
    match inertial {
        Some(i) => geom::inertial(&View::new(i, class, ctx.defaults)?, &ctx.compiler),
        None => Ok(MassProperties::diagonal(0.0, Vec3::ZERO)),
    }
}

/// Mass properties summed, massless parts left out (no 0/0 centre).
pub(crate) fn sum(parts: impl Iterator<Item = MassProperties>) -> MassProperties {
    let parts: Vec<MassProperties> = parts.filter(|p| p.mass > 0.0).collect();
    if parts.is_empty() {
        return MassProperties::diagonal(0.0, Vec3::ZERO);
    }
    MassProperties::sum(parts)
}

/// The class an element's children take: its own `childclass` (which must be a defined
/// `<default>` class), else `class`, the one it inherited.
fn child_class<'a>(
    elem: &'a Elem,
    v: &View<'_>,
    defaults: &Defaults,
    class: &'a str,
) -> Result<&'a str> {
    match elem.own("childclass") {
        Some(c) if !defaults.has(c) => Err(v.err(
            "childclass",
            format!("no <default class=\"{}\">", printable(c)),
        )),
        Some(c) => Ok(c),
        None => Ok(class),
    }
}

fn child_body(
    ctx: &mut Ctx<'_>,
    elem: &Elem,
    parent: usize,
    parent_pose: (Vec3, Quat),
    class: &str,
) -> Result<()> {
    let defaults = ctx.defaults;
    let v = View::new(elem, class, defaults)?;
    let pose = compose(parent_pose, frame::frame(&v, &ctx.compiler)?);
    let child_class = child_class(elem, &v, defaults, class)?;
    // A mocap body is moved by MuJoCo's mocap_pos (here: static, as welded to the world);
    // gravity compensation has nothing to map to.
    if elem.own("mocap") == Some("true") {
        ctx.warn
            .add(elem, "body mocap: not read (the body stays where it is)");
    }
    if elem
        .own("gravcomp")
        .is_some_and(|g| g.trim().parse::<f64>() != Ok(0.0))
    {
        ctx.warn.add(elem, "body gravcomp: not read");
    }
    let joints: Vec<&Elem> = elem
        .children
        .iter()
        .filter(|k| k.tag == "joint" || k.tag == "freejoint")
        .collect();
    let target = if joints.is_empty() {
        parent
    } else {
        let index = new_body(ctx, elem, pose, None);
        add_joints(ctx, &joints, index, parent, child_class)?;
        index
    };
    if let Some(name) = elem.own("name") {
        ctx.names.push((name.to_string(), target));
    }
    body_contents(ctx, elem, target, pose, child_class)
}

fn new_body(ctx: &mut Ctx<'_>, elem: &Elem, pose: (Vec3, Quat), light_of: Option<usize>) -> usize {
    let name = match light_of {
        None => elem.own("name").map(str::to_string),
        Some(_) => None,
    };
    ctx.bodies.push(PlanBody {
        name,
        label: elem.label(),
        dynamic: true,
        position: pose.0,
        orientation: pose.1,
        geoms: Vec::new(),
        mass: Vec::new(),
        light_of,
    });
    ctx.bodies.len() - 1
}

/// The body's joints, first nearest the parent: a free joint alone makes it free; more
/// than one joint chains it to its parent through light intermediate bodies.
fn add_joints(
    ctx: &mut Ctx<'_>,
    joints: &[&Elem],
    body: usize,
    parent: usize,
    class: &str,
) -> Result<()> {
    let defaults = ctx.defaults;
    let views = joints
        .iter()
        .map(|j| View::new(j, class, defaults))
        .collect::<Result<Vec<_>>>()?;
    let is_free = |v: &View<'_>| v.elem.tag == "freejoint" || v.get("type") == Some("free");
    if let Some(free) = views.iter().find(|v| is_free(v)) {
        if views.len() > 1 {
            return Err(free.elem.err("a free joint must be its body's only joint"));
        }
        if non_negative(free, "armature")? > 0.0 {
            ctx.warn.add(free.elem, "free joint armature: not applied");
        }
        let name = joint_name(ctx, free.elem);
        ctx.free.push((name, body));
        if ctx.bodies[parent].dynamic {
            ctx.excluded.push((body, parent));
        }
        return Ok(());
    }
    if views.len() > 1 {
        ctx.warn.add(
            views[1].elem,
            "several joints in one body: chained through light intermediate bodies (1/1000 of its mass)",
        );
        if ctx.bodies[parent].dynamic {
            ctx.excluded.push((body, parent));
        }
    }
    let pose = (ctx.bodies[body].position, ctx.bodies[body].orientation);
    let mut other = parent;
    for (k, v) in views.iter().enumerate() {
        let this = if k + 1 == views.len() {
            body
        } else {
            new_body(ctx, v.elem, pose, Some(body))
        };
        let joint = joint(ctx, v, this, other)?;
        ctx.joints.push(joint);
        other = this;
    }
    Ok(())
}

/// A joint's name: its own, or MuJoCo's position-based `jointN` for unnamed ones.
fn joint_name(ctx: &mut Ctx<'_>, elem: &Elem) -> String {
    match elem.own("name") {
        Some(n) => n.to_string(),
        None => {
            ctx.unnamed_joints += 1;
            format!("joint{}", ctx.unnamed_joints - 1)
        }
    }
}

/// One hinge, slide or ball joint from `body` (the child side) to `other`.
fn joint(ctx: &mut Ctx<'_>, v: &View<'_>, body: usize, other: usize) -> Result<PlanJoint> {
    let kind = v.get("type").unwrap_or("hinge").to_string();
    let angular = match kind.as_str() {
        "hinge" | "ball" => true,
        "slide" => false,
        t => {
            return Err(v.err(
                "type",
                format!(
                    "unknown joint type '{}' (expected hinge, slide, ball, free)",
                    printable(t)
                ),
            ))
        }
    };
    let c = &ctx.compiler;
    let unit = |x: Real| if angular { c.angle(x) } else { x };
    let anchor = frame::position(v)?;
    let axis = v.reals("axis", &[3])?.map_or(Vec3::Z, |a| vec3(&a));
    let axis = axis
        .try_normalize()
        .ok_or_else(|| v.err("axis", "must not be zero"))?;
    let reference = unit(v.real("ref")?.unwrap_or(0.0));
    let range = joint_range(v, c)?
        .filter(|_| ctx.limits)
        .map(|[lo, hi]| [unit(lo) - reference, unit(hi) - reference]);
    let passive = if ctx.passive { 1.0 } else { 0.0 };
    let stiffness = non_negative(v, "stiffness")? * passive;
    let damping = non_negative(v, "damping")? * passive;
    let springref = unit(v.real("springref")?.unwrap_or(0.0));
    let mut armature = non_negative(v, "armature")?;
    warn_unread_joint(ctx, v)?;
    let def = match kind.as_str() {
        "hinge" => JointKind::Hinge {
            limits: range,
            motor: None,
            spring: None,
            servo: None,
        },
        "slide" => JointKind::Slider {
            limits: range,
            motor: None,
            spring: None,
            servo: None,
        },
        _ => {
            if stiffness > 0.0 || damping > 0.0 {
                ctx.warn
                    .add(v.elem, "ball joint stiffness and damping: not applied");
            }
            if armature > 0.0 {
                ctx.warn.add(v.elem, "ball joint armature: not applied");
                armature = 0.0;
            }
            JointKind::Ball {
                cone: range.map(|r| r[1] + reference),
                twist: None,
            }
        }
    };
    Ok(PlanJoint {
        name: joint_name(ctx, v.elem),
        label: v.elem.label(),
        kind,
        def,
        body,
        other: Some(other),
        anchor,
        axis,
        reference,
        spring: (stiffness, springref - reference, damping),
        armature,
    })
}

/// Joint attributes with nothing to map to, warned about once each.
fn warn_unread_joint(ctx: &mut Ctx<'_>, v: &View<'_>) -> Result<()> {
    for key in ["solreflimit", "solimplimit", "margin"] {
        if v.get(key).is_some() {
            ctx.warn.add(v.elem, &format!("joint {key}: not read"));
        }
    }
    if non_negative(v, "frictionloss")? > 0.0 {
        ctx.warn.add(
            v.elem,
            "joint frictionloss: cannot be expressed, not applied",
        );
    }
    Ok(())
}

fn non_negative(v: &View<'_>, key: &str) -> Result<Real> {
    let x = v.real(key)?.unwrap_or(0.0);
    if x < 0.0 {
        return Err(v.err(key, format!("must be >= 0, got {x}")));
    }
    Ok(x)
}

/// `range` when the joint is limited (`limited`, or a range under `autolimits`).
fn joint_range(v: &View<'_>, c: &Compiler) -> Result<Option<[Real; 2]>> {
    let range = v.reals("range", &[2])?;
    let limited = v
        .flag("limited")?
        .unwrap_or(c.autolimits && range.is_some());
    match (limited, range) {
        (false, _) => Ok(None),
        (true, None) => Err(v.err("range", "missing on a limited joint")),
        (true, Some(r)) if r[0] > r[1] => Err(v.err("range", "lower must be <= upper")),
        (true, Some(r)) => Ok(Some([r[0], r[1]])),
    }
}

/// `<contact><exclude body1 body2>` pairs (by the plan bodies the two are part of).
fn exclusions(ctx: &mut Ctx<'_>, root: &Elem) -> Result<()> {
    for contact in root.kids("contact") {
        for kid in &contact.children {
            if kid.tag != "exclude" {
                ctx.warn
                    .add(kid, &format!("<contact><{}>: not read", kid.tag));
                continue;
            }
            let find = |key: &str| -> Result<usize> {
                let name = kid
                    .own(key)
                    .ok_or_else(|| kid.err(format!("{key}: missing")))?;
                ctx.names
                    .iter()
                    .find(|(n, _)| n == name)
                    .map(|b| b.1)
                    .or((name == "world").then_some(0))
                    .ok_or_else(|| kid.err(format!("{key}: no body '{}'", printable(name))))
            };
            let pair = (find("body1")?, find("body2")?);
            ctx.excluded.push(pair);
        }
    }
    Ok(())
}

/// The largest principal moment (kg·m²).
pub(crate) fn largest_moment(m: &MassProperties) -> Real {
    tumble::math::symmetric_eigen(m.inertia).0.max_element()
}

/// An actuator as read, before the joint ids exist.
pub(crate) struct PlanActuator {
    pub name: String,
    pub kind: String,
    pub joint: usize,
    pub gain: Real,
    /// Position actuators' damping (`kv`).
    pub damping: Real,
    pub ctrl_range: Option<[Real; 2]>,
    pub force_range: Option<[Real; 2]>,
}

fn read_actuators(ctx: &mut Ctx<'_>, root: &Elem) -> Result<Vec<PlanActuator>> {
    let mut out = Vec::new();
    for section in root.kids("actuator") {
        for a in &section.children {
            if let Some(act) = actuator(ctx, a, out.len())? {
                out.push(act);
            }
        }
    }
    Ok(out)
}

fn actuator(ctx: &mut Ctx<'_>, a: &Elem, index: usize) -> Result<Option<PlanActuator>> {
    if !matches!(a.tag.as_str(), "motor" | "position" | "velocity") {
        ctx.warn.add(a, &format!("<{}> actuators: not read", a.tag));
        return Ok(None);
    }
    let v = View::new(a, MAIN, ctx.defaults)?;
    let Some(joint_name) = a.own("joint").or_else(|| v.get("joint")) else {
        ctx.warn.add(a, "actuators on tendons or sites: not read");
        return Ok(None);
    };
    let Some(joint) = ctx.joints.iter().position(|j| j.name == joint_name) else {
        if ctx.free.iter().any(|f| f.0 == joint_name) {
            ctx.warn.add(a, "actuators on free joints: not read");
            return Ok(None);
        }
        return Err(v.err("joint", format!("no joint '{}'", printable(joint_name))));
    };
    if ctx.joints[joint].kind == "ball" {
        ctx.warn.add(a, "actuators on ball joints: not read");
        return Ok(None);
    }
    for key in ["timeconst", "dampratio"] {
        if a.tag == "position" && v.get(key).is_some() {
            ctx.warn
                .add(a, &format!("position actuator {key}: not read"));
        }
    }
    let gear = v.reals("gear", &[1, 2, 3, 4, 5, 6])?.map_or(1.0, |g| g[0]);
    let (gain, damping) = match a.tag.as_str() {
        "motor" => (gear, 0.0),
        "position" => (v.real("kp")?.unwrap_or(1.0), v.real("kv")?.unwrap_or(0.0)),
        _ => (v.real("kv")?.unwrap_or(1.0), 0.0),
    };
    if gain < 0.0 || damping < 0.0 {
        return Err(v.err("kp", "gains must be >= 0"));
    }
    let range = |key: &str, limited: &str| -> Result<Option<[Real; 2]>> {
        let r = v.reals(key, &[2])?;
        let on = v
            .flag(limited)?
            .unwrap_or(ctx.compiler.autolimits && r.is_some());
        Ok(if on { r.map(|r| [r[0], r[1]]) } else { None })
    };
    Ok(Some(PlanActuator {
        name: a
            .own("name")
            .map_or_else(|| format!("actuator{index}"), str::to_string),
        kind: a.tag.clone(),
        joint,
        gain,
        damping,
        ctrl_range: range("ctrlrange", "ctrllimited")?,
        force_range: range("forcerange", "forcelimited")?,
    }))
}

/// Each joint's servo at zero control: its spring and damper with the position
/// actuators' kp (pulling to qpos 0) and the velocity actuators' kv added.
fn servos(ctx: &Ctx<'_>, actuators: &[PlanActuator]) -> Vec<Option<Servo>> {
    let mut out = Vec::new();
    for (i, j) in ctx.joints.iter().enumerate() {
        let (k, target, c) = j.spring;
        let (mut stiff, mut pull, mut damp) = (k, k * target, c);
        for a in actuators.iter().filter(|a| a.joint == i) {
            match a.kind.as_str() {
                "position" => {
                    stiff += a.gain;
                    pull += a.gain * (0.0 - j.reference);
                    damp += a.damping;
                }
                "velocity" => damp += a.gain,
                _ => {}
            }
        }
        out.push((stiff > 0.0 || damp > 0.0).then(|| Servo {
            target: if stiff > 0.0 { pull / stiff } else { 0.0 },
            stiffness: stiff,
            damping: damp,
            max_force: UNLIMITED,
        }));
    }
    out
}
