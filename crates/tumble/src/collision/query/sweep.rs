//! Sweeps of whole shapes (compounds, meshes, height fields, planes) against each other,
//! by the convex time of impact of `toi.rs` applied to their convex parts, stopping where
//! a [`Stop`] says.
//!
//! Two callers, two kinds of stop. The ghost check of speculative contacts asks whether
//! two bodies come within a fixed distance ([`Stop::At`]). Continuous collision asks where
//! a fast body goes farther than it may ([`Stop::Allowance`]): a gap short of a shape it
//! starts clear of, or, starting within reach of it, a depth into it (see `Allowance` and
//! `pipeline/ccd.rs` for why). A triangle mesh or height field is one surface for the
//! allowance: the start distance is the least over its triangles near the sweep, so a body
//! sliding over a mesh is not stopped at every triangle it slides onto (each of which it
//! starts clear of, by the distance to its edge).

use crate::collision::geometry::{Aabb, Pose};
use crate::collision::narrow_phase::closest_points;
use crate::collision::query::toi::{advance, time_of_impact, Goal, Sweep, Toi};
use crate::collision::shape::{Convex, Shape};
use crate::math::{Quat, Real, Vec3};

/// How far a sweep may take a shape into another, by how far apart the two start.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Allowance {
    /// The gap left before a shape the sweep starts clear of (m).
    pub gap: Real,
    /// The start distance up to which a pair counts as within reach (m).
    pub near: Real,
    /// The depth a pair within reach may reach (m).
    pub depth: Real,
    /// How much deeper a pair already past `depth` may get (m).
    pub creep: Real,
    /// The depth no sweep goes past (m): a pair starting deeper stops at once.
    pub floor: Real,
}

impl Allowance {
    /// The goal of a sweep whose pair starts `d0` apart (negative: overlapping).
    fn goal(&self, d0: Real) -> Goal {
        if d0 > self.near {
            Goal {
                target: self.gap,
                tol: None,
            }
        } else {
            // A tolerance well inside the creep: converging at t = 0 needs a start deeper
            // than the target, which `min` and `creep` rule out above the floor.
            Goal {
                target: (d0.min(-self.depth) - self.creep).max(-self.floor),
                tol: Some(0.25 * self.creep),
            }
        }
    }
}

/// Where a sweep stops.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Stop {
    /// Where the shapes come within this distance (m) of each other.
    At(Real),
    /// Where they get closer (or deeper) than the allowance lets them.
    Allowance(Allowance),
}

impl Stop {
    fn goal(&self, d0: Real) -> Goal {
        match self {
            Stop::At(target) => Goal {
                target: *target,
                tol: None,
            },
            Stop::Allowance(allowance) => allowance.goal(d0),
        }
    }
}

/// A sweep's first stop: where (normal from A to B and witness points at that moment, as in
/// [`Toi`]), and whether the pair started within the allowance's reach.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Impact {
    pub toi: Toi,
    pub near: bool,
}

/// The first stop before `limit` of shape `a` moving along `sa` against `b` along `sb`, or
/// `None`. Convex shapes and compounds may both move; a mesh, height field or plane must
/// be `b` and at rest.
pub(crate) fn sweep_shapes(
    a: &Shape,
    sa: &Sweep,
    b: &Shape,
    sb: &Sweep,
    stop: Stop,
    limit: Real,
) -> Option<Impact> {
    match (a, b) {
        (Shape::Compound(children), _) => children.iter().fold(None, |first, c| {
            let sc = child_sweep(sa, c.position, c.orientation);
            earlier(
                first,
                sweep_shapes(&c.shape, &sc, b, sb, stop, bound(first, limit)),
            )
        }),
        (_, Shape::Compound(children)) => children.iter().fold(None, |first, c| {
            let sc = child_sweep(sb, c.position, c.orientation);
            earlier(
                first,
                sweep_shapes(a, sa, &c.shape, &sc, stop, bound(first, limit)),
            )
        }),
        (_, Shape::Plane { .. } | Shape::TriMesh(_) | Shape::HeightField(_)) => {
            let ca = Convex::from_shape(a)?;
            static_sweep(&ca, a, sa, b, sb, stop, limit)
        }
        _ => {
            let (ca, cb) = (Convex::from_shape(a)?, Convex::from_shape(b)?);
            convex_sweep(&ca, sa, &cb, sb, stop, None).filter(|i| i.toi.t < limit)
        }
    }
}

/// The earlier of two stops.
fn earlier(a: Option<Impact>, b: Option<Impact>) -> Option<Impact> {
    match (a, b) {
        (Some(x), Some(y)) => Some(if y.toi.t < x.toi.t { y } else { x }),
        (x, None) => x,
        (None, y) => y,
    }
}

