//! Ray casts and point queries against every shape.
//!
//! Everything is computed in the shape's local frame (the ray's origin and direction
//! rotated in; a rotation keeps lengths, so `t` is the same in both frames) and the
//! normal is rotated back out.
//!
//! Convex solids are handled as *spans*: the interval [t_in, t_out] of the whole line
//! inside the solid, with the outward normals at both ends. The hit then follows from
//! where the span lies relative to 0 and `max_t`, one rule for every shape:
//! - the span lies ahead (0 < t_in): the hit is the entry, t_in, if t_in ≤ max_t;
//! - the origin is inside or on the surface (t_in ≤ 0 ≤ t_out): with `solid` the ray hits
//!   at t = 0 with a zero normal (it starts in the material); without, it reports the exit
//!   t_out, normal pointing outward (along the ray);
//! - the span lies behind (t_out < 0): no hit.
//!
//! Planes, meshes and height fields are surfaces to a ray: it crosses them from either
//! side, `solid` does not apply, and the normal is always the surface's own outward (front)
//! normal — up for a height field, the winding's front for a mesh triangle, n for a plane —
//! whichever side the ray comes from.

use crate::collision::geometry::{Pose, Ray, RayHit};
use crate::collision::shape::{ConvexHull, HeightField, Shape, TriMesh};
use crate::math::{Quat, Real, Vec3};

/// The first hit of `ray` (world frame) on `shape` at `pose` with t in [0, max_t].
/// A ray that starts inside a solid shape hits at t = 0 with a zero normal when `solid`;
/// when not, it reports the boundary where it leaves (normal pointing outward). Planes,
/// meshes and height fields are hit from either side (a mesh has no inside).
///
/// Compounds report the nearest hit over their children (`subshape` = child index, the
/// lower one on exact ties); meshes and height fields the nearest triangle (`subshape` =
/// triangle index). Non-finite input or a negative `max_t` give `None`, and so does a zero
/// direction unless `solid` and the origin is inside.
pub fn cast_ray(shape: &Shape, pose: &Pose, ray: &Ray, max_t: Real, solid: bool) -> Option<RayHit> {
    if !finite(ray.origin) || !finite(ray.direction) || max_t.is_nan() || max_t < 0.0 {
        return None;
    }
    let hit = cast(shape, pose, ray, max_t, solid)?;
    // Garbage shapes (negative sizes, NaN fields built by hand) must not leak NaN.
    if hit.t.is_finite() && finite(hit.normal) {
        Some(hit)
    } else {
        None
    }
}

fn cast(shape: &Shape, pose: &Pose, ray: &Ray, max_t: Real, solid: bool) -> Option<RayHit> {
    let o = pose.inverse_transform_point(ray.origin);
    let d = pose.inverse_transform_vector(ray.direction);
    let world = |t: Real, n: Vec3, subshape: u32| {
        let n = if n == Vec3::ZERO {
            n
        } else {
            pose.transform_vector(n).normalize_or_zero()
        };
        Some(RayHit {
            t,
            normal: n,
            subshape,
        })
    };
    match shape {
        Shape::Compound(children) => {
            let mut best: Option<RayHit> = None;
            for (i, child) in children.iter().enumerate() {
                let limit = best.map_or(max_t, |b| b.t);
                let Some(child_pose) = child_pose(pose, child.position, child.orientation) else {
                    continue;
                };
                if let Some(mut h) = cast(&child.shape, &child_pose, ray, limit, solid) {
                    // Strictly nearer only: on a tie the earlier (lower) child stays.
                    if best.is_none_or(|b| h.t < b.t) {
                        h.subshape = i as u32;
                        best = Some(h);
                    }
                }
            }
            best
        }
        Shape::Plane { normal, offset } => {
            let n = normal.normalize_or_zero();
            let denom = n.dot(d);
            if n == Vec3::ZERO || denom == 0.0 {
                return None;
            }
            let t = (offset - n.dot(o)) / denom;
            if t >= 0.0 && t <= max_t {
                world(t, n, 0)
            } else {
                None
            }
        }
        Shape::TriMesh(mesh) => {
            let (t, i) = mesh.cast_ray(o, d, max_t)?;
            world(t, mesh.normal(i)?, i as u32)
        }
        Shape::HeightField(field) => {
            let (t, i) = field.cast_ray(o, d, max_t)?;
            world(t, field.normal(i)?, i as u32)
        }
        _ => {
            if d == Vec3::ZERO {
                // A point, not a ray: it can only be "inside".
                return if solid && contains_local(shape, o) {
                    world(0.0, Vec3::ZERO, 0)
                } else {
                    None
                };
            }
            let span = convex_span(shape, o, d)?;
            let (t, n) = resolve(&span, max_t, solid)?;
            world(t, n, 0)
        }
    }
}

