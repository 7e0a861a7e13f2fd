//! Tumble's JSON scene format: a document describing bodies, force elements and run
//! settings, read into a [`tumble::World`].
//!
//! Every refusal is one [`SceneError`] whose `Display` is a single line naming the field,
//! `bodies[3].shape.radius: must be > 0`. The format is documented key by key in
//! `docs/scene-format.md`; the built-in scenes are in [`mod@builtin`].
//!
//! ```
//! let scene = tumble_scene::load("free_fall").unwrap();
//! assert_eq!(scene.body_names, ["ball"]);
//! assert_eq!(scene.plan().unwrap().steps, 100);
//! ```
#![warn(missing_docs)]

mod body;
pub mod builtin;
mod character;
mod error;
mod force;
mod joint;
pub mod mesh_file;
pub mod mjcf;
mod models;
mod plan;
mod reader;
mod save;
mod shape;
pub mod urdf;

use std::fmt;
use std::path::Path;

use serde_json::Value;
use tumble::limits::ContactLimits;
use tumble::{
    Integrator, JointTrees, Real, SolverKind, SolverSettings, SpeedLimits, Vec3, World, WorldDef,
};

pub use body::BODY_KINDS;
pub use builtin::{builtin, builtin_names};
pub use character::{Leg, Walker};
pub use error::{printable, Result, SceneError};
pub use force::FORCE_TYPES;
pub use joint::JOINT_TYPES;
pub use plan::{RunPlan, MAX_STEPS};
pub use reader::{whole_rule, ROOT};
pub use save::{save, save_scene, save_with, SaveOptions};
pub use shape::SHAPE_TYPES;
// Python checks the names it is given with the same rule.
pub use body::check_name;

use reader::{Node, Obj};

const TOP_KEYS: [&str; 28] = [
    "name",
    "description",
    "gravity",
    "dt",
    "duration",
    "integrator",
    "bodies",
    "forces",
    "joints",
    "solver",
    "substeps",
    "iterations",
    "contact_hertz",
    "contact_damping_ratio",
    "joint_hertz",
    "joint_damping_ratio",
    "joint_trees",
    "length_unit",
    "sleep",
    "max_speed",
    "max_angular_speed",
    "max_contacts",
    "max_contacts_per_body",
    "max_push_speed",
    "character",
    "state",
    "models",
    "exclude",
];

/// The most `substeps` and `iterations` a scene or the command line may ask for: the
/// engine's own bound (`tumble::limits`), so that a scene the loader passes is one the
/// world takes.
pub const MAX_PASSES: u32 = tumble::limits::MAX_SUBSTEPS;
const _: () = assert!(tumble::limits::MAX_ITERATIONS == MAX_PASSES);

/// Default step (s).
pub const DEFAULT_DT: Real = 0.01;
/// Default run length (s).
pub const DEFAULT_DURATION: Real = 1.0;

/// A loaded scene: the world at time 0 and how long to run it.
pub struct Scene {
    /// The document's `name`, if it has one.
    pub name: Option<String>,
    /// The document's `description`, if it has one.
    pub description: Option<String>,
    /// The world, with every body and force element created, at time 0.
    pub world: World,
    /// Step (s).
    pub dt: Real,
    /// Run length (s).
    pub duration: Real,
    /// A label per body in creation order (the order of `world.body_ids()`): its name, or
    /// its index in `bodies` when it has none. Used to label output rows.
    pub body_names: Vec<String>,
    /// Each body's `color` as RGB, creation order; `None` where the scene gives none.
    pub body_colors: Vec<Option<[u8; 3]>>,
    /// The scene's `character`, walked along its path by [`Scene::step`]; its body is the
    /// last of the world's.
    pub character: Option<Walker>,
    /// What a model file held that was read but not built as written, one line each
    /// (see [`urdf::Imported::warnings`]); the CLI prints them.
    pub warnings: Vec<String>,
}

impl Scene {
    /// The steps of a run of `duration` with `dt` (see [`RunPlan`]).
    pub fn plan(&self) -> Result<RunPlan> {
        RunPlan::from_duration(self.duration, self.dt)
    }

    /// One step of the run, `dt` (s): the character's move, if the scene has one (see
    /// [`Walker::advance`]), then the world's step. A run that steps `world` itself
    /// leaves the character standing where it started.
    pub fn step(&mut self, dt: Real) -> tumble::Result<()> {
        if let Some(walker) = &mut self.character {
            walker.advance(&mut self.world, dt)?;
        }
        self.world.step(dt)
    }
}

