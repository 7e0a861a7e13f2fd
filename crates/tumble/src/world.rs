//! The world: bodies, force elements, and the step that advances them.

use crate::body::{Body, BodyDef, BodyKind};
use crate::broad_phase::{BroadPhase, ProxyId, ProxyKind};
use crate::contact_cache::{Contact, ContactCache, ContactEvent};
use crate::diagnostics::{self, Diagnostics};
use crate::error::{check, Error, Result};
use crate::force::{Force, ForceCallback};
use crate::handles::Handles;
use crate::id::{BodyId, ForceId};
use crate::integrate::{self, Integrator, Motion, Scratch, System, VerletMemory};
use crate::joint::{Joint, JointId};
use crate::math::{Quat, Real, Vec3};
use crate::shape::Shape;
use crate::solver::{Scales, Solver, SolverSettings, StepInput};

/// World settings; `Default` is the seed's: g = 9.8 m/s² down the y axis, symplectic Euler.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WorldDef {
    /// Gravitational acceleration (m/s²).
    pub gravity: Vec3,
    /// The time-stepping method.
    pub integrator: Integrator,
    /// The length scale of the scene (m): 1 for a scene in metres, 0.01 for one built in
    /// centimetres. Every tolerance (speculative distance, slop, sleep and bounce
    /// thresholds, broad-phase margins) is this times its value for metres, so a scene
    /// behaves the same at any scale.
    pub length_unit: Real,
    /// The contact solver.
    pub solver: SolverSettings,
    /// Whether resting islands may fall asleep (they wake on any disturbance).
    pub sleep: bool,
}

impl Default for WorldDef {
    fn default() -> Self {
        WorldDef {
            gravity: Vec3::new(0.0, -9.8, 0.0),
            integrator: Integrator::default(),
            length_unit: 1.0,
            solver: SolverSettings::default(),
            sleep: true,
        }
    }
}

/// Tolerances for a scene whose lengths are in multiples of `length_unit` metres; the
/// figures are Box2D v3's, which are tuned for metres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Tolerances {
    /// Speculative contact distance: gaps narrower than this are contacts already.
    pub contact_margin: Real,
    /// How far the broad phase enlarges each box, so slow bodies are not reinserted.
    pub aabb_margin: Real,
    /// Solver scales (slop, push-out speed, restitution threshold).
    pub scales: Scales,
    /// Speed below which a body counts as resting (m/s).
    pub sleep_speed: Real,
}

