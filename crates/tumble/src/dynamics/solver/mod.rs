//! The constraint solver: contacts and joints as impulses inside substeps.
//!
//! One step of `dt` with n substeps of h = dt/n, for the bodies that touch something:
//!
//! ```text
//! prepare constraints (anchors, effective masses, last step's impulses)
//! repeat n times:
//!     kick      v += h F/m, L += h N            forces at the substep's state
//!     warm start: apply the accumulated impulses
//!     solve     (iterations passes, with position bias: soft spring or Baumgarte)
//!     drift     x += h v, q by the rotor splitting with L (exact torque-free turning)
//!     relax     (soft step only: passes without bias, removing the push-out velocity)
//!     tall stacks: k finer substeps of their own (kick, warm start, solve, drift, relax)
//! bounces (restitution.rs), then store impulses for the next step's warm start
//! ```
//!
//! This is Box2D v3's soft step (Catto 2024) carried to 3D, with angular momentum as the
//! integrated rotational state so that constrained bodies tumble as correctly as free ones.
//!
//! With `joint_trees` = `Reduced`, the step's contact-free joint trees are taken out first
//! and advanced in their joints' own coordinates after each substep's kick
//! (`articulation.rs`); a step with nothing else to solve skips the rest.

mod angular;
mod articulation;
mod body;
mod contact;
mod contact_wide;
mod joint;
mod joint_colours;
mod lanes;
mod mass_ratio;
mod overlap;
mod restitution;
mod rows;
mod settings;
mod softness;
mod spatial;
mod stacks;
mod wide;

use settings::{bias_rule, joint_passes};
pub use settings::{JointTrees, SolverKind, SolverSettings};
pub(crate) use settings::{Scales, StepTime};
use softness::LoadSpring;
pub use softness::Softness;

pub(crate) use body::BODIES_A_PIECE;
pub(crate) use body::{BodySim, BodyState, SharedStates, SolverBodies};
use contact::{BiasRule, ContactConstraint, PairData, Point, PointCold, Points};
use joint::{
    find_chains, Block as JointBlock, Chain, ChainBlock, ChainLists, Frame as JointFrame,
    JointConstraint, JointPass, SharedBlocks,
};
use joint_colours::JointRun;

use crate::collision::contact::{Contact, ContactMaterial};
use crate::collision::narrow_phase::{Overlap, MAX_MANIFOLD_POINTS};
use crate::dynamics::body::Motion;
use crate::dynamics::body::{Body, BodyKind};
use crate::dynamics::force::Wrench;
use crate::dynamics::integrate::{exact_spin, rotor_drift, System};
use crate::dynamics::joint::Joint;
use crate::math::{Mat3, Real, Vec3};
use crate::team::Parts;
use crate::threads::Par;
use std::ops::Range;

/// What the solver needs of a step.
pub(crate) struct StepInput<'a, 'b> {
    pub system: &'a mut System<'b>,
    pub settings: &'a SolverSettings,
    pub scales: &'a Scales,
    /// Contacts to leave out this step (speculative ones the bodies will not reach).
    pub ghosts: &'a [bool],
    /// Per contact, the material the contact modifier left; empty without one (each pair
    /// then has its bodies' own).
    pub materials: &'a [ContactMaterial],
    /// The world's joints, and the dense indices of each one's bodies (`None`: the world
    /// or a broken joint's absent partner).
    pub joints: &'a mut [Joint],
    pub joint_bodies: &'a [[Option<usize>; 2]],
    /// The step's time, length and substep.
    pub time: &'a StepTime,
    /// How the passes may split their work (see `threads.rs`).
    pub par: Par,
}

/// Buffers reused from step to step.
#[derive(Default)]
pub(crate) struct Solver {
    /// The joint trees solved in reduced coordinates this step (see `articulation.rs`).
    trees: articulation::Articulations,
    /// The states at the step's start, for the bounce replay.
    start_states: Vec<BodyState>,
    moving: Vec<bool>,
    constraints: Vec<ContactConstraint>,
    points: Points,
    joints: Vec<JointConstraint>,
    /// Each joint's frame at the current poses (see `joint::Frame`), made again after
    /// every drift.
    joint_frames: Vec<JointFrame>,
    /// The hard blocks of the joints that have one (`JointConstraint::block` says
    /// where), each made at its first use at the current frames: emptied after each
    /// drift.
    joint_blocks: Vec<JointBlock>,
    /// Chains of joints through light bodies, solved as one block each (see
    /// `joint_chain.rs`), and their blocks at the current frames (emptied with
    /// `joint_blocks`).
    chains: Vec<Chain>,
    chain_blocks: Vec<Option<ChainBlock>>,
    /// Whether a joint has an armature (see `joint_armature.rs`).
    armatures: bool,
    /// The joint list's colours and serial rests (see `joint_colours.rs`), and scratch.
    joint_runs: Vec<JointRun>,
    joint_used: Vec<u64>,
    /// Per body, whether its island has a large mass ratio (see `mass_ratio`); empty when
    /// none has. Such islands' contacts and joints sit at the end of their lists, from
    /// `heavy_contacts` and `heavy_joints`, and get `heavy_passes` times the passes.
    heavy: Vec<bool>,
    heavy_contacts: usize,
    heavy_joints: usize,
    heavy_passes: u32,
    /// Per body, whether its heavy island holds a hub (see `mass_ratio`); empty when none
    /// does. There joints that lock rotation keep their spring (see `passes`).
    hub: Vec<bool>,
    /// Scratch of the searches for heavy islands and chains, kept from step to step: a
    /// cart-pole's step made six allocations there (7 % of its instructions).
    joined: Vec<mass_ratio::Joined>,
    hub_load: Vec<[Real; 4]>,
    chain_lists: ChainLists,
    /// Per body, whether its island is a tall stack (see `stacks`); empty when none is.
    /// Such islands' contacts sit last, from `tall_contacts`, and run `fine` substeps
    /// for each of the world's (`fine` is 1 when there is none).
    tall: Vec<bool>,
    tall_contacts: usize,
    fine: u32,
    /// Bodies whose kick is split around the drift (see `split_kicks`).
    split_kick: Vec<bool>,
    wrench: Vec<Wrench>,
    motions: Vec<Motion>,
    /// The step's points of overlapping pairs deeper than allowed, with their guards
    /// (see `overlap`), and scratch.
    deep: Vec<overlap::Deep>,
    overlap: overlap::Scratch,
    /// What planning the lane groups needs of each constraint (scratch of `prepare`).
    planned: Vec<contact_wide::Planned>,
    /// Per contact, its constraint's index (`u32::MAX`: not solved), for `store_contacts`.
    of_contact: Vec<u32>,
    /// How this step's passes may split their work.
    par: Par,
}

