//! The world: its lasting state, in a few named stores, and the edits and reads of it.
//!
//! What a world *is* between two steps, and so what a snapshot must keep, is exactly the
//! fields of [`World`] other than `scratch`:
//!
//! | store       | holds                                                                  |
//! |-------------|------------------------------------------------------------------------|
//! | `settings`  | gravity, integrator, solver settings, tolerances (from `length_unit`), sleeping on/off |
//! | `clock`     | simulated time, steps taken                                            |
//! | `bodies`    | bodies in creation order (state x, q, v, L, ω; awake, sleep timer, island tag) and their generational handles |
//! | `forces`    | force elements with their handles, force callbacks (code: not data)    |
//! | `joints`    | joints (with warm-start impulses, reactions, broken flag) and their handles; each joint's bodies and the pairs joints keep from colliding are re-derived every step |
//! | `collision` | the broad phase (trees, fat boxes, pair set), one proxy per body, the contact cache (manifolds with warm starts and friction anchors, events) |
//! | `islands`   | the sleep tag counter (islands' membership lives in the bodies' tags)  |
//! | `memory`    | the integrator's memory (Störmer–Verlet's previous positions)          |
//! | `sensors`   | sensors' overlapping pairs, the last step's sensor events, end events of edits since |
//! | `hooks`     | the contact filter and modifier (code: re-attached, not saved), the filter's verdicts, the count of one-way bodies |
//!
//! `scratch` ([`StepContext`]) is what one step builds and throws away; it is kept only so
//! that stepping allocates nothing, and nothing in it is read before a step writes it.
//! The step itself is in `step.rs`; body, force and joint edits in `bodies.rs`,
//! `forces.rs` and `joints.rs`; queries in `query.rs`; contact hooks and sensor reports in
//! `contact_hooks.rs`.

mod bodies;
pub mod bulk;
mod contact_hooks;
mod forces;
mod invariant;
mod joint_coords;
mod joint_edit;
mod joints;
mod properties;
pub mod query;
mod snapshot;
pub(crate) mod step;

use crate::collision::broad_phase::{BroadPhase, ProxyId};
use crate::collision::contact::{Contact, ContactEvent};
use crate::dynamics::body::Body;
use crate::dynamics::force::{Force, ForceCallback};
use crate::dynamics::integrate::{Integrator, IntegratorMemory};
use crate::dynamics::joint::{Joint, JointId};
use crate::dynamics::solver::{Scales, SolverSettings};
use crate::error::{check, Error, Result};
use crate::handles::Handles;
use crate::id::{BodyId, ForceId};
use crate::limits::{ContactLimits, SpeedLimits, MAX_ACCELERATION};
use crate::math::{Real, Vec3};
use crate::pipeline::contact_cache::ContactCache;
use crate::pipeline::diagnostics::{self, Diagnostics};
use crate::pipeline::hooks::{Hooks, OneWayRule};
use crate::pipeline::sensors::SensorStore;
use crate::threads::Workers;
use step::StepContext;

/// A body's velocities must be within the world's speed limits.
pub(crate) fn check_speeds(limits: &SpeedLimits, v: Vec3, w: Vec3) -> Result<()> {
    check::length_at_most("velocity", v, limits.max_speed, "m/s (max_speed)")?;
    check::length_at_most(
        "angular_velocity",
        w,
        limits.max_angular_speed,
        "rad/s (max_angular_speed)",
    )
}

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
    /// The speeds no body may reach (see `limits.rs`); `None` takes the defaults for
    /// `length_unit`.
    pub limits: Option<SpeedLimits>,
    /// How many contacts a body and a step may have (see `limits.rs`).
    pub contact_limits: ContactLimits,
    /// The fastest that contacts push overlapping bodies apart (m/s), by the solver's
    /// depth correction and by overlap recovery; `None` takes Box2D's 3 m/s ×
    /// `length_unit`.
    pub max_push_speed: Option<Real>,
    /// How many threads a step runs on; `None` takes `TUMBLE_THREADS`, else every core
    /// (see `threads.rs`). Results are bit-identical for every count.
    pub threads: Option<usize>,
}