/// The pose of a compound child, or `None` for an orientation that is no rotation.
fn child_pose(parent: &Pose, position: Vec3, orientation: Quat) -> Option<Pose> {
    let len = orientation.length();
    if !(len.is_finite() && len > 0.0 && finite(position)) {
        return None;
    }
    Some(parent.mul(&Pose::new(position, orientation / len)))
}

fn finite(v: Vec3) -> bool {
    v.x.is_finite() && v.y.is_finite() && v.z.is_finite()
}

/// The part of the line `o + t·d` inside a convex solid: entry and exit parameters with
/// the outward normals there (local frame).
#[derive(Debug, Clone, Copy)]
struct Span {
    t_in: Real,
    n_in: Vec3,
    t_out: Real,
    n_out: Vec3,
}

/// Applies the rule in the module comment to a span.
fn resolve(s: &Span, max_t: Real, solid: bool) -> Option<(Real, Vec3)> {
    if s.t_out < 0.0 {
        None
    } else if s.t_in <= 0.0 {
        if solid {
            Some((0.0, Vec3::ZERO))
        } else if s.t_out <= max_t {
            Some((s.t_out, s.n_out))
        } else {
            None
        }
    } else if s.t_in <= max_t {
        Some((s.t_in, s.n_in))
    } else {
        None
    }
}

fn convex_span(shape: &Shape, o: Vec3, d: Vec3) -> Option<Span> {
    match shape {
        Shape::Sphere { radius } => sphere_span(o, d, Vec3::ZERO, *radius),
        Shape::Box { half_extents } => box_span(o, d, *half_extents),
        Shape::Capsule {
            radius,
            half_height,
        } => capsule_span(o, d, *radius, *half_height),
        Shape::Cylinder {
            radius,
            half_height,
        } => cylinder_span(o, d, *radius, *half_height),
        Shape::ConvexHull(hull) => hull_span(o, d, hull),
        _ => None,
    }
}

/// The roots t of |o + t·d|² = r² (o relative to the centre), in a stable form: with
/// b = o·d and the line's offset from the centre p⊥ = o − (b/|d|²)·d, the discriminant is
/// |d|²(r² − |p⊥|²), which does not cancel catastrophically for far-away origins the way
/// b² − |d|²(|o|² − r²) does; the smaller-magnitude root comes from Vieta's c/q rather
/// than from a difference.
fn quadratic_roots(o: Vec3, d: Vec3, r: Real) -> Option<(Real, Real)> {
    let a = d.dot(d);
    if a.is_nan() || a <= 0.0 || r.is_nan() || r < 0.0 {
        return None;
    }
    let b = o.dot(d);
    let c = o.dot(o) - r * r;
    let perp = o - d * (b / a);
    let disc = a * (r * r - perp.dot(perp));
    if disc.is_nan() || disc < 0.0 {
        return None;
    }
    let q = -(b + disc.sqrt().copysign(b));
    if q == 0.0 {
        // b = 0 and a tangent line through the surface at the origin: one double root.
        return Some((0.0, 0.0));
    }
    let (t0, t1) = (q / a, c / q);
    Some((t0.min(t1), t0.max(t1)))
}

fn sphere_span(o: Vec3, d: Vec3, center: Vec3, r: Real) -> Option<Span> {
    let rel = o - center;
    let (t_in, t_out) = quadratic_roots(rel, d, r)?;
    let normal = |t: Real| radial(rel + d * t, Vec3::Y);
    Some(Span {
        t_in,
        n_in: normal(t_in),
        t_out,
        n_out: normal(t_out),
    })
}

/// `v` normalised, or `fallback` for a zero vector.
fn radial(v: Vec3, fallback: Vec3) -> Vec3 {
    let n = v.normalize_or_zero();
    if n == Vec3::ZERO {
        fallback
    } else {
        n
    }
}