impl Solver {
    /// Stage of the step: advances the bodies the solver moves (`moves` in `bodies`, at
    /// their start-of-step states) through the substeps, in place. Reads the contacts,
    /// joints, forces and settings of `input`; writes the moved bodies' states, every
    /// solved contact's impulses and every solved joint's reaction.
    pub fn step(
        &mut self,
        mut input: StepInput<'_, '_>,
        bodies: &mut SolverBodies,
        contacts: &mut [Contact],
    ) {
        let (world_bodies, time) = (input.system.bodies, input.time);
        self.par = input.par;
        let rule = bias_rule(input.settings, input.scales, time);
        self.take_trees(&input, bodies, contacts);
        if !self.trees.is_empty() && !bodies.sims.iter().any(|s| s.moves) {
            // Every body the step solves is in a tree: nothing for the soft step.
            return self.step_trees(&mut input, bodies);
        }
        self.find_islands(&input, bodies, contacts);
        let fine_rule = self.fine_rule(input.settings, input.scales, time);
        let gravity = input.system.gravity;
        self.prepare(
            (bodies, world_bodies),
            (contacts, input.materials),
            input.ghosts,
            (
                input.scales.linear_slop,
                gravity,
                overlap::Allowance::new(input.settings, time, input.scales.linear_slop),
                LoadSpring::new(&rule.softness, time.h, gravity.length()),
            ),
            input.settings.iterations,
        );
        self.prepare_joints(bodies, world_bodies, input.joints, input.joint_bodies);
        // The bounce replay starts from the step's start states; only a contact with
        // restitution can bounce (2 % of the joint grid's step went to this copy).
        self.start_states.clear();
        if self.constraints.iter().any(|c| c.restitution > 0.0) {
            self.start_states.extend_from_slice(&bodies.states);
        }
        let passes = joint_passes(input.settings, time);
        let any_split = self.split_kicks(bodies);
        let rules = (&rule, &fine_rule, &passes);
        for i in 0..time.substeps {
            self.substep(bodies, &mut input, rules, i, any_split);
        }
        for j in &self.joints {
            j.store(&mut input.joints[j.joint], time.dt);
        }
        self.moving.clear();
        self.moving.extend(bodies.sims.iter().map(|s| s.moves));
        // The bounce and overlap passes read the grouped points whole, as scalar points.
        if !self.start_states.is_empty() || !self.deep.is_empty() {
            self.points.save_lanes(&self.constraints, self.par);
        }
        restitution::resolve_bounces(
            &self.constraints,
            &mut self.points,
            &mut bodies.states,
            &self.start_states,
            &self.moving,
            restitution::bounce_threshold(
                input.system.gravity,
                time.h,
                input.scales.restitution_threshold,
            ),
        );
        overlap::push_apart(
            &self.constraints,
            &self.points,
            &mut self.deep,
            (&mut bodies.sims, &mut bodies.states),
            input.scales.max_push * time.dt,
            &mut self.overlap,
        );
        self.store_contacts(contacts);
        self.final_omegas(bodies, world_bodies);
        self.finish_trees(&mut input, bodies);
    }

    /// ω from the final L, each body alone: on the team (3 % of the rain's step).
    fn final_omegas(&self, bodies: &mut SolverBodies, world_bodies: &[Body]) {
        let work = |start: usize, sims: &mut [BodySim], states: &mut [BodyState]| {
            for (j, (sim, state)) in sims.iter_mut().zip(states).enumerate() {
                if sim.moves {
                    sim.sync_momentum(state);
                    state.w = world_bodies[start + j].omega_from_momentum(sim.q, sim.l);
                }
            }
        };
        self.per_body(bodies, &work);
    }

    /// With reduced joint trees chosen, takes the step's trees out of the soft step and
    /// onto their joints (see `articulation.rs`).
    fn take_trees(
        &mut self,
        input: &StepInput<'_, '_>,
        bodies: &mut SolverBodies,
        contacts: &[Contact],
    ) {
        if input.settings.joint_trees != JointTrees::Reduced {
            self.trees = articulation::Articulations::default();
            return;
        }
        self.trees.find(&articulation::TreeInput {
            bodies: input.system.bodies,
            sims: &bodies.sims,
            states: &bodies.states,
            joints: input.joints,
            links: input.joint_bodies,
            contacts,
            ghosts: input.ghosts,
        });
        if !self.trees.is_empty() {
            let world_bodies = input.system.bodies;
            self.trees
                .begin(world_bodies, &mut bodies.sims, &mut bodies.states);
        }
    }

    /// Hands the trees' bodies back and writes their joints' reactions.
    fn finish_trees(&mut self, input: &mut StepInput<'_, '_>, bodies: &mut SolverBodies) {
        let time = input.time;
        if !self.trees.is_empty() {
            (self.trees).finish(&mut bodies.sims, input.joints, time.substeps);
        }
    }

    /// The step of a world whose solved bodies are all in joint trees: each substep's
    /// forces, then the trees' substep.
    fn step_trees(&mut self, input: &mut StepInput<'_, '_>, bodies: &mut SolverBodies) {
        let time = input.time;
        for i in 0..time.substeps {
            self.evaluate_forces(bodies, input.system, time.t + i as Real * time.h);
            let forces = (input.system.bodies, &self.wrench[..]);
            let (sims, states) = (&mut bodies.sims, &mut bodies.states);
            self.trees.substep(forces, sims, states, time.h);
        }
        self.joints.clear();
        self.finish_trees(input, bodies);
    }

    /// Writes back each solved contact's impulses, the rate it was solved at, and whether
    /// it is still being pushed out of an overlap. Walked in the contacts' order, in
    /// pieces on the step's team: in colour order it jumped through the kilobyte-sized
    /// contacts, all on one thread (0.19 ms of the rain's step on two).
    fn store_contacts(&mut self, contacts: &mut [Contact]) {
        let of_contact = &mut self.of_contact;
        of_contact.clear();
        of_contact.resize(contacts.len(), u32::MAX);
        for (k, c) in self.constraints.iter().enumerate() {
            of_contact[c.contact] = k as u32;
        }
        let (of_contact, constraints, points) = (&self.of_contact, &self.constraints, &self.points);
        let (tall_contacts, fine) = (self.tall_contacts, self.fine as u8);
        let n = contacts.len();
        let size = n.div_ceil(self.par.pieces(n, STORES_A_PIECE));
        crate::team::chunks(self.par.threads, contacts, size, &|start, part| {
            for (contact, &k) in part.iter_mut().zip(&of_contact[start..]) {
                let Some(c) = constraints.get(k as usize) else {
                    continue;
                };
                let m = &mut contact.manifold;
                m.fine = if k as usize >= tall_contacts { fine } else { 1 };
                m.overlap = Overlap::Clear;
                c.store_impulses(k as usize, points, contact);
            }
        });
        for d in self.deep.iter().filter(|d| !d.guard) {
            let c = &self.constraints[d.constraint as usize];
            contacts[c.contact].manifold.overlap = Overlap::Recovering;
        }
    }