impl Tolerances {
    fn new(length_unit: Real) -> Tolerances {
        let slop = 0.005 * length_unit;
        Tolerances {
            contact_margin: 4.0 * slop,
            aabb_margin: 0.1 * length_unit,
            scales: Scales {
                linear_slop: slop,
                max_push: 3.0 * length_unit,
                restitution_threshold: 1.0 * length_unit,
            },
            sleep_speed: 0.05 * length_unit,
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
    pub(crate) bodies: Vec<Body>,
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
    tolerances: Tolerances,
    solver_settings: SolverSettings,
    solver: Solver,
    start: Vec<Motion>,
    solved: Vec<bool>,
    /// Bodies whose integrator result is replaced this step (solved or asleep).
    discarded: Vec<bool>,
    /// Contacts the solver leaves out this step (see `speculative.rs`).
    ghosts: Vec<bool>,
    sleep_enabled: bool,
    sleep_tag: u32,
    pub(crate) broad_phase: BroadPhase,
    /// One broad-phase proxy per body, in body order.
    pub(crate) proxies: Vec<ProxyId>,
    /// Scratch for `store_motions`: the moved proxies' new tight boxes and displacements.
    proxy_updates: Vec<(ProxyId, crate::geometry::Aabb, Vec3)>,
    contacts: ContactCache,
    /// Joints in creation order, with their handles (see `world_joints.rs`).
    pub(crate) joints: Vec<Joint>,
    pub(crate) joint_handles: Handles<JointId>,
    /// Each joint's bodies as dense indices, refreshed every step.
    pub(crate) joint_bodies: Vec<[Option<usize>; 2]>,
    /// Dense body pairs a joint keeps from colliding, sorted, refreshed every step.
    pub(crate) joined_pairs: Vec<(u32, u32)>,
}

impl World {
    /// An empty world, after checking the definition.
    pub fn try_new(def: &WorldDef) -> Result<World> {
        check::vec3("gravity", def.gravity)?;
        check::positive("length_unit", def.length_unit)?;
        let mut world = World::new(def);
        world.set_solver_settings(def.solver)?;
        Ok(world)
    }

    /// An empty world. A non-positive or non-finite `length_unit` is taken as 1 m; use
    /// [`World::try_new`] to have bad settings refused instead.
    pub fn new(def: &WorldDef) -> World {
        let def = &WorldDef {
            length_unit: if def.length_unit.is_finite() && def.length_unit > 0.0 {
                def.length_unit
            } else {
                1.0
            },
            ..*def
        };
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
            tolerances: Tolerances::new(def.length_unit),
            solver_settings: def.solver,
            solver: Solver::default(),
            start: Vec::new(),
            solved: Vec::new(),
            discarded: Vec::new(),
            ghosts: Vec::new(),
            sleep_enabled: def.sleep,
            sleep_tag: 0,
            broad_phase: BroadPhase::new(Tolerances::new(def.length_unit).aabb_margin),
            proxies: Vec::new(),
            proxy_updates: Vec::new(),
            contacts: ContactCache::default(),
            joints: Vec::new(),
            joint_handles: Handles::default(),
            joint_bodies: Vec::new(),
            joined_pairs: Vec::new(),
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
        let kind = if body.kind == BodyKind::Static {
            ProxyKind::Static
        } else {
            ProxyKind::Moving
        };
        let proxy = self.broad_phase.insert(
            body.shape.aabb(&body.pose()),
            self.bodies.len() as u32,
            kind,
            body.filter,
        );
        self.proxies.push(proxy);
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
        // Whatever rested on it must notice it is gone.
        self.wake_around(dense);
        // Keep creation order (outputs list bodies in it); removal is rare.
        self.bodies.remove(dense);
        self.body_ids.remove(dense);
        self.verlet.remove(dense);
        self.broad_phase.remove(self.proxies.remove(dense));
        for (i, proxy) in self.proxies.iter().enumerate().skip(dense) {
            self.broad_phase.set_user(*proxy, i as u32);
        }
        self.contacts.forget(id, dense);
        self.remove_joints_of(id);
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

    pub(crate) fn dense(&self, id: BodyId) -> Option<usize> {
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

    /// The body at dense index `i` (creation order) with its id.
    pub(crate) fn body_at(&self, i: usize) -> Option<(BodyId, &Body)> {
        Some((*self.body_ids.get(i)?, self.bodies.get(i)?))
    }

    /// Number of bodies.
    pub fn body_count(&self) -> usize {
        self.bodies.len()
    }

    /// Wakes body `i`'s island and every island touching it: after an edit nothing that
    /// rests on it, or that it rests on, may assume the world is unchanged.
    pub(crate) fn wake_around(&mut self, i: usize) {
        crate::island::wake_island(&mut self.bodies, i);
        let touching: Vec<usize> = self
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
            crate::island::wake_island(&mut self.bodies, j);
        }
    }

    /// Wakes a body's island (and the islands touching it).
    pub fn wake_body(&mut self, id: BodyId) -> Result<()> {
        let i = self.dense_or_err(id)?;
        self.wake_around(i);
        Ok(())
    }

    /// Turns sleeping on or off; turning it off wakes everything.
    pub fn set_sleep_enabled(&mut self, enabled: bool) {
        self.sleep_enabled = enabled;
        if !enabled {
            self.wake_all();
        }
    }

    /// Whether resting islands may fall asleep.
    pub fn sleep_enabled(&self) -> bool {
        self.sleep_enabled
    }

    fn wake_all(&mut self) {
        for b in &mut self.bodies {
            b.awake = true;
            b.sleep_time = 0.0;
        }
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
        let aabb = self.bodies[i].shape.aabb(&self.bodies[i].pose());
        self.broad_phase.update(self.proxies[i], aabb, Vec3::ZERO);
        self.wake_around(i);
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
        self.wake_around(i);
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
        self.wake_around(i);
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
        self.wake_force_bodies(&force);
        self.forces.push(force);
        self.force_ids.push(id);
        Ok(id)
    }

    /// Removes a force element; false if there was none with this id.
    pub fn remove_force(&mut self, id: ForceId) -> bool {
        match self.force_ids.iter().position(|f| *f == id) {
            Some(i) => {
                let force = self.forces.remove(i);
                self.wake_force_bodies(&force);
                self.force_ids.remove(i);
                true
            }
            None => false,
        }
    }

    fn wake_force_bodies(&mut self, force: &Force) {
        let (a, b) = force.bodies();
        for id in std::iter::once(a).chain(b) {
            if let Some(i) = self.dense(id) {
                self.wake_around(i);
            }
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
        if gravity != self.gravity {
            self.wake_all();
        }
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

    /// Advances the world by `dt` seconds: contacts are found at the current state, bodies
    /// touching nothing advance with the world's integrator alone, bodies in contact go
    /// through the solver's substeps (see `solver/mod.rs`).
    pub fn step(&mut self, dt: Real) -> Result<()> {
        check::positive("dt", dt)?;
        self.refresh_joint_links();
        self.update_contacts();
        crate::island::wake_touched(
            &mut self.bodies,
            self.contacts.contacts(),
            &self.joint_bodies,
        );
        let mut motions = std::mem::take(&mut self.motions);
        motions.clear();
        motions.extend(self.bodies.iter().map(Motion::of));
        self.start.clear();
        self.start.extend_from_slice(&motions);
        self.mark_solved();
        crate::speculative::find_ghosts(
            &self.bodies,
            self.contacts.contacts(),
            self.gravity,
            dt * (1.0 + 1.0 / self.solver_settings.substeps.max(1) as Real),
            self.tolerances.scales.linear_slop,
            &mut self.ghosts,
        );
        let slots = &self.slots;
        let find = |id: BodyId| lookup(slots, id);
        let mut system = System {
            gravity: self.gravity,
            forces: &self.forces,
            bodies: &self.bodies,
            lookup: &find,
            callbacks: &mut self.callbacks,
        };
        // When every awake dynamic body is in contact, the integrator's whole-step result
        // would be thrown away for all of them; only kinematic bodies need moving.
        let free = self
            .bodies
            .iter()
            .zip(&self.solved)
            .any(|(b, s)| b.kind == BodyKind::Dynamic && b.awake && !s);
        if free {
            // Their results are replaced below: the solver's or the start's.
            self.discarded.clear();
            self.discarded.extend(
                self.bodies
                    .iter()
                    .zip(&self.solved)
                    .map(|(b, &solved)| solved || !b.awake),
            );
            integrate::advance(
                self.integrator,
                &mut system,
                &mut motions,
                &mut self.verlet,
                (self.time, dt),
                &mut self.scratch,
                &self.discarded,
            );
        } else {
            integrate::move_kinematic(self.bodies.as_slice(), &mut motions, dt);
        }
        for ((m, start), body) in motions.iter_mut().zip(&self.start).zip(&self.bodies) {
            if !body.awake {
                *m = *start;
            }
        }
        if self.solved.iter().any(|s| *s) {
            for ((m, start), (solved, verlet)) in motions
                .iter_mut()
                .zip(&self.start)
                .zip(self.solved.iter().zip(self.verlet.iter_mut()))
            {
                if *solved {
                    *m = *start;
                    *verlet = None;
                }
            }
            let input = StepInput {
                system: &mut system,
                settings: &self.solver_settings,
                scales: &self.tolerances.scales,
                solved: &self.solved,
                ghosts: &self.ghosts,
                joints: &mut self.joints,
                joint_bodies: &self.joint_bodies,
                time: self.time,
                dt,
            };
            self.solver
                .step(input, &mut motions, self.contacts.contacts_mut());
        }
        crate::ccd::sweep_fast_bodies(
            &self.bodies,
            &self.start,
            &mut motions,
            &self.broad_phase,
            self.tolerances.scales.linear_slop,
        );
        self.store_motions(&motions);
        self.motions = motions;
        if self.sleep_enabled {
            crate::island::update_sleep(
                &mut self.bodies,
                self.contacts.contacts(),
                &self.joint_bodies,
                dt,
                self.tolerances.sleep_speed,
                &mut self.sleep_tag,
            );
        }
        self.time += dt;
        self.step_count += 1;
        Ok(())
    }

    /// Marks the dynamic bodies that take part in a contact with points or a joint.
    fn mark_solved(&mut self) {
        self.solved.clear();
        self.solved.resize(self.bodies.len(), false);
        let touching = self
            .contacts
            .contacts()
            .iter()
            .filter(|c| !c.manifold.is_empty())
            .flat_map(|c| [c.index_a as usize, c.index_b as usize]);
        let joined = self.joint_bodies.iter().flatten().flatten().copied();
        for i in touching.chain(joined) {
            if self.bodies[i].kind == BodyKind::Dynamic && self.bodies[i].awake {
                self.solved[i] = true;
            }
        }
    }

    /// Writes the step's results into the bodies and their broad-phase proxies.
    fn store_motions(&mut self, motions: &[Motion]) {
        // Handed to the broad phase together: it may rebuild its tree rather than move
        // most of its leaves one by one.
        self.proxy_updates.clear();
        for ((body, m), proxy) in self.bodies.iter_mut().zip(motions).zip(&self.proxies) {
            if body.kind != BodyKind::Static && body.awake {
                let moved = m.x - body.com;
                let pose = crate::geometry::Pose::new(m.x - m.q * body.local_center, m.q);
                self.proxy_updates
                    .push((*proxy, body.shape.aabb(&pose), moved));
            }
            body.com = m.x;
            body.orientation = m.q;
            body.velocity = m.v;
            body.angular_momentum = m.l;
            body.angular_velocity = m.w;
        }
        self.broad_phase.update_many(&self.proxy_updates);
    }

    /// Speculative contact distance (m).
    pub fn contact_margin(&self) -> Real {
        self.tolerances.contact_margin
    }

    /// The solver settings.
    pub fn solver_settings(&self) -> SolverSettings {
        self.solver_settings
    }

    /// Changes the solver settings from the next step on.
    pub fn set_solver_settings(&mut self, settings: SolverSettings) -> Result<()> {
        if settings.substeps == 0 {
            return Err(Error::invalid("substeps", "must be >= 1"));
        }
        if settings.iterations == 0 {
            return Err(Error::invalid("iterations", "must be >= 1"));
        }
        check::positive("contact_hertz", settings.contact_hertz)?;
        check::non_negative("contact_damping_ratio", settings.contact_damping_ratio)?;
        check::non_negative("baumgarte", settings.baumgarte)?;
        check::positive("joint_hertz", settings.joint_hertz)?;
        check::non_negative("joint_damping_ratio", settings.joint_damping_ratio)?;
        self.solver_settings = settings;
        Ok(())
    }

    /// Runs the broad and narrow phases on the current state and returns every contact
    /// manifold; points keep last update's impulses where their feature ids match.
    pub fn update_contacts(&mut self) -> &[Contact] {
        self.contacts.update(
            &mut self.broad_phase,
            &self.bodies,
            &self.body_ids,
            self.tolerances.contact_margin,
            &self.joined_pairs,
        );
        self.contacts.contacts()
    }

    /// The contacts of the last step (or [`World::update_contacts`]), with the normal and
    /// friction impulses the solver applied at each point (N·s, per substep).
    pub fn contacts(&self) -> &[Contact] {
        self.contacts.contacts()
    }

    /// Pairs that started or stopped touching at the last contact update (each step
    /// runs one), plus end events for bodies removed since.
    pub fn contact_events(&self) -> &[ContactEvent] {
        self.contacts.events()
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
