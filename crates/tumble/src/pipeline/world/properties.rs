//! Run-time edits of a body's properties: friction, restitution, collision filter,
//! sensor flag, one-way normal, damping, gravity scale, and a kinematic body's target
//! pose. Each checks its value with
//! the rule `World::create_body` applies to the same field of `BodyDef` (the same message,
//! so a scene file, Rust and Python refuse a value alike), changes nothing when it fails,
//! and wakes the body and what touches it: a resting pile must notice that its friction
//! went, or its support stopped colliding.

use crate::collision::broad_phase::Filter;
use crate::dynamics::body::BodyKind;
use crate::dynamics::body::{
    check_friction, check_gravity_scale, check_one_way, check_restitution, Body,
};
use crate::error::{check, Error, Result};
use crate::id::BodyId;
use crate::limits::MAX_COORDINATE;
use crate::math::{rotation_vector, Quat, Real, Vec3};
use crate::pipeline::world::World;

impl World {
    /// Changes one property of body `id` through `edit` (its value already checked), then
    /// wakes it and the islands touching it.
    fn edit_property(&mut self, id: BodyId, edit: impl FnOnce(&mut Body)) -> Result<()> {
        let i = self.dense(id).ok_or(Error::UnknownBody {
            field: "body".into(),
            id,
        })?;
        edit(&mut self.bodies.list[i]);
        self.wake_around(i);
        Ok(())
    }

    /// Sets a body's Coulomb friction coefficient (>= 0; a pair uses √(μ_a μ_b)), from the
    /// next step on.
    pub fn set_friction(&mut self, id: BodyId, friction: Real) -> Result<()> {
        check_friction(friction)?;
        self.edit_property(id, |b| b.friction = friction)
    }

    /// Sets a body's coefficient of restitution (in [0, 1]; a pair uses the larger).
    pub fn set_restitution(&mut self, id: BodyId, restitution: Real) -> Result<()> {
        check_restitution(restitution)?;
        self.edit_property(id, |b| b.restitution = restitution)
    }

    /// Sets a body's collision layers (`group`) and the layers it collides with (`mask`).
    /// The broad phase searches the body's pairs again at the next step: a pair the new
    /// filter forbids stops colliding there, one it allows starts.
    /// The body's collision owner is kept.
    pub fn set_collision_filter(&mut self, id: BodyId, group: u32, mask: u32) -> Result<()> {
        self.edit_property(id, |b| {
            b.filter = Filter {
                group,
                mask,
                owner: b.filter.owner,
            }
        })?;
        self.refilter(id);
        Ok(())
    }

    /// Sets a body's collision owner (see `BodyDef::collision_owner`; 0: none): bodies
    /// with the same non-zero owner stop colliding with each other at the next step.
    pub fn set_collision_owner(&mut self, id: BodyId, owner: u32) -> Result<()> {
        self.edit_property(id, |b| b.filter.owner = owner)?;
        self.refilter(id);
        Ok(())
    }

    /// A collision owner no body of the world has (never 0): the largest one in use plus
    /// one, or if that is past `u32::MAX` the least free one. For a model's bodies, so
    /// that they do not collide with each other but do with every other model's.
    pub fn unused_collision_owner(&self) -> u32 {
        let owners = self.bodies.list.iter().map(|b| b.filter.owner);
        match owners.clone().max().unwrap_or(0).checked_add(1) {
            Some(n) => n,
            None => {
                let used: std::collections::BTreeSet<u32> = owners.collect();
                (1..=u32::MAX)
                    .find(|n| !used.contains(n))
                    .expect("fewer bodies than owners")
            }
        }
    }

    /// Hands body `id`'s proxy filter to the broad phase, which searches its pairs again
    /// at the next step.
    fn refilter(&mut self, id: BodyId) {
        if let Some(i) = self.dense(id) {
            let c = &mut self.collision;
            c.broad_phase
                .set_filter(c.proxies[i], self.bodies.list[i].proxy_filter());
        }
    }

    /// Makes a body a sensor or an ordinary body (see `BodyDef::sensor`), from the next
    /// step on. Its overlaps as a sensor, or with sensors, end at once (their end events
    /// come first among the next step's sensor events); its contacts end at the next step.
    pub fn set_sensor(&mut self, id: BodyId, sensor: bool) -> Result<()> {
        let was = self.body(id)?.sensor;
        self.edit_property(id, |b| b.sensor = sensor)?;
        if was != sensor {
            self.sensors.forget(id, self.clock.time);
            self.sensors.sensor_bodies =
                self.sensors.sensor_bodies + usize::from(sensor) - usize::from(was);
            self.refilter(id);
        }
        Ok(())
    }