    /// Substep `i`: kick, warm start, solve, drift, relax (see the module header).
    fn substep(
        &mut self,
        bodies: &mut SolverBodies,
        input: &mut StepInput<'_, '_>,
        (rule, fine_rule, (solve_pass, relax_pass)): (
            &BiasRule,
            &BiasRule,
            &(JointPass, JointPass),
        ),
        i: u32,
        any_split: bool,
    ) {
        let (h, world_bodies) = (input.time.h, input.system.bodies);
        let t = input.time.t + i as Real * h;
        self.for_armatures(&mut bodies.states, JointConstraint::begin_armature);
        // After a split kick's second half the forces are those of this substep's start.
        self.kick(bodies, input.system, t, h, (i == 0 || !any_split, false));
        if !self.trees.is_empty() {
            let forces = (world_bodies, &self.wrench[..]);
            self.trees
                .substep(forces, &mut bodies.sims, &mut bodies.states, h);
        }
        if self.fine > 1 {
            self.fine_substeps(bodies, input, fine_rule);
        }
        self.warm_start_joints(&mut bodies.states);
        contact_wide::warm_start(
            &self.constraints,
            0..self.tall_contacts,
            &self.points,
            &mut bodies.states,
            self.par,
        );
        let iterations = input.settings.iterations;
        let relax = input.settings.kind == SolverKind::SoftStep && iterations > 0;
        self.passes(bodies, iterations, (rule, solve_pass), true, !relax);
        self.drift(bodies, world_bodies, h, false);
        self.make_joint_frames(&bodies.sims);
        if any_split {
            self.kick(bodies, input.system, t + h, h, (true, true));
        }
        if relax {
            self.passes(bodies, iterations, (rule, relax_pass), false, true);
        }
        if iterations == 0 {
            ContactConstraint::add_to_totals(&self.points.hot, &mut self.points.cold);
        }
        self.for_armatures(&mut bodies.states, JointConstraint::end_armature);
        self.add_joint_totals();
    }

    /// `f` on every joint with its frame when a joint has an armature (see
    /// `joint_armature.rs`): its flywheel started before the kick
    /// (`JointConstraint::begin_armature`), its lag kept at the substep's end
    /// (`end_armature`).
    fn for_armatures(
        &mut self,
        states: &mut [BodyState],
        f: impl Fn(&mut JointConstraint, &JointFrame, &mut [BodyState]),
    ) {
        if !self.armatures {
            return;
        }
        for (j, fr) in self.joints.iter_mut().zip(&self.joint_frames) {
            f(j, fr, states);
        }
    }

    /// Adds each joint's substep impulses to its totals, in pieces on the step's team.
    fn add_joint_totals(&mut self) {
        let (n, frames) = (self.joints.len(), &self.joint_frames);
        let size = n.div_ceil(self.par.pieces(n, FRAMES_A_PIECE));
        let blocks = Parts::new(&mut self.joint_blocks);
        // SAFETY: each block slot belongs to one joint, and each joint to one piece.
        let blocks = unsafe { SharedBlocks::new(&blocks) };
        crate::team::chunks(self.par.threads, &mut self.joints, size, &|start, part| {
            let mut blocks = blocks;
            for (j, fr) in part.iter_mut().zip(&frames[start..]) {
                j.add_to_totals(fr, &mut blocks);
            }
        });
    }

    /// `iterations` passes over the joints then the contacts, with `bias` or without
    /// (relax); islands with a large mass ratio get 4 to 16 times as many. The substep's impulses
    /// are final once the last pass has visited a manifold, so with `totals` that pass adds
    /// them to the step's totals on its way instead of a separate walk over every point.
    fn passes(
        &mut self,
        bodies: &mut SolverBodies,
        iterations: u32,
        rules: (&BiasRule, &JointPass),
        bias: bool,
        totals: bool,
    ) {
        let (rule, joint_pass) = rules;
        let stiffened = BiasRule {
            stiffened: true,
            ..*rule
        };
        let stiff_joints = JointPass {
            soft: joint_pass.soft.stiffened(softness::STIFFEST),
            ..*joint_pass
        };
        // Joints that lock rotation keep their spring in an island with a hub: stiffened,
        // a chassis carrying eight hinged motors (see `mass_ratio`) rang up from rounding
        // within a second even with four times the passes, and held unstiffened.
        let parts = [
            (
                0..self.heavy_contacts,
                0..self.heavy_joints,
                iterations,
                (rule, joint_pass, joint_pass),
            ),
            (
                self.heavy_contacts..self.tall_contacts,
                self.heavy_joints..self.joints.len(),
                self.heavy_passes * iterations,
                (&stiffened, &stiff_joints, joint_pass),
            ),
        ];
        for (contacts, joints, count, (rule, joint_pass, locked_pass)) in parts {
            for k in 0..count {
                self.solve_joints(
                    &mut bodies.states,
                    joints.clone(),
                    (joint_pass, locked_pass),
                );
                let last = totals && k + 1 == count;
                self.solve_pass(bodies, contacts.clone(), rule, bias, last);
            }
        }
    }

    /// Warm starts the joints, colour by colour (see `joint_colours.rs`).
    fn warm_start_joints(&mut self, states: &mut [BodyState]) {
        for run in &self.joint_runs {
            let r = run.range.clone();
            let (joints, frames) = (&mut self.joints[r.clone()], &self.joint_frames[r]);
            if run.splits(self.par) {
                let each =
                    |j: &mut JointConstraint,
                     fr: &JointFrame,
                     s: &mut SharedStates<'_>,
                     b: &mut SharedBlocks<'_, '_>| { j.warm_start(fr, s, b) };
                let stripes = (&run.stripes[..], run.range.start);
                for_colour(
                    (joints, frames),
                    stripes,
                    (states, &mut self.joint_blocks),
                    self.par,
                    &each,
                );
                continue;
            }
            for (j, fr) in joints.iter_mut().zip(frames) {
                j.warm_start(fr, states, &mut self.joint_blocks[..]);
            }
        }
    }

    /// One pass over the joints of `part` (the light or the heavy islands'), colour by
    /// colour, then the part's serial rest with its chains (see `joint_colours.rs`).
    /// Joints that lock rotation get `locked_pass` in an island with a hub, the others
    /// `joint_pass`.
    fn solve_joints(
        &mut self,
        states: &mut [BodyState],
        part: Range<usize>,
        (joint_pass, locked_pass): (&JointPass, &JointPass),
    ) {
        let hub = &self.hub;
        let pass = |j: &JointConstraint| {
            if j.locks_rotation() && j.on(hub) {
                locked_pass
            } else {
                joint_pass
            }
        };
        for run in self
            .joint_runs
            .iter()
            .filter(|r| part.contains(&r.range.start))
        {
            let r = run.range.clone();
            if run.splits(self.par) {
                let each = |j: &mut JointConstraint,
                            fr: &JointFrame,
                            s: &mut SharedStates<'_>,
                            b: &mut SharedBlocks<'_, '_>| {
                    j.solve(fr, s, pass(j), b)
                };
                let joints = (&mut self.joints[r.clone()], &self.joint_frames[r]);
                let stripes = (&run.stripes[..], run.range.start);
                for_colour(
                    joints,
                    stripes,
                    (states, &mut self.joint_blocks),
                    self.par,
                    &each,
                );
                continue;
            }
            for i in r {
                if let Some(c) = self.joints[i].chain {
                    self.chains[c].solve_free(
                        i,
                        (&mut self.joints, &self.joint_frames),
                        states,
                        pass,
                        (&mut self.joint_blocks, &mut self.chain_blocks[c]),
                    );
                }
                let (j, fr) = (&mut self.joints[i], &self.joint_frames[i]);
                j.solve(fr, states, pass(j), &mut self.joint_blocks[..]);
                // A chain's block comes after its last joint's other rows.
                if let Some(c) = j.chain.filter(|&c| self.chains[c].last() == i) {
                    self.chains[c].solve(
                        (&mut self.joints, &self.joint_frames),
                        states,
                        pass,
                        (&mut self.joint_blocks, &mut self.chain_blocks[c]),
                    );
                }
            }
        }
    }

