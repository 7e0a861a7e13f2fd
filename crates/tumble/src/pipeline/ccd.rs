//! Continuous collision detection: after the solver, bodies whose points moved farther in
//! the step than their own thickness (or that are flagged `bullet`) are swept from their
//! start to their end pose, and put back to the first moment the sweep goes where it may
//! not (`collision/query/sweep.rs` does the sweeping).
//!
//! Where that is depends on the pair's signed distance d₀ at the step's start, because two
//! different things go wrong:
//!
//! * **Apart** (d₀ above half the contact margin): the solver had no contact between them,
//!   so nothing stopped the body. It is put back to where the gap is down to the slop,
//!   keeping its velocity, and next step's speculative contact, which then exists, stops
//!   it (as in Box2D).
//! * **Within reach** (d₀ at most half the margin, so every feature this close had a
//!   speculative point): the solver is trusted to stop the body, but only so far. It works
//!   on points found at the step's start, with the rotation of each point's anchor
//!   standing in for the shape's motion, and both fail for a fast body. A cube met at
//!   500 m/s on one corner turns about it and drives its other corners, which had no
//!   points, through a 10 cm wall within a substep. A 1 cm ball that friction spins up to
//!   rolling turns 1.6 rad per substep; its rotated anchor says the gap opened by most of
//!   its radius and the relax pass lets it sink that far, so that a ball placed at the
//!   slop by the sweep ended the next step with its centre inside the wall, and was pushed
//!   out of its far side. Such sweeps, which start touching, were ignored (stopping them at
//!   t = 0 froze a ragdoll's forearm lying on a stair while its elbow pulled it up at
//!   12 m/s), so all of this went through: of the 3,840 shots of
//!   `tests/engine/continuous_collision.rs`, 820 ended with the centre behind the wall's face.
//!   Now the sweep stops where the body would get deeper than `depth` (the slop, or a
//!   quarter of the body's thickness if that is less), or, already deeper, deeper than it
//!   is plus a tenth of that, and never past a floor at three eighths of its thickness, so
//!   its centre stays in front of the surface. A body lying, sliding or pulled away from a
//!   surface never gets deeper and is not touched: the forearm moves off as before.
//!
//! Stopped within reach, the body is where the solver failed, and would fail again next
//! step, so it is not merely put back. It goes on from the impact with the rest of its
//! translation less the part into the surface, as far as a second sweep allows (its turn
//! stops at the impact): put back and no farther, a ball that the solver sinks a little
//! every step was held in place while its velocity said 18 m/s. And the approach at the
//! point of impact is taken out by an inelastic impulse along the normal (on both bodies
//! when a bullet hits a moving one): without it a 1 m octahedron grazing a mesh at 500 m/s
//! was held to 0.19 m in three steps where its velocity said 5.8 m.
//!
//! Fast bodies are swept against static geometry. Bullets come after them and are also
//! swept against every body that is not a bullet, along that body's motion over the step
//! as it now stands (a falling box is fast itself once it moves more than half its
//! thickness a step, 0.3 m/s for a 1 cm plate at 60 Hz, and bullets used to skip fast
//! bodies and pass through it); two bullets do not see each other, as in Box2D, which
//! would need each other's sweeps. A bullet stopped by a moving body is carried with it
//! to the step's end, keeping the pose it had relative to it at the impact, so the
//! two meet where the target ends up (put back along its own path only, a bullet that hit a
//! box falling towards it would be inside the box by the box's remaining travel).

use crate::collision::broad_phase::BroadPhase;
use crate::collision::geometry::{Aabb, Pose};
use crate::collision::query::{sweep_shapes, Allowance, Impact, Stop, Sweep};
use crate::collision::shape::Shape;
use crate::dynamics::body::{Body, BodyKind};
use crate::dynamics::solver::{BodySim, BodyState, SolverBodies};
use crate::math::{quat_from_rotation_vector, Real, Vec3};

/// The allowance of fast body `body` in a world of contact slop `slop` and contact margin
/// `margin` (m); see the module header.
fn allowance(body: &Body, slop: Real, margin: Real) -> Allowance {
    // `ccd_extent` is half the body's thinnest extent.
    let depth = slop.min(body.quarter_thickness());
    Allowance {
        gap: slop,
        near: 0.5 * margin,
        depth,
        creep: 0.1 * depth,
        floor: 0.75 * body.ccd_extent,
    }
}

/// A body's motion over the step, from its pose at the step's start (`x0`, `q0`) to its
/// pose now, as a sweep of its frame.
fn sweep_of(body: &Body, s: &BodySim) -> Sweep {
    let origin = s.x0 - s.q0 * body.local_center;
    Sweep {
        start: Pose::new(origin, s.q0),
        translation: s.x - s.x0,
        rotation: (s.q * s.q0.inverse()).to_scaled_axis(),
        local_center: body.local_center,
    }
}

