//! The step: `World::step` as a pipeline of named stages over the world's stores and one
//! step context.
//!
//! ```text
//! stage                reads                               writes
//! refresh_joint_links  joints, body handles                joints' dense bodies, joined pairs
//! take_kinematic_targets  kinematic targets, bodies        kinematic bodies' velocities,
//!                                                          awake flags; targets cleared
//! update_contacts      bodies, broad phase, joined pairs   broad-phase pairs, contact cache
//! check_contacts       contact cache                       nothing; past the step's contact
//!                                                          limit, undoes the step and
//!                                                          returns the error
//! wake_touched         contacts, joint links               bodies' awake flags
//! gather               bodies, contacts, joint links       context: solved mask, solver bodies
//! find_ghosts          bodies, contacts                    context: ghost mask
//! integrate_free       forces, bodies; context             solver bodies touching nothing
//! check_callbacks      forces' failure                     nothing; after a force callback
//!                                                          failed (after integrate_free and
//!                                                          after solve), undoes the step
//!                                                          and returns the error
//! solve                forces, joints, contacts; context   solver bodies in contact or joined,
//!                                                          contact impulses, joint reactions
//! move_kinematic       context                             kinematic solver bodies
//! sweep_fast           bodies, broad phase; context        fast solver bodies (time of impact)
//! check_result         context                             nothing; on a non-finite or too
//!                                                          fast body, undoes the step and
//!                                                          returns the error
//! scatter              context                             bodies' state, broad-phase proxies
//! update_sleep         bodies, contacts, joint links       sleep timers, awake flags, tags
//! update_sensors       bodies, broad phase, contact filter sensors' overlaps and events
//! ```
//!
//! Time has one vocabulary ([`StepTime`]): `dt` is the step, `h` = `dt` / substeps the
//! solver's substep, both derived once per step. Every body has one representation inside
//! the step, the solver's ([`SolverBodies`]): gathered from `Body` once, advanced in place
//! by whichever stage moves it, scattered back once.

use crate::collision::geometry::{Aabb, Pose};
use crate::dynamics::body::{BodyKind, Motion};
use crate::dynamics::integrate::{self, exact_spin, Scratch, System};
use crate::dynamics::solver::{Solver, SolverBodies, StepInput, StepTime};
use crate::error::{check, Result};
use crate::id::BodyId;
use crate::math::{Real, Vec3};
use crate::pipeline::world::World;
use crate::threads::Par;

/// Fewest bodies for which a step goes to the world's threads at all. The bench's
/// 385-cube pyramid (graph colours of at most 31 lane groups, too short to split) took
/// 0.72–0.93× its one-thread speed on two threads with the team formed: below about a
/// thousand bodies nothing splits enough to pay for it.
const SMALL_WORLD: usize = 1000;

/// Everything a step builds and throws away, kept between steps only so that stepping
/// allocates nothing. Nothing here is read before the step that needs it writes it.
#[derive(Default)]
pub(crate) struct StepContext {
    /// Every body as the step sees it (see `solver/body.rs`).
    pub bodies: SolverBodies,
    /// Per body: the solver advances it (awake, dynamic, touching something or joined).
    solved: Vec<bool>,
    /// Per body: the free integrator's result for it is not used (solved, or asleep).
    discarded: Vec<bool>,
    /// Per contact: a speculative contact the bodies will not reach this step.
    ghosts: Vec<bool>,
    /// Per body: fast this step (swept by `sweep_fast`).
    fast: Vec<bool>,
    /// The free integrator's ODE vector and its stages.
    ode: Vec<Motion>,
    integrate: Scratch,
    /// The solver's constraints and buffers.
    solver: Solver,
    /// What the stages before the check change, as it was (see `invariant.rs`).
    pub(super) undo: super::invariant::Undo,
    /// The moved proxies' new tight boxes and displacements, handed to the broad phase
    /// together.
    proxy_updates: Vec<(crate::collision::broad_phase::ProxyId, Aabb, Vec3)>,
    /// Per body, its proxy update (`None`: static or asleep), filled in pieces.
    body_updates: Vec<Option<(crate::collision::broad_phase::ProxyId, Aabb, Vec3)>>,
    /// How this step may split its work (see `threads.rs`).
    pub par: Par,
}

impl World {
    /// Advances the world by `dt` seconds: contacts are found at the current state, bodies
    /// touching nothing advance with the world's integrator alone, bodies in contact or
    /// joined go through the solver's substeps (see `dynamics/solver/mod.rs`).
    ///
    /// A step whose result has a non-finite value or a speed beyond the world's limits is
    /// undone, leaving the world as it was, and returns [`Error::Unstable`] naming the
    /// step, the body and the quantity (see `invariant.rs`); so is a step a force callback
    /// stops ([`Error::CallbackFailed`]).
    ///
    /// [`Error::Unstable`]: crate::error::Error::Unstable
    /// [`Error::CallbackFailed`]: crate::error::Error::CallbackFailed
    pub fn step(&mut self, dt: Real) -> Result<()> {
        check::positive("dt", dt)?;
        // A small world steps on the calling thread: handing a step to the pool and back
        // costs tens of µs, and a team whose members spin costs a core, more than a few
        // hundred bodies' stages could save.
        if Par::split_at(self.bodies.list.len(), SMALL_WORLD) == 0 {
            return self.step_on(dt, Par::SERIAL);
        }
        // Out of the world while it runs, so that the step can borrow the whole world.
        let mut workers = std::mem::take(&mut self.workers);
        let result = workers.run(|par| self.step_on(dt, par));
        self.workers = workers;
        result
    }