    /// Finds the islands whose contacts get passes of their own: those with a large mass
    /// ratio (`mass_ratio`) and tall stacks (`stacks`).
    fn find_islands(
        &mut self,
        input: &StepInput<'_, '_>,
        bodies: &SolverBodies,
        contacts: &[Contact],
    ) {
        let (ghosts, joint_bodies) = (input.ghosts, input.joint_bodies);
        self.find_heavy_islands(bodies, contacts, ghosts, input.joints, joint_bodies);
        let (g, slop) = (input.system.gravity.length(), input.scales.linear_slop);
        self.find_tall_islands(
            (bodies, input.system.bodies, contacts),
            (ghosts, joint_bodies),
            (input.settings, input.time, g, slop),
        );
    }

    /// Marks the bodies of tall stacks (see `stacks`) and sets how many times finer their
    /// substeps are, from the contacts the step will solve (soft step only: PGS has no
    /// spring to sag, and without passes nothing is solved).
    fn find_tall_islands(
        &mut self,
        (bodies, world_bodies, contacts): (&SolverBodies, &[Body], &[Contact]),
        (ghosts, joint_bodies): (&[bool], &[[Option<usize>; 2]]),
        (settings, time, g, slop): (&SolverSettings, &StepTime, Real, Real),
    ) {
        self.tall.clear();
        self.fine = 1;
        if settings.kind != SolverKind::SoftStep || settings.iterations == 0 {
            return;
        }
        // Pairs being pushed out of an overlap (`overlap.rs`), or new and deeper than the
        // slop (they may have been made overlapping), keep their islands at the world's
        // rate until they are out: the push-out's allowances are the world rate's.
        let busy = |c: &Contact| match c.manifold.overlap {
            Overlap::Clear => false,
            Overlap::Recovering => true,
            Overlap::New => c.manifold.points().iter().any(|p| p.separation < -slop),
        };
        // A contact supports where it touches. Plates thinner than the contact margin have
        // speculative contacts with the plates two and three away (4 mm apart for 4 mm
        // plates) and with the ground under them: counted as supports, those carried the
        // load past the plate between, and a stack of twenty such plates, predicted to
        // stand, sank 5.3 mm at the world's rate. A contact touches whose deepest point is
        // within the slop, or a quarter of its thinner moving body where that is less (the
        // depth `ccd.rs` allows such a body). The bodies are read only for a gap, and
        // most contacts of a resting stack have none.
        let touching = |c: &Contact| {
            let gap = c.manifold.min_separation();
            if gap <= 0.0 {
                return true;
            }
            let quarter = [c.index_a, c.index_b]
                .into_iter()
                .map(|k| &world_bodies[k as usize])
                .filter(|b| b.kind == BodyKind::Dynamic)
                .map(Body::quarter_thickness)
                .fold(Real::INFINITY, Real::min);
            gap <= slop.min(quarter)
        };
        let supports: Vec<stacks::Support> = contacts
            .iter()
            .enumerate()
            .filter(|&(i, c)| !idle(c, i, ghosts) && touching(c))
            .map(|(_, c)| stacks::Support {
                a: c.index_a as usize,
                b: c.index_b as usize,
                busy: busy(c),
                was_fine: c.manifold.fine > 1,
            })
            .collect();
        let fixed = |k: usize| match world_bodies[k].kind {
            BodyKind::Kinematic => stacks::Fixed::Kinematic,
            _ => stacks::Fixed::Ground,
        };
        let joined = joint_bodies.iter().flatten().flatten().copied();
        let scale = stacks::Scale {
            g,
            omega: 2.0 * crate::math::PI * settings.contact_hertz.min(0.25 * time.inv_h),
            tolerance: slop,
            rest_speed: (2.0 * g * time.dt).max((2.0 * g * slop).sqrt()),
        };
        let speed = |k: usize| bodies.states[k].v.length();
        let half_thickness = |k: usize| world_bodies[k].ccd_extent;
        let sims = (&bodies.sims[..], speed, half_thickness);
        if let Some((tall, fine)) =
            stacks::tall_islands(sims, fixed, &supports, (joined, &self.heavy), scale)
        {
            (self.tall, self.fine) = (tall, fine);
        }
    }

    /// The contacts' bias rule at the tall stacks' substep: `fine` times the substeps and
    /// the contact frequency (the quarter-rate cap moves with them).
    fn fine_rule(&self, settings: &SolverSettings, scales: &Scales, time: &StepTime) -> BiasRule {
        let fine = SolverSettings {
            substeps: time.substeps * self.fine,
            contact_hertz: settings.contact_hertz * self.fine as Real,
            ..*settings
        };
        bias_rule(&fine, scales, &StepTime::new(time.t, time.dt, &fine))
    }

    /// The tall stacks' `fine` substeps within one of the world's, on their own bodies and
    /// contacts (disjoint from the others'): each a kick with the forces of the world's
    /// substep, a warm start, the solve, the drift and the relax, at the stiffer `rule`.
    fn fine_substeps(
        &mut self,
        bodies: &mut SolverBodies,
        input: &mut StepInput<'_, '_>,
        rule: &BiasRule,
    ) {
        let h = input.time.h / self.fine as Real;
        let range = self.tall_contacts..self.constraints.len();
        let iterations = input.settings.iterations;
        for _ in 0..self.fine {
            self.kick_tall(bodies, input.system.bodies, h);
            let (cs, points) = (&self.constraints, &self.points);
            contact_wide::warm_start(cs, range.clone(), points, &mut bodies.states, self.par);
            for _ in 0..iterations {
                self.solve_pass(bodies, range.clone(), rule, true, false);
            }
            self.drift(bodies, input.system.bodies, h, true);
            for k in 0..iterations {
                self.solve_pass(bodies, range.clone(), rule, false, k + 1 == iterations);
            }
        }
    }

    /// The tall stacks' bodies' kick over `h`, with the forces of the world's substep.
    fn kick_tall(&mut self, bodies: &mut SolverBodies, world_bodies: &[Body], h: Real) {
        let (tall, wrench) = (&self.tall, &self.wrench);
        let work = |start: usize, sims: &mut [BodySim], states: &mut [BodyState]| {
            for (j, (sim, state)) in sims.iter_mut().zip(states).enumerate() {
                let k = start + j;
                if is_flagged(tall, k) {
                    kick_body((sim, state), &wrench[k], &world_bodies[k], h);
                }
            }
        };
        self.per_body(bodies, &work);
    }