impl Default for WorldDef {
    fn default() -> Self {
        WorldDef {
            gravity: Vec3::new(0.0, -9.8, 0.0),
            integrator: Integrator::default(),
            length_unit: 1.0,
            solver: SolverSettings::default(),
            sleep: true,
            limits: None,
            contact_limits: ContactLimits::default(),
            max_push_speed: None,
            threads: None,
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
    pub(crate) fn new(length_unit: Real) -> Tolerances {
        let slop = 0.005 * length_unit;
        Tolerances {
            contact_margin: 4.0 * slop,
            aabb_margin: 0.1 * length_unit,
            scales: Scales {
                linear_slop: slop,
                max_push: 3.0 * length_unit,
                restitution_threshold: 0.01 * length_unit,
            },
            sleep_speed: 0.05 * length_unit,
        }
    }
}

/// The world's settings: what the user chose, and the tolerances derived from it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Settings {
    pub gravity: Vec3,
    pub integrator: Integrator,
    /// The scene's length scale (m), which `tolerances` were derived from.
    pub length_unit: Real,
    pub tolerances: Tolerances,
    pub solver: SolverSettings,
    pub sleep: bool,
    pub limits: SpeedLimits,
    pub contacts: ContactLimits,
}

/// Simulated time (s) and the number of steps taken.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Clock {
    pub time: Real,
    pub steps: u64,
}

/// The bodies, dense in creation order, behind generational handles.
#[derive(Default)]
pub(crate) struct BodyStore {
    pub list: Vec<Body>,
    pub handles: Handles<BodyId>,
}

impl BodyStore {
    /// The dense index of the live body `id`.
    pub fn dense(&self, id: BodyId) -> Option<usize> {
        self.handles.dense(id)
    }

    /// Each dense body's handle.
    pub fn ids(&self) -> &[BodyId] {
        self.handles.ids()
    }
}

/// Force elements in creation order with their handles, and the force callbacks.
#[derive(Default)]
pub(crate) struct ForceStore {
    pub list: Vec<Force>,
    pub handles: Handles<ForceId>,
    pub callbacks: Vec<ForceCallback>,
    /// The reason a callback gave for stopping the current step (`ForceContext::fail`);
    /// `None` between steps (the step's check takes it).
    pub failure: Option<String>,
}

/// Joints in creation order with their handles (see `joints.rs`), and what each
/// step re-derives of them before anything reads it.
#[derive(Default)]
pub(crate) struct JointStore {
    pub list: Vec<Joint>,
    pub handles: Handles<JointId>,
    /// Each joint's bodies as dense indices (`None`: the world, or a broken joint).
    pub links: Vec<[Option<usize>; 2]>,
    /// Dense body pairs that must not collide, sorted: those a joint keeps apart and the
    /// `excluded` ones.
    pub joined_pairs: Vec<(u32, u32)>,
    /// Body pairs kept from touching by [`World::exclude_contacts`], each (lower, higher),
    /// sorted. Data, not code (unlike a contact filter), so a world holding them is copied,
    /// snapshotted and saved whole.
    pub excluded: Vec<(BodyId, BodyId)>,
}

/// What collision detection keeps between steps.
pub(crate) struct CollisionStore {
    pub broad_phase: BroadPhase,
    /// One broad-phase proxy per body, in body order.
    pub proxies: Vec<ProxyId>,
    pub contacts: ContactCache,
}

/// A simulated world. See the module documentation for what each store holds.
pub struct World {
    pub(crate) settings: Settings,
    pub(crate) clock: Clock,
    pub(crate) bodies: BodyStore,
    pub(crate) forces: ForceStore,
    pub(crate) joints: JointStore,
    pub(crate) collision: CollisionStore,
    /// The islands' tag counter (see `dynamics/island.rs`).
    pub(crate) sleep_tag: u32,
    pub(crate) memory: IntegratorMemory,
    /// Sensors' overlaps and events (see `pipeline/sensors.rs`).
    pub(crate) sensors: SensorStore,
    /// The contact filter and modifier (code: not saved, re-attached) and what they hand
    /// to the step (see `pipeline/hooks.rs`).
    pub(crate) hooks: Hooks,
    /// Scratch of one step (see `step.rs`): not part of the world's state.
    pub(crate) scratch: StepContext,
    /// The threads steps run on (a setting, not state: results do not depend on it).
    pub(crate) workers: Workers,
}

