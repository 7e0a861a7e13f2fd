//! The world's bodies: creating, finding, editing and removing them. Every edit checks
//! its value before it changes anything, then wakes what the body touches and forgets the
//! integrator's memory of it (the edit breaks the sequence of steps the memory assumes).

use crate::collision::broad_phase::ProxyKind;
use crate::collision::shape::Shape;
use crate::dynamics::body::{Body, BodyDef, BodyKind};
use crate::error::{check, Error, Result};
use crate::id::BodyId;
use crate::limits::{MAX_COORDINATE, MAX_MAGNITUDE};
use crate::math::{Quat, Vec3};
use crate::pipeline::world::{check_speeds, World};

impl World {
    /// Creates a body; fails (changing nothing) if the definition or shape is invalid or
    /// the name is taken. Error fields are relative to the def (`shape.radius`, `mass`).
    pub fn create_body(&mut self, def: &BodyDef, shape: Shape) -> Result<BodyId> {
        if let Some(name) = &def.name {
            if self.find_body(name).is_some() {
                return Err(Error::invalid(
                    "name",
                    format!("a body named '{name}' already exists"),
                ));
            }
        }
        let body = Body::new(def, shape)?;
        check_speeds(&self.settings.limits, body.velocity, body.angular_velocity)?;
        let store = &mut self.bodies;
        let id = store.handles.insert();
        let kind = if body.kind == BodyKind::Static {
            ProxyKind::Static
        } else {
            ProxyKind::Moving
        };
        let proxy = self.collision.broad_phase.insert(
            body.shape.aabb(&body.pose()),
            store.list.len() as u32,
            kind,
            body.proxy_filter(),
        );
        self.hooks.one_way_bodies += usize::from(body.one_way.is_some());
        self.sensors.sensor_bodies += usize::from(body.sensor);
        self.collision.proxies.push(proxy);
        store.list.push(body);
        self.memory.push();
        Ok(id)
    }

    /// Removes a body and every force element attached to it.
    pub fn remove_body(&mut self, id: BodyId) -> Result<()> {
        let dense = self.dense(id).ok_or(Error::UnknownBody {
            field: "body".into(),
            id,
        })?;
        // Whatever rested on it must notice it is gone.
        self.wake_around(dense);
        // Keep creation order (outputs list bodies in it); removal is rare.
        let body = self.bodies.list.remove(dense);
        self.hooks.one_way_bodies -= usize::from(body.one_way.is_some());
        self.sensors.sensor_bodies -= usize::from(body.sensor);
        self.sensors.forget(id, self.clock.time);
        self.bodies.handles.remove(id);
        self.memory.remove(dense);
        let c = &mut self.collision;
        c.broad_phase.remove(c.proxies.remove(dense));
        for (i, proxy) in c.proxies.iter().enumerate().skip(dense) {
            c.broad_phase.set_user(*proxy, i as u32);
        }
        c.contacts.forget(id, dense);
        self.remove_joints_of(id);
        self.remove_forces_of(id);
        self.joints.excluded.retain(|&(a, b)| a != id && b != id);
        // The bodies after it moved down one place: the joints' links follow now, not at
        // the next step, for what reads them before (setting a joint's coordinate).
        self.refresh_joint_links();
        Ok(())
    }

    pub(crate) fn dense(&self, id: BodyId) -> Option<usize> {
        self.bodies.dense(id)
    }

    fn dense_or_err(&self, id: BodyId) -> Result<usize> {
        self.dense(id).ok_or(Error::UnknownBody {
            field: "body".into(),
            id,
        })
    }

    /// The body with handle `id`.
    pub fn body(&self, id: BodyId) -> Result<&Body> {
        Ok(&self.bodies.list[self.dense_or_err(id)?])
    }

    /// The handle of the body called `name`.
    pub fn find_body(&self, name: &str) -> Option<BodyId> {
        self.bodies
            .list
            .iter()
            .position(|b| b.name.as_deref() == Some(name))
            .map(|i| self.bodies.ids()[i])
    }

    /// Handles of all bodies, in creation order.
    pub fn body_ids(&self) -> &[BodyId] {
        self.bodies.ids()
    }

    /// All bodies with their handles, in creation order.
    pub fn bodies(&self) -> impl Iterator<Item = (BodyId, &Body)> {
        self.bodies
            .ids()
            .iter()
            .copied()
            .zip(self.bodies.list.iter())
    }

    /// The body at dense index `i` (creation order) with its id.
    pub(crate) fn body_at(&self, i: usize) -> Option<(BodyId, &Body)> {
        Some((*self.bodies.ids().get(i)?, self.bodies.list.get(i)?))
    }

    /// Number of bodies.
    pub fn body_count(&self) -> usize {
        self.bodies.list.len()
    }

