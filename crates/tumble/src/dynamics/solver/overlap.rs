//! Overlap recovery: bodies created inside each other are pushed apart by moving them,
//! not by giving them velocity.
//!
//! The soft step corrects depth with a velocity bias capped at `max_push` (3 m/s, as in
//! Box2D v3) per contact, and its relax pass is meant to take that velocity back. It
//! cannot in a stack: one Gauss–Seidel pass carries a correction one body up a column, so
//! the bias velocities of ten boxes created half inside each other summed to 21 m/s that
//! the relax pass left in place, and the column flew 24 m up (5 boxes: 11 m/s, 7 m).
//!
//! Which depth is an overlap. Only a pair found deeper than its motion explains when its
//! contact is new was created overlapping (a body placed inside another, by the scene or
//! by a setter); the manifold keeps that verdict (`Overlap`) until no point of it is
//! deep. Depth met by motion stays the solver's, as it always was: an impact (crates
//! landing at 5 m/s on the rope bridge's planks meet them 4 to 9 cm deep, inside the
//! 2 cm speculative margin of pairs that do not bounce) and a load's sag. Judging every
//! point every step instead, by what its approach and load explain, took the rest of a
//! landing's depth on the step after it for an overlap and dropped crates off the
//! bridge, and took a swaying tower's shifting loads for overlaps and doubled its sway.
//!
//! How it is pushed out. The solver sees a deep point no deeper than it is allowed to be
//! (`Solver::prepare` clamps its separation), which its soft contact holds as it holds
//! any resting point, and the rest is taken out here, after the substeps, as a
//! displacement: Gauss–Seidel passes over the deep points on the linearised separation
//! s + n·(d_b − d_a) of the bodies' displacements d, each pair's total push clamped to
//! [0, max_push · dt] of relative travel, the substeps' included, so a pair is pushed
//! apart at most at `max_push` and the bodies keep the velocities the solver gave them. This is the
//! position pass of Box2D v2.4 (and Bullet's split impulse) for the points that need it;
//! a scene with no such pair never enters it. The other points of the pushed bodies are
//! guards: the pass may not push a body further into a neighbour. The pushes move, never
//! turn: with the rows' angular terms, the order of a manifold's four points left each
//! box a little turned, and a column of ten 1 m cubes stood with its top 0.5 m aside
//! (1.7 cm moving only).
//!
//! A column needs its pushes to add up: the k-th box must rise by the depths of all the
//! contacts below it. Local passes cannot do that (with both sides of each point moving,
//! four passes left a column of ten 0.1 m boxes, created half inside each other, with
//! its lower pairs pushed deeper by the ones below them, and it collapsed). So the pass
//! propagates shocks, as Guendelman et al. (2003) do for stacks: each body's level is its
//! distance in contacts from a body the solver does not move, points are taken lowest
//! level first, and a point moves only its higher-level side (both sides on one level,
//! or apart from any fixed body). One pass then carries a correction up the column.

use super::contact::{ContactConstraint, Points};
use super::rows::Point;
use super::{BodySim, BodyState};
use super::{SolverSettings, StepTime};
use crate::math::{Real, Vec3};

/// Passes over the deep points per step: with `SHARE` each takes half the remaining
/// error, so a lone point is within 6 % of its target after them.
const PASSES: usize = 4;

/// The fraction of a point's remaining depth one pass corrects: all of it overshoots
/// where several points of a manifold push one body.
const SHARE: Real = 0.5;

/// A point of a recovering pair deeper than it may be, or a guard.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Deep {
    /// Its manifold's index among the step's constraints, and its own in [`Points`].
    pub constraint: u32,
    pub point: u32,
    /// Its separation at the step's start, as found (negative), before the solver's clamp.
    pub separation: Real,
    /// The depth it is pushed out to, and the solver sees (m; see [`Deep::find`]).
    pub depth: Real,
    /// Its separation after the substeps, the push accumulated (kg m), and the lower
    /// of its bodies' levels.
    now: Real,
    pushed: Real,
    level: u32,
    /// A point that was not deep, of a body that is pushed: kept from getting deeper.
    pub guard: bool,
}