    /// Marks the bodies of islands with a large mass ratio (see `mass_ratio`), over the
    /// contacts and joints the step will solve.
    fn find_heavy_islands(
        &mut self,
        bodies: &SolverBodies,
        contacts: &[Contact],
        ghosts: &[bool],
        joints: &[Joint],
        joint_bodies: &[[Option<usize>; 2]],
    ) {
        let touching = contacts
            .iter()
            .enumerate()
            .filter(|&(i, c)| !idle(c, i, ghosts))
            .map(|(_, c)| (c.index_a as usize, c.index_b as usize));
        let joined =
            joints
                .iter()
                .zip(joint_bodies)
                .filter_map(|(j, link)| match (j.acts(), *link) {
                    (true, [Some(a), Some(b)]) => Some(mass_ratio::Joined {
                        a,
                        b,
                        locks_rotation: j.def.kind.spec().locks_rotation(),
                    }),
                    _ => None,
                });
        self.joined.clear();
        self.joined.extend(joined);
        let links = touching.chain(self.joined.iter().map(|j| (j.a, j.b)));
        let heavy =
            mass_ratio::heavy_islands(&bodies.sims, links, &self.joined, &mut self.hub_load)
                .unwrap_or_default();
        (self.heavy, self.heavy_passes, self.hub) = (heavy.flags, heavy.passes, heavy.hub);
    }

    /// The step's contact constraints, in colour order, and their lane groups; `slop` (m)
    /// tells rolled friction anchors (see `contact::rolled_away`), the world's bodies
    /// their shapes' round radii. With no `iterations` nothing is grouped.
    fn prepare(
        &mut self,
        (bodies, world_bodies): (&SolverBodies, &[Body]),
        (contacts, materials): (&[Contact], &[ContactMaterial]),
        ghosts: &[bool],
        (slop, gravity, allow, spring): (Real, Vec3, overlap::Allowance, LoadSpring),
        iterations: u32,
    ) {
        self.points.clear_rows();
        self.deep.clear();
        let order = self.colour_order(&bodies.sims, contacts, ghosts);
        self.heavy_contacts = order.partition_point(|&(part, _, _)| part < Part::Heavy as u8);
        self.tall_contacts = order.partition_point(|&(part, _, _)| part < Part::Tall as u8);
        // Each constraint's first point: the constraints and their points are written in
        // place, in pieces on the step's team, so the lists take their final lengths first.
        // (None without contacts: a jointed world's step allocates nothing here.)
        let mut firsts = Vec::new();
        let mut total = 0;
        if !order.is_empty() {
            firsts.reserve_exact(order.len() + 1);
            for &(_, _, i) in &order {
                firsts.push(total);
                total += contacts[i].manifold.len();
            }
            firsts.push(total);
        }
        // Every entry is overwritten whole below, so only a list's growth is written
        // now (cleared and refilled with defaults, the lists' writes were 4 % of the
        // pyramid's step).
        set_len(&mut self.constraints, order.len());
        set_len(&mut self.points.hot, total);
        set_len(&mut self.points.cold, total);
        let angular = self.plan_lanes(&order, contacts, &bodies.sims, iterations == 0);
        let with = PrepareWith {
            bodies: (bodies, world_bodies),
            contacts: (contacts, materials),
            slop,
            gravity,
            order: &order,
            firsts: &firsts,
            fit: (self.fine, spring),
        };
        // Rolling and twist rows are listed in order in one list of their own: a step
        // with any is prepared on one thread.
        let pieces = if angular {
            1
        } else {
            self.par.pieces(order.len(), CONSTRAINTS_A_PIECE)
        };
        let Points {
            hot,
            cold,
            lanes,
            angular,
        } = &mut self.points;
        let writer = lanes.writer();
        if order.is_empty() {
            // No contact to prepare (a cart-pole): no piece, and no scratch for one (its
            // manifold buffer's clearing was 4 % of a cart-pole's step).
        } else if pieces <= 1 {
            let n = order.len();
            // SAFETY: the only part, of the whole order.
            let mut lanes = unsafe { writer.part(0..n, |k| firsts[k + 1] - firsts[k]) };
            let out = (&mut hot[..], &mut cold[..]);
            with.piece(0..n, (&mut self.constraints, &mut lanes), out, angular);
        } else {
            let out = (&mut self.constraints[..], &mut hot[..], &mut cold[..]);
            prepare_in_pieces(&with, out, &writer, (pieces, self.par.threads));
        }
        // The points that overlap too deeply, in order (each touches its own
        // constraint's points).
        for (k, &(_, _, i)) in order.iter().enumerate() {
            let c = &contacts[i];
            if c.manifold.overlap != Overlap::Clear {
                self.find_deep(c, (k, firsts[k]), &allow);
            }
        }
        self.points.lanes.fill(&self.constraints, self.par);
    }

    /// Plans the lane groups (none when `off`) before the constraints are prepared, so
    /// that the grouped points are prepared straight into their lanes; returns whether
    /// any pair has rolling or twist rows (which stay scalar).
    fn plan_lanes(
        &mut self,
        order: &[(u8, u32, usize)],
        contacts: &[Contact],
        sims: &[BodySim],
        off: bool,
    ) -> bool {
        self.planned.clear();
        self.planned.extend(order.iter().map(|&(_, colour, i)| {
            let c = &contacts[i];
            let (r, t) = angular::combine(&sims[c.index_a as usize], &sims[c.index_b as usize]);
            (colour, c.manifold.len(), r > 0.0 || t > 0.0)
        }));
        let angular = self.planned.iter().any(|p| p.2);
        let splits = [self.heavy_contacts, self.tall_contacts];
        self.points
            .lanes
            .plan(&self.planned, (splits, angular), off);
        angular
    }

    /// The points of constraint `k` (contact `c`, its points from `first`) deeper than
    /// `allow`, kept for the push apart at the end of the step.
    fn find_deep(&mut self, c: &Contact, (k, first): (usize, usize), allow: &overlap::Allowance) {
        for (j, mp) in c.manifold.points().iter().enumerate() {
            let start_velocity = self.points.cold[first + j].start_velocity;
            let at = (mp.separation, start_velocity);
            // A grouped point lives in its lane.
            let lanes = &mut self.points.lanes;
            let grouped = lanes.point(k, j);
            let p = grouped.as_ref().unwrap_or(&self.points.hot[first + j]);
            if let Some(deep) = overlap::Deep::find((k, first + j), at, p, allow) {
                match grouped {
                    Some(_) => lanes.set_separation((k, j), -deep.depth),
                    None => self.points.hot[first + j].separation = -deep.depth,
                }
                self.deep.push(deep);
            }
        }
    }

    /// Chooses each body's kick. Bodies in contact take symplectic Euler's whole kick
    /// before the solve: a resting contact must see the substep's full approach, and the
    /// contact tuning (stacks, friction anchors, sleeping) rests on it. Bodies held only by
    /// joints take half a kick before the solve and half after the drift, so joint-held
    /// motion is Störmer–Verlet with the solve and the relax pass enforcing the position and
    /// velocity constraints (RATTLE): second order, where symplectic Euler's O(h) energy
    /// wobble moved a 2 rad pendulum's energy by 1.1 %. Returns whether any body splits.
    fn split_kicks(&mut self, bodies: &SolverBodies) -> bool {
        self.split_kick.clear();
        self.split_kick.extend(bodies.sims.iter().map(|s| s.moves));
        for c in &self.constraints {
            let (a, b) = c.bodies();
            self.split_kick[a] = false;
            self.split_kick[b] = false;
        }
        self.split_kick.iter().any(|s| *s)
    }