    /// Makes a body one-way with `normal` (body frame; finite, non-zero, normalised), or
    /// an ordinary body with `None` (see `BodyDef::one_way`). Manifolds with it are decided
    /// afresh as they begin.
    pub fn set_one_way(&mut self, id: BodyId, normal: Option<Vec3>) -> Result<()> {
        let normal = normal.map(check_one_way).transpose()?;
        let was = self.body(id)?.one_way.is_some();
        self.edit_property(id, |b| b.one_way = normal)?;
        self.hooks.one_way_bodies =
            self.hooks.one_way_bodies + usize::from(normal.is_some()) - usize::from(was);
        Ok(())
    }

    /// Sets a body's linear damping (1/s, >= 0): dv/dt = −c v besides the forces.
    pub fn set_linear_damping(&mut self, id: BodyId, damping: Real) -> Result<()> {
        check::non_negative("linear_damping", damping)?;
        self.edit_property(id, |b| b.linear_damping = damping)
    }

    /// Sets a body's angular damping (1/s, >= 0): dL/dt = −c L besides the torques.
    pub fn set_angular_damping(&mut self, id: BodyId, damping: Real) -> Result<()> {
        check::non_negative("angular_damping", damping)?;
        self.edit_property(id, |b| b.angular_damping = damping)
    }

    /// Sets the multiplier of the world's gravity for a body (|s| <= 1e6).
    pub fn set_gravity_scale(&mut self, id: BodyId, scale: Real) -> Result<()> {
        check_gravity_scale(scale)?;
        self.edit_property(id, |b| b.gravity_scale = scale)
    }

    /// Tells a kinematic body to be at `position` (its frame's origin, m) and
    /// `orientation` exactly at the end of the next step. The target is kept until that
    /// step, which sets the body's velocities from its `dt`: v = Δx / dt and ω = θ / dt,
    /// θ the rotation vector of q_target q⁻¹ taken the short way (at most π). The body then
    /// keeps those velocities, as any kinematic body keeps the velocity it is given: give
    /// a target every step to drive it along a path, or its own pose (or zero velocities)
    /// to stop it. What it pushes or carries meets it moving at those velocities through
    /// the step. Refused (nothing changed) for a body that is not kinematic.
    pub fn set_kinematic_target(
        &mut self,
        id: BodyId,
        position: Vec3,
        orientation: Quat,
    ) -> Result<()> {
        check::vec3_at_most("position", position, MAX_COORDINATE, "m")?;
        let q = check::rotation("orientation", orientation)?;
        let kind = self.body(id)?.kind;
        if kind != BodyKind::Kinematic {
            return Err(Error::invalid(
                "kind",
                "a kinematic target needs a kinematic body",
            ));
        }
        self.edit_property(id, |b| {
            b.kinematic_target = Some((position + q * b.local_center, q));
        })
    }

    /// Stage of the step, before the contact update (whose margins and ghost checks read
    /// the velocities): every kinematic body with a target gets the velocities that take
    /// it there over `dt` (the way `move_kinematic` moves it: x₀ + dt v, exp(dt ω/2) q₀),
    /// wakes, and forgets the target; the step's undo keeps what it took.
    pub(super) fn take_kinematic_targets(&mut self, dt: Real) {
        for (i, b) in self.bodies.list.iter_mut().enumerate() {
            let Some((com, q)) = b.kinematic_target.take() else {
                continue;
            };
            let undo = (i, (com, q), b.velocity, b.angular_velocity);
            self.scratch.undo.targets.push(undo);
            b.velocity = (com - b.com) / dt;
            b.angular_velocity = rotation_vector(q * b.orientation.inverse()) / dt;
            if b.planar {
                // As `set_linear_velocity` and `set_angular_velocity` do for a planar body.
                b.velocity.z = 0.0;
                b.angular_velocity = Vec3::new(0.0, 0.0, b.angular_velocity.z);
            }
            (b.awake, b.sleep_time) = (true, 0.0);
        }
    }
}