    /// The stages of a step, with `par` telling how they may split their work.
    fn step_on(&mut self, dt: Real, par: Par) -> Result<()> {
        self.scratch.par = par;
        let time = StepTime::new(self.clock.time, dt, &self.settings.solver);
        self.refresh_joint_links();
        self.keep_undo();
        self.take_kinematic_targets(dt);
        self.update_contacts_for(dt);
        self.check_contacts(&time)?;
        self.wake_touched();
        self.gather();
        self.find_ghosts(&time);
        self.integrate_free(&time);
        self.check_callbacks(&time)?;
        self.solve(&time);
        self.check_callbacks(&time)?;
        self.move_kinematic(&time);
        self.sweep_fast();
        self.check_result(&time)?;
        self.scatter();
        self.follow_hinge_angles(dt);
        self.update_sleep(&time);
        self.clock.time += dt;
        self.clock.steps += 1;
        self.update_sensors();
        Ok(())
    }

    /// Islands touched by an awake body or a joint to one wake.
    fn wake_touched(&mut self) {
        let contacts = self.collision.contacts.contacts();
        crate::dynamics::island::wake_touched(&mut self.bodies.list, contacts, &self.joints.links);
    }

    /// Marks the bodies the solver advances (awake dynamic bodies with a contact that has
    /// points, or a joint) and gathers every body into the step's representation.
    fn gather(&mut self) {
        let (bodies, ctx) = (&self.bodies.list, &mut self.scratch);
        ctx.solved.clear();
        ctx.solved.resize(bodies.len(), false);
        let touching = self
            .collision
            .contacts
            .contacts()
            .iter()
            .filter(|c| !c.manifold.is_empty())
            .flat_map(|c| [c.index_a as usize, c.index_b as usize]);
        let joined = self.joints.links.iter().flatten().flatten().copied();
        for i in touching.chain(joined) {
            if bodies[i].kind == BodyKind::Dynamic && bodies[i].awake {
                ctx.solved[i] = true;
            }
        }
        ctx.bodies.gather(bodies, &ctx.solved, ctx.par);
    }

    /// Speculative contacts that the bodies' motion over the step and one substep more
    /// will not reach sit the step out (see `pipeline/speculative.rs`).
    fn find_ghosts(&mut self, time: &StepTime) {
        crate::pipeline::speculative::find_ghosts(
            &self.bodies.list,
            self.collision.contacts.contacts(),
            (
                self.settings.gravity,
                time.dt * (1.0 + 1.0 / time.substeps as Real),
                self.settings.tolerances.scales.linear_slop,
            ),
            &mut self.scratch.ghosts,
            self.scratch.par,
        );
    }

    /// Bodies touching nothing advance over the whole step with the world's integrator;
    /// their results are written into the step's bodies (awake dynamic ones only: the
    /// solver's start from their state at the step's start, sleeping ones stay).
    fn integrate_free(&mut self, time: &StepTime) {
        let ctx = &mut self.scratch;
        let bodies = &self.bodies.list;
        let free = bodies
            .iter()
            .zip(&ctx.solved)
            .any(|(b, s)| b.kind == BodyKind::Dynamic && b.awake && !s);
        if !free {
            // Every awake dynamic body is in contact: the integrator's whole-step result
            // would be thrown away for all of them.
            return;
        }
        ctx.discarded.clear();
        let discarded = bodies.iter().zip(&ctx.solved).map(|(b, &s)| s || !b.awake);
        ctx.discarded.extend(discarded);
        ctx.ode.clear();
        ctx.ode
            .extend((0..bodies.len()).map(|i| ctx.bodies.motion(i)));
        let handles = &self.bodies.handles;
        let find = |id: BodyId| handles.dense(id);
        let mut system = system(
            &self.settings,
            &mut self.forces,
            (bodies, handles.ids()),
            &find,
        );
        integrate::advance(
            self.settings.integrator,
            &mut system,
            &mut ctx.ode,
            &mut self.memory,
            (time.t, time.dt),
            &mut ctx.integrate,
            &ctx.discarded,
        );
        for (i, b) in bodies.iter().enumerate() {
            if b.kind == BodyKind::Dynamic && !ctx.discarded[i] {
                ctx.bodies.set_motion(i, &ctx.ode[i]);
            }
        }
    }