    /// The joints that join at least one body the solver moves, in creation order.
    fn prepare_joints(
        &mut self,
        solver_bodies: &SolverBodies,
        bodies: &[Body],
        joints: &[Joint],
        links: &[[Option<usize>; 2]],
    ) {
        self.joints.clear();

        for (i, (joint, link)) in joints.iter().zip(links).enumerate() {
            if !joint.acts() {
                continue;
            }
            let center = |k: Option<usize>| k.map_or(Vec3::ZERO, |k| bodies[k].local_center);
            let c = JointConstraint::new(
                i,
                joint,
                [(link[0], center(link[0])), (link[1], center(link[1]))],
            );
            if c.active(&solver_bodies.sims) {
                self.joints.push(c);
            }
        }
        // Joints of islands with a large mass ratio go last, in creation order, for their
        // extra passes (see `passes`); the others keep their order.
        let flags = &self.heavy;
        let heavy = |c: &JointConstraint| {
            c.bodies()
                .into_iter()
                .flatten()
                .any(|k| is_flagged(flags, k))
        };
        if self.heavy.is_empty() {
            self.heavy_joints = self.joints.len();
        } else {
            let (mut light, heavy): (Vec<_>, Vec<_>) =
                self.joints.drain(..).partition(|c| !heavy(c));
            self.heavy_joints = light.len();
            light.extend(heavy);
            self.joints = light;
        }
        let mut blocks = 0;
        for j in self.joints.iter_mut().filter(|j| j.has_block()) {
            j.block = Some(blocks);
            blocks += 1;
        }
        // Kept from step to step (a block is a kilobyte): only marked out of date, and
        // carried (see `Block::refresh`), once the frames are made below.
        self.joint_blocks.truncate(blocks);
        self.joint_blocks.resize_with(blocks, JointBlock::default);
        self.chains = find_chains(&mut self.joints, &solver_bodies.sims, &mut self.chain_lists);
        self.armatures = self.joints.iter().any(|j| j.has_armature());
        let (n, heavy) = (self.joints.len(), self.heavy_joints);
        joint_colours::order(
            &mut self.joints,
            &mut self.chains,
            [0..heavy, heavy..n],
            (solver_bodies.sims.len(), &mut self.joint_used),
            &mut self.joint_runs,
        );
        self.chain_blocks.clear();
        self.chain_blocks.resize(self.chains.len(), None);
        self.make_joint_frames(&solver_bodies.sims);
        // (After: `make_joint_frames` clears `carried`, and not `ready` when the joints'
        // count changed.)
        self.joint_blocks
            .iter_mut()
            .for_each(|b| (b.ready, b.carried) = (false, true));
    }

    /// Each joint's frame at the poses in `sims`; after each drift of the bodies outside
    /// tall stacks (those of joints never are, see `stacks::tall_islands`).
    fn make_joint_frames(&mut self, sims: &[BodySim]) {
        let n = self.joints.len();
        if self.joint_frames.len() != n {
            self.joint_frames.clear();
            self.joint_frames
                .extend(self.joints.iter().map(|j| j.frame(sims)));
            return;
        }
        let joints = &self.joints;
        let size = n.div_ceil(self.par.pieces(n, FRAMES_A_PIECE));
        crate::team::chunks(
            self.par.threads,
            &mut self.joint_frames,
            size,
            &|start, part| {
                for (j, fr) in joints[start..].iter().zip(part) {
                    j.write_frame(sims, fr);
                }
            },
        );
        self.joint_blocks
            .iter_mut()
            .for_each(|b| (b.ready, b.carried) = (false, false));
        self.chain_blocks.fill(None);
    }

    /// The contacts to solve, ordered so that neighbours in the list rarely share a moving
    /// body (greedy graph colouring, colour by colour). Gauss–Seidel passes are a chain of
    /// dependent updates; constraints on disjoint bodies let the processor overlap them.
    /// Deterministic: colours depend only on the contacts' order, itself deterministic.
    /// Contacts of islands with a large mass ratio come last, for their extra passes.
    /// Colour 63 keeps the contacts' order.
    fn colour_order(
        &self,
        sims: &[BodySim],
        contacts: &[Contact],
        ghosts: &[bool],
    ) -> Vec<(u8, u32, usize)> {
        let mut used = vec![0u64; sims.len()];
        let mut coloured = Vec::with_capacity(contacts.len());
        for (i, c) in contacts.iter().enumerate() {
            let (a, b) = (c.index_a as usize, c.index_b as usize);
            if idle(c, i, ghosts) || !(sims[a].moves || sims[b].moves) {
                continue;
            }
            let mask = |k: usize| if sims[k].moves { used[k] } else { 0 };
            let colour = (!(mask(a) | mask(b))).trailing_zeros().min(63);
            for k in [a, b] {
                if sims[k].moves {
                    used[k] |= 1u64 << colour;
                }
            }
            let on = |flags: &[bool]| is_flagged(flags, a) || is_flagged(flags, b);
            let part = if on(&self.tall) {
                Part::Tall
            } else if on(&self.heavy) {
                Part::Heavy
            } else {
                Part::Light
            };
            coloured.push((part as u8, colour, i));
        }
        // Within a colour below 63 the order is free (no moving body in common, so the
        // updates commute, bit for bit): manifolds of equal size go together, so that the
        // lane groups (see `contact_wide`) carry few empty points. (Ordering a colour by
        // blocks of bodies first, so that each thread's share of every colour writes the
        // same bodies, made the rain no faster on two threads and slower on one.)
        // Sorted as packed integers, each key (part, colour, size, i) made once: compared
        // as tuples, the sort read each manifold's size again at every comparison, in an
        // order that jumps through the contacts (2 % of the pyramid's step).
        // (An index fits in 32 bits: four billion contacts would take terabytes.)
        let size = |colour: u32, i: usize| match colour {
            63 => 0,
            _ => contacts[i].manifold.len() as u64,
        };
        let mut keys: Vec<u64> = coloured
            .iter()
            .map(|&(part, colour, i)| {
                (u64::from(part) << 48)
                    | (u64::from(colour) << 40)
                    | (size(colour, i) << 32)
                    | i as u64
            })
            .collect();
        keys.sort_unstable();
        coloured.clear();
        coloured.extend(keys.iter().map(|&k| {
            let (part, colour) = ((k >> 48) as u8, ((k >> 40) & 0xff) as u32);
            (part, colour, (k & 0xffff_ffff) as usize)
        }));
        coloured
    }

    /// One pass over the constraints in `range`, in colour order; consecutive constraints
    /// of one colour are solved several at a time in lanes (see `contact_wide`).
    fn solve_pass(
        &mut self,
        bodies: &mut SolverBodies,
        range: Range<usize>,
        rule: &BiasRule,
        bias: bool,
        totals: bool,
    ) {
        let pass = contact_wide::Pass { rule, bias, totals };
        let (cs, points, states) = (&self.constraints, &mut self.points, &mut bodies.states);
        contact_wide::solve_pass(cs, range, points, states, (pass, self.par));
    }

