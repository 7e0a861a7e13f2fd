//! The scene's `character`: a character controller (`tumble::CharacterController`)
//! walked along a scripted path of velocities, with a body that shows where it is.
//!
//! The controller is not a body (see `tumble::character`). So that the run's outputs, its
//! pictures and the viewer show it, the scene gives it a kinematic capsule body of the
//! character's `name`, in no collision layer and colliding with nothing, which follows it
//! by kinematic targets: before each step of the world the character moves, and the
//! step takes the body to where it went.

use tumble::{
    BodyDef, BodyId, BodyKind, CharacterController, CharacterDef, QueryFilter, Real, Vec3, World,
};

use crate::error::{Result, SceneError};
use crate::reader::{Node, Obj};

const CHARACTER_KEYS: [&str; 16] = [
    "name",
    "position",
    "radius",
    "half_height",
    "up",
    "max_slope",
    "step_height",
    "skin",
    "snap_distance",
    "max_push_force",
    "collision_mask",
    "color",
    "path",
    "fall",
    "velocity",
    "ground",
];

const GROUND_KEYS: [&str; 3] = ["body", "normal", "point"];

const LEG_KEYS: [&str; 2] = ["until", "velocity"];

/// One leg of a character's path: the velocity it is asked to walk at until a time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Leg {
    /// The end of the leg (s); it starts where the previous one ended, the first at 0.
    pub until: Real,
    /// The velocity asked for (m/s, world): its displacement over a step is what the
    /// controller is asked to move, gravity's fall added while it is in the air.
    pub velocity: Vec3,
}

/// A scene's character: its controller, the body that shows it, its path, and the speed
/// of its fall while in the air.
#[derive(Debug, Clone, PartialEq)]
pub struct Walker {
    /// The controller, at the character's current position.
    pub controller: CharacterController,
    /// The kinematic body that follows it (colliding with nothing).
    pub body: BodyId,
    /// The legs of its path, in time order; after the last it stands still.
    pub path: Vec<Leg>,
    /// Its fall velocity (m/s): gravity accumulated while it is in the air, zero on the
    /// ground.
    pub fall: Vec3,
}

impl Walker {
    /// The velocity the path asks for at `time` (s): the first leg not yet over.
    pub fn velocity_at(&self, time: Real) -> Vec3 {
        self.path
            .iter()
            .find(|leg| time < leg.until)
            .map_or(Vec3::ZERO, |leg| leg.velocity)
    }

    /// Moves the character over the world's next step of `dt` (s), before that step: the
    /// path's velocity at the step's middle (so a step belongs to one leg whatever the
    /// rounding of the time it starts at) plus the fall (the world's gravity accumulated
    /// while it is in the air), then its body's kinematic target set where it went.
    pub fn advance(&mut self, world: &mut World, dt: Real) -> tumble::Result<()> {
        let velocity = self.velocity_at(world.time() + 0.5 * dt);
        if self.controller.on_ground() {
            self.fall = Vec3::ZERO;
        } else {
            self.fall += world.gravity() * dt;
        }
        self.controller
            .move_by(world, (velocity + self.fall) * dt, dt)?;
        let pose = self.controller.pose();
        world.set_kinematic_target(self.body, pose.position, pose.rotation)
    }
}

/// Reads the `character` object, creates its controller in `world` (after the bodies,
/// whose ground it finds) and the body that shows it. Returns the walker, the body's
/// label and its colour.
pub(crate) fn character(
    node: &Node<'_>,
    world: &mut World,
) -> Result<(Walker, String, Option<[u8; 3]>)> {
    let obj = node.object()?;
    obj.only(&CHARACTER_KEYS)?;
    let def = definition(&obj)?;
    let controller =
        CharacterController::new(world, &def).map_err(|e| SceneError::from_engine(e, ""))?;
    let name = crate::body::name(&obj, "bodies")?.unwrap_or_else(|| "character".into());
    let color = crate::body::color(node)?;
    let pose = controller.pose();
    let body_def = BodyDef {
        name: Some(name.clone()),
        kind: BodyKind::Kinematic,
        position: pose.position,
        orientation: pose.rotation,
        collision_group: 0,
        collision_mask: 0,
        ..Default::default()
    };
    let body = world
        .create_body(&body_def, controller.shape())
        .map_err(|e| SceneError::from_engine(e, "character"))?;
    let path = match obj.get("path") {
        Some(node) => path(&node, world.speed_limits().max_speed)?,
        None => Vec::new(),
    };
    let walker = Walker {
        controller,
        body,
        path,
        fall: Vec3::ZERO,
    };
    Ok((walker, name, color))
}