impl Deep {
    /// Point `point` of constraint `constraint`, `separation` apart and approaching at
    /// `-start_velocity` when the step began, as a deep point if it is deeper than
    /// `allow` lets it be (see [`Allowance`]).
    pub fn find(
        (constraint, point): (usize, usize),
        (separation, start_velocity): (Real, Real),
        p: &Point,
        allow: &Allowance,
    ) -> Option<Deep> {
        let depth = allow.depth(p, start_velocity);
        (separation < -depth).then_some(Deep {
            constraint: constraint as u32,
            point: point as u32,
            separation,
            depth,
            now: separation,
            pushed: 0.0,
            level: 0,
            guard: false,
        })
    }
}

/// The depth a point may start a step at and still be left to the solver: the slop, what
/// its load explains and what its approach explains. Only the rest was created.
///
/// A load is not an overlap: the soft contact, a spring of the point's effective mass m
/// times ω² h per unit of a substep's impulse, sinks d = λ / (m ω² h) under last step's
/// impulse λ per substep. A 100 kg box on a 1 kg one rests 7 mm deep, and held at the
/// slop by this pass while the solver saw no more depth, it rocked at 3.3 cm/s (0.4 mm/s
/// before). A new overlap has no impulse yet.
///
/// Nor is an impact: a point closing at v when the step began travelled about v·dt into
/// its depth during the last step, and a new contact met that way is not an overlap.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Allowance {
    slop: Real,
    /// ω² h of the contacts' soft spring (1/s): the stiffness per unit effective mass,
    /// times the substep that turns a force into an impulse.
    spring: Real,
    dt: Real,
}

impl Allowance {
    pub fn new(settings: &SolverSettings, time: &StepTime, slop: Real) -> Allowance {
        let hertz = settings.contact_hertz.min(0.25 * time.inv_h);
        let omega = 2.0 * std::f64::consts::PI as Real * hertz;
        Allowance {
            slop,
            spring: omega * omega * time.h,
            dt: time.dt,
        }
    }

    fn depth(&self, p: &Point, start_velocity: Real) -> Real {
        let k = p.normal.mass * self.spring;
        let load = if k > 0.0 { p.normal_impulse / k } else { 0.0 };
        let travel = -start_velocity * self.dt;
        self.slop + load.max(0.0) + travel.max(0.0)
    }
}

/// Buffers of the pass, reused from step to step.
#[derive(Debug, Default)]
pub(crate) struct Scratch {
    /// Each body's displacement.
    shift: Vec<Vec3>,
    /// Which bodies have deep points, and which points are deep.
    pushed: Vec<bool>,
    deep: Vec<bool>,
    /// Each body's level (see the module header), and the contact graph's adjacency.
    level: Vec<u32>,
    start: Vec<u32>,
    next: Vec<u32>,
    queue: Vec<u32>,
    /// Each manifold's push so far (kg m), the sum over its points, and the relative
    /// travel left to it (m): see [`push_point`].
    manifold: Vec<Real>,
    left: Vec<Real>,
}