    /// v += h F/m, L += h N, over the substep's start (`end` false) or end: bodies in
    /// contact take the whole kick first (symplectic Euler), the others half at each end.
    fn kick(
        &mut self,
        bodies: &mut SolverBodies,
        system: &mut System<'_>,
        t: Real,
        h: Real,
        (evaluate, end): (bool, bool),
    ) {
        if evaluate {
            self.evaluate_forces(bodies, system, t);
        }
        let (wrench, split_kick, tall) = (&self.wrench, &self.split_kick, &self.tall);
        let world_bodies = system.bodies;
        let work = |start: usize, sims: &mut [BodySim], states: &mut [BodyState]| {
            for (j, (sim, state)) in sims.iter_mut().zip(states).enumerate() {
                let k = start + j;
                let h = match (split_kick[k], end) {
                    (true, _) => 0.5 * h,
                    (false, false) => h,
                    (false, true) => continue,
                };
                if sim.moves && !is_flagged(tall, k) {
                    kick_body((sim, state), &wrench[k], &world_bodies[k], h);
                }
            }
        };
        self.per_body(bodies, &work);
    }

    /// `work(start, sims, states)` over the bodies in pieces of [`BODIES_A_PIECE`] on
    /// the step's team; each body's update must read no other body's state.
    fn per_body(
        &self,
        bodies: &mut SolverBodies,
        work: &crate::team::PairWork<'_, BodySim, BodyState>,
    ) {
        let n = bodies.sims.len();
        let size = n.div_ceil(self.par.pieces(n, BODIES_A_PIECE));
        let pair = (&mut bodies.sims[..], &mut bodies.states[..]);
        crate::team::chunks2(self.par.threads, pair, size, work);
    }

    /// Every force element and callback at the solver's current state and time `t`.
    fn evaluate_forces(&mut self, bodies: &SolverBodies, system: &mut System<'_>, t: Real) {
        self.motions.clear();
        self.motions
            .extend((0..bodies.sims.len()).map(|i| bodies.motion(i)));
        self.wrench.resize(self.motions.len(), Wrench::default());
        system.wrenches(t, &self.motions, &mut self.wrench);
    }

    /// x += h v and the exact torque-free rotation with L, for the tall stacks' bodies
    /// (`tall`) or the others; kinematic bodies move with the others, so contacts see them
    /// where they are.
    fn drift(&mut self, solver_bodies: &mut SolverBodies, bodies: &[Body], h: Real, tall: bool) {
        let flags = &self.tall;
        let work = |start: usize, sims: &mut [BodySim], states: &mut [BodyState]| {
            for (j, (sim, state)) in sims.iter_mut().zip(states).enumerate() {
                let k = start + j;
                if is_flagged(flags, k) == tall {
                    drift_body((sim, state), &bodies[k], h);
                }
            }
        };
        self.per_body(solver_bodies, &work);
    }
}

/// Fewest contacts worth a piece of `store_contacts` on another thread (one is some
/// 50 ns, a tenth of its preparation).
const STORES_A_PIECE: usize = 512;

/// Fewest joints worth a piece of the frames and the totals on another thread (each
/// joint's share is tens of nanoseconds).
const FRAMES_A_PIECE: usize = 512;

/// Calls `each` on every joint of one colour with its frame, a stripe (`stripes`: where
/// each starts, offset by `base`) to a piece on the step's team, in order in each; in
/// order on the calling thread when the step is serial.
fn for_colour<F>(
    (joints, frames): (&mut [JointConstraint], &[JointFrame]),
    (stripes, base): (&[usize], usize),
    (states, blocks): (&mut [BodyState], &mut [JointBlock]),
    par: Par,
    each: &F,
) where
    F: Fn(&mut JointConstraint, &JointFrame, &mut SharedStates<'_>, &mut SharedBlocks<'_, '_>)
        + Sync,
{
    let n = joints.len();
    let bounds = |i: usize| stripes[i] - base..stripes.get(i + 1).map_or(n, |&s| s - base);
    let blocks = Parts::new(blocks);
    // SAFETY: the stripes of a colour share no body, moving or not (`joint_colours::order`),
    // so each state is reached through one piece's joints alone, and each block slot
    // belongs to one joint.
    let (states, blocks) = unsafe { (SharedStates::new(states), SharedBlocks::new(&blocks)) };
    let parts = Parts::new(joints);
    crate::team::pieces(par.threads, stripes.len(), &|i| {
        let range = bounds(i);
        // SAFETY: piece i takes stripe i alone (each piece runs once).
        let joints = unsafe { parts.part(range.clone()) };
        let (mut s, mut b) = (states, blocks);
        for (j, fr) in joints.iter_mut().zip(&frames[range]) {
            each(j, fr, &mut s, &mut b);
        }
    });
}

/// Fewest constraints worth a piece of the preparation on another thread (one is some
/// half a microsecond; a hand-off to the team about one).
const CONSTRAINTS_A_PIECE: usize = 64;

/// What preparing the contacts reads: the bodies, the contacts and their materials, the
/// contact slop and gravity, the solver's order of the contacts and each one's first point.
struct PrepareWith<'a> {
    bodies: (&'a SolverBodies, &'a [Body]),
    contacts: (&'a [Contact], &'a [ContactMaterial]),
    slop: Real,
    gravity: Vec3,
    order: &'a [(u8, u32, usize)],
    firsts: &'a [usize],
    /// How many times finer the tall stacks' substeps are, and the heavy islands' spring
    /// (see [`PrepareWith::fit`]).
    fit: (u32, LoadSpring),
}

/// [`PrepareWith::piece`] over `pieces` consecutive runs of the order on the step's team,
/// each writing its own constraints and their points, scalar or in lanes (no pair of the
/// step has angular rows). The runs are cut where no lane group straddles.
fn prepare_in_pieces(
    with: &PrepareWith<'_>,
    (constraints, hot, cold): (&mut [ContactConstraint], &mut [Point], &mut [PointCold]),
    writer: &contact_wide::LaneWriter<'_>,
    (pieces, threads): (usize, usize),
) {
    let n = with.order.len();
    let size = n.div_ceil(pieces).max(1);
    let count = n.div_ceil(size);
    let bounds: Vec<usize> = (0..=count)
        .map(|i| writer.boundary((i * size).min(n)))
        .collect();
    let constraints = Parts::new(constraints);
    let (hot, cold) = (Parts::new(hot), Parts::new(cold));
    crate::team::pieces(threads, count, &|i| {
        let range = bounds[i]..bounds[i + 1];
        if range.is_empty() {
            return;
        }
        let at = with.firsts[range.start]..with.firsts[range.end];
        // SAFETY: piece i takes the constraints between its bounds alone, and the points
        // from the first's first to the last's end: `bounds` and `firsts` rise, so the
        // pieces' point ranges are disjoint too; its lanes are those of its own groups,
        // whole between bounds (each piece runs once).
        let (cs, out, mut lanes) = unsafe {
            (
                constraints.part(range.clone()),
                (hot.part(at.clone()), cold.part(at)),
                writer.part(range.clone(), |k| with.firsts[k + 1] - with.firsts[k]),
            )
        };
        with.piece(range, (cs, &mut lanes), out, &mut Vec::new());
    });
}