/// Where a saved run left the character (a saved scene's `fall`, `velocity` and
/// `ground`), applied once the world is whole (its `state` restored), so that the ground
/// body is the restored world's. `ground: null` is in the air; without `ground` the
/// ground found at `position` is kept.
pub(crate) fn resume(node: &Node<'_>, walker: &mut Walker, world: &World) -> Result<()> {
    let obj = node.object()?;
    if let Some(fall) = obj.vec3("fall")? {
        walker.fall = fall;
    }
    let velocity = obj.vec3("velocity")?;
    let ground = match obj.get("ground") {
        None => walker.controller.ground(),
        Some(g) if g.is_null() => None,
        Some(g) => {
            let o = g.object()?;
            o.only(&GROUND_KEYS)?;
            Some(tumble::Ground {
                body: crate::body::reference(&o.required("body")?, world)?,
                normal: o.required("normal")?.vec3()?,
                point: o.required("point")?.vec3()?,
            })
        }
    };
    let c = &mut walker.controller;
    let (position, velocity) = (c.position(), velocity.unwrap_or(c.velocity()));
    c.restore(world, position, ground, velocity)
        .map_err(|e| SceneError::from_engine(e, node.path()))
}

/// The controller's settings: each key as `CharacterDef`'s field, the engine's default
/// where it is missing. The engine checks them, naming them under `character`.
fn definition(obj: &Obj<'_>) -> Result<CharacterDef> {
    let d = CharacterDef::default();
    let mask = obj
        .get("collision_mask")
        .map(|n| n.whole(u32::MAX as u64).map(|v| v as u32))
        .transpose()?;
    Ok(CharacterDef {
        position: obj.vec3("position")?.unwrap_or(d.position),
        radius: obj.real("radius")?.unwrap_or(d.radius),
        half_height: obj.real("half_height")?.unwrap_or(d.half_height),
        up: obj.vec3("up")?.unwrap_or(d.up),
        max_slope: obj.real("max_slope")?.unwrap_or(d.max_slope),
        step_height: obj.real("step_height")?.unwrap_or(d.step_height),
        skin: obj.real("skin")?.unwrap_or(d.skin),
        snap_distance: obj.real("snap_distance")?.unwrap_or(d.snap_distance),
        max_push_force: obj.real("max_push_force")?.unwrap_or(d.max_push_force),
        filter: QueryFilter {
            mask: mask.unwrap_or(u32::MAX),
            exclude: None,
        },
    })
}

/// The `path`: legs with `until` increasing from above 0, velocities no faster than the
/// world's `max_speed`.
fn path(node: &Node<'_>, max_speed: Real) -> Result<Vec<Leg>> {
    let mut legs: Vec<Leg> = Vec::new();
    for item in node.array()? {
        let obj = item.object()?;
        obj.only(&LEG_KEYS)?;
        let until = obj.required("until")?.real()?;
        let start = legs.last().map_or(0.0, |l| l.until);
        if until <= start {
            let after = if legs.is_empty() {
                "0".to_string()
            } else {
                format!(
                    "the previous leg's until ({} s)",
                    tumble::limits::short(start)
                )
            };
            return Err(obj.err_at("until", format!("must be after {after}")));
        }
        let velocity = obj.required("velocity")?.vec3()?;
        if velocity.length() > max_speed {
            return Err(obj.err_at(
                "velocity",
                format!(
                    "must be no faster than max_speed ({} m/s)",
                    tumble::limits::short(max_speed)
                ),
            ));
        }
        legs.push(Leg { until, velocity });
    }
    Ok(legs)
}