/// Slab test: the entry is the last of the three slab entries, the exit the first exit;
/// the slab that decides each gives the normal (the first axis on ties).
fn box_span(o: Vec3, d: Vec3, h: Vec3) -> Option<Span> {
    let mut s = Span {
        t_in: Real::NEG_INFINITY,
        n_in: Vec3::ZERO,
        t_out: Real::INFINITY,
        n_out: Vec3::ZERO,
    };
    for axis in 0..3 {
        let mut e = Vec3::ZERO;
        e[axis] = 1.0;
        if d[axis] == 0.0 {
            if o[axis].abs() > h[axis] {
                return None;
            }
            continue;
        }
        let (lo, hi) = (
            (-h[axis] - o[axis]) / d[axis],
            (h[axis] - o[axis]) / d[axis],
        );
        let (ta, tb, na) = if d[axis] > 0.0 {
            (lo, hi, -e)
        } else {
            (hi, lo, e)
        };
        if ta > s.t_in {
            s.t_in = ta;
            s.n_in = na;
        }
        if tb < s.t_out {
            s.t_out = tb;
            s.n_out = -na;
        }
    }
    if s.t_in <= s.t_out {
        Some(s)
    } else {
        None
    }
}

/// Intersection of the infinite cylinder x² + z² ≤ r² with the slab |y| ≤ h.
fn cylinder_span(o: Vec3, d: Vec3, r: Real, h: Real) -> Option<Span> {
    let flat = |v: Vec3| Vec3::new(v.x, 0.0, v.z);
    let (side_in, side_out) = if flat(d) == Vec3::ZERO {
        if flat(o).length_squared() > r * r {
            return None;
        }
        (Real::NEG_INFINITY, Real::INFINITY)
    } else {
        quadratic_roots(flat(o), flat(d), r)?
    };
    let mut s = Span {
        t_in: side_in,
        n_in: radial(flat(o + d * side_in), Vec3::X),
        t_out: side_out,
        n_out: radial(flat(o + d * side_out), Vec3::X),
    };
    if d.y == 0.0 {
        if o.y.abs() > h {
            return None;
        }
    } else {
        let (lo, hi) = ((-h - o.y) / d.y, (h - o.y) / d.y);
        let (ta, tb, na) = if d.y > 0.0 {
            (lo, hi, -Vec3::Y)
        } else {
            (hi, lo, Vec3::Y)
        };
        if ta > s.t_in {
            s.t_in = ta;
            s.n_in = na;
        }
        if tb < s.t_out {
            s.t_out = tb;
            s.n_out = -na;
        }
    }
    if s.t_in <= s.t_out && s.t_in.is_finite() && s.t_out.is_finite() {
        Some(s)
    } else {
        None
    }
}

/// A capsule is the union of a finite cylinder and two balls, and it is convex, so its
/// span is the hull of theirs: the earliest entry and the latest exit. The normals follow
/// from the geometry at those points (away from the nearest point of the core segment).
fn capsule_span(o: Vec3, d: Vec3, r: Real, h: Real) -> Option<Span> {
    let parts = [
        cylinder_span(o, d, r, h),
        sphere_span(o, d, Vec3::new(0.0, -h, 0.0), r),
        sphere_span(o, d, Vec3::new(0.0, h, 0.0), r),
    ];
    let (mut t_in, mut t_out) = (Real::INFINITY, Real::NEG_INFINITY);
    for s in parts.iter().flatten() {
        t_in = t_in.min(s.t_in);
        t_out = t_out.max(s.t_out);
    }
    if t_in > t_out {
        return None; // no part was hit
    }
    let normal = |t: Real| {
        let p = o + d * t;
        radial(p - Vec3::new(0.0, p.y.clamp(-h, h), 0.0), Vec3::X)
    };
    Some(Span {
        t_in,
        n_in: normal(t_in),
        t_out,
        n_out: normal(t_out),
    })
}