/// The parameter a further stop must come before.
fn bound(first: Option<Impact>, limit: Real) -> Real {
    first.map_or(limit, |i| i.toi.t)
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

/// The first stop before `limit` of convex `ca` (of shape `a`) against a resting plane,
/// mesh or height field `b`; a mesh or field is searched only over the triangles the
/// sweep's region overlaps, under an allowance all with the goal of the least start
/// distance among them.
fn static_sweep(
    ca: &Convex,
    a: &Shape,
    sa: &Sweep,
    b: &Shape,
    sb: &Sweep,
    stop: Stop,
    limit: Real,
) -> Option<Impact> {
    if let Shape::Plane { normal, offset } = b {
        let n = sb.start.transform_vector(*normal);
        return plane_sweep(ca, sa, (n, sb.start.position, *offset), stop)
            .filter(|i| i.toi.t < limit);
    }
    let region = local_region(a, sa, &sb.start);
    let shared = match stop {
        Stop::At(_) => None,
        Stop::Allowance(allowance) => {
            let (start, at) = (sa.at(0.0), sb.at(0.0));
            let mut d0 = Real::INFINITY;
            for_each_triangle(b, &region, |tri| {
                d0 = d0.min(closest_points(ca, &start, &Convex::Triangle(tri), &at).distance);
            });
            Some((allowance.goal(d0), d0 <= allowance.near))
        }
    };
    let mut first = None;
    for_each_triangle(b, &region, |tri| {
        let hit = convex_sweep(ca, sa, &Convex::Triangle(tri), sb, stop, shared);
        first = earlier(first, hit.filter(|i| i.toi.t < bound(first, limit)));
    });
    first
}

/// Calls `f` with each triangle of mesh or height field `b` (its frame) that overlaps
/// `region`; nothing for other shapes.
fn for_each_triangle(b: &Shape, region: &Aabb, mut f: impl FnMut([Vec3; 3])) {
    match b {
        Shape::TriMesh(mesh) => mesh.for_each_triangle_in(region, |k| f(mesh.triangle(k))),
        Shape::HeightField(field) => field.for_each_triangle_in(region, |_, tri| f(tri)),
        _ => {}
    }
}

/// The stop of two convex shapes: a fixed one by [`time_of_impact`] (what the ghost check
/// has always used), an allowance's by the goal for the pair's start distance, or the
/// `shared` goal (and whether it is within reach) of the surface the pair belongs to.
fn convex_sweep(
    a: &Convex,
    sa: &Sweep,
    b: &Convex,
    sb: &Sweep,
    stop: Stop,
    shared: Option<(Goal, bool)>,
) -> Option<Impact> {
    match stop {
        Stop::At(target) => {
            time_of_impact(a, sa, b, sb, target).map(|toi| Impact { toi, near: false })
        }
        Stop::Allowance(allowance) => {
            let mut near = false;
            let toi = advance(a, sa, b, sb, |d0| {
                let (goal, within) =
                    shared.unwrap_or_else(|| (allowance.goal(d0), d0 <= allowance.near));
                near = within;
                goal
            })?;
            Some(Impact { toi, near })
        }
    }
}

/// The swept region of shape `a`, in the frame of the body at `at`.
fn local_region(a: &Shape, sa: &Sweep, at: &Pose) -> Aabb {
    let end = Pose::new(sa.start.position + sa.translation, sa.start.rotation);
    let world = a
        .aabb(&sa.start)
        .union(&a.aabb(&end))
        .expanded(a.bounding_radius());
    world.mapped(|c| at.inverse_transform_point(c))
}

/// Conservative advancement against a half-space n·(x − origin) ≤ offset: the gap of the
/// deepest point shrinks at most by |n·Δx| + |Δθ|·r per unit of t, so stepping t by
/// gap / that bound never passes the surface. A fixed stop at s converges below s and
/// aims at s/2; an allowance's goal converges below its target plus tolerance and aims
/// at the target.
fn plane_sweep(
    a: &Convex,
    sweep: &Sweep,
    (n, origin, offset): (Vec3, Vec3, Real),
    stop: Stop,
) -> Option<Impact> {
    let reach = (0..6)
        .map(|k| {
            let mut d = Vec3::ZERO;
            d[k / 2] = if k % 2 == 0 { 1.0 } else { -1.0 };
            (a.support(d) - sweep.local_center).length()
        })
        .fold(0.0, Real::max);
    let bound = n.dot(sweep.translation).abs() + sweep.rotation.length() * reach;
    let deepest = |t: Real| {
        let pose = sweep.at(t);
        let p = pose.transform_point(a.support(pose.inverse_transform_vector(-n)));
        (p, n.dot(p - origin) - offset)
    };
    let gap0 = deepest(0.0).1;
    let (aim, done) = match stop.goal(gap0) {
        Goal { target, tol: None } => (0.5 * target, target),
        Goal {
            target,
            tol: Some(tol),
        } => (target, target + tol),
    };
    let near = matches!(stop, Stop::Allowance(a) if gap0 <= a.near);
    let mut t: Real = 0.0;
    for _ in 0..32 {
        let (p, gap) = deepest(t);
        if gap <= done {
            let toi = Toi {
                t,
                normal: -n,
                point_a: p,
                point_b: p - n * gap,
            };
            return Some(Impact { toi, near });
        }
        if bound <= 0.0 {
            return None;
        }
        t += (gap - aim) / bound;
        if t >= 1.0 {
            return None;
        }
    }
    let (p, gap) = deepest(t);
    let toi = Toi {
        t,
        normal: -n,
        point_a: p,
        point_b: p - n * gap,
    };
    Some(Impact { toi, near })
}
