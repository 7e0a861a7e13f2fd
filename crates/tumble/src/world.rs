//! The world: bodies, force elements, and the step that advances them.

use crate::body::{Body, BodyDef, BodyKind};
use crate::diagnostics::{self, Diagnostics};
use crate::error::{check, Error, Result};
use crate::force::{Force, ForceCallback};
use crate::id::{BodyId, ForceId};
use crate::integrate::{self, Integrator, Motion, Scratch, System, VerletMemory};
use crate::math::{Quat, Real, Vec3};
use crate::shape::Shape;

/// World settings; `Default` is the seed's: g = 9.8 m/s² down the y axis, symplectic Euler.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WorldDef {
    /// Gravitational acceleration (m/s²).
    pub gravity: Vec3,
    /// The time-stepping method.
    pub integrator: Integrator,
}

impl Default for WorldDef {
    fn default() -> Self {
        WorldDef {
            gravity: Vec3::new(0.0, -9.8, 0.0),
            integrator: Integrator::default(),
        }
    }
}

#[derive(Debug, Clone, Copy)]
struct Slot {
    generation: u32,
    dense: Option<u32>,
}

/// A simulated world.
pub struct World {
    gravity: Vec3,
    integrator: Integrator,
    time: Real,
    step_count: u64,
    // Bodies are dense, in creation order; `slots` maps ids to dense indices.
    bodies: Vec<Body>,
    body_ids: Vec<BodyId>,
    verlet: Vec<Option<VerletMemory>>,
    slots: Vec<Slot>,
    free_slots: Vec<u32>,
    forces: Vec<Force>,
    force_ids: Vec<ForceId>,
    next_force_id: u32,
    callbacks: Vec<ForceCallback>,
    motions: Vec<Motion>,
    scratch: Scratch,
}

