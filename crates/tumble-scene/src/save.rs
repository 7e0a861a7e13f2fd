//! Writing a world as a scene file (issue 18): `save`, `save_scene`, `save_with`.
//!
//! Every number is written in Rust's shortest round-trip form (`{:?}`), which the reader
//! parses straight into `Real`: each reads back to the same bits, in f64 and in f32. The
//! keys are the scene format's, so the file loads as any scene does. What the keys cannot
//! hold (warm starts, contacts, sleep timers, islands, integrator memory, joints' rest
//! poses, handles' generations, the clock) is in the optional `"state"` section: the
//! world's snapshot (`World::snapshot`) in hex, which the loader restores after building
//! the world from the keys. With it, running the saved scene on is bit-identical to
//! running on the world it was saved from; without it, the file is a fresh scene at the
//! saved poses and velocities.
//!
//! Bodies are referred to by name, or by their index in `bodies` when they have none.

use std::fmt::Write;

use tumble::joint::OptionValue;
use tumble::{Body, BodyId, BodyKind, Force, Joint, Quat, Real, Shape, SpringEnd, Vec3, World};

use crate::{Scene, Walker};

/// What `save_with` writes besides the world.
#[derive(Debug, Clone, PartialEq)]
pub struct SaveOptions {
    /// The scene's `name`.
    pub name: Option<String>,
    /// The scene's `description`.
    pub description: Option<String>,
    /// The step written as `dt` (s).
    pub dt: Real,
    /// The run length written as `duration` (s).
    pub duration: Real,
    /// Each body's colour, creation order (missing or `None`: none written).
    pub colors: Vec<Option<[u8; 3]>>,
    /// Whether to write the `"state"` section (the world's snapshot).
    pub state: bool,
    /// The scene's character, written as its `character` object (settings, path, and
    /// where it is: position, fall, last velocity and ground), its body then left out of
    /// `bodies` (the character makes it again, as the last body, when loaded). Written
    /// only while its body is the world's last, as a scene makes it; otherwise the body
    /// is written as a plain kinematic body.
    pub character: Option<Walker>,
}

impl Default for SaveOptions {
    fn default() -> Self {
        SaveOptions {
            name: None,
            description: None,
            dt: crate::DEFAULT_DT,
            duration: crate::DEFAULT_DURATION,
            colors: Vec::new(),
            state: true,
            character: None,
        }
    }
}

/// `world` as scene JSON with its `"state"`, default `dt` and `duration`.
pub fn save(world: &World) -> String {
    save_with(world, &SaveOptions::default())
}

/// A loaded scene's world as scene JSON with its `"state"`, keeping the scene's name,
/// description, `dt`, `duration`, colours and character.
pub fn save_scene(scene: &Scene) -> String {
    save_with(
        &scene.world,
        &SaveOptions {
            name: scene.name.clone(),
            description: scene.description.clone(),
            dt: scene.dt,
            duration: scene.duration,
            colors: scene.body_colors.clone(),
            state: true,
            character: scene.character.clone(),
        },
    )
}

/// `world` as scene JSON, with what `options` says.
pub fn save_with(world: &World, options: &SaveOptions) -> String {
    let mut top = Fields::default();
    if let Some(n) = &options.name {
        top.add("name", text(n));
    }
    if let Some(d) = &options.description {
        top.add("description", text(d));
    }
    settings(world, options, &mut top);
    let refs = References::of(world);
    let walker = options
        .character
        .as_ref()
        .filter(|w| world.body_ids().last() == Some(&w.body));
    let bodies: Vec<String> = world
        .body_ids()
        .iter()
        .enumerate()
        .filter(|&(_, &id)| walker.is_none_or(|w| w.body != id))
        .map(|(i, &id)| {
            let color = options.colors.get(i).copied().flatten();
            body(world.body(id).expect("a live body"), color)
        })
        .collect();
    top.add("bodies", list(&bodies, ",\n    "));
    let forces: Vec<String> = world.forces().map(|(_, f)| force(f, &refs)).collect();
    top.add("forces", list(&forces, ",\n    "));
    let joints: Vec<String> = world.joints().map(|(_, j)| joint(j, &refs)).collect();
    top.add("joints", list(&joints, ",\n    "));
    if let Some(w) = walker {
        let color = options
            .colors
            .get(world.body_count() - 1)
            .copied()
            .flatten();
        top.add("character", character(w, world, &refs, color));
    }
    if !world.excluded_contacts().is_empty() {
        let pairs = world
            .excluded_contacts()
            .iter()
            .map(|&(a, b)| format!("[{}, {}]", refs.of_body(a), refs.of_body(b)));
        top.add("exclude", inline(pairs));
    }
    if options.state {
        top.add("state", format!("\"{}\"", hex(&world.snapshot())));
    }
    let mut out = String::from("{\n  ");
    out.push_str(&top.0.join(",\n  "));
    out.push_str("\n}\n");
    out
}

