//! Continuous collision detection: bodies that move farther in a step than their own
//! thickness (or that are flagged `bullet`) are swept from their start to their end pose;
//! if the sweep hits something first, the body is put back to just before that moment,
//! keeping its velocity, and next step's speculative contact stops it.
//!
//! Fast bodies are swept against static geometry; bullets against every body that is not
//! itself fast this step (two fast bodies would need each other's sweeps, as in Box2D).

use crate::collision::broad_phase::BroadPhase;
use crate::collision::geometry::Pose;
use crate::collision::query::{time_of_impact, Sweep};
use crate::collision::shape::Convex;
use crate::collision::shape::Shape;
use crate::dynamics::body::{Body, BodyKind};
use crate::dynamics::solver::{BodySim, SolverBodies};
use crate::math::{quat_from_rotation_vector, Quat, Real, Vec3};

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

/// Whether body `i` moved farther this step than its own thickness (or is a bullet).
fn is_fast(b: &Body, s: &BodySim) -> bool {
    b.kind == BodyKind::Dynamic && b.awake && (b.bullet || (s.x - s.x0).length() > b.ccd_extent)
}

/// Stage of the step: moves fast bodies back to their first time of impact over the
/// step. Reads the bodies' shapes and poses at the step's start (`bodies`, the broad
/// phase, each solver body's `x0`, `q0`) and their poses now; writes the pose and ω of
/// the bodies it moves back.
pub(crate) fn sweep_fast_bodies(
    bodies: &[Body],
    solver_bodies: &mut SolverBodies,
    broad: &BroadPhase,
    slop: Real,
) {
    let sims = &solver_bodies.sims;
    let fast: Vec<bool> = bodies
        .iter()
        .zip(sims)
        .map(|(b, s)| is_fast(b, s))
        .collect();
    for i in 0..bodies.len() {
        if !fast[i] {
            continue;
        }
        let (body, s) = (&bodies[i], solver_bodies.sims[i]);
        let sweep = sweep_of(body, &s);
        let first = first_impact(bodies, i, &sweep, &s, &fast, broad, slop);
        if first < 1.0 {
            let sim = &mut solver_bodies.sims[i];
            sim.x = s.x0 + (s.x - s.x0) * first;
            sim.q = (quat_from_rotation_vector(sweep.rotation * first) * s.q0).normalize();
            solver_bodies.states[i].w = body.omega_from_momentum(sim.q, s.l);
        }
    }
}

/// The earliest impact parameter in [0, 1) of body `i`'s sweep against the bodies it may
/// not pass (static ones; for a bullet, every body that is not fast itself), or 1.
fn first_impact(
    bodies: &[Body],
    i: usize,
    sweep: &Sweep,
    s: &BodySim,
    fast: &[bool],
    broad: &BroadPhase,
    slop: Real,
) -> Real {
    let body = &bodies[i];
    let end_pose = Pose::new(s.x - s.q * body.local_center, s.q);
    let swept = body
        .shape
        .aabb(&sweep.start)
        .union(&body.shape.aabb(&end_pose));
    let mut first: Real = 1.0;
    broad.query_aabb(&swept, |user| {
        let j = user as usize;
        let Some(other) = bodies.get(j) else { return };
        let eligible = j != i
            && !fast[j]
            && body.filter.allows(&other.filter)
            && (other.kind == BodyKind::Static || (body.bullet && other.kind != BodyKind::Static));
        if eligible {
            let still = Sweep {
                start: other.pose(),
                translation: Vec3::ZERO,
                rotation: Vec3::ZERO,
                local_center: Vec3::ZERO,
            };
            let t = shape_toi(&body.shape, sweep, &other.shape, &still, slop, first);
            // Touching from the start (t = 0) is the contact solver's business: stopping
            // the body there instead froze a forearm lying on the floor in place while
            // its joint pulled it up at 12 m/s, until the joint tore and the ragdoll
            // exploded.
            if t > 0.0 {
                first = first.min(t);
            }
        }
    });
    first
}