impl World {
    /// An empty world, after checking the definition.
    pub fn try_new(def: &WorldDef) -> Result<World> {
        check::vec3_at_most("gravity", def.gravity, MAX_ACCELERATION, "m/s²")?;
        check::positive("length_unit", def.length_unit)?;
        let mut world = World::new(def);
        world.set_solver_settings(def.solver)?;
        if let Some(limits) = def.limits {
            world.set_speed_limits(limits)?;
        }
        world.set_contact_limits(def.contact_limits)?;
        if let Some(speed) = def.max_push_speed {
            world.set_max_push_speed(speed)?;
        }
        match def.threads {
            Some(n) => world.set_threads(n)?,
            None => {
                crate::threads::threads_from_env()?;
            }
        }
        Ok(world)
    }

    /// An empty world. A non-positive or non-finite `length_unit` is taken as 1 m; use
    /// [`World::try_new`] to have bad settings refused instead.
    pub fn new(def: &WorldDef) -> World {
        let unit = if def.length_unit.is_finite() && def.length_unit > 0.0 {
            def.length_unit
        } else {
            1.0
        };
        let mut tolerances = Tolerances::new(unit);
        if let Some(speed) = def
            .max_push_speed
            .filter(|s| check::positive("", *s).is_ok())
        {
            tolerances.scales.max_push = speed;
        }
        World {
            settings: Settings {
                gravity: def.gravity,
                integrator: def.integrator,
                length_unit: unit,
                tolerances,
                solver: def.solver,
                sleep: def.sleep,
                limits: def.limits.unwrap_or(SpeedLimits::for_length_unit(unit)),
                contacts: ContactLimits {
                    per_body: def.contact_limits.per_body.max(1),
                    per_step: def.contact_limits.per_step.max(1),
                },
            },
            clock: Clock::default(),
            bodies: BodyStore::default(),
            forces: ForceStore::default(),
            joints: JointStore::default(),
            collision: CollisionStore {
                broad_phase: BroadPhase::new(tolerances.aabb_margin),
                proxies: Vec::new(),
                contacts: ContactCache::default(),
            },
            sleep_tag: 0,
            memory: IntegratorMemory::default(),
            sensors: SensorStore::default(),
            hooks: Hooks::default(),
            scratch: StepContext::default(),
            workers: Workers::new(def.threads.unwrap_or_else(crate::threads::default_threads)),
        }
    }

    /// How many threads a step runs on.
    pub fn threads(&self) -> usize {
        self.workers.threads()
    }

    /// Changes how many threads steps run on (1 to [`MAX_THREADS`]); refused, changing
    /// nothing, outside that range. Results are bit-identical for every count.
    ///
    /// [`MAX_THREADS`]: crate::threads::MAX_THREADS
    pub fn set_threads(&mut self, threads: usize) -> Result<()> {
        crate::threads::check(threads)?;
        if threads != self.workers.threads() {
            self.workers = Workers::new(threads);
        }
        Ok(())
    }

    /// Turns sleeping on or off; turning it off wakes everything.
    pub fn set_sleep_enabled(&mut self, enabled: bool) {
        self.settings.sleep = enabled;
        if !enabled {
            self.wake_all();
        }
    }

    /// Whether resting islands may fall asleep.
    pub fn sleep_enabled(&self) -> bool {
        self.settings.sleep
    }

    /// Gravitational acceleration (m/s²).
    pub fn gravity(&self) -> Vec3 {
        self.settings.gravity
    }

    /// Changes gravity.
    pub fn set_gravity(&mut self, gravity: Vec3) -> Result<()> {
        check::vec3_at_most("gravity", gravity, MAX_ACCELERATION, "m/s²")?;
        if gravity != self.settings.gravity {
            self.wake_all();
        }
        self.settings.gravity = gravity;
        Ok(())
    }

    /// How many touching pairs a body keeps when crowded, and how many manifolds a step
    /// may hold (see [`ContactLimits`]).
    pub fn contact_limits(&self) -> ContactLimits {
        self.settings.contacts
    }

    /// Changes the contact limits; refused (changing nothing) if either is 0.
    pub fn set_contact_limits(&mut self, limits: ContactLimits) -> Result<()> {
        if limits.per_body == 0 {
            return Err(Error::invalid("max_contacts_per_body", "must be >= 1"));
        }
        if limits.per_step == 0 {
            return Err(Error::invalid("max_contacts", "must be >= 1"));
        }
        self.settings.contacts = limits;
        Ok(())
    }