/// The contact hooks' word on whether body i may be stopped at body j (dense indices).
pub(crate) type Allow<'a> = &'a mut dyn FnMut(usize, usize) -> bool;

/// Whether body `i` moved a point farther this step than its own thickness (or is a
/// bullet). A point at r from the centre moves by at most |Δx| + 2 |r| sin(φ/2) for a turn
/// φ, and sin(φ/2) is the length of the turn's quaternion's vector part: a plank 1 cm thick
/// turning about its middle passes its end through a wall while its centre hardly moves.
fn is_fast(b: &Body, s: &BodySim) -> bool {
    if b.kind != BodyKind::Dynamic || !b.awake || b.sensor {
        return false;
    }
    let moved = (s.x - s.x0).length_squared();
    if b.bullet || moved > b.ccd_extent * b.ccd_extent {
        return true;
    }
    let turn = s.q * s.q0.inverse();
    let room = b.ccd_extent - moved.sqrt();
    turn_arc(b, s.q0, Vec3::new(turn.x, turn.y, turn.z)) > room
}

/// How far a turn whose quaternion has vector part `v` (sin(φ/2) times its axis) can move
/// the region the body's shape fills, the shape at orientation `q0`: 2 |r| sin(φ/2) for
/// the farthest point r from the centre of mass, less what the shape's symmetry leaves in
/// place. A ball about its centre fills the same region however it turns, and a capsule
/// or a cylinder turning about its axis too: only the axis's own motion counts,
/// 2 |v × a| times the reach along it. Counted like any other body, a capsule rolling at
/// 8 m/s (1.3 rad a step) was swept every step, and the sweeps' nudges on a mesh's edges
/// gave it a normal velocity of 1.1 mm/s.
fn turn_arc(b: &Body, q0: crate::math::Quat, v: Vec3) -> Real {
    let off_centre = 2.0 * v.length() * b.local_center.length();
    let along_axis = |reach: Real| 2.0 * v.cross(q0 * Vec3::Y).length() * reach + off_centre;
    match b.shape {
        Shape::Sphere { .. } => off_centre,
        Shape::Capsule { half_height, .. } => along_axis(half_height),
        Shape::Cylinder {
            radius,
            half_height,
        } => along_axis(radius.hypot(half_height)),
        _ => 2.0 * b.ccd_reach * v.length(),
    }
}

/// Stage of the step: moves fast bodies back to their first time of impact over the
/// step. Reads the bodies' shapes and poses at the step's start (`bodies`, the broad
/// phase, each solver body's `x0`, `q0`) and their poses now; writes the pose, velocity
/// and angular momentum of the bodies it stops (and of moving bodies bullets hit). `slop`
/// and `margin` are the contact slop and margin (m); `joined` the sorted dense pairs a
/// joint keeps from colliding, which the sweeps pass through as the contacts do (a door
/// turning on its hinge was stopped by the frame it is hinged to). `fast` is scratch for
/// the fast bodies' mask. `allow` is the contact hooks' word on a dense pair (see
/// `pipeline/hooks.rs`): a pair the contact filter refuses, or whose manifolds a hook
/// emptied this step (a one-way body passed through), is passed through here too.
pub(crate) fn sweep_fast_bodies(
    bodies: &[Body],
    (solver_bodies, fast): (&mut SolverBodies, &mut Vec<bool>),
    (broad, joined, allow): (&BroadPhase, &[(u32, u32)], Allow<'_>),
    (slop, margin): (Real, Real),
) {
    fast.clear();
    // Nothing a sweep could meet: no static body, and no bullet (only a bullet meets
    // moving bodies). A jointed world without ground skips the sweeps' setup.
    if broad.has_no_static() && !bodies.iter().any(|b| b.bullet) {
        return;
    }
    let sims = &solver_bodies.sims;
    fast.extend(bodies.iter().zip(sims).map(|(b, s)| is_fast(b, s)));
    if !fast.contains(&true) {
        return;
    }
    let sweeps = Sweeps {
        bodies,
        broad,
        joined,
    };
    // Bullets last, so that they meet the other fast bodies where those end up.
    let order = |bullets: bool| (0..bodies.len()).filter(move |&i| bodies[i].bullet == bullets);
    for i in order(false).chain(order(true)).filter(|&i| fast[i]) {
        let body = &bodies[i];
        let sweep = sweep_of(body, &solver_bodies.sims[i]);
        let stop = Stop::Allowance(allowance(body, slop, margin));
        let first = sweeps.first_impact(&solver_bodies.sims, (i, &mut *allow), &sweep, stop);
        let Some((hit, with)) = first else {
            continue;
        };
        let contact = match with {
            None if hit.near => {
                let sims = &mut solver_bodies.sims;
                sweeps.slide(sims, (i, &mut *allow), &sweep, &hit, stop)
            }
            _ => {
                let carry = with.map(|j| sweep_of(&bodies[j], &solver_bodies.sims[j]));
                place(
                    body,
                    &mut solver_bodies.sims[i],
                    &sweep,
                    &hit,
                    carry.as_ref(),
                )
            }
        };
        let sim = &solver_bodies.sims[i];
        solver_bodies.states[i].w = body.omega_from_momentum(sim.q, sim.l);
        if hit.near {
            let other = with.filter(|&j| bodies[j].kind == BodyKind::Dynamic && bodies[j].awake);
            stop_approach(bodies, solver_bodies, (i, other), contact);
        }
    }
}

/// What every sweep of a step reads.
struct Sweeps<'a> {
    bodies: &'a [Body],
    broad: &'a BroadPhase,
    joined: &'a [(u32, u32)],
}