impl fmt::Debug for Scene {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        // World holds boxed callbacks and is not Debug; its size and settings suffice.
        f.debug_struct("Scene")
            .field("name", &self.name)
            .field("dt", &self.dt)
            .field("duration", &self.duration)
            .field("integrator", &self.world.integrator())
            .field("gravity", &self.world.gravity())
            .field("body_names", &self.body_names)
            .field("forces", &self.world.forces().count())
            .finish()
    }
}

/// Reads a scene from JSON text. Model files its `models` name are found from the
/// current directory.
pub fn load_str(json: &str) -> Result<Scene> {
    load_str_in(json, Path::new(""))
}

/// Reads a scene from JSON text whose `models` files are relative to `dir`.
pub fn load_str_in(json: &str, dir: &Path) -> Result<Scene> {
    let value: Value = serde_json::from_str(json).map_err(json_error)?;
    build(&Node::root(&value), dir)
}

/// The kinds of file [`load_file`] reads, told apart by extension (any case): `urdf` a
/// URDF model (see [`urdf::scene`]), `xml` an MJCF model (see [`mjcf::load_scene`]);
/// anything else a JSON scene.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FileKind {
    /// A JSON scene (docs/scene-format.md).
    Scene,
    /// A URDF model.
    Urdf,
    /// An MJCF (MuJoCo XML) model.
    Mjcf,
}

impl FileKind {
    /// The kind of `path`, by its extension.
    pub fn of(path: &Path) -> FileKind {
        let ext = path.extension().and_then(|e| e.to_str());
        match ext.map(str::to_ascii_lowercase).as_deref() {
            Some("urdf") => FileKind::Urdf,
            Some("xml") => FileKind::Mjcf,
            _ => FileKind::Scene,
        }
    }
}

/// Reads a scene file, or a model file run as a scene (by extension, see [`FileKind`]).
pub fn load_file(path: impl AsRef<Path>) -> Result<Scene> {
    let path = path.as_ref();
    match FileKind::of(path) {
        FileKind::Urdf => return urdf::scene(path, &urdf::UrdfOptions::default()),
        FileKind::Mjcf => return mjcf::load_scene(path).map(|(scene, _)| scene),
        FileKind::Scene => {}
    }
    let text = std::fs::read_to_string(path).map_err(|e| {
        SceneError::new(
            ROOT,
            format!(
                "cannot read '{}': {e}",
                printable(&path.display().to_string())
            ),
        )
    })?;
    load_str_in(&text, path.parent().unwrap_or(Path::new("")))
}

/// Reads a built-in scene by name, or else a file by path. Built-in names win, so a file
/// in the current directory called `spring` is reached as `./spring`.
pub fn load(name_or_path: &str) -> Result<Scene> {
    match builtin(name_or_path) {
        Some(json) => load_str(json),
        // Model files by extension, so that a missing one is named by its loader.
        None if FileKind::of(Path::new(name_or_path)) != FileKind::Scene => load_file(name_or_path),
        None if Path::new(name_or_path).exists() => load_file(name_or_path),
        None => Err(SceneError::new(
            ROOT,
            format!(
                "'{}' is neither a built-in scene ({}) nor an existing file",
                printable(name_or_path),
                builtin_names().join(", ")
            ),
        )),
    }
}

/// serde_json appends " at line L column C" to its messages; the position goes first here.
fn json_error(e: serde_json::Error) -> SceneError {
    let full = e.to_string();
    let suffix = format!(" at line {} column {}", e.line(), e.column());
    let what = full.strip_suffix(&suffix).unwrap_or(&full);
    SceneError::new(
        ROOT,
        format!(
            "invalid JSON at line {} column {}: {what}",
            e.line(),
            e.column()
        ),
    )
}

fn build(root: &Node<'_>, dir: &Path) -> Result<Scene> {
    let obj = root.object()?;
    obj.only(&TOP_KEYS)?;
    let name = obj.str("name")?.map(str::to_string);
    let description = obj.str("description")?.map(str::to_string);
    let length_unit = obj.real("length_unit")?.unwrap_or(1.0);
    let def = WorldDef {
        gravity: obj.vec3("gravity")?.unwrap_or(Vec3::new(0.0, -9.8, 0.0)),
        integrator: integrator(&obj)?,
        length_unit,
        solver: solver_settings(&obj)?,
        sleep: obj.bool("sleep")?.unwrap_or(true),
        limits: speed_limits(&obj, length_unit)?,
        contact_limits: contact_limits(&obj)?,
        max_push_speed: obj.real("max_push_speed")?,
        // A property of the machine, not of the scene: the program running it chooses.
        threads: None,
    };
    let dt = obj.real("dt")?.unwrap_or(DEFAULT_DT);
    let duration = obj.real("duration")?.unwrap_or(DEFAULT_DURATION);
    // Checked now, so a bad value is reported as the scene's, not when a run starts.
    plan::check_settings(duration, dt)?;
    let mut world = World::try_new(&def).map_err(|e| SceneError::from_engine(e, ""))?;
    let (mut body_names, mut body_colors) = add_bodies(&obj, &mut world)?;
    let warnings = models::add_models(&obj, dir, &mut world, &mut body_names, &mut body_colors)?;
    add_forces(&obj, &mut world)?;
    add_joints(&obj, &mut world)?;
    add_exclusions(&obj, &mut world)?;
    let mut character = match obj.get("character") {
        Some(node) => {
            let (walker, label, color) = character::character(&node, &mut world)?;
            body_names.push(label);
            body_colors.push(color);
            Some(walker)
        }
        None => None,
    };
    if let Some(node) = obj.get("state") {
        restore_state(&node, &mut world, body_names.len())?;
    }
    if let (Some(walker), Some(node)) = (character.as_mut(), obj.get("character")) {
        character::resume(&node, walker, &world)?;
    }
    check_number_names(&world)?;
    Ok(Scene {
        name,
        description,
        world,
        dt,
        duration,
        body_names,
        body_colors,
        character,
        warnings,
    })
}