/// Earliest impact parameter of a moving shape against a resting one, or `limit`.
/// Convex shapes and compounds may both move; a mesh, height field or plane must be `b`
/// and at rest.
pub(crate) fn shape_toi(
    a: &Shape,
    sa: &Sweep,
    b: &Shape,
    sb: &Sweep,
    slop: Real,
    limit: Real,
) -> Real {
    match (a, b) {
        (Shape::Compound(children), _) => children
            .iter()
            .map(|c| {
                shape_toi(
                    &c.shape,
                    &child_sweep(sa, c.position, c.orientation),
                    b,
                    sb,
                    slop,
                    limit,
                )
            })
            .fold(limit, Real::min),
        (_, Shape::Compound(children)) => children
            .iter()
            .map(|c| {
                shape_toi(
                    a,
                    sa,
                    &c.shape,
                    &child_sweep(sb, c.position, c.orientation),
                    slop,
                    limit,
                )
            })
            .fold(limit, Real::min),
        (_, Shape::Plane { .. } | Shape::TriMesh(_) | Shape::HeightField(_)) => {
            match Convex::from_shape(a) {
                Some(ca) => static_toi(&ca, a, sa, b, sb, slop, limit),
                None => limit,
            }
        }
        _ => match (Convex::from_shape(a), Convex::from_shape(b)) {
            (Some(ca), Some(cb)) => toi(&ca, sa, &cb, sb, slop).min(limit),
            _ => limit,
        },
    }
}

/// The sweep of a compound's child at `position`, `orientation` in the compound's frame.
fn child_sweep(s: &Sweep, position: Vec3, orientation: Quat) -> Sweep {
    let child = s.start.mul(&Pose::new(position, orientation));
    Sweep {
        start: child,
        local_center: Pose::new(position, orientation).inverse_transform_point(s.local_center),
        ..*s
    }
}

/// Earliest impact of the convex `ca` (of shape `a`) against a resting plane, mesh or height
/// field `b`, or `limit`; a mesh or field is searched only over the triangles the sweep's
/// region overlaps.
fn static_toi(
    ca: &Convex,
    a: &Shape,
    sa: &Sweep,
    b: &Shape,
    sb: &Sweep,
    slop: Real,
    limit: Real,
) -> Real {
    match b {
        Shape::Plane { normal, offset } => plane_toi(
            ca,
            sa,
            sb.start.transform_vector(*normal),
            sb.start.position,
            *offset,
            slop,
        )
        .min(limit),
        Shape::TriMesh(mesh) => {
            let mut t = limit;
            let region = local_region(a, sa, &sb.start);
            mesh.for_each_triangle_in(&region, |k| {
                t = t.min(toi(ca, sa, &Convex::Triangle(mesh.triangle(k)), sb, slop));
            });
            t
        }
        Shape::HeightField(field) => {
            let mut t = limit;
            let region = local_region(a, sa, &sb.start);
            field.for_each_triangle_in(&region, |_, tri| {
                t = t.min(toi(ca, sa, &Convex::Triangle(tri), sb, slop));
            });
            t
        }
        _ => limit,
    }
}

fn toi(a: &Convex, sa: &Sweep, b: &Convex, sb: &Sweep, slop: Real) -> Real {
    time_of_impact(a, sa, b, sb, slop).map_or(1.0, |hit| hit.t)
}

/// The swept region of shape `a`, in the frame of the body at `at`.
fn local_region(a: &Shape, sa: &Sweep, at: &Pose) -> crate::collision::geometry::Aabb {
    let end = Pose::new(sa.start.position + sa.translation, sa.start.rotation);
    let world = a
        .aabb(&sa.start)
        .union(&a.aabb(&end))
        .expanded(a.bounding_radius());
    world.mapped(|c| at.inverse_transform_point(c))
}

/// Conservative advancement against a half-space n·(x − origin) ≤ offset: the gap of the
/// deepest point shrinks at most by |n·Δx| + |Δθ|·r per unit of t, so stepping t by
/// gap / that bound never passes the surface.
fn plane_toi(a: &Convex, sweep: &Sweep, n: Vec3, origin: Vec3, offset: Real, slop: Real) -> Real {
    let reach = (0..6)
        .map(|k| {
            let mut d = Vec3::ZERO;
            d[k / 2] = if k % 2 == 0 { 1.0 } else { -1.0 };
            (a.support(d) - sweep.local_center).length()
        })
        .fold(0.0, Real::max);
    let bound = n.dot(sweep.translation).abs() + sweep.rotation.length() * reach;
    let mut t: Real = 0.0;
    for _ in 0..32 {
        let pose = pose_at(sweep, t);
        let deepest = pose.transform_point(a.support(pose.inverse_transform_vector(-n)));
        let gap = n.dot(deepest - origin) - offset;
        if gap <= slop {
            return t;
        }
        if bound <= 0.0 {
            return 1.0;
        }
        t += (gap - 0.5 * slop) / bound;
        if t >= 1.0 {
            return 1.0;
        }
    }
    t
}

/// The sweep's pose at parameter t: rotation about the centre, then translation.
fn pose_at(sweep: &Sweep, t: Real) -> Pose {
    let q = (quat_from_rotation_vector(sweep.rotation * t) * sweep.start.rotation).normalize();
    let center = sweep.start.transform_point(sweep.local_center) + sweep.translation * t;
    Pose::new(center - q * sweep.local_center, q)
}