/// Puts a body back to its impact, at `hit.toi.t` of its sweep or, stopped by a body
/// moving along `carry`, to where it stood relative to that body then, at that body's end
/// pose. Returns the impact's point on the body and normal (into the other) as placed.
fn place(
    body: &Body,
    sim: &mut BodySim,
    sweep: &Sweep,
    hit: &Impact,
    carry: Option<&Sweep>,
) -> (Vec3, Vec3) {
    let t = hit.toi.t;
    let (point, normal) = (hit.toi.point_a, hit.toi.normal);
    match carry {
        None => {
            sim.x = sim.x0 + (sim.x - sim.x0) * t;
            sim.q = (quat_from_rotation_vector(sweep.rotation * t) * sim.q0).normalize();
            (point, normal)
        }
        Some(other) => {
            let (then, after) = (other.at(t), other.at(1.0));
            let pose = after.mul(&then.inverse().mul(&sweep.at(t)));
            sim.x = pose.transform_point(body.local_center);
            sim.q = pose.rotation.normalize();
            let moved = |p: Vec3| after.transform_point(then.inverse_transform_point(p));
            let turned = after.transform_vector(then.inverse_transform_vector(normal));
            (moved(point), turned)
        }
    }
}

impl Sweeps<'_> {
    /// Body `i` stopped within reach of a static body, where the solver let it get too
    /// deep: it goes on from the impact with the rest of its step's translation, less the
    /// part into the surface, as far as a second sweep lets it (the turn stops at the
    /// impact). Put back to the impact and no farther, a ball the solver sinks a little
    /// every step (see the module header) was held in place while its velocity said
    /// 18 m/s. Returns the impact's point on the body and normal.
    fn slide(
        &self,
        sims: &mut [BodySim],
        (i, allow): (usize, Allow<'_>),
        sweep: &Sweep,
        hit: &Impact,
        stop: Stop,
    ) -> (Vec3, Vec3) {
        let (t, normal) = (hit.toi.t, hit.toi.normal);
        let rest = sweep.translation * (1.0 - t);
        let into = rest.dot(normal);
        let glide = if into > 0.0 {
            rest - normal * into
        } else {
            rest
        };
        let from = sweep.at(t);
        let along = Sweep {
            start: from,
            translation: glide,
            rotation: Vec3::ZERO,
            local_center: sweep.local_center,
        };
        // No floor for the glide: a body the solver keeps sinking reaches the floor within
        // a few steps, and it must still get along the surface from there.
        let stop = match stop {
            Stop::Allowance(a) => Stop::Allowance(Allowance {
                floor: Real::INFINITY,
                ..a
            }),
            at => at,
        };
        let reached = self
            .first_impact(sims, (i, allow), &along, stop)
            .map_or(1.0, |(second, _)| second.toi.t);
        let sim = &mut sims[i];
        sim.x = from.transform_point(sweep.local_center) + glide * reached;
        sim.q = from.rotation;
        (hit.toi.point_a + glide * reached, normal)
    }

    /// The earliest stop of body `i`'s sweep against the bodies it may not pass (static
    /// ones; for a bullet, every body that is not a bullet) and the body, when it moves.
    fn first_impact(
        &self,
        sims: &[BodySim],
        (i, allow): (usize, Allow<'_>),
        sweep: &Sweep,
        stop: Stop,
    ) -> Option<(Impact, Option<usize>)> {
        let body = &self.bodies[i];
        let mut first: Option<(Impact, Option<usize>)> = None;
        let visit = |user: u32| {
            let j = user as usize;
            let Some(other) = self.bodies.get(j) else {
                return;
            };
            let pair = (i.min(j) as u32, i.max(j) as u32);
            let eligible = j != i
                && !other.sensor
                && body.filter.allows(&other.filter)
                && (other.kind == BodyKind::Static || (body.bullet && !other.bullet))
                && self.joined.binary_search(&pair).is_err();
            if !eligible {
                return;
            }
            let moving = other.kind != BodyKind::Static;
            let path = if moving {
                sweep_of(other, &sims[j])
            } else {
                Sweep {
                    start: other.pose(),
                    translation: Vec3::ZERO,
                    rotation: Vec3::ZERO,
                    local_center: Vec3::ZERO,
                }
            };
            let closing = sweep.translation - path.translation;
            if !(meets(other, closing) && meets(body, -closing) && allow(i, j)) {
                return;
            }
            let limit = first.map_or(1.0, |(f, _)| f.toi.t);
            if let Some(hit) = sweep_shapes(&body.shape, sweep, &other.shape, &path, stop, limit) {
                first = Some((hit, moving.then_some(j)));
            }
        };
        // Only a bullet is stopped by moving bodies: any other needs the static tree alone
        // (walking the moving one for nothing was half the sweep of a swinging pole).
        let region = swept_region(body, sweep);
        if body.bullet {
            self.broad.query_aabb(&region, visit);
        } else {
            self.broad.query_static_aabb(&region, visit);
        }
        first
    }
}

/// Whether a body moving by `closing` relative to one-way body `p` comes at it from the
/// side of its normal (against the normal), and so may be stopped by it: a body moving
/// up through a platform, or along it, passes (see `pipeline/hooks.rs`). Any body that
/// is not one-way stops everything.
fn meets(p: &Body, closing: Vec3) -> bool {
    p.one_way
        .is_none_or(|n| closing.dot(p.orientation * n) < 0.0)
}

/// The region body `b` sweeps through: its boxes at both ends, widened by how far a point
/// strays from the straight line between its end positions while the body turns by φ
/// about its centre: |e^{iφt} − 1 − t (e^{iφ} − 1)| ≤ φ²/8 in each of the turn's plane's
/// two coordinates (the bound on linear interpolation's error, the second derivative
/// being φ²), and never more than 2 (two chords of the unit circle).
fn swept_region(b: &Body, sweep: &Sweep) -> Aabb {
    let end = sweep.at(1.0);
    let boxes = b.shape.aabb(&sweep.start).union(&b.shape.aabb(&end));
    let phi = sweep.rotation.length();
    if phi == 0.0 {
        return boxes;
    }
    let stray = (Real::sqrt(2.0) * phi * phi / 8.0).min(2.0);
    boxes.expanded(b.ccd_reach * stray)
}

/// Takes out the approach of body `i` (and of dynamic body `j`, when it was hit) at the
/// contact `(point, normal)`, normal from `i` into the other, by an inelastic impulse
/// along the normal: no friction, no bounce; the solver deals with both next step.
fn stop_approach(
    bodies: &[Body],
    sb: &mut SolverBodies,
    (i, j): (usize, Option<usize>),
    (point, normal): (Vec3, Vec3),
) {
    let (ri, rj) = (
        point - sb.sims[i].x,
        j.map_or(Vec3::ZERO, |j| point - sb.sims[j].x),
    );
    let velocity = |k: usize, r: Vec3| sb.states[k].v + sb.states[k].w.cross(r);
    let approach = (velocity(i, ri) - j.map_or(Vec3::ZERO, |j| velocity(j, rj))).dot(normal);
    if approach.is_nan() || approach <= 0.0 {
        return;
    }
    let give = |k: usize, r: Vec3| {
        let (b, sim) = (&bodies[k], &sb.sims[k]);
        let arm = r.cross(normal);
        b.inv_mass * (sim.linear_mask * normal).dot(normal)
            + arm.dot(b.omega_from_momentum(sim.q, arm))
    };
    let lambda = approach / (give(i, ri) + j.map_or(0.0, |j| give(j, rj)));
    if !lambda.is_finite() {
        return;
    }
    push(
        &bodies[i],
        &mut sb.sims[i],
        &mut sb.states[i],
        ri,
        -lambda * normal,
    );
    if let Some(j) = j {
        push(
            &bodies[j],
            &mut sb.sims[j],
            &mut sb.states[j],
            rj,
            lambda * normal,
        );
    }
}

/// Applies `impulse` at `r` from body `b`'s centre to its step state.
fn push(b: &Body, sim: &mut BodySim, state: &mut BodyState, r: Vec3, impulse: Vec3) {
    state.v += b.inv_mass * (sim.linear_mask * impulse);
    let turn = r.cross(impulse);
    sim.l += if b.planar {
        Vec3::new(0.0, 0.0, turn.z)
    } else {
        turn
    };
    state.w = b.omega_from_momentum(sim.q, sim.l);
}