/// Pushes the deep points' bodies apart to their depth, each pair by at most `reach` (m)
/// of relative travel in the step, substeps included (see [`push_point`]), moving the
/// poses in `sims` (and `states`' Δp, ΔR) only.
pub(crate) fn push_apart(
    constraints: &[ContactConstraint],
    points: &Points,
    deep: &mut Vec<Deep>,
    (sims, states): (&mut [BodySim], &mut [BodyState]),
    reach: Real,
    scratch: &mut Scratch,
) {
    if deep.is_empty() {
        return;
    }
    add_guards(constraints, points, deep, sims.len(), scratch);
    levels(constraints, sims, scratch);
    let level = &scratch.level;
    let left = &mut scratch.left;
    left.clear();
    left.resize(constraints.len(), reach);
    for d in deep.iter_mut() {
        let c = &constraints[d.constraint as usize];
        let (a, b) = c.bodies();
        let p = &points.hot[d.point as usize];
        d.now = p.separation_from(d.separation, c.frame.normal, &states[a], &states[b]);
        d.level = level[a].min(level[b]);
        let (k, travel) = (d.constraint as usize, (d.now - d.separation).max(0.0));
        left[k] = left[k].min((reach - travel).max(0.0));
        if d.guard {
            d.depth = (-d.now).max(0.0);
        }
    }
    deep.sort_by_key(|d| (d.level, d.constraint, d.point));
    let shift = &mut scratch.shift;
    shift.clear();
    shift.resize(sims.len(), Vec3::ZERO);
    let manifold = &mut scratch.manifold;
    manifold.clear();
    manifold.resize(constraints.len(), 0.0);
    for _ in 0..PASSES {
        for d in deep.iter_mut() {
            push_point(constraints, d, left, (level, shift, manifold));
        }
    }
    stop_approach(constraints, points, deep, states);
    for (k, &dx) in shift.iter().enumerate() {
        if dx != Vec3::ZERO {
            sims[k].x += dx;
            states[k].dp = sims[k].x - sims[k].x0;
        }
    }
}

/// Takes out the approach at the deep points by inelastic impulses on both sides. The
/// solver sees them no deeper than the slop, so where a load needs more depth than that
/// of its soft contact (a 100 kg box on a 1 kg one sinks 7 mm) it gives less support than
/// the weight, and the bodies approached a little every step while the pass above put
/// them back (3.3 cm/s at 1:100); nor may they close while still this deep. Only
/// approach is removed: no body is pushed apart in velocity.
fn stop_approach(
    constraints: &[ContactConstraint],
    points: &Points,
    deep: &[Deep],
    states: &mut [BodyState],
) {
    for _ in 0..PASSES {
        for d in deep.iter().filter(|d| !d.guard) {
            let c = &constraints[d.constraint as usize];
            let p = &points.hot[d.point as usize];
            let (a, b) = c.bodies();
            let Some((sa, sb)) = super::contact::pair(states, a, b) else {
                continue;
            };
            let vn = p.normal.velocity_at(c.frame.normal, p, sa, sb);
            if vn < 0.0 {
                let push = (c.frame.push_a[0], c.frame.push_b[0]);
                p.normal
                    .apply_at(-vn * p.normal.mass, push, c.moves, sa, sb);
            }
        }
    }
}

/// Adds to `deep` the other points of the bodies it pushes, as guards: their depth now
/// (or touching, for points still apart) is their target, so the pass may not push a
/// body further into a neighbour. Without them, of five 1 m cubes created half inside
/// each other, the bottom one, pushed up, went into the third (which it had just touched), whose
/// contact the solver then resolved in velocity: the column's top left at 1.1 m/s.
fn add_guards(
    constraints: &[ContactConstraint],
    points: &Points,
    deep: &mut Vec<Deep>,
    bodies: usize,
    s: &mut Scratch,
) {
    s.pushed.clear();
    s.pushed.resize(bodies, false);
    s.deep.clear();
    s.deep.resize(points.hot.len(), false);
    for d in deep.iter() {
        let (a, b) = constraints[d.constraint as usize].bodies();
        (s.pushed[a], s.pushed[b]) = (true, true);
        s.deep[d.point as usize] = true;
    }
    for (k, c) in constraints.iter().enumerate() {
        let (a, b) = c.bodies();
        if !(s.pushed[a] || s.pushed[b]) {
            continue;
        }
        for j in c.range() {
            if s.deep[j] {
                continue;
            }
            let separation = points.hot[j].separation;
            deep.push(Deep {
                constraint: k as u32,
                point: j as u32,
                separation,
                depth: 0.0,
                now: separation,
                pushed: 0.0,
                level: 0,
                guard: true,
            });
        }
    }
}