/// Cyrus–Beck clipping of the line by every face plane n·x ≤ d.
fn hull_span(o: Vec3, d: Vec3, hull: &ConvexHull) -> Option<Span> {
    let mut s = Span {
        t_in: Real::NEG_INFINITY,
        n_in: Vec3::ZERO,
        t_out: Real::INFINITY,
        n_out: Vec3::ZERO,
    };
    for &(n, off) in hull.face_planes() {
        let inside = off - n.dot(o); // ≥ 0 when the origin is on the inner side
        let denom = n.dot(d);
        if denom == 0.0 {
            if inside < 0.0 {
                return None;
            }
            continue;
        }
        let t = inside / denom;
        if denom < 0.0 {
            if t > s.t_in {
                s.t_in = t;
                s.n_in = n;
            }
        } else if t < s.t_out {
            s.t_out = t;
            s.n_out = n;
        }
    }
    if s.t_in <= s.t_out && s.t_in.is_finite() && s.t_out.is_finite() {
        Some(s)
    } else {
        None
    }
}

/// Whether the world point lies inside (or on) the shape.
///
/// Meshes have no inside; a height field's inside is everything below its surface over
/// its footprint; a plane's is its half-space.
pub fn contains_point(shape: &Shape, pose: &Pose, point: Vec3) -> bool {
    if !finite(point) {
        return false;
    }
    match shape {
        Shape::Compound(children) => children.iter().any(|c| {
            child_pose(pose, c.position, c.orientation)
                .is_some_and(|p| contains_point(&c.shape, &p, point))
        }),
        _ => contains_local(shape, pose.inverse_transform_point(point)),
    }
}

/// `contains_point` for a point already in the shape's frame (compounds excluded).
fn contains_local(shape: &Shape, p: Vec3) -> bool {
    match shape {
        Shape::Sphere { radius } => p.length_squared() <= radius * radius,
        Shape::Box { half_extents } => p.abs().cmple(*half_extents).all(),
        Shape::Capsule {
            radius,
            half_height,
        } => {
            let core = Vec3::new(0.0, p.y.clamp(-half_height, *half_height), 0.0);
            (p - core).length_squared() <= radius * radius
        }
        Shape::Cylinder {
            radius,
            half_height,
        } => p.x * p.x + p.z * p.z <= radius * radius && p.y.abs() <= *half_height,
        Shape::ConvexHull(hull) => hull.face_planes().iter().all(|&(n, d)| n.dot(p) <= d),
        Shape::Plane { normal, offset } => {
            let n = normal.normalize_or_zero();
            n != Vec3::ZERO && n.dot(p) <= *offset
        }
        Shape::HeightField(field) => field.height_at(p.x, p.z).is_some_and(|h| p.y <= h),
        Shape::TriMesh(_) | Shape::Compound(_) => false,
    }
}

/// The closest point of a shape's surface to a world point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointProjection {
    /// Closest surface point, world frame (m).
    pub point: Vec3,
    /// Whether the query point was inside the shape.
    pub inside: bool,
    /// Signed distance: positive outside, negative inside (m).
    pub distance: Real,
}

/// Projects a world point onto the shape's surface.
///
/// Meshes: the nearest point on any triangle, never inside (distance ≥ 0). Height fields:
/// the nearest point on any triangle, inside below the surface. Compounds: outside every
/// child, the nearest child surface; inside some, the surface of the child the point is
/// deepest in (overlapping children make that a lower bound of the true depth). A point at
/// the very centre of a sphere, capsule axis or cylinder axis, where every direction is as
/// near, projects along +y (sphere) or +x (the others). `None` for a non-finite point.
pub fn project_point(shape: &Shape, pose: &Pose, point: Vec3) -> Option<PointProjection> {
    if !finite(point) {
        return None;
    }
    if let Shape::Compound(children) = shape {
        let mut best: Option<PointProjection> = None;
        for c in children {
            let Some(p) = child_pose(pose, c.position, c.orientation) else {
                continue;
            };
            let Some(proj) = project_point(&c.shape, &p, point) else {
                continue;
            };
            let better = match best {
                None => true,
                Some(b) if proj.inside != b.inside => proj.inside,
                // Outside: the nearest surface; inside: the deepest child.
                Some(b) => proj.distance < b.distance,
            };
            if better {
                best = Some(proj);
            }
        }
        return best;
    }
    let p = pose.inverse_transform_point(point);
    let (q, inside, distance) = project_local(shape, p)?;
    let proj = PointProjection {
        point: pose.transform_point(q),
        inside,
        distance,
    };
    if finite(proj.point) && proj.distance.is_finite() {
        Some(proj)
    } else {
        None
    }
}