    /// The fastest that contacts push overlapping bodies apart (m/s).
    pub fn max_push_speed(&self) -> Real {
        self.settings.tolerances.scales.max_push
    }

    /// Changes how fast contacts may push overlapping bodies apart; refused (changing
    /// nothing) unless it is a positive number. It takes effect from the next step.
    pub fn set_max_push_speed(&mut self, speed: Real) -> Result<()> {
        check::positive("max_push_speed", speed)?;
        self.settings.tolerances.scales.max_push = speed;
        Ok(())
    }

    /// The speeds no body may reach: every step checks its result against them.
    pub fn speed_limits(&self) -> SpeedLimits {
        self.settings.limits
    }

    /// Changes the speed limits; refused (changing nothing) if they are not positive
    /// numbers or a body already moves faster.
    pub fn set_speed_limits(&mut self, limits: SpeedLimits) -> Result<()> {
        check::positive("max_speed", limits.max_speed)?;
        check::positive("max_angular_speed", limits.max_angular_speed)?;
        for (i, b) in self.bodies.list.iter().enumerate() {
            let (v, w) = (b.velocity.length(), b.angular_velocity.length());
            let refuse = |field: &str, x: Real, unit: &str| {
                let x = crate::limits::short(x);
                let reason = format!("must be at least {x} {unit}: bodies[{i}] moves that fast");
                Err(Error::invalid(field, reason))
            };
            if v > limits.max_speed {
                return refuse("max_speed", v, "m/s");
            }
            if w > limits.max_angular_speed {
                return refuse("max_angular_speed", w, "rad/s");
            }
        }
        self.settings.limits = limits;
        Ok(())
    }

    /// The time-stepping method.
    pub fn integrator(&self) -> Integrator {
        self.settings.integrator
    }

    /// Changes the time-stepping method from the next step on. The old method's memory
    /// (Störmer–Verlet's previous positions) is forgotten: a method switched back to
    /// starts afresh, as in a new world from the same state.
    pub fn set_integrator(&mut self, integrator: Integrator) {
        if integrator != self.settings.integrator {
            self.memory.clear();
        }
        self.settings.integrator = integrator;
    }

    /// Simulated time (s).
    pub fn time(&self) -> Real {
        self.clock.time
    }

    /// Steps taken.
    pub fn step_count(&self) -> u64 {
        self.clock.steps
    }

    /// The length scale the world's tolerances were derived from (m; see
    /// [`WorldDef::length_unit`]).
    pub fn length_unit(&self) -> Real {
        self.settings.length_unit
    }

    /// Speculative contact distance (m).
    pub fn contact_margin(&self) -> Real {
        self.settings.tolerances.contact_margin
    }

    /// The solver settings.
    pub fn solver_settings(&self) -> SolverSettings {
        self.settings.solver
    }

    /// Changes the solver settings from the next step on.
    pub fn set_solver_settings(&mut self, settings: SolverSettings) -> Result<()> {
        check_solver_settings(&settings)?;
        self.settings.solver = settings;
        Ok(())
    }

    /// Runs the broad and narrow phases on the current state and returns every contact
    /// manifold; points keep last update's impulses where their feature ids match. The
    /// contact filter, one-way bodies and the contact modifier act as in a step. At most
    /// [`ContactLimits::per_step`] are returned (a step that needs more fails).
    pub fn update_contacts(&mut self) -> &[Contact] {
        let mut workers = std::mem::take(&mut self.workers);
        workers.run(|par| {
            self.scratch.par = par;
            self.update_contacts_for(0.0);
        });
        self.workers = workers;
        self.collision.contacts.contacts()
    }