    /// Bodies in contact or joined go through the solver's substeps; the integrator's
    /// memory of them is forgotten (the solver's steps are not the integrator's).
    fn solve(&mut self, time: &StepTime) {
        let ctx = &mut self.scratch;
        if !ctx.solved.iter().any(|s| *s) {
            return;
        }
        for (i, _) in ctx.solved.iter().enumerate().filter(|(_, s)| **s) {
            self.memory.forget(i);
        }
        let handles = &self.bodies.handles;
        let find = |id: BodyId| handles.dense(id);
        let mut system = system(
            &self.settings,
            &mut self.forces,
            (&self.bodies.list, handles.ids()),
            &find,
        );
        let input = StepInput {
            system: &mut system,
            settings: &self.settings.solver,
            scales: &self.settings.tolerances.scales,
            ghosts: &ctx.ghosts,
            materials: &self.hooks.materials,
            joints: &mut self.joints.list,
            joint_bodies: &self.joints.links,
            time,
            par: ctx.par,
        };
        let contacts = self.collision.contacts.contacts_mut();
        ctx.solver.step(input, &mut ctx.bodies, contacts);
    }

    /// Kinematic bodies end the step exactly where their velocities take them from its
    /// start: x₀ + dt v, exp(dt ω/2) q₀ (the solver's substeps moved them too, so that
    /// contacts met them where they were, but by sums of substeps).
    fn move_kinematic(&mut self, time: &StepTime) {
        let ctx = &mut self.scratch;
        for (i, b) in self.bodies.list.iter().enumerate() {
            if b.kind == BodyKind::Kinematic && b.awake {
                let (sim, state) = (&mut ctx.bodies.sims[i], &ctx.bodies.states[i]);
                sim.x = sim.x0 + state.v * time.dt;
                sim.q = exact_spin(state.w, sim.q0, time.dt);
            }
        }
    }

    /// Fast bodies go back to their first time of impact (see `pipeline/ccd.rs`).
    fn sweep_fast(&mut self) {
        let (bodies, ids) = (&self.bodies.list, self.bodies.handles.ids());
        let hooks = &mut self.hooks;
        let mut allow = |i: usize, j: usize| hooks.ccd_allows(bodies, ids, i, j);
        crate::pipeline::ccd::sweep_fast_bodies(
            bodies,
            (&mut self.scratch.bodies, &mut self.scratch.fast),
            (
                &self.collision.broad_phase,
                &self.joints.joined_pairs,
                &mut allow,
            ),
            (
                self.settings.tolerances.scales.linear_slop,
                self.settings.tolerances.contact_margin,
            ),
        );
    }

    /// Writes the step's results into the bodies and their broad-phase proxies.
    fn scatter(&mut self) {
        let ctx = &mut self.scratch;
        let c = &mut self.collision;
        let (sims, states, proxies) = (&ctx.bodies.sims, &ctx.bodies.states, &c.proxies);
        let n = self.bodies.list.len();
        ctx.body_updates.resize(n, None);
        // In pieces on the step's team: one after another it was 0.17 ms of the rain's
        // step on two threads (a box and five writes a body).
        let size = n.div_ceil(ctx.par.pieces(n, crate::dynamics::solver::BODIES_A_PIECE));
        let pair = (&mut self.bodies.list[..], &mut ctx.body_updates[..]);
        crate::team::chunks2(ctx.par.threads, pair, size, &|start, bodies, updates| {
            for (j, (body, update)) in bodies.iter_mut().zip(updates).enumerate() {
                let (sim, state) = (&sims[start + j], &states[start + j]);
                *update = (body.kind != BodyKind::Static && body.awake).then(|| {
                    let moved = sim.x - body.com;
                    let pose = Pose::new(sim.x - sim.q * body.local_center, sim.q);
                    (proxies[start + j], body.shape.aabb(&pose), moved)
                });
                body.com = sim.x;
                body.orientation = sim.q;
                body.velocity = state.v;
                body.angular_momentum = sim.l;
                body.angular_velocity = state.w;
            }
        });
        // Handed to the broad phase together: it may rebuild its tree rather than move
        // most of its leaves one by one.
        ctx.proxy_updates.clear();
        ctx.proxy_updates.extend(ctx.body_updates.iter().flatten());
        c.broad_phase.update_many(&ctx.proxy_updates);
    }

    /// Sleep timers run; islands at rest long enough fall asleep (see `dynamics/island.rs`).
    fn update_sleep(&mut self, time: &StepTime) {
        if self.settings.sleep {
            crate::dynamics::island::update_sleep(
                &mut self.bodies.list,
                self.collision.contacts.contacts(),
                &self.joints.links,
                time.dt,
                self.settings.tolerances.sleep_speed,
                &mut self.sleep_tag,
            );
        }
    }
}

/// The forces on the bodies as the integrators and the solver see them.
fn system<'a>(
    settings: &crate::pipeline::world::Settings,
    forces: &'a mut crate::pipeline::world::ForceStore,
    (bodies, ids): (&'a [crate::dynamics::body::Body], &'a [BodyId]),
    find: &'a dyn Fn(BodyId) -> Option<usize>,
) -> System<'a> {
    System {
        gravity: settings.gravity,
        forces: &forces.list,
        bodies,
        ids,
        lookup: find,
        callbacks: &mut forces.callbacks,
        failure: &mut forces.failure,
    }
}