/// (surface point, inside, signed distance) in the shape's frame.
fn project_local(shape: &Shape, p: Vec3) -> Option<(Vec3, bool, Real)> {
    Some(match shape {
        Shape::Sphere { radius } => {
            let l = p.length();
            (radial(p, Vec3::Y) * *radius, l <= *radius, l - radius)
        }
        Shape::Box { half_extents } => project_box(p, *half_extents),
        Shape::Capsule {
            radius,
            half_height,
        } => {
            let core = Vec3::new(0.0, p.y.clamp(-half_height, *half_height), 0.0);
            let l = (p - core).length();
            (
                core + radial(p - core, Vec3::X) * *radius,
                l <= *radius,
                l - radius,
            )
        }
        Shape::Cylinder {
            radius,
            half_height,
        } => project_cylinder(p, *radius, *half_height),
        Shape::ConvexHull(hull) => project_hull(p, hull)?,
        Shape::Plane { normal, offset } => {
            let n = normal.normalize_or_zero();
            if n == Vec3::ZERO {
                return None;
            }
            let dist = n.dot(p) - offset;
            (p - n * dist, dist <= 0.0, dist)
        }
        Shape::TriMesh(mesh) => {
            let (q, _) = mesh.closest_point(p)?;
            (q, false, (q - p).length())
        }
        Shape::HeightField(field) => project_heightfield(p, field)?,
        Shape::Compound(_) => return None,
    })
}

fn project_box(p: Vec3, h: Vec3) -> (Vec3, bool, Real) {
    if p.abs().cmple(h).all() {
        // Inside: out through the nearest face (the first axis on ties).
        let gap = h - p.abs();
        let axis = if gap.x <= gap.y && gap.x <= gap.z {
            0
        } else if gap.y <= gap.z {
            1
        } else {
            2
        };
        let mut q = p;
        q[axis] = if p[axis] < 0.0 { -h[axis] } else { h[axis] };
        (q, true, -gap[axis])
    } else {
        let q = p.clamp(-h, h);
        (q, false, (p - q).length())
    }
}

fn project_cylinder(p: Vec3, r: Real, h: Real) -> (Vec3, bool, Real) {
    let flat = Vec3::new(p.x, 0.0, p.z);
    let rho = flat.length();
    if rho <= r && p.y.abs() <= h {
        let (side, cap) = (r - rho, h - p.y.abs());
        if side < cap {
            let rim = radial(flat, Vec3::X) * r;
            (Vec3::new(rim.x, p.y, rim.z), true, -side)
        } else {
            let y = if p.y < 0.0 { -h } else { h };
            (Vec3::new(p.x, y, p.z), true, -cap)
        }
    } else {
        // Outside, the nearest point of a solid cylinder clamps the radius and the height
        // independently.
        let rim = if rho > r { flat * (r / rho) } else { flat };
        let q = Vec3::new(rim.x, p.y.clamp(-h, h), rim.z);
        (q, false, (p - q).length())
    }
}

fn project_hull(p: Vec3, hull: &ConvexHull) -> Option<(Vec3, bool, Real)> {
    let (n, dist) = hull
        .face_planes()
        .iter()
        .map(|&(n, d)| (n, n.dot(p) - d))
        .reduce(|a, b| if b.1 > a.1 { b } else { a })?;
    if dist <= 0.0 {
        // Inside: the nearest face plane is the nearest surface, and the foot of the
        // perpendicular lies on that face itself.
        return Some((p - n * dist, true, dist));
    }
    let v = hull.vertices();
    let mut best: Option<(Real, Vec3)> = None;
    for t in hull.triangles() {
        let tri = t.map(|i| v[i as usize]);
        let q = TriMesh::closest_point_on_triangle(p, &tri);
        let d2 = (q - p).length_squared();
        if best.is_none_or(|(b, _)| d2 < b) {
            best = Some((d2, q));
        }
    }
    let (d2, q) = best?;
    Some((q, false, d2.sqrt()))
}

fn project_heightfield(p: Vec3, field: &HeightField) -> Option<(Vec3, bool, Real)> {
    let (q, _) = field.closest_point(p)?;
    let inside = field.height_at(p.x, p.z).is_some_and(|h| p.y <= h);
    let l = (q - p).length();
    Some((q, inside, if inside { -l } else { l }))
}
