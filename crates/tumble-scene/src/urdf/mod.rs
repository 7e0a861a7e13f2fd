//! URDF models (ROS's Unified Robot Description Format) read into a [`World`]: links
//! become bodies (mass, centre of mass and full inertia tensor from `<inertial>`;
//! `<collision>` boxes, spheres, cylinders and meshes as one shape, meshes as convex
//! hulls), joints become the engine's hinges (revolute, continuous), sliders (prismatic)
//! and welds (fixed, unless merged), a planar joint two sliders and a hinge through two
//! light bodies, named as in the file and with URDF's coordinates:
//! zero at the pose the file describes, positive about (along) the axis, the child
//! relative to the parent.
//!
//! ```no_run
//! use tumble_scene::urdf::{load, UrdfOptions};
//! let mut world = tumble::World::new(&tumble::WorldDef::default());
//! let arm = load("arm.urdf".as_ref(), &mut world, &UrdfOptions::default()).unwrap();
//! let elbow = arm.joint("elbow").unwrap();
//! ```
//!
//! Errors are one line naming the file, the line and the element,
//! `arm.urdf:12: <link name="upper">: inertial.mass: must be >= 0, got -1`, and leave
//! the world as it was.

mod build;
mod parse;

use std::path::Path;

use tumble::{BodyId, JointId, Quat, Vec3, World, WorldDef};

use crate::error::{printable, Result, SceneError};
use crate::{Scene, DEFAULT_DT, DEFAULT_DURATION};

/// How a model is placed in the world.
#[derive(Debug, Clone, PartialEq)]
pub struct UrdfOptions {
    /// The root link is static (a robot bolted down) rather than free to fall. Default
    /// `true`.
    pub fixed_base: bool,
    /// World position of the root link's frame (m).
    pub position: Vec3,
    /// World orientation of the root link's frame, [x, y, z, w].
    pub orientation: Quat,
    /// Links joined by fixed joints become one body (`true`, the default: exact and
    /// cheapest) or separate bodies welded by fixed joints (`false`).
    pub merge_fixed: bool,
    /// Put before every body and joint name in the world (the model's own names stay the
    /// keys of [`Imported`]), so that one file can be added more than once.
    pub prefix: String,
    /// Whether the model's links collide with each other. Default `false`, as PyBullet's
    /// (its `URDF_USE_SELF_COLLISION` flag turns it on): the bodies get one collision
    /// owner of their own (`World::unused_collision_owner`), so they still collide with
    /// everything else, another copy of the same model included. With `true`, links
    /// that no joint connects collide.
    pub self_collision: bool,
}

impl Default for UrdfOptions {
    fn default() -> Self {
        UrdfOptions {
            fixed_base: true,
            position: Vec3::ZERO,
            orientation: Quat::IDENTITY,
            merge_fixed: true,
            prefix: String::new(),
            self_collision: false,
        }
    }
}

/// What a model became.
#[derive(Debug, Clone, PartialEq)]
pub struct Imported {
    /// The `<robot name>`.
    pub name: String,
    /// Every link by its name in the file, in the file's order, with its body (links
    /// merged by fixed joints share their group's body).
    pub bodies: Vec<(String, BodyId)>,
    /// Every joint that became an engine joint, by its name in the file.
    pub joints: Vec<(String, JointId)>,
    /// The bodies created, in creation order (one per link, or per merged group).
    pub created: Vec<BodyId>,
    /// Each created body's colour (its link's first visual material), for pictures.
    pub colors: Vec<Option<[u8; 3]>>,
    /// What was read but not built as written, one line each.
    pub warnings: Vec<String>,
}

impl Imported {
    /// The body of the link called `name` in the file.
    pub fn body(&self, name: &str) -> Option<BodyId> {
        self.bodies.iter().find(|(n, _)| n == name).map(|p| p.1)
    }
    /// The joint called `name` in the file.
    pub fn joint(&self, name: &str) -> Option<JointId> {
        self.joints.iter().find(|(n, _)| n == name).map(|p| p.1)
    }
}

/// Reads a URDF file into `world`. Nothing is added if anything is wrong.
pub fn load(path: &Path, world: &mut World, opts: &UrdfOptions) -> Result<Imported> {
    let label = printable(&path.display().to_string());
    let text = std::fs::read_to_string(path)
        .map_err(|e| SceneError::new(label.clone(), format!("cannot read: {e}")))?;
    let dir = path.parent().unwrap_or(Path::new("."));
    load_str(&text, &label, dir, world, opts)
}

/// Reads URDF text into `world`: `label` names it in errors, `dir` is where relative
/// mesh paths start.
pub fn load_str(
    text: &str,
    label: &str,
    dir: &Path,
    world: &mut World,
    opts: &UrdfOptions,
) -> Result<Imported> {
    let src = parse::Source {
        label: label.to_string(),
        dir,
    };
    let model = parse::parse(text, &src)?;
    let plan = build::plan(&model, opts)?;
    let owner = if opts.self_collision {
        0
    } else {
        world.unused_collision_owner()
    };
    let (created, joints) = build::create(world, &plan, owner)?;
    Ok(Imported {
        name: model.name,
        bodies: plan
            .links
            .iter()
            .map(|(name, b)| (name.clone(), created[*b]))
            .collect(),
        joints: plan
            .joints
            .iter()
            .zip(&joints)
            .map(|(j, id)| (j.name[opts.prefix.len()..].to_string(), *id))
            .collect(),
        created,
        colors: plan.bodies.iter().map(|b| b.color).collect(),
        warnings: plan.warnings,
    })
}

/// URDF's gravity: models are z-up (the world is never turned to suit them).
pub const GRAVITY: Vec3 = Vec3::new(0.0, 0.0, -9.81);

/// A URDF file as a scene: a world with z-up gravity (0, 0, −9.81) m/s², the model placed
/// at the origin with `opts`, the default step and duration.
pub fn scene(path: &Path, opts: &UrdfOptions) -> Result<Scene> {
    let def = WorldDef {
        gravity: GRAVITY,
        ..WorldDef::default()
    };
    let mut world = World::try_new(&def).map_err(|e| SceneError::from_engine(e, ""))?;
    let imported = load(path, &mut world, opts)?;
    let body_names = imported
        .created
        .iter()
        .map(|&id| {
            let body = world.body(id).expect("just created");
            body.name().unwrap_or_default().to_string()
        })
        .collect();
    Ok(Scene {
        name: Some(imported.name),
        description: None,
        world,
        dt: DEFAULT_DT,
        duration: DEFAULT_DURATION,
        body_colors: imported.colors,
        body_names,
        character: None,
        warnings: imported.warnings,
    })
}