/// The top level's settings: gravity, integrator, solver, scale, limits, sleep.
fn settings(world: &World, options: &SaveOptions, top: &mut Fields) {
    let solver = world.solver_settings();
    let limits = world.speed_limits();
    let contacts = world.contact_limits();
    top.add("gravity", vec3(world.gravity()));
    top.add("dt", num(options.dt));
    top.add("duration", num(options.duration));
    top.add("integrator", text(world.integrator().name()));
    top.add("solver", text(solver.kind.name()));
    top.add("substeps", solver.substeps.to_string());
    top.add("iterations", solver.iterations.to_string());
    top.add("contact_hertz", num(solver.contact_hertz));
    top.add("contact_damping_ratio", num(solver.contact_damping_ratio));
    top.add("joint_hertz", num(solver.joint_hertz));
    top.add("joint_damping_ratio", num(solver.joint_damping_ratio));
    top.add("joint_trees", text(solver.joint_trees.name()));
    top.add("length_unit", num(world.length_unit()));
    top.add("sleep", world.sleep_enabled().to_string());
    top.add("max_speed", num(limits.max_speed));
    top.add("max_angular_speed", num(limits.max_angular_speed));
    top.add("max_contacts", contacts.per_step.to_string());
    top.add("max_contacts_per_body", contacts.per_body.to_string());
    top.add("max_push_speed", num(world.max_push_speed()));
}

/// How forces and joints name a body: its name, or its index when it has none.
struct References {
    ids: Vec<BodyId>,
    names: Vec<Option<String>>,
}

impl References {
    fn of(world: &World) -> References {
        let ids = world.body_ids().to_vec();
        let names = ids
            .iter()
            .map(|&id| {
                world
                    .body(id)
                    .ok()
                    .and_then(|b| b.name().map(str::to_string))
            })
            .collect();
        References { ids, names }
    }

    fn of_body(&self, id: BodyId) -> String {
        match self.ids.iter().position(|&b| b == id) {
            Some(i) => match &self.names[i] {
                Some(n) => text(n),
                None => i.to_string(),
            },
            // A force or joint on a removed body is not kept by the world.
            None => "null".to_string(),
        }
    }
}

/// An object's fields as `"key": value` texts.
#[derive(Default)]
struct Fields(Vec<String>);

impl Fields {
    fn add(&mut self, key: &str, value: String) {
        self.0.push(format!("\"{key}\": {value}"));
    }

    fn object(self) -> String {
        format!("{{{}}}", self.0.join(", "))
    }
}

/// A number that reads back to the same bits.
fn num(x: Real) -> String {
    format!("{x:?}")
}

fn vec3(v: Vec3) -> String {
    format!("[{}, {}, {}]", num(v.x), num(v.y), num(v.z))
}

fn quat(q: Quat) -> String {
    format!("[{}, {}, {}, {}]", num(q.x), num(q.y), num(q.z), num(q.w))
}

fn text(s: &str) -> String {
    serde_json::Value::String(s.to_string()).to_string()
}

fn list(items: &[String], sep: &str) -> String {
    if items.is_empty() {
        "[]".to_string()
    } else {
        format!("[\n    {}\n  ]", items.join(sep))
    }
}

fn inline(items: impl Iterator<Item = String>) -> String {
    format!("[{}]", items.collect::<Vec<_>>().join(", "))
}

fn kind_name(kind: BodyKind) -> &'static str {
    match kind {
        BodyKind::Static => "static",
        BodyKind::Kinematic => "kinematic",
        BodyKind::Dynamic => "dynamic",
    }
}