impl World {
    /// An empty world.
    pub fn new(def: &WorldDef) -> World {
        World {
            gravity: def.gravity,
            integrator: def.integrator,
            time: 0.0,
            step_count: 0,
            bodies: Vec::new(),
            body_ids: Vec::new(),
            verlet: Vec::new(),
            slots: Vec::new(),
            free_slots: Vec::new(),
            forces: Vec::new(),
            force_ids: Vec::new(),
            next_force_id: 0,
            callbacks: Vec::new(),
            motions: Vec::new(),
            scratch: Scratch::default(),
        }
    }

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
        let index = match self.free_slots.pop() {
            Some(i) => i,
            None => {
                self.slots.push(Slot {
                    generation: 0,
                    dense: None,
                });
                (self.slots.len() - 1) as u32
            }
        };
        let slot = &mut self.slots[index as usize];
        slot.dense = Some(self.bodies.len() as u32);
        let id = BodyId {
            index,
            generation: slot.generation,
        };
        self.bodies.push(body);
        self.body_ids.push(id);
        self.verlet.push(None);
        Ok(id)
    }

    /// Removes a body and every force element attached to it.
    pub fn remove_body(&mut self, id: BodyId) -> Result<()> {
        let dense = self.dense(id).ok_or(Error::UnknownBody {
            field: "body".into(),
            id,
        })?;
        // Keep creation order (outputs list bodies in it); removal is rare.
        self.bodies.remove(dense);
        self.body_ids.remove(dense);
        self.verlet.remove(dense);
        let slot = &mut self.slots[id.index as usize];
        slot.dense = None;
        slot.generation = slot.generation.wrapping_add(1);
        self.free_slots.push(id.index);
        for (i, other) in self.body_ids.iter().enumerate().skip(dense) {
            self.slots[other.index as usize].dense = Some(i as u32);
        }
        let mut keep = self.forces.iter().map(|f| {
            let (a, b) = f.bodies();
            a != id && b != Some(id)
        });
        let keep: Vec<bool> = keep.by_ref().collect();
        let mut k = keep.iter();
        self.forces.retain(|_| *k.next().unwrap_or(&true));
        let mut k = keep.iter();
        self.force_ids.retain(|_| *k.next().unwrap_or(&true));
        Ok(())
    }

    fn dense(&self, id: BodyId) -> Option<usize> {
        lookup(&self.slots, id)
    }

    fn dense_or_err(&self, id: BodyId) -> Result<usize> {
        self.dense(id).ok_or(Error::UnknownBody {
            field: "body".into(),
            id,
        })
    }

    /// The body with handle `id`.
    pub fn body(&self, id: BodyId) -> Result<&Body> {
        Ok(&self.bodies[self.dense_or_err(id)?])
    }

    /// The handle of the body called `name`.
    pub fn find_body(&self, name: &str) -> Option<BodyId> {
        self.bodies
            .iter()
            .position(|b| b.name.as_deref() == Some(name))
            .map(|i| self.body_ids[i])
    }

    /// Handles of all bodies, in creation order.
    pub fn body_ids(&self) -> &[BodyId] {
        &self.body_ids
    }

    /// All bodies with their handles, in creation order.
    pub fn bodies(&self) -> impl Iterator<Item = (BodyId, &Body)> {
        self.body_ids.iter().copied().zip(self.bodies.iter())
    }

    /// Number of bodies.
    pub fn body_count(&self) -> usize {
        self.bodies.len()
    }

    /// Changes one body's state through `edit`, then re-derives what depends on it.
    fn edit_body(&mut self, id: BodyId, edit: impl FnOnce(&mut Body)) -> Result<()> {
        let i = self.dense_or_err(id)?;
        let body = &mut self.bodies[i];
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
        self.verlet[i] = None;
        Ok(())
    }

    /// Moves a body so its frame's origin is at `position` (m); velocities are kept.
    pub fn set_position(&mut self, id: BodyId, position: Vec3) -> Result<()> {
        check::vec3("position", position)?;
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
        check::vec3("velocity", velocity)?;
        self.edit_body(id, |b| {
            if b.kind != BodyKind::Static {
                b.velocity = velocity;
            }
        })
    }

    /// Sets the angular velocity (rad/s, world frame); L follows as I_world ω.
    pub fn set_angular_velocity(&mut self, id: BodyId, omega: Vec3) -> Result<()> {
        check::vec3("angular_velocity", omega)?;
        let i = self.dense_or_err(id)?;
        self.bodies[i].set_angular_velocity_internal(omega);
        self.verlet[i] = None;
        Ok(())
    }

    /// Applies an impulse J (N·s) at a world point: Δp = J, ΔL = (point − x) × J.
    pub fn apply_impulse(&mut self, id: BodyId, impulse: Vec3, world_point: Vec3) -> Result<()> {
        check::vec3("impulse", impulse)?;
        check::vec3("point", world_point)?;
        let i = self.dense_or_err(id)?;
        let b = &mut self.bodies[i];
        if b.kind != BodyKind::Dynamic {
            return Ok(());
        }
        b.velocity += impulse * b.inv_mass;
        let mut l = b.angular_momentum + (world_point - b.com).cross(impulse);
        if b.planar {
            b.velocity.z = 0.0;
            l = Vec3::new(0.0, 0.0, l.z);
        }
        b.angular_momentum = l;
        b.angular_velocity = b.omega_from_momentum(b.orientation, l);
        self.verlet[i] = None;
        Ok(())
    }

    /// Adds a force element; its bodies must exist. Fields in errors are relative to it.
    pub fn add_force(&mut self, force: Force) -> Result<ForceId> {
        force.validate()?;
        let (a, b) = force.bodies();
        if self.dense(a).is_none() {
            return Err(Error::UnknownBody {
                field: "body".into(),
                id: a,
            });
        }
        if let Some(b) = b {
            if self.dense(b).is_none() {
                return Err(Error::UnknownBody {
                    field: "other".into(),
                    id: b,
                });
            }
        }
        let id = ForceId(self.next_force_id);
        self.next_force_id += 1;
        self.forces.push(force);
        self.force_ids.push(id);
        Ok(id)
    }

    /// Removes a force element; false if there was none with this id.
    pub fn remove_force(&mut self, id: ForceId) -> bool {
        match self.force_ids.iter().position(|f| *f == id) {
            Some(i) => {
                self.forces.remove(i);
                self.force_ids.remove(i);
                true
            }
            None => false,
        }
    }

    /// The force elements with their ids.
    pub fn forces(&self) -> impl Iterator<Item = (ForceId, &Force)> {
        self.force_ids.iter().copied().zip(self.forces.iter())
    }

    /// Adds a user force function, evaluated with every other force.
    pub fn add_force_callback(&mut self, callback: ForceCallback) {
        self.callbacks.push(callback);
    }

    /// Gravitational acceleration (m/s²).
    pub fn gravity(&self) -> Vec3 {
        self.gravity
    }

    /// Changes gravity.
    pub fn set_gravity(&mut self, gravity: Vec3) -> Result<()> {
        check::vec3("gravity", gravity)?;
        self.gravity = gravity;
        Ok(())
    }

    /// The time-stepping method.
    pub fn integrator(&self) -> Integrator {
        self.integrator
    }

    /// Changes the time-stepping method from the next step on.
    pub fn set_integrator(&mut self, integrator: Integrator) {
        self.integrator = integrator;
    }

    /// Simulated time (s).
    pub fn time(&self) -> Real {
        self.time
    }

    /// Steps taken.
    pub fn step_count(&self) -> u64 {
        self.step_count
    }

    /// Advances the world by `dt` seconds.
    pub fn step(&mut self, dt: Real) -> Result<()> {
        check::positive("dt", dt)?;
        let mut motions = std::mem::take(&mut self.motions);
        motions.clear();
        motions.extend(self.bodies.iter().map(Motion::of));
        let slots = &self.slots;
        let find = |id: BodyId| lookup(slots, id);
        let mut system = System {
            gravity: self.gravity,
            forces: &self.forces,
            bodies: &self.bodies,
            lookup: &find,
            callbacks: &mut self.callbacks,
        };
        integrate::advance(
            self.integrator,
            &mut system,
            &mut motions,
            &mut self.verlet,
            self.time,
            dt,
            &mut self.scratch,
        );
        for (body, m) in self.bodies.iter_mut().zip(&motions) {
            body.com = m.x;
            body.orientation = m.q;
            body.velocity = m.v;
            body.angular_momentum = m.l;
            body.angular_velocity = m.w;
        }
        self.motions = motions;
        self.time += dt;
        self.step_count += 1;
        Ok(())
    }

    /// Energies and momenta of the current state.
    pub fn diagnostics(&self) -> Diagnostics {
        let slots = &self.slots;
        let find = |id: BodyId| lookup(slots, id);
        let motions: Vec<Motion> = self.bodies.iter().map(Motion::of).collect();
        diagnostics::measure(self.gravity, &self.bodies, &self.forces, &motions, &find)
    }

    /// A hash of every body's state bits: equal hashes mean bit-identical states.
    pub fn state_hash(&self) -> u64 {
        diagnostics::state_hash(&self.bodies)
    }
}

fn lookup(slots: &[Slot], id: BodyId) -> Option<usize> {
    slots
        .get(id.index as usize)
        .filter(|s| s.generation == id.generation)
        .and_then(|s| s.dense)
        .map(|d| d as usize)
}
