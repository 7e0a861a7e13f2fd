//! The character controller: a kinematic capsule moved by a desired displacement, in the
//! manner of Box3D's mover, Jolt's `CharacterVirtual` and Rapier's kinematic character
//! controller.
//!
//! ```text
//! mod.rs      CharacterDef (settings, defaults, checks), CharacterController (state,
//!             move_by), Ground, Push
//! surface.rs  the capsule's queries: surfaces near it (Touch), the sweep that stops a
//!             skin short of the first surface in the way
//! planes.rs   the plane solver (collide and slide), steep slopes as walls
//! walk.rs     one move's stages: slide, step up, ground, snap down, pushes
//! ```
//!
//! The character is not a body. It reads the world's bodies (through the query filter)
//! and never changes them, except that what blocks its way and is dynamic gets an
//! impulse of at most `max_push_force · dt` per move: a kinematic body in its place would
//! shove what it meets with unbounded force. Other bodies do not collide with it; a
//! program that wants them to (or wants it drawn) can give it a body of its own that
//! follows `position` (the scene format does that, with a body that collides with
//! nothing, so that outputs and pictures show the character).
//!
//! Sensors do not block it (a trigger volume is walked through), and one-way bodies block
//! it only from their side, as the contact hooks decide for bodies: it jumps up through
//! a one-way platform and lands on it (`surface.rs`, `Owner::blocks`).
//!
//! One move (`move_by`), in order:
//!
//! 1. **Slide**: up to [`MAX_SLIDES`] passes of: gather the surfaces within two skins,
//!    solve the planes for the move nearest what remains of the displacement
//!    (`planes.rs`), sweep the capsule along that move and stop a skin short of the first
//!    surface it would meet (`surface.rs`), so a fast move never passes through a thin
//!    wall. Slopes up to `max_slope` are climbed along their plane; steeper ones stop the
//!    character as a wall would.
//! 2. **Step up**, when it stood on the ground and a wall stopped it: lifted by up to
//!    `step_height` (less under a ceiling), slid across by the horizontal displacement,
//!    dropped back down; taken if it lands on walkable ground no higher than
//!    `step_height` and got farther than the slide did.
//! 3. **Ground**: the most upward-facing walkable surface within two skins below it;
//!    a steep contact counts when it is the edge of a walkable face (a step's nose),
//!    found by a short ray down just past the edge.
//! 4. **Snap**: unless it was asked to rise, when it stood on the ground before and has
//!    none now, or its ground is more than 1.1 skins below it, it is swept down by up to
//!    `snap_distance` and kept there if it lands on walkable ground: walking down a slope
//!    or a stair keeps it on the ground, a skin above it.
//! 5. **Push**: each dynamic body whose steep face held the move back by p (m, not
//!    counting the character's own correction back out to its skin) gets the impulse
//!    m·p/dt along the face's inward normal (what makes it move off at the speed it
//!    blocked), at most `max_push_force · dt`.

mod planes;
mod surface;
mod walk;

use crate::collision::geometry::Pose;
use crate::collision::shape::Shape;
use crate::error::{check, Error, Result};
use crate::id::BodyId;
use crate::limits::{short, MAX_COORDINATE};
use crate::math::{Quat, Real, Vec3};
use crate::pipeline::world::query::QueryFilter;
use crate::pipeline::world::World;

use surface::Capsule;

/// Passes of gather, solve and sweep in one slide: each meets at most one new surface,
/// so this many is enough for a move into a corner of several.
pub const MAX_SLIDES: usize = 6;

/// A character controller's settings and starting position.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CharacterDef {
    /// The capsule's centre at the start (m, world).
    pub position: Vec3,
    /// The capsule's radius (m, > 0). Default 0.3.
    pub radius: Real,
    /// Half the length of the segment between the capsule's two sphere centres (m, >= 0),
    /// as `Shape::capsule`: the character is 2 (half_height + radius) tall. Default 0.6
    /// (1.8 m tall).
    pub half_height: Real,
    /// The up direction (any length, normalised; not zero): the capsule's axis, what
    /// slopes and steps are measured against. Default +y.
    pub up: Vec3,
    /// The steepest slope it walks up (rad, in [0, π/2)); steeper surfaces stop it as
    /// walls do. Default π/4 (45°).
    pub max_slope: Real,
    /// The highest step it climbs (m, >= 0; 0: none). Default 0.3.
    pub step_height: Real,
    /// The gap it keeps to every surface (m, > 0 and less than `radius`): contacts are
    /// gathered within two skins, moves stop one skin short. Default 0.02.
    pub skin: Real,
    /// How far down it follows the ground when walking off a slope or a stair (m, >= 0;
    /// 0: never). Default 0.3.
    pub snap_distance: Real,
    /// The largest force it pushes a dynamic body with (N, >= 0): the impulse per move is
    /// at most this times dt. Default 1000.
    pub max_push_force: Real,
    /// Which bodies block it: those whose collision group meets `filter.mask`, less
    /// `filter.exclude`. Default: every body.
    pub filter: QueryFilter,
}