    /// The contact update before a step of `dt`: pairs that can close more than the
    /// contact margin within it get a margin as wide as that.
    /// The hooks (see `pipeline/hooks.rs`) act between the narrow phase and the events.
    pub(crate) fn update_contacts_for(&mut self, dt: Real) -> &[Contact] {
        let c = &mut self.collision;
        let step = (dt, self.settings.gravity.length() * dt);
        let (bodies, ids) = (&self.bodies.list, self.bodies.handles.ids());
        let hooks = &mut self.hooks;
        c.contacts.update(
            &mut c.broad_phase,
            bodies,
            ids,
            (self.settings.tolerances.contact_margin, step),
            (&self.joints.joined_pairs, |pairs: &mut Vec<(u32, u32)>| {
                hooks.filter_pairs(pairs, bodies, ids);
            }),
            (&self.settings.contacts, self.scratch.par),
        );
        let rule = OneWayRule {
            kick: self.settings.gravity * dt,
            speed: self.settings.tolerances.sleep_speed,
        };
        let max_speed = self.settings.limits.max_speed;
        hooks.apply(c.contacts.contacts_mut(), bodies, &rule, max_speed);
        c.contacts.find_events();
        c.contacts.contacts()
    }

    /// Pairs the last contact update left out because both bodies were crowded past
    /// [`ContactLimits::per_body`], in the broad phase (candidates) and among touching
    /// pairs: `(candidates, touching)`. Both 0 unless bodies overlap en masse.
    pub fn crowded_pairs(&self) -> (usize, usize) {
        let c = &self.collision;
        (c.broad_phase.crowded(), c.contacts.crowded())
    }

    /// The contacts of the last step (or [`World::update_contacts`]), with the normal and
    /// friction impulses the solver applied at each point (N·s, per substep).
    pub fn contacts(&self) -> &[Contact] {
        self.collision.contacts.contacts()
    }

    /// Pairs that started or stopped touching at the last contact update (each step
    /// runs one), plus end events for bodies removed since.
    pub fn contact_events(&self) -> &[ContactEvent] {
        self.collision.contacts.events()
    }

    /// Energies and momenta of the current state.
    pub fn diagnostics(&self) -> Diagnostics {
        let find = |id: BodyId| self.bodies.dense(id);
        let bodies = &self.bodies.list;
        let motions: Vec<_> = bodies
            .iter()
            .map(crate::dynamics::body::Motion::of)
            .collect();
        let gravity = self.settings.gravity;
        diagnostics::measure(gravity, bodies, &self.forces.list, &motions, &find)
    }

    /// A hash of every body's state bits: equal hashes mean bit-identical states.
    pub fn state_hash(&self) -> u64 {
        diagnostics::state_hash(&self.bodies.list)
    }
}

/// The rules for solver settings, in `World::set_solver_settings` and for a snapshot's.
pub(crate) fn check_solver_settings(settings: &SolverSettings) -> Result<()> {
    use crate::limits::{MAX_DAMPING_RATIO, MAX_HERTZ, MAX_ITERATIONS, MAX_SUBSTEPS};
    for (field, n, most) in [
        ("substeps", settings.substeps, MAX_SUBSTEPS),
        ("iterations", settings.iterations, MAX_ITERATIONS),
    ] {
        if n == 0 {
            return Err(Error::invalid(field, "must be >= 1"));
        }
        if n > most {
            return Err(Error::invalid(field, format!("must be <= {most}")));
        }
    }
    for (field, hz) in [
        ("contact_hertz", settings.contact_hertz),
        ("joint_hertz", settings.joint_hertz),
    ] {
        check::positive(field, hz)?;
        check::at_most(field, hz, MAX_HERTZ, "Hz")?;
    }
    for (field, ratio) in [
        ("contact_damping_ratio", settings.contact_damping_ratio),
        ("joint_damping_ratio", settings.joint_damping_ratio),
    ] {
        check::non_negative(field, ratio)?;
        check::at_most(field, ratio, MAX_DAMPING_RATIO, "")?;
    }
    check::non_negative("baumgarte", settings.baumgarte)
}

crate::codec::codec_struct!(Tolerances {
    contact_margin,
    aabb_margin,
    scales,
    sleep_speed
});
crate::codec::codec_struct!(Settings {
    gravity,
    integrator,
    length_unit,
    tolerances,
    solver,
    sleep,
    limits,
    contacts
});
crate::codec::codec_struct!(Clock { time, steps });
crate::codec::codec_struct!(BodyStore { list, handles });
crate::codec::codec_struct!(JointStore {
    list,
    handles,
    links,
    joined_pairs,
    excluded
});
crate::codec::codec_struct!(CollisionStore {
    broad_phase,
    proxies,
    contacts
});