impl PrepareWith<'_> {
    /// Prepares the constraints `range` of the order into `cs` and their points into
    /// `out` (theirs alone, from the range's first point) or, for a grouped constraint,
    /// into its lane in `lanes`; rolling and twist rows onto `angular`.
    fn piece(
        &self,
        range: Range<usize>,
        (cs, lanes): (&mut [ContactConstraint], &mut contact_wide::LanePart<'_>),
        (hot, cold): contact::PointsOut<'_>,
        angular: &mut Vec<angular::AngularRows>,
    ) {
        let (bodies, _) = self.bodies;
        let base = self.firsts[range.start];
        // A grouped manifold's points, on their way to the lanes.
        let mut buffer = [Point::default(); MAX_MANIFOLD_POINTS];
        for (k, c_out) in range.zip(cs) {
            // The order jumps through the contacts: fetch a few ahead (waiting for the
            // manifolds was a fifth of the preparation's time on the pyramid).
            if let Some(&(_, _, ahead)) = self.order.get(k + PREFETCH_AHEAD) {
                crate::math::prefetch(&self.contacts.0[ahead].manifold);
            }
            let (part, _, i) = self.order[k];
            let c = &self.contacts.0[i];
            let at = self.firsts[k] - base..self.firsts[k + 1] - base;
            let grouped = lanes.grouped(k);
            let points = if grouped {
                &mut buffer[..at.len()]
            } else {
                &mut hot[at.clone()]
            };
            *c_out = ContactConstraint::prepare(
                i,
                c,
                &self.pair(i),
                (&bodies.sims, &bodies.states),
                (
                    self.firsts[k],
                    (&mut *points, &mut cold[at.clone()]),
                    angular,
                ),
            );
            self.fit(c_out, (part, c.manifold.fine), (&mut *points, angular));
            if grouped {
                lanes.put(k, points, &cold[at]);
            }
        }
    }

    /// Fits constraint `c` (its points as prepared, its rolling and twist rows in
    /// `angular`) to its `part`'s passes: warm starts made per substep of the length it
    /// was last solved at (`was` times finer than the world's) brought to this step's,
    /// and a heavy island's contacts stiffened for their load.
    fn fit(
        &self,
        c: &mut ContactConstraint,
        (part, was): (u8, u8),
        (points, angular): (&mut [Point], &mut [angular::AngularRows]),
    ) {
        let (fine, spring) = &self.fit;
        let fine = if part == Part::Tall as u8 { *fine } else { 1 };
        let was = u32::from(was.max(1));
        if was != fine {
            let share = was as Real / fine as Real;
            c.rescale_warm_start((&mut *points, angular), share);
        }
        if part == Part::Heavy as u8 {
            c.stiffen(spring, points);
        }
    }

    /// What contact `i`'s pair brings to its constraint.
    fn pair(&self, i: usize) -> PairData {
        let ((bodies, world_bodies), (contacts, materials)) = (self.bodies, self.contacts);
        let c = &contacts[i];
        let (a, b) = (c.index_a as usize, c.index_b as usize);
        let (sa, sb) = (&bodies.sims[a], &bodies.sims[b]);
        let (friction, restitution, surface) = match materials.get(i) {
            Some(m) => (m.friction, m.restitution, m.surface_velocity),
            None => (
                (sa.friction * sb.friction).sqrt(),
                sa.restitution.max(sb.restitution),
                Vec3::ZERO,
            ),
        };
        let pose =
            |s: &BodySim| crate::collision::geometry::Pose::new(s.x - s.q * s.local_center, s.q);
        let gravity = self.gravity;
        let falls = |s: &BodySim| {
            if s.moves {
                gravity * s.linear_mask * s.gravity_scale
            } else {
                Vec3::ZERO
            }
        };
        PairData {
            bodies: (a, b),
            material: (friction, restitution),
            surface,
            angular: angular::combine(sa, sb),
            poses: (pose(sa), pose(sb)),
            round: (
                sa.round.unwrap_or_else(|| {
                    let shape = &world_bodies[a].shape;
                    shape.round_toward(c.manifold.subshape_a, sa.q, c.manifold.normal)
                }),
                sb.round.unwrap_or_else(|| {
                    let shape = &world_bodies[b].shape;
                    shape.round_toward(c.manifold.subshape_b, sb.q, c.manifold.normal)
                }),
            ),
            slop: self.slop,
            gravity: (!(sa.moves && sb.moves) || gravity == Vec3::ZERO)
                .then(|| (falls(sa), falls(sb))),
        }
    }
}

/// How many constraints ahead `PrepareWith::piece` and `store_contacts` fetch the
/// contacts.
const PREFETCH_AHEAD: usize = 4;

/// Gives `v` length `n`, writing defaults only into entries it did not have: for lists
/// whose every entry the caller then overwrites.
fn set_len<T: Default + Clone>(v: &mut Vec<T>, n: usize) {
    v.truncate(n);
    if v.len() < n {
        // The default made only to grow the list: a constraint's is a kilobyte cleared.
        v.resize(n, T::default());
    }
}

/// x += h v and the exact torque-free rotation with L for a body the solver moves; a
/// kinematic body moves with its velocities; others stay.
fn drift_body((sim, state): (&mut BodySim, &mut BodyState), body: &Body, h: Real) {
    match (sim.moves, body.kind) {
        (true, _) => {
            // The ω the substep's rows saw: the one the drift turns with.
            state.turned += state.w * h;
            sim.sync_momentum(state);
            sim.x += state.v * h;
            sim.q = rotor_drift(body, sim.q, sim.l, state.w, h);
            sim.turn_inertia(body);
            state.w = body.omega_from_momentum(sim.q, sim.l);
            sim.w_synced = state.w;
        }
        (false, BodyKind::Kinematic) => {
            state.turned += state.w * h;
            sim.x += state.v * h;
            sim.q = exact_spin(state.w, sim.q, h);
        }
        _ => return,
    }
    state.dp = sim.x - sim.x0;
    state.dr = Mat3::from_quat(sim.q * sim.q0.inverse());
}

/// v += h F/m, L += h N for one body the solver moves. A damped body's kick is wrapped
/// in half a substep of exact damping on each side, v ← f (f v + h F/m) with
/// f = exp(−c h/2) (the same Strang splitting as the free integrators', see
/// `integrate::damp_half`): the contact and joint rows then see the damped velocity, and
/// the damping over a step is exp(−c dt) exactly however the kicks are split.
fn kick_body((sim, state): (&mut BodySim, &mut BodyState), w: &Wrench, body: &Body, h: Real) {
    sim.sync_momentum(state);
    let dv = sim.linear_mask * w.force * (sim.inv_mass * h);
    if let Some((fv, fw)) = body.damping_factors(0.5 * h) {
        state.v = (state.v * fv + dv) * fv;
        sim.l = (sim.l * fw + w.torque * h) * fw;
    } else {
        state.v += dv;
        sim.l += w.torque * h;
    }
    state.w = body.omega_from_momentum(sim.q, sim.l);
    sim.w_synced = state.w;
}

/// Whether body `k` is flagged in per-body `flags` that are empty when none is (the
/// solver's `heavy` and `tall` islands).
fn is_flagged(flags: &[bool], k: usize) -> bool {
    flags.get(k).copied().unwrap_or(false)
}

/// Which passes a contact gets: its island's (see `Solver::colour_order`).
#[derive(Clone, Copy, PartialEq, Eq)]
enum Part {
    Light,
    Heavy,
    Tall,
}

/// Whether contact `i` sits the step out: no points, or a speculative ghost.
fn idle(c: &Contact, i: usize, ghosts: &[bool]) -> bool {
    c.manifold.is_empty() || ghosts.get(i).copied().unwrap_or(false)
}