impl Default for CharacterDef {
    fn default() -> Self {
        CharacterDef {
            position: Vec3::ZERO,
            radius: 0.3,
            half_height: 0.6,
            up: Vec3::Y,
            max_slope: core::f64::consts::FRAC_PI_4 as Real,
            step_height: 0.3,
            skin: 0.02,
            snap_distance: 0.3,
            max_push_force: 1000.0,
            filter: QueryFilter::default(),
        }
    }
}

/// The surface a character stands on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ground {
    /// The body it belongs to.
    pub body: BodyId,
    /// Its unit normal, facing up (for a step's nose, the normal of the walkable face
    /// beyond the edge).
    pub normal: Vec3,
    /// The point of it nearest the character (m, world).
    pub point: Vec3,
}

/// An impulse a move gave a dynamic body in its way.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Push {
    /// The body pushed.
    pub body: BodyId,
    /// The impulse (N·s, world); its length is at most `max_push_force · dt`.
    pub impulse: Vec3,
    /// Where it was applied (m, world): the point of the body's surface nearest the
    /// character.
    pub point: Vec3,
}

/// A kinematic capsule that walks: see the module header for what one move does.
#[derive(Debug, Clone, PartialEq)]
pub struct CharacterController {
    def: CharacterDef,
    capsule: Capsule,
    cos_slope: Real,
    position: Vec3,
    ground: Option<Ground>,
    velocity: Vec3,
    pushes: Vec<Push>,
}

impl CharacterController {
    /// A controller with the settings of `def`, at `def.position`, its ground found in
    /// `world` (it is not moved: a start inside a body is pushed out by the first move).
    /// A bad setting is refused naming it under `character` (`character.radius: must be
    /// > 0`).
    pub fn new(world: &World, def: &CharacterDef) -> Result<CharacterController> {
        let capsule = check_def(def).map_err(|e| e.within("character"))?;
        let mut c = CharacterController {
            def: CharacterDef {
                up: capsule.up,
                ..*def
            },
            capsule,
            cos_slope: def.max_slope.cos(),
            position: def.position,
            ground: None,
            velocity: Vec3::ZERO,
            pushes: Vec::new(),
        };
        c.ground = c.find_ground(world, c.position).map(|(g, _)| g);
        Ok(c)
    }

    /// The settings, with `position` the current one and `up` normalised.
    pub fn def(&self) -> CharacterDef {
        CharacterDef {
            position: self.position,
            ..self.def
        }
    }

    /// The capsule's centre (m, world).
    pub fn position(&self) -> Vec3 {
        self.position
    }

    /// Puts the character at `position` (m) without sweeping it there, and finds its
    /// ground again.
    pub fn set_position(&mut self, world: &World, position: Vec3) -> Result<()> {
        check::vec3_at_most("position", position, MAX_COORDINATE, "m")?;
        self.position = position;
        self.velocity = Vec3::ZERO;
        self.ground = self.find_ground(world, position).map(|(g, _)| g);
        Ok(())
    }

    /// Puts the character back where a saved run left it: at `position`, on `ground` (or
    /// in the air with `None`), its last move's `velocity`; the next move then goes on as
    /// it would have (a move reads only where it is and whether it is on the ground).
    /// Refused, changing nothing, for a position beyond the world's range, a velocity or
    /// ground that is not finite, a ground normal that is not a unit vector, or a ground
    /// body the world does not hold.
    pub fn restore(
        &mut self,
        world: &World,
        position: Vec3,
        ground: Option<Ground>,
        velocity: Vec3,
    ) -> Result<()> {
        check::vec3_at_most("position", position, MAX_COORDINATE, "m")?;
        check::vec3("velocity", velocity)?;
        if let Some(g) = ground {
            world.body(g.body).map_err(|e| e.within("ground"))?;
            check::vec3("ground.point", g.point)?;
            check::vec3("ground.normal", g.normal)?;
            if (g.normal.length() - 1.0).abs() > 1e-3 {
                return Err(Error::invalid("ground.normal", "must be a unit vector"));
            }
        }
        (self.position, self.ground, self.velocity) = (position, ground, velocity);
        self.pushes.clear();
        Ok(())
    }

