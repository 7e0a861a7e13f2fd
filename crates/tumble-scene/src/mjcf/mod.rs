//! MJCF (MuJoCo's XML) models into a [`World`]: the subset the dm_control suite and
//! Gymnasium's MuJoCo models use.
//!
//! - `parse.rs`: the text to an element tree (`<include>` spliced in, file and line kept),
//!   `<default>` classes and attribute look-up through them;
//! - `frame.rs`: `<compiler>` and the five ways of giving an orientation;
//! - `geom.rs`: geoms and `<inertial>` (shapes, mass properties, contact settings);
//! - `mesh.rs`: `<asset><mesh>` (OBJ and STL files) and mesh geoms' hulls and inertia;
//! - `build.rs`: the body tree to Tumble bodies and joints, collision filters, actuators.
//!
//! What maps to what:
//! - a body with joints is a Tumble body whose frame is the MJCF body frame; its geoms
//!   are one compound shape, its mass properties the file's (`<inertial>`, or the geoms'
//!   with each geom's own density or mass); a body without joints is welded into its
//!   parent (its geoms and mass added to the parent's), into a static body for the world;
//! - hinge → hinge, slide → slider, ball → ball joint, each from the child (`body`) to its
//!   parent (`other`), created at the file's placement, so a joint's coordinate is 0
//!   there: MuJoCo's qpos is Tumble's coordinate plus the joint's `ref` (0 unless given).
//!   A ball's coordinate is a rotation vector in the parent's frame; MuJoCo's ball qpos is
//!   a quaternion in the child's frame: with q0 the child's placement in its parent,
//!   Tumble's vector is `q0 · log(qpos)`. A free joint is a body with no joint: MuJoCo's
//!   free qpos (x y z, qw qx qy qz) is the body frame's position and orientation.
//!   A body with several joints is joined to its parent through light intermediate
//!   bodies, one per extra joint (MuJoCo's chain of joints in one body);
//! - `stiffness`, `springref` and `damping` → the joint's servo (τ = −k (q − q_ref) − c q̇,
//!   the same law); position (kp) and velocity (kv) actuators at zero control add their
//!   gains to it; motors at zero control exert nothing; a hinge's or slide's `armature`
//!   → the joint's armature (`JointDef::armature`, the same generalised inertia; a ball's
//!   or free joint's is warned about); `frictionloss` cannot be expressed and is warned
//!   about;
//! - `condim` 4 and 6 → the body's torsional friction (MuJoCo's second coefficient, in
//!   metres, as Tumble's) and rolling resistance (the third over the radius the geom
//!   rolls on: Tumble's is dimensionless), the largest of its geoms'; `condim` 1 is
//!   warned about (frictionless only between two such geoms in MuJoCo);
//! - contype/conaffinity → collision group/mask (exact, see `build::filters`); parent and
//!   child never collide; `<contact><exclude>` pairs are filtered out (the world's contact
//!   filter, set when there are such pairs, replaces any filter set before).
//!
//! Anything not read is reported once as a [`Warning`] naming the element and its line.

mod build;
mod control;
mod create;
mod frame;
mod geom;
mod mesh;
mod parse;

use std::path::Path;

use tumble::{BodyId, JointId, Quat, Real, Vec3, World, WorldDef};

pub use crate::error::{Result, SceneError};
use crate::Scene;

/// How a model is placed in the world.
#[derive(Debug, Clone, PartialEq)]
pub struct MjcfOptions {
    /// Where the model's world frame goes (m).
    pub position: Vec3,
    /// Its orientation, [x, y, z, w].
    pub orientation: Quat,
    /// Whether `<option>` sets the world's gravity and integrator (true when the model
    /// makes the world, false when it is added to a scene).
    pub world_settings: bool,
    /// Put before every body and joint name in the world (the [`ImportedMjcf`]'s names
    /// stay the file's), so that one file can be added twice.
    pub prefix: String,
}

impl Default for MjcfOptions {
    fn default() -> Self {
        MjcfOptions {
            position: Vec3::ZERO,
            orientation: Quat::IDENTITY,
            world_settings: true,
            prefix: String::new(),
        }
    }
}

/// A joint of the file.
#[derive(Debug, Clone, PartialEq)]
pub struct MjcfJoint {
    /// Its name in the file (`joint3` style names for unnamed ones: MuJoCo's order).
    pub name: String,
    /// `hinge`, `slide`, `ball` or `free`.
    pub kind: String,
    /// The Tumble joint; `None` for a free joint (see `body`).
    pub id: Option<JointId>,
    /// The body it moves.
    pub body: BodyId,
    /// MuJoCo's qpos at the file's placement (`ref`, rad or m): qpos = coordinate + ref.
    pub reference: Real,
    /// The passive spring and damper: stiffness k, its rest coordinate (`springref −
    /// ref`), damping c.
    pub spring: (Real, Real, Real),
}