fn body(b: &Body, color: Option<[u8; 3]>) -> String {
    let mut f = Fields::default();
    if let Some(n) = b.name() {
        f.add("name", text(n));
    }
    f.add("kind", text(kind_name(b.kind())));
    f.add("shape", shape(b.shape()));
    if b.kind() == BodyKind::Dynamic {
        let i = b.inertia_local();
        f.add("mass", num(b.mass()));
        f.add("inertia", inline((0..3).map(|r| vec3(i.row(r)))));
        f.add("center_of_mass", vec3(b.local_center_of_mass()));
    }
    f.add("position", vec3(b.position()));
    f.add("orientation", quat(b.orientation()));
    f.add("velocity", vec3(b.linear_velocity()));
    f.add("angular_velocity", vec3(b.angular_velocity()));
    let (group, mask) = b.collision_filter();
    let flags = [
        ("planar", b.is_planar()),
        ("bullet", b.is_bullet()),
        ("sensor", b.is_sensor()),
    ];
    for (key, on) in flags {
        f.add(key, on.to_string());
    }
    f.add("collision_group", group.to_string());
    f.add("collision_mask", mask.to_string());
    if b.collision_owner() != 0 {
        f.add("collision_owner", b.collision_owner().to_string());
    }
    let numbers = [
        ("friction", b.friction()),
        ("restitution", b.restitution()),
        ("rolling_resistance", b.rolling_resistance()),
        ("torsional_friction", b.torsional_friction()),
        ("linear_damping", b.linear_damping()),
        ("angular_damping", b.angular_damping()),
        ("gravity_scale", b.gravity_scale()),
    ];
    for (key, x) in numbers {
        f.add(key, num(x));
    }
    if let Some(n) = b.one_way() {
        f.add("one_way", vec3(n));
    }
    if let Some([r, g, b]) = color {
        f.add("color", format!("\"#{r:02x}{g:02x}{b:02x}\""));
    }
    f.object()
}

/// The `character` object of `w` (see `crate::character` for its keys).
fn character(w: &Walker, world: &World, refs: &References, color: Option<[u8; 3]>) -> String {
    let c = &w.controller;
    let d = c.def();
    let mut f = Fields::default();
    if let Some(n) = world.body(w.body).ok().and_then(|b| b.name()) {
        f.add("name", text(n));
    }
    f.add("position", vec3(c.position()));
    for (key, x) in [
        ("radius", d.radius),
        ("half_height", d.half_height),
        ("max_slope", d.max_slope),
        ("step_height", d.step_height),
        ("skin", d.skin),
        ("snap_distance", d.snap_distance),
        ("max_push_force", d.max_push_force),
    ] {
        f.add(key, num(x));
    }
    f.add("up", vec3(d.up));
    f.add("collision_mask", d.filter.mask.to_string());
    if let Some([r, g, b]) = color {
        f.add("color", format!("\"#{r:02x}{g:02x}{b:02x}\""));
    }
    let legs = w.path.iter().map(|leg| {
        format!(
            "{{\"until\": {}, \"velocity\": {}}}",
            num(leg.until),
            vec3(leg.velocity)
        )
    });
    f.add("path", inline(legs));
    f.add("fall", vec3(w.fall));
    f.add("velocity", vec3(c.velocity()));
    let ground = c.ground().map_or("null".to_string(), |g| {
        format!(
            "{{\"body\": {}, \"normal\": {}, \"point\": {}}}",
            refs.of_body(g.body),
            vec3(g.normal),
            vec3(g.point)
        )
    });
    f.add("ground", ground);
    f.object()
}

fn shape(s: &Shape) -> String {
    let mut f = Fields::default();
    f.add("type", text(s.kind_name()));
    match s {
        Shape::Sphere { radius } => f.add("radius", num(*radius)),
        Shape::Box { half_extents } => f.add("half_extents", vec3(*half_extents)),
        Shape::Capsule {
            radius,
            half_height,
        }
        | Shape::Cylinder {
            radius,
            half_height,
        } => {
            f.add("radius", num(*radius));
            f.add("half_height", num(*half_height));
        }
        Shape::ConvexHull(hull) => {
            f.add("points", inline(hull.vertices().iter().map(|&p| vec3(p))))
        }
        Shape::Compound(children) => {
            let child = |c: &tumble::CompoundChild| {
                let mut cf = Fields::default();
                cf.add("shape", shape(&c.shape));
                cf.add("position", vec3(c.position));
                cf.add("orientation", quat(c.orientation));
                cf.object()
            };
            f.add("children", inline(children.iter().map(child)));
        }
        Shape::Plane { normal, offset } => {
            f.add("normal", vec3(*normal));
            f.add("offset", num(*offset));
        }
        Shape::TriMesh(mesh) => {
            f.add("vertices", inline(mesh.vertices().iter().map(|&p| vec3(p))));
            let tri = |t: &[u32; 3]| format!("[{}, {}, {}]", t[0], t[1], t[2]);
            f.add("indices", inline(mesh.indices().iter().map(tri)));
        }
        Shape::HeightField(field) => {
            let rows = field.heights().chunks(field.cols().max(1));
            let row = |r: &[Real]| inline(r.iter().map(|&h| num(h)));
            f.add("heights", inline(rows.map(row)));
            f.add("scale", vec3(field.scale()));
        }
    }
    f.object()
}