    /// The capsule's pose: its centre, and the rotation taking y to `up`.
    pub fn pose(&self) -> Pose {
        self.capsule.pose(self.position)
    }

    /// The capsule as a shape (along y; place it with [`pose`](Self::pose)).
    pub fn shape(&self) -> Shape {
        self.capsule.shape()
    }

    /// Whether the last move (or the start) left it on walkable ground.
    pub fn on_ground(&self) -> bool {
        self.ground.is_some()
    }

    /// What it stands on, if anything.
    pub fn ground(&self) -> Option<Ground> {
        self.ground
    }

    /// The unit normal of what it stands on.
    pub fn ground_normal(&self) -> Option<Vec3> {
        self.ground.map(|g| g.normal)
    }

    /// The body it stands on.
    pub fn ground_body(&self) -> Option<BodyId> {
        self.ground.map(|g| g.body)
    }

    /// The last move's displacement over its dt (m/s): what it did, not what was asked.
    pub fn velocity(&self) -> Vec3 {
        self.velocity
    }

    /// The impulses the last move gave dynamic bodies, one per body pushed.
    pub fn pushes(&self) -> &[Push] {
        &self.pushes
    }

    /// Moves the character by `displacement` (m, world) over `dt` (s): slides along what
    /// it meets, climbs walkable slopes and steps, follows the ground down, pushes
    /// dynamic bodies in its way (see the module header). `dt` sets the push bound and
    /// `velocity`. Gravity is the caller's: add it to `displacement` while it is in the
    /// air. Refused, nothing changed, for a `displacement` not finite or leaving the
    /// world's ±1e9 m, or a `dt` not > 0.
    pub fn move_by(&mut self, world: &mut World, displacement: Vec3, dt: Real) -> Result<()> {
        check::positive("dt", dt)?;
        check::vec3_at_most("displacement", displacement, MAX_COORDINATE, "m")?;
        if (self.position + displacement).abs().max_element() > MAX_COORDINATE {
            return Err(Error::invalid(
                "displacement",
                format!(
                    "would take the character beyond ±{} m",
                    short(MAX_COORDINATE)
                ),
            ));
        }
        self.walk(world, displacement, dt);
        Ok(())
    }
}

/// The checks of a definition, each naming its field, and the capsule it describes.
fn check_def(def: &CharacterDef) -> Result<Capsule> {
    check::vec3_at_most("position", def.position, MAX_COORDINATE, "m")?;
    check::positive("radius", def.radius)?;
    check::non_negative("half_height", def.half_height)?;
    check::vec3("up", def.up)?;
    let up = def.up.normalize_or_zero();
    if up == Vec3::ZERO || !up.is_finite() {
        return Err(Error::invalid("up", "must be a non-zero vector"));
    }
    check::finite("max_slope", def.max_slope)?;
    let right = core::f64::consts::FRAC_PI_2 as Real;
    if !(def.max_slope >= 0.0 && def.max_slope < right) {
        return Err(Error::invalid(
            "max_slope",
            format!(
                "must be >= 0 and below π/2 rad (90°), got {}",
                short(def.max_slope)
            ),
        ));
    }
    check::non_negative("step_height", def.step_height)?;
    check::positive("skin", def.skin)?;
    if def.skin >= def.radius {
        return Err(Error::invalid(
            "skin",
            format!("must be less than radius ({} m)", short(def.radius)),
        ));
    }
    check::non_negative("snap_distance", def.snap_distance)?;
    check::non_negative("max_push_force", def.max_push_force)?;
    Ok(Capsule {
        radius: def.radius,
        half_height: def.half_height,
        up,
        rotation: Quat::from_rotation_arc(Vec3::Y, up),
        skin: def.skin,
        filter: def.filter,
    })
}