/// Refuses a body or joint named with a plain number `k` (as imported models may name
/// theirs) when the `k`-th body or joint is unnamed: output rows label an unnamed one by
/// its index, so the two would read the same.
fn check_number_names(world: &World) -> Result<()> {
    fn clash<'a>(names: &[Option<&'a str>]) -> Option<&'a str> {
        names.iter().flatten().copied().find(|name| {
            body::is_plain_number(name)
                && name
                    .parse::<usize>()
                    .is_ok_and(|k| names.get(k) == Some(&None))
        })
    }
    let bodies: Vec<Option<&str>> = world.bodies().map(|(_, b)| b.name()).collect();
    let joints: Vec<Option<&str>> = world.joints().map(|(_, j)| j.name()).collect();
    for (what, names) in [("body", bodies), ("joint", joints)] {
        if let Some(name) = clash(&names) {
            return Err(SceneError::new(
                "models",
                format!(
                    "a model names a {what} '{name}', the label of the unnamed {what} at \
                     index {name} (name that one, or give the model a prefix)"
                ),
            ));
        }
    }
    Ok(())
}

/// The `state` section (a snapshot in hex, see `save.rs`) restored into the world built
/// from the keys; it must hold as many bodies as the scene lists.
fn restore_state(node: &Node<'_>, world: &mut World, bodies: usize) -> Result<()> {
    let bytes = save::unhex(node.str()?).map_err(|reason| node.err(reason))?;
    world.restore(&bytes).map_err(|e| node.err(e.to_string()))?;
    let held = world.body_count();
    if held != bodies {
        return Err(node.err(format!("holds {held} bodies, but the scene lists {bodies}")));
    }
    Ok(())
}

/// `max_speed` and `max_angular_speed`, each defaulting to the engine's value for the
/// scene's length unit; `None` when neither is given.
fn speed_limits(obj: &Obj<'_>, length_unit: Real) -> Result<Option<SpeedLimits>> {
    let (v, w) = (obj.real("max_speed")?, obj.real("max_angular_speed")?);
    if v.is_none() && w.is_none() {
        return Ok(None);
    }
    let unit = if length_unit.is_finite() && length_unit > 0.0 {
        length_unit
    } else {
        1.0
    };
    let default = SpeedLimits::for_length_unit(unit);
    Ok(Some(SpeedLimits {
        max_speed: v.unwrap_or(default.max_speed),
        max_angular_speed: w.unwrap_or(default.max_angular_speed),
    }))
}

/// `max_contacts` (manifolds per step) and `max_contacts_per_body` (touching pairs a
/// crowded body keeps), whole numbers from 1, defaulting to the engine's.
fn contact_limits(obj: &Obj<'_>) -> Result<ContactLimits> {
    let d = ContactLimits::default();
    let whole = |key: &str, default: u32| -> Result<u32> {
        Ok(obj
            .get(key)
            .map(|n| n.whole_in(1, u32::MAX.into()))
            .transpose()?
            .map_or(default, |v| v as u32))
    };
    Ok(ContactLimits {
        per_body: whole("max_contacts_per_body", d.per_body)?,
        per_step: whole("max_contacts", d.per_step)?,
    })
}

/// The solver called `name`, with the scene format's error for any other name.
pub fn parse_solver(name: &str) -> Result<SolverKind> {
    SolverKind::from_name(name).ok_or_else(|| {
        SceneError::new(
            "solver",
            format!(
                "unknown solver '{}' (expected one of: soft_step, pgs)",
                printable(name)
            ),
        )
    })
}

