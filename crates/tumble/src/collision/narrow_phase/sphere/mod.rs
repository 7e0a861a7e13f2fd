//! Closed-form contacts of round shapes: spheres and capsules, with each other and boxes.
//!
//! A sphere is a point swept by a radius, a capsule a segment swept by one. Every routine
//! first finds the closest points `c_a`, `c_b` of the *cores* (point, segment, box) and
//! then moves them out by the radii along the normal n:
//!
//!   point_a = c_a + r_a n,   point_b = c_b − r_b n,
//!   separation = (point_b − point_a)·n = (c_b − c_a)·n − r_a − r_b,
//!
//! which is the exact signed distance when n = (c_b − c_a)/|c_b − c_a|: the closest points
//! of two convex sets differ along their common normal. Only when the cores touch or
//! overlap must n come from elsewhere (least penetration, or a fixed fallback so that
//! coincident centres never give NaN).
//!
//! Feature ids of round shapes: a sphere is vertex 0; a capsule's lower end (local −y) is
//! vertex 0, its upper end vertex 1, its shaft edge 0. The two points of parallel capsules
//! are edges 1 and 2 (the low and high ends of the overlap along A's axis) on both; the ends
//! of a capsule clipped on a box face are its vertices, or edges 2 and 3 where the face's
//! sides cut it. Box features are numbered as in `box_box.rs`.
//!
//! Layout: this file holds the shared segment helpers and the round–round pairs;
//! `boxes.rs` spheres and capsules against boxes; `tests.rs` the tests.

mod boxes;
#[cfg(test)]
mod tests;

use super::box_box::{EDGE, VERTEX};
use super::{feature_id, Manifold};
use crate::collision::geometry::Pose;
use crate::math::{Real, Vec3};
pub use boxes::{capsule_box, sphere_box};

/// Vectors at most this long have no usable direction. Anything longer has a square that
/// is a normal float in both precisions (1e-36 > f32::MIN_POSITIVE), so v/|v| is unit to
/// rounding; shorter ones fall back to a fixed direction instead of dividing by ~0.
pub(super) const TINY: Real = 1e-18;
/// Two capsule axes count as parallel below this sine of their angle (about 1.1°): a
/// capsule lying on a capsule then gets two points spanning the overlap and rests stably,
/// where the single closest point would let it rock. At this angle, points s = 0.5 m
/// either side of the closest ones on axes d = 0.2 m apart are farther apart than those by
/// only √(d² + s²θ²) − d ≈ s²θ²/(2d) = 0.25 mm, and the separation each point reports is
/// measured along the common normal, not assumed.
const PARALLEL_SIN: Real = 0.02;
/// Closest core points nearer than this many ulps of the coordinates' magnitude count as
/// meeting: segment end points come out of rotations with a few ulps of error, so a
/// smaller gap is rounding noise and its direction arbitrary.
const MEET_ULPS: Real = 64.0;
/// A two-point patch shorter than this fraction of the radii is one point.
const MIN_SPAN: Real = 1e-3;

/// `v / |v|`, or `None` when `v` is too short (or not finite) to have a direction.
pub(super) fn direction(v: Vec3) -> Option<Vec3> {
    let len = v.length();
    if len > TINY && len.is_finite() {
        Some(v / len)
    } else {
        None
    }
}

/// The direction of `v`, unless it is shorter than [`MEET_ULPS`] ulps of `scale` (the
/// magnitude of the coordinates it was computed from).
fn direction_above_noise(v: Vec3, scale: Real) -> Option<Vec3> {
    if v.length() > MEET_ULPS * Real::EPSILON * scale {
        direction(v)
    } else {
        None
    }
}

/// The largest coordinate magnitude of some points.
fn magnitude(points: &[Vec3]) -> Real {
    points.iter().fold(0.0, |m, p| m.max(p.abs().max_element()))
}

/// A local axis of `pose` in world, unit even if the quaternion is slightly off.
fn frame_axis(pose: &Pose, axis: Vec3) -> Vec3 {
    direction(pose.transform_vector(axis)).unwrap_or(axis)
}

/// The parameter in [0, 1] of the point of segment p0–p1 closest to `x`:
/// t = (x − p0)·d / d·d clamped, d = p1 − p0 (0 for a degenerate segment).
fn closest_on_segment(p0: Vec3, p1: Vec3, x: Vec3) -> Real {
    let d = p1 - p0;
    let dd = d.length_squared();
    if dd > TINY * TINY {
        ((x - p0).dot(d) / dd).clamp(0.0, 1.0)
    } else {
        0.0
    }
}