/// What an actuator drives and how.
#[derive(Debug, Clone, PartialEq)]
pub struct MjcfActuator {
    /// Its name in the file (or `actuatorN`).
    pub name: String,
    /// `motor`, `position` or `velocity`.
    pub kind: String,
    /// The joint's name in the file.
    pub joint: String,
    /// The Tumble joint.
    pub id: JointId,
    /// gear (motor), kp (position) or kv (velocity).
    pub gain: Real,
    /// A position actuator's `kv` (its damping), 0 otherwise.
    pub damping: Real,
    /// `ctrlrange` when the control is limited.
    pub ctrl_range: Option<[Real; 2]>,
    /// `forcerange` when the force is limited.
    pub force_range: Option<[Real; 2]>,
    /// The control last set (MuJoCo's `ctrl`), 0 at load; see [`ImportedMjcf::set_control`].
    pub control: Real,
}

/// Something in the file the import did not read, with where it is.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Warning {
    /// `file:line: <tag name="...">`.
    pub place: String,
    /// What was not read.
    pub message: String,
}

impl std::fmt::Display for Warning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}", self.place, self.message)
    }
}

/// Warnings, each kind once (the first place it occurs).
#[derive(Debug, Default)]
pub(crate) struct Warnings {
    pub list: Vec<Warning>,
}

impl Warnings {
    pub fn add(&mut self, elem: &parse::Elem, message: &str) {
        if !self.list.iter().any(|w| w.message == message) {
            self.list.push(Warning {
                place: elem.label(),
                message: message.to_string(),
            });
        }
    }
}

/// What [`load`] made: the file's names mapped to Tumble's handles.
#[derive(Debug, Clone, Default)]
pub struct ImportedMjcf {
    /// `<mujoco model>`.
    pub model: Option<String>,
    /// Every named body and the Tumble body it is part of (a body welded to its parent
    /// maps to the parent's; bodies welded to the world map to a static body).
    pub bodies: Vec<(String, BodyId)>,
    /// Every joint, in file order.
    pub joints: Vec<MjcfJoint>,
    /// Every actuator read, in file order.
    pub actuators: Vec<MjcfActuator>,
    /// `<option timestep>` (s), 0.002 by default.
    pub timestep: Real,
    /// What was not read.
    pub warnings: Vec<Warning>,
    /// Each created Tumble body with its colour (the first geom's `rgba`), creation order.
    pub colors: Vec<(BodyId, Option<[u8; 3]>)>,
}

impl ImportedMjcf {
    /// The Tumble body of a file body.
    pub fn body(&self, name: &str) -> Option<BodyId> {
        self.bodies.iter().find(|(n, _)| n == name).map(|b| b.1)
    }

    /// A file joint.
    pub fn joint(&self, name: &str) -> Option<&MjcfJoint> {
        self.joints.iter().find(|j| j.name == name)
    }
}

/// Adds the model in `path` to `world`. On an error the world is as it was.
pub fn load(
    path: impl AsRef<Path>,
    world: &mut World,
    options: &MjcfOptions,
) -> Result<ImportedMjcf> {
    let path = path.as_ref();
    let root = parse::read(path)?;
    let dir = path.parent().unwrap_or(Path::new(""));
    build::build(&root, dir, world, options)
}

/// A scene of one model: a world with the file's gravity (default (0, 0, −9.81): MJCF is
/// z-up), integrator and timestep, run for 1 s; with what the import made of the file.
pub fn load_scene(path: impl AsRef<Path>) -> Result<(Scene, ImportedMjcf)> {
    let def = WorldDef {
        gravity: Vec3::new(0.0, 0.0, -9.81),
        ..WorldDef::default()
    };
    let mut world = World::try_new(&def).map_err(|e| SceneError::from_engine(e, ""))?;
    let model = load(path, &mut world, &MjcfOptions::default())?;
    let body_names = world
        .body_ids()
        .iter()
        .enumerate()
        .map(|(i, id)| {
            world
                .body(*id)
                .ok()
                .and_then(|b| b.name().map(str::to_string))
                .unwrap_or_else(|| i.to_string())
        })
        .collect();
    let body_colors = model.colors.iter().map(|c| c.1).collect();
    let scene = Scene {
        name: model.model.clone(),
        description: None,
        world,
        dt: model.timestep,
        duration: crate::DEFAULT_DURATION,
        body_names,
        body_colors,
        character: None,
        warnings: model.warnings.iter().map(ToString::to_string).collect(),
    };
    Ok((scene, model))
}