/// Each body's level: 0 for bodies the solver does not move, else one more than its
/// lowest neighbour's through the step's contacts (a breadth-first search); `u32::MAX`
/// for bodies no chain of contacts joins to a fixed one.
fn levels(constraints: &[ContactConstraint], sims: &[BodySim], s: &mut Scratch) {
    let n = sims.len();
    s.start.clear();
    s.start.resize(n + 1, 0);
    for c in constraints {
        let (a, b) = c.bodies();
        s.start[a + 1] += 1;
        s.start[b + 1] += 1;
    }
    for k in 0..n {
        s.start[k + 1] += s.start[k];
    }
    s.next.clear();
    s.next.resize(s.start[n] as usize, 0);
    let mut fill: Vec<u32> = s.start[..n].to_vec();
    for c in constraints {
        let (a, b) = c.bodies();
        s.next[fill[a] as usize] = b as u32;
        fill[a] += 1;
        s.next[fill[b] as usize] = a as u32;
        fill[b] += 1;
    }
    s.level.clear();
    s.level
        .extend(sims.iter().map(|m| if m.moves { u32::MAX } else { 0 }));
    s.queue.clear();
    s.queue
        .extend((0..n as u32).filter(|&k| !sims[k as usize].moves));
    let mut head = 0;
    while head < s.queue.len() {
        let k = s.queue[head] as usize;
        head += 1;
        for e in s.start[k]..s.start[k + 1] {
            let j = s.next[e as usize] as usize;
            if s.level[j] == u32::MAX {
                s.level[j] = s.level[k] + 1;
                s.queue.push(j as u32);
            }
        }
    }
}

/// One pass's correction at deep point `d`, into the bodies' `shift`: only the side of
/// the higher `level` moves, or both on one level; along the normal, without turning.
///
/// `left[c]` is what manifold c may still travel apart: the step's reach less the most
/// any of its points parted in the substeps (the mean let a turning pair part faster
/// than the cap, and leaned columns twice as far). It bounds the pair's relative travel,
/// not each point's push: the pushes of a manifold's points all move its bodies along its one
/// normal, so they add up (capping each point alone let two cubes created half inside
/// each other part at 4.3 times the cap, their four points each pushing the full reach),
/// and the solver's own parting (its soft contact holds the point at `depth`, correcting
/// any more) comes out of the same budget (without, they parted at 1.3 times the cap).
fn push_point(
    constraints: &[ContactConstraint],
    d: &mut Deep,
    left: &[Real],
    (level, shift, manifold): (&[u32], &mut [Vec3], &mut [Real]),
) {
    let c = &constraints[d.constraint as usize];
    let (a, b) = c.bodies();
    let moves = (
        c.moves.0 && level[a] >= level[b],
        c.moves.1 && level[b] >= level[a],
    );
    let n = c.frame.normal;
    // M⁻¹n of each side (zero where the solver does not move it): n·M⁻¹n is its share.
    let push = (c.frame.push_a[0], c.frame.push_b[0]);
    let k = if moves.0 { n.dot(push.0) } else { 0.0 } + if moves.1 { n.dot(push.1) } else { 0.0 };
    if k <= 0.0 {
        return;
    }
    let s = d.now + n.dot(shift[b] - shift[a]);
    let others = manifold[d.constraint as usize] - d.pushed;
    let most = (left[d.constraint as usize] / k - others).max(0.0);
    let total = (d.pushed + SHARE * (-d.depth - s) / k).clamp(0.0, most);
    let delta = total - d.pushed;
    if delta == 0.0 {
        return;
    }
    d.pushed = total;
    manifold[d.constraint as usize] = others + total;
    if moves.0 {
        shift[a] -= push.0 * delta;
    }
    if moves.1 {
        shift[b] += push.1 * delta;
    }
}