/// `solver`, `substeps`, `iterations`, `contact_hertz`, `contact_damping_ratio`,
/// `joint_hertz`, `joint_damping_ratio`, `joint_trees`. Values are
/// checked by the engine (`World::try_new`), which names the same keys.
fn solver_settings(obj: &Obj<'_>) -> Result<SolverSettings> {
    let d = SolverSettings::default();
    // Checked here rather than by the engine, so that 0 and -1 are told the same rule.
    let count = |key: &str, default: u32| -> Result<u32> {
        Ok(obj
            .get(key)
            .map(|n| n.whole_in(1, MAX_PASSES.into()))
            .transpose()?
            .map_or(default, |v| v as u32))
    };
    Ok(SolverSettings {
        kind: obj
            .str("solver")?
            .map(parse_solver)
            .transpose()?
            .unwrap_or(d.kind),
        substeps: count("substeps", d.substeps)?,
        iterations: count("iterations", d.iterations)?,
        contact_hertz: obj.real("contact_hertz")?.unwrap_or(d.contact_hertz),
        contact_damping_ratio: obj
            .real("contact_damping_ratio")?
            .unwrap_or(d.contact_damping_ratio),
        joint_hertz: obj.real("joint_hertz")?.unwrap_or(d.joint_hertz),
        joint_damping_ratio: obj
            .real("joint_damping_ratio")?
            .unwrap_or(d.joint_damping_ratio),
        joint_trees: obj
            .str("joint_trees")?
            .map(parse_joint_trees)
            .transpose()?
            .unwrap_or(d.joint_trees),
        ..d
    })
}

/// How joint trees are solved, by name, with the scene format's error for any other.
pub fn parse_joint_trees(name: &str) -> Result<JointTrees> {
    JointTrees::from_name(name).ok_or_else(|| {
        SceneError::new(
            "joint_trees",
            format!(
                "unknown way '{}' (expected one of: maximal, reduced)",
                printable(name)
            ),
        )
    })
}

/// The integrator called `name`, with the scene format's error for any other name.
pub fn parse_integrator(name: &str) -> Result<Integrator> {
    Integrator::from_name(name).ok_or_else(|| {
        SceneError::new(
            "integrator",
            format!(
                "unknown integrator '{}' (expected one of: {})",
                printable(name),
                Integrator::names()
            ),
        )
    })
}

fn integrator(obj: &Obj<'_>) -> Result<Integrator> {
    match obj.str("integrator")? {
        None => Ok(Integrator::default()),
        // The key is top-level, so its path is the bare `integrator` this error names.
        Some(name) => parse_integrator(name),
    }
}

/// Creates the bodies; returns their labels and colours.
#[allow(clippy::type_complexity)]
fn add_bodies(obj: &Obj<'_>, world: &mut World) -> Result<(Vec<String>, Vec<Option<[u8; 3]>>)> {
    let Some(bodies) = obj.get("bodies") else {
        return Ok((Vec::new(), Vec::new()));
    };
    let mut names = Vec::new();
    let mut colors = Vec::new();
    for (i, node) in bodies.array()?.iter().enumerate() {
        let (def, shape) = body::body(node)?;
        colors.push(body::color(node)?);
        names.push(def.name.clone().unwrap_or_else(|| i.to_string()));
        world
            .create_body(&def, shape)
            .map_err(|e| SceneError::from_engine(e, node.path()))?;
    }
    Ok((names, colors))
}

fn add_joints(obj: &Obj<'_>, world: &mut World) -> Result<()> {
    let Some(joints) = obj.get("joints") else {
        return Ok(());
    };
    for node in joints.array()? {
        let def = joint::joint(&node, world)?;
        world
            .create_joint(&def)
            .map_err(|e| SceneError::from_engine(e, node.path()))?;
    }
    Ok(())
}

/// `exclude`: pairs of bodies (each by name or index) that never touch.
fn add_exclusions(obj: &Obj<'_>, world: &mut World) -> Result<()> {
    let Some(pairs) = obj.get("exclude") else {
        return Ok(());
    };
    for node in pairs.array()? {
        let ends = node.array()?;
        let [a, b] = ends.as_slice() else {
            return Err(node.err(format!(
                "must be a pair of bodies, got {} items",
                ends.len()
            )));
        };
        let (a, b) = (body::reference(a, world)?, body::reference(b, world)?);
        world
            .exclude_contacts(a, b)
            .map_err(|e| node.err(e.to_string().replace("exclude: ", "")))?;
    }
    Ok(())
}

fn add_forces(obj: &Obj<'_>, world: &mut World) -> Result<()> {
    let Some(forces) = obj.get("forces") else {
        return Ok(());
    };
    for node in forces.array()? {
        let force = force::force(&node, world)?;
        world
            .add_force(force)
            .map_err(|e| SceneError::from_engine(e, node.path()))?;
    }
    Ok(())
}