/// Parameters (s, t) in [0, 1] of the closest points p1 + s d1 and p2 + t d2 of segments
/// p1–q1 and p2–q2 (Ericson, *Real-Time Collision Detection*, 5.1.9).
///
/// Minimising |r + s d1 − t d2|², r = p1 − p2, gives the normal equations
///   a s − b t = −c,   b s − e t = −f,   a = d1·d1, b = d1·d2, e = d2·d2, c = d1·r, f = d2·r,
/// so s = (b f − c e)/(a e − b²) on the infinite lines. Clamping s, then taking the t
/// closest to that point, t = (b s + f)/e, and re-clamping s if t had to be clamped gives
/// the segment solution. When a e − b² vanishes the segments are parallel, every s is as
/// good as any, and s = 0 is taken; the caller handles parallel overlap separately where it
/// matters. Degenerate segments reduce to point–segment distances.
pub(super) fn closest_segments(p1: Vec3, q1: Vec3, p2: Vec3, q2: Vec3) -> (Real, Real) {
    let (d1, d2, r) = (q1 - p1, q2 - p2, p1 - p2);
    let (a, e, f) = (d1.length_squared(), d2.length_squared(), d2.dot(r));
    let tiny = TINY * TINY;
    if a <= tiny && e <= tiny {
        return (0.0, 0.0);
    }
    if a <= tiny {
        return (0.0, (f / e).clamp(0.0, 1.0));
    }
    let c = d1.dot(r);
    if e <= tiny {
        return ((-c / a).clamp(0.0, 1.0), 0.0);
    }
    let b = d1.dot(d2);
    let denom = a * e - b * b;
    // a e − b² = a e sin²θ; relative to a e this is the squared sine of the angle.
    let s = if denom > Real::EPSILON * a * e {
        ((b * f - c * e) / denom).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let t = (b * s + f) / e;
    if t < 0.0 {
        ((-c / a).clamp(0.0, 1.0), 0.0)
    } else if t > 1.0 {
        (((b - c) / a).clamp(0.0, 1.0), 1.0)
    } else {
        (s, t)
    }
}

/// The world end points of a capsule's segment (local y from −h to +h).
fn capsule_segment(h: Real, pose: &Pose) -> (Vec3, Vec3) {
    (
        pose.transform_point(Vec3::new(0.0, -h, 0.0)),
        pose.transform_point(Vec3::new(0.0, h, 0.0)),
    )
}

/// Feature of a capsule at segment parameter `t`: an end (vertex 0 or 1) or the shaft.
fn segment_feature(t: Real) -> (u32, u32) {
    if t <= 0.0 {
        (VERTEX, 0)
    } else if t >= 1.0 {
        (VERTEX, 1)
    } else {
        (EDGE, 0)
    }
}

/// A core point and the radius swept around it.
#[derive(Clone, Copy)]
struct Ball {
    centre: Vec3,
    radius: Real,
}

/// One contact between two balls (the closest core points of two round shapes) along `n`,
/// their centre line (or a fallback when the centres coincide).
fn ball_pair(a: Ball, b: Ball, n: Vec3, margin: Real, feature: u32, out: &mut Manifold) -> bool {
    let point_a = a.centre + n * a.radius;
    let point_b = b.centre - n * b.radius;
    if (point_b - point_a).dot(n) < margin {
        out.normal = n;
        out.push(point_a, point_b, feature);
    }
    !out.is_empty()
}

/// Sphere (radius `ra`, centre at `pa`) against sphere.
pub fn sphere_sphere(
    ra: Real,
    pa: &Pose,
    rb: Real,
    pb: &Pose,
    margin: Real,
    out: &mut Manifold,
) -> bool {
    let a = Ball {
        centre: pa.position,
        radius: ra,
    };
    let b = Ball {
        centre: pb.position,
        radius: rb,
    };
    // Concentric: no direction is better than another; A's local y moves with the bodies.
    let n = direction(b.centre - a.centre).unwrap_or_else(|| frame_axis(pa, Vec3::Y));
    ball_pair(a, b, n, margin, feature_id(VERTEX, 0, VERTEX, 0), out)
}

/// Sphere against capsule (along the capsule's local y).
pub fn sphere_capsule(
    r: Real,
    pa: &Pose,
    rc: Real,
    half_height: Real,
    pb: &Pose,
    margin: Real,
    out: &mut Manifold,
) -> bool {
    let (b0, b1) = capsule_segment(half_height, pb);
    let t = closest_on_segment(b0, b1, pa.position);
    let a = Ball {
        centre: pa.position,
        radius: r,
    };
    let b = Ball {
        centre: b0.lerp(b1, t),
        radius: rc,
    };
    // Centre on the axis: push out sideways, along the capsule's local x.
    let n = direction_above_noise(b.centre - a.centre, magnitude(&[a.centre, b0, b1]))
        .unwrap_or_else(|| frame_axis(pb, Vec3::X));
    let (kind, index) = segment_feature(t);
    ball_pair(a, b, n, margin, feature_id(VERTEX, 0, kind, index), out)
}

/// Capsule against capsule.
#[allow(clippy::too_many_arguments)]
pub fn capsule_capsule(
    ra: Real,
    ha: Real,
    pa: &Pose,
    rb: Real,
    hb: Real,
    pb: &Pose,
    margin: Real,
    out: &mut Manifold,
) -> bool {
    let (a0, a1) = capsule_segment(ha, pa);
    let (b0, b1) = capsule_segment(hb, pb);
    let (s, t) = closest_segments(a0, a1, b0, b1);
    let (ca, cb) = (a0.lerp(a1, s), b0.lerp(b1, t));
    let n = direction_above_noise(cb - ca, magnitude(&[a0, a1, b0, b1]))
        .unwrap_or_else(|| crossing_normal(a1 - a0, b1 - b0, pb.position - pa.position, pa));
    // The closest points decide: nothing when even they are a margin apart.
    if (cb - ca).dot(n) - ra - rb >= margin {
        return false;
    }
    if parallel_pair([a0, a1], ra, [b0, b1], rb, n, margin, out) {
        return true;
    }
    let (ka, ia) = segment_feature(s);
    let (kb, ib) = segment_feature(t);
    let a = Ball {
        centre: ca,
        radius: ra,
    };
    let b = Ball {
        centre: cb,
        radius: rb,
    };
    ball_pair(a, b, n, margin, feature_id(ka, ia, kb, ib), out)
}

/// The normal of two capsules whose axes meet (closest points coincide): the common
/// perpendicular da × db when the axes cross, else a perpendicular of A's axis, else the
/// centre line, else A's local x; always turned towards B's centre.
fn crossing_normal(da: Vec3, db: Vec3, toward: Vec3, pa: &Pose) -> Vec3 {
    let n = direction_above_noise(da.cross(db), da.length() * db.length())
        .or_else(|| {
            direction(da).map(|u| {
                direction(toward - u * toward.dot(u)).unwrap_or_else(|| u.any_orthonormal_vector())
            })
        })
        .or_else(|| direction(toward))
        .unwrap_or_else(|| frame_axis(pa, Vec3::X));
    if n.dot(toward) < 0.0 {
        -n
    } else {
        n
    }
}

/// Two (nearly) parallel capsules: two points at the ends of the overlap of B's axis
/// projected on A's, each paired with the closest point of B's axis, both along the common
/// normal `n`. Pushes them and returns true only if the axes are parallel, the overlap is
/// not a point and both points are within the margin; otherwise the caller falls back to
/// the single closest point.
fn parallel_pair(
    a: [Vec3; 2],
    ra: Real,
    b: [Vec3; 2],
    rb: Real,
    n: Vec3,
    margin: Real,
    out: &mut Manifold,
) -> bool {
    let (da, db) = (a[1] - a[0], b[1] - b[0]);
    let (la2, lb2) = (da.length_squared(), db.length_squared());
    // |da × db|² = la² lb² sin²θ.
    if la2 <= TINY * TINY
        || lb2 <= TINY * TINY
        || da.cross(db).length_squared() > PARALLEL_SIN * PARALLEL_SIN * la2 * lb2
    {
        return false;
    }
    // B's ends as parameters along A, the overlap clamped to A.
    let s0 = (b[0] - a[0]).dot(da) / la2;
    let s1 = (b[1] - a[0]).dot(da) / la2;
    let lo = s0.min(s1).max(0.0);
    let hi = s0.max(s1).min(1.0);
    if (hi - lo) * la2.sqrt() <= MIN_SPAN * (ra + rb) {
        return false;
    }
    let mut points = [(Vec3::ZERO, Vec3::ZERO); 2];
    for (point, s) in points.iter_mut().zip([lo, hi]) {
        let pa = a[0] + da * s;
        let pb = b[0].lerp(b[1], closest_on_segment(b[0], b[1], pa));
        *point = (pa + n * ra, pb - n * rb);
        if (point.1 - point.0).dot(n) >= margin {
            return false;
        }
    }
    out.normal = n;
    for (i, (point_a, point_b)) in points.into_iter().enumerate() {
        out.push(
            point_a,
            point_b,
            feature_id(EDGE, 1 + i as u32, EDGE, 1 + i as u32),
        );
    }
    true
}