    /// Wakes body `i`'s island and every island touching it: after an edit nothing that
    /// rests on it, or that it rests on, may assume the world is unchanged.
    pub(crate) fn wake_around(&mut self, i: usize) {
        crate::dynamics::island::wake_island(&mut self.bodies.list, i);
        let touching: Vec<usize> = self
            .collision
            .contacts
            .contacts()
            .iter()
            .filter_map(|c| match (c.index_a as usize, c.index_b as usize) {
                (a, b) if a == i => Some(b),
                (a, b) if b == i => Some(a),
                _ => None,
            })
            .collect();
        for j in touching {
            crate::dynamics::island::wake_island(&mut self.bodies.list, j);
        }
    }

    /// Wakes a body's island (and the islands touching it).
    pub fn wake_body(&mut self, id: BodyId) -> Result<()> {
        let i = self.dense_or_err(id)?;
        self.wake_around(i);
        Ok(())
    }

    pub(crate) fn wake_all(&mut self) {
        for b in &mut self.bodies.list {
            b.awake = true;
            b.sleep_time = 0.0;
        }
    }

    /// Changes one body's state through `edit`, then re-derives what depends on it.
    fn edit_body(&mut self, id: BodyId, edit: impl FnOnce(&mut Body)) -> Result<()> {
        let i = self.dense_or_err(id)?;
        let body = &mut self.bodies.list[i];
        let omega = body.angular_velocity;
        edit(body);
        if body.planar {
            body.velocity.z = 0.0;
        }
        body.set_angular_velocity_internal(if body.kind == BodyKind::Static {
            Vec3::ZERO
        } else {
            omega
        });
        self.memory.forget(i);
        let body = &self.bodies.list[i];
        let aabb = body.shape.aabb(&body.pose());
        let c = &mut self.collision;
        c.broad_phase.update(c.proxies[i], aabb, Vec3::ZERO);
        self.wake_around(i);
        Ok(())
    }

    /// Moves a body so its frame's origin is at `position` (m); velocities are kept.
    pub fn set_position(&mut self, id: BodyId, position: Vec3) -> Result<()> {
        check::vec3_at_most("position", position, MAX_COORDINATE, "m")?;
        self.edit_body(id, |b| b.com = position + b.orientation * b.local_center)
    }

    /// Turns a body about its frame's origin; its angular velocity is kept.
    pub fn set_orientation(&mut self, id: BodyId, orientation: Quat) -> Result<()> {
        let q = check::rotation("orientation", orientation)?;
        self.edit_body(id, |b| {
            let origin = b.position();
            b.orientation = q;
            b.com = origin + q * b.local_center;
        })
    }

    /// Sets the velocity of the centre of mass (m/s).
    pub fn set_linear_velocity(&mut self, id: BodyId, velocity: Vec3) -> Result<()> {
        check_speeds(&self.settings.limits, velocity, Vec3::ZERO)?;
        self.edit_body(id, |b| {
            if b.kind != BodyKind::Static {
                b.velocity = velocity;
            }
        })
    }

    /// Sets the angular velocity (rad/s, world frame); L follows as I_world ω.
    pub fn set_angular_velocity(&mut self, id: BodyId, omega: Vec3) -> Result<()> {
        check_speeds(&self.settings.limits, Vec3::ZERO, omega)?;
        let i = self.dense_or_err(id)?;
        self.bodies.list[i].set_angular_velocity_internal(omega);
        self.memory.forget(i);
        self.wake_around(i);
        Ok(())
    }

    /// Applies an impulse J (N·s) at a world point: Δp = J, ΔL = (point − x) × J.
    pub fn apply_impulse(&mut self, id: BodyId, impulse: Vec3, world_point: Vec3) -> Result<()> {
        check::vec3_at_most("impulse", impulse, MAX_MAGNITUDE, "N·s")?;
        check::vec3_at_most("point", world_point, MAX_COORDINATE, "m")?;
        let i = self.dense_or_err(id)?;
        let b = &self.bodies.list[i];
        if b.kind != BodyKind::Dynamic {
            return Ok(());
        }
        // Worked out in full and checked before anything changes: an impulse that would
        // take the body past the speed limits is refused, the body left as it was.
        let mut v = b.velocity + impulse * b.inv_mass;
        let mut l = b.angular_momentum + (world_point - b.com).cross(impulse);
        if b.planar {
            v.z = 0.0;
            l = Vec3::new(0.0, 0.0, l.z);
        }
        let w = b.omega_from_momentum(b.orientation, l);
        check_speeds(&self.settings.limits, v, w)
            .map_err(|e| Error::invalid("impulse", format!("would make the body's {e}")))?;
        let b = &mut self.bodies.list[i];
        b.velocity = v;
        b.angular_momentum = l;
        b.angular_velocity = w;
        self.memory.forget(i);
        self.wake_around(i);
        Ok(())
    }
}