fn force(force: &Force, refs: &References) -> String {
    let mut f = Fields::default();
    match force {
        Force::Spring(s) => {
            f.add("type", text("spring"));
            f.add("body", refs.of_body(s.body));
            f.add("anchor", vec3(s.anchor));
            match s.other {
                SpringEnd::World(p) => f.add("world_point", vec3(p)),
                SpringEnd::Body { body, anchor } => {
                    f.add("other", refs.of_body(body));
                    f.add("other_anchor", vec3(anchor));
                }
            }
            f.add("stiffness", num(s.stiffness));
            f.add("rest_length", num(s.rest_length));
            f.add("damping", num(s.damping));
        }
        Force::Drag(d) => {
            f.add("type", text("drag"));
            f.add("body", refs.of_body(d.body));
            f.add("linear", num(d.linear));
            f.add("quadratic", num(d.quadratic));
        }
        Force::Applied(a) => {
            f.add("type", text("force"));
            f.add("body", refs.of_body(a.body));
            f.add("force", vec3(a.force));
            if let Some(p) = a.point {
                f.add("point", vec3(p));
            }
            f.add("torque", vec3(a.torque));
        }
    }
    f.object()
}

fn joint(j: &Joint, refs: &References) -> String {
    let def = j.def();
    let spec = def.kind.spec();
    let mut f = Fields::default();
    f.add("type", text(spec.name));
    if let Some(n) = &def.name {
        f.add("name", text(n));
    }
    f.add("body", refs.of_body(def.body));
    f.add("anchor", vec3(def.anchor));
    f.add("axis", vec3(def.axis));
    if let Some(other) = def.other {
        f.add("other", refs.of_body(other));
    }
    f.add("other_anchor", vec3(def.other_anchor));
    f.add("other_axis", vec3(def.other_axis));
    f.add("collide_connected", def.collide_connected.to_string());
    if let Some(b) = def.break_force {
        f.add("break_force", num(b));
    }
    if def.armature != 0.0 {
        f.add("armature", num(def.armature));
    }
    let options = def.kind.options();
    let limit = spec.motor_limit_key();
    for option in spec.options.iter().map(|o| o.option) {
        let Some(value) = options.get(option) else {
            continue;
        };
        let written = match value {
            OptionValue::Real(x) => num(x),
            OptionValue::Range([lo, hi]) => format!("[{}, {}]", num(lo), num(hi)),
            OptionValue::Motor(m) => format!(
                "{{\"speed\": {}, \"{limit}\": {}}}",
                num(m.speed),
                num(m.max_force)
            ),
            OptionValue::Spring(s) => format!(
                "{{\"hertz\": {}, \"damping_ratio\": {}, \"target\": {}}}",
                num(s.hertz),
                num(s.damping_ratio),
                num(s.target)
            ),
            OptionValue::Servo(s) => format!(
                "{{\"target\": {}, \"stiffness\": {}, \"damping\": {}, \"{limit}\": {}}}",
                num(s.target),
                num(s.stiffness),
                num(s.damping),
                num(s.max_force)
            ),
        };
        f.add(option.key(), written);
    }
    f.object()
}

/// Bytes as lowercase hex.
fn hex(bytes: &[u8]) -> String {
    let mut out = String::with_capacity(2 * bytes.len());
    for b in bytes {
        let _ = write!(out, "{b:02x}");
    }
    out
}

/// Hex text back to bytes; the error names the first bad character's index.
pub(crate) fn unhex(text: &str) -> Result<Vec<u8>, String> {
    let digits = text.as_bytes();
    if digits.len() % 2 != 0 {
        return Err(format!(
            "expected an even number of hex digits, got {}",
            digits.len()
        ));
    }
    let value = |i: usize| match digits[i] {
        c @ b'0'..=b'9' => Ok(c - b'0'),
        c @ b'a'..=b'f' => Ok(c - b'a' + 10),
        c @ b'A'..=b'F' => Ok(c - b'A' + 10),
        _ => Err(format!(
            "expected hex digits, not '{}' at character {i}",
            digits[i] as char
        )),
    };
    (0..digits.len() / 2)
        .map(|k| Ok(value(2 * k)? << 4 | value(2 * k + 1)?))
        .collect()
}
