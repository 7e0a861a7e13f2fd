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

use super::box_box::{edge_index, face_index, surface_feature, EDGE, EDGE_SIN, FACE, VERTEX};
use super::box_box::{ABS_TOL, REL_TOL};
use super::{feature_id, Manifold};
use crate::geometry::Pose;
use crate::math::{Real, Vec3};

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
/// A capsule–box normal within about 0.8° of a box face normal is snapped to it and the
/// segment clipped against that face: closest points over a face give exactly the face
/// normal anyway, and the snap keeps a capsule lying flat on a face at two points where
/// rounding would otherwise tilt the normal. The patch is kept only if its nearest point is
/// within the face-preference tolerance of the exact gap.
const FACE_COS: Real = 0.9999;

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

/// Sphere against box.
pub fn sphere_box(
    r: Real,
    pa: &Pose,
    half_extents: Vec3,
    pb: &Pose,
    margin: Real,
    out: &mut Manifold,
) -> bool {
    let he = half_extents;
    let c = pb.inverse_transform_point(pa.position);
    let clamped = c.max(-he).min(he);
    let (n_local, q, (kind, index)) = match direction(c - clamped) {
        // Outside: the clamped centre is the closest box point, the normal runs from the
        // sphere's centre to it.
        Some(outward) => (-outward, clamped, surface_feature(c, he)),
        // Inside (or on the surface): leave through the face of least penetration
        // h_k − |c_k|; the box lies on the other side, so the normal is −sign(c_k) e_k.
        None => {
            let mut k = 0;
            for m in 1..3 {
                if he[m] - c[m].abs() < he[k] - c[k].abs() {
                    k = m;
                }
            }
            let s = if c[k] >= 0.0 { 1.0 } else { -1.0 };
            let mut q = c;
            q[k] = s * he[k];
            let mut n = Vec3::ZERO;
            n[k] = -s;
            (n, q, (FACE, face_index(k, s > 0.0)))
        }
    };
    let n = pb.transform_vector(n_local);
    let point_a = pa.position + n * r;
    let point_b = pb.transform_point(q);
    if (point_b - point_a).dot(n) < margin {
        out.normal = n;
        out.push(point_a, point_b, feature_id(VERTEX, 0, kind, index));
    }
    !out.is_empty()
}

/// Capsule against box.
///
/// In the box's frame: the exact closest points of segment and box. When they are apart
/// the normal joins them; when the segment touches or enters the box, a separating-axis
/// test over the box's face normals and the segment × box-edge directions gives the axis
/// of least penetration. A normal along a box face normal clips the segment against that
/// face (two points for a capsule lying on it); otherwise there is one point.
pub fn capsule_box(
    r: Real,
    h: Real,
    pa: &Pose,
    half_extents: Vec3,
    pb: &Pose,
    margin: Real,
    out: &mut Manifold,
) -> bool {
    let he = half_extents;
    let to_box = |y: Real| pb.inverse_transform_point(pa.transform_point(Vec3::new(0.0, y, 0.0)));
    let seg = [to_box(-h), to_box(h)];
    let t = segment_box_closest(seg[0], seg[1], he);
    // The same expression as the search evaluated, so a zero distance stays zero.
    let s = seg[0] + (seg[1] - seg[0]) * t;
    let q = s.max(-he).min(he);
    // A gap of rounding noise is a touch: the separating-axis test decides its normal.
    let (n, found) = match direction_above_noise(q - s, magnitude(&[seg[0], seg[1], he])) {
        Some(n) => {
            let sep = (q - s).length() - r;
            if sep >= margin {
                return false;
            }
            (n, Found::Closest(sep))
        }
        None => segment_box_sat(seg, he),
    };

    // Face: the axis the normal (nearly) runs along, the face whose outward normal is −n.
    let mut k = 0;
    for m in 1..3 {
        if n[m].abs() > n[k].abs() {
            k = m;
        }
    }
    if n[k].abs() >= FACE_COS && capsule_face(seg, r, he, (k, n[k] < 0.0), pb, margin, out) {
        // The patch's separations are heights above the face plane, never below the exact
        // one; if none comes near it, the closest point lies beyond the face (a segment
        // sloping down past an edge) and the patch would overstate the gap.
        match found {
            Found::Closest(sep)
                if out.min_separation()
                    > sep + REL_TOL * sep.abs() + ABS_TOL * he.max_element() =>
            {
                out.clear()
            }
            _ => return true,
        }
    }
    let world_n = pb.transform_vector(n);
    let (kind_a, index_a) = segment_feature(t);
    let (point_a, point_b, kind_b, index_b) = match found {
        Found::Closest(_) => {
            let (kind, index) = surface_feature(s, he);
            (s + n * r, q, kind, index)
        }
        // Unreachable in practice (a segment entering the box passes over the face it
        // leaves by): the segment point projected onto the face.
        Found::Face => {
            let mut on_face = s;
            on_face[k] = -n[k].signum() * he[k];
            (s + n * r, on_face, FACE, face_index(k, n[k] < 0.0))
        }
        // The box edge along `j` that is farthest towards the capsule (along −n), and its
        // closest point to the segment; n is perpendicular to both, so the two points
        // differ along n by the (negative) depth.
        Found::Edge(j) => {
            let mut signs = [n.x <= 0.0, n.y <= 0.0, n.z <= 0.0];
            signs[j] = false;
            let e0 = super::box_box::vertex(he, signs);
            signs[j] = true;
            let e1 = super::box_box::vertex(he, signs);
            let (ts, te) = closest_segments(seg[0], seg[1], e0, e1);
            let s = seg[0].lerp(seg[1], ts);
            (s + n * r, e0.lerp(e1, te), EDGE, edge_index(j, signs))
        }
    };
    let point_a = pb.transform_point(point_a);
    let point_b = pb.transform_point(point_b);
    if (point_b - point_a).dot(world_n) < margin {
        out.normal = world_n;
        out.push(
            point_a,
            point_b,
            feature_id(kind_a, index_a, kind_b, index_b),
        );
    }
    !out.is_empty()
}

/// How the capsule–box normal was found.
#[derive(Clone, Copy)]
enum Found {
    /// From the closest points, apart by this separation (core distance − radius).
    Closest(Real),
    /// The separating-axis test: a box face normal.
    Face,
    /// The separating-axis test: segment × the box edges along this axis.
    Edge(usize),
}

/// The capsule against face `(k, positive)` of the box (box frame): the segment clipped to
/// the face's slabs |x_m| ≤ h_m (m ≠ k), each end of what remains projected onto the face
/// plane. Returns false, pushing nothing, when the segment does not pass over the face or
/// no point is within the margin.
#[allow(clippy::too_many_arguments)]
fn capsule_face(
    seg: [Vec3; 2],
    r: Real,
    he: Vec3,
    face: (usize, bool),
    pb: &Pose,
    margin: Real,
    out: &mut Manifold,
) -> bool {
    let (k, positive) = face;
    let sk = if positive { 1.0 } else { -1.0 };
    let d = seg[1] - seg[0];
    let (mut lo, mut hi) = (0.0, 1.0);
    let (mut lo_cut, mut hi_cut) = (false, false);
    for m in [(k + 1) % 3, (k + 2) % 3] {
        if d[m] != 0.0 {
            // x_m(t) = p0_m + t d_m crosses ±h_m at t = (±h_m − p0_m)/d_m.
            let ta = (-he[m] - seg[0][m]) / d[m];
            let tb = (he[m] - seg[0][m]) / d[m];
            let (ta, tb) = (ta.min(tb), ta.max(tb));
            if ta > lo {
                lo = ta;
                lo_cut = true;
            }
            if tb < hi {
                hi = tb;
                hi_cut = true;
            }
        } else if seg[0][m].abs() > he[m] {
            return false; // parallel to the slab and outside it
        }
    }
    if lo > hi {
        return false;
    }
    let mut n = Vec3::ZERO;
    n[k] = -sk;
    out.normal = pb.transform_vector(n);
    let two = (hi - lo) * d.length() > MIN_SPAN * r;
    let ends = [(lo, lo_cut, 0u32), (hi, hi_cut, 1u32)];
    for &(t, cut, end) in ends.iter().take(if two { 2 } else { 1 }) {
        let s = seg[0] + d * t;
        let mut q = s;
        q[k] = sk * he[k];
        // (q − s)·n − r: the height of the segment point above the face, less the radius.
        if (q - s).dot(n) - r < margin {
            let (kind, index) = if cut { (EDGE, 2 + end) } else { (VERTEX, end) };
            out.push(
                pb.transform_point(s + n * r),
                pb.transform_point(q),
                feature_id(kind, index, FACE, face_index(k, positive)),
            );
        }
    }
    !out.is_empty()
}

/// The parameter t of the point of segment p0–p1 closest to the box |x_i| ≤ h_i.
///
/// The squared distance f(t) = Σᵢ max(|x_i(t)| − h_i, 0)² of x(t) = p0 + t d is convex and
/// piecewise quadratic, with breaks where a coordinate crosses ±h_i. Between breaks each
/// axis is either inside its slab (no term) or beyond a fixed face c_i = ±h_i, so
/// f'(t) = 2 Σ_active d_i (p0_i − c_i + t d_i) = 0 gives t = −Σ d_i (p0_i − c_i) / Σ d_i².
/// Clamping that to each piece and keeping the best is exact, with no iteration. Ties keep
/// the smallest t.
fn segment_box_closest(p0: Vec3, p1: Vec3, he: Vec3) -> Real {
    let d = p1 - p0;
    let dist2 = |t: Real| {
        let x = p0 + d * t;
        (x - x.max(-he).min(he)).length_squared()
    };
    let mut knots = [0.0; 8];
    knots[1] = 1.0;
    let mut n = 2;
    for i in 0..3 {
        if d[i] != 0.0 {
            for c in [-he[i], he[i]] {
                let t = (c - p0[i]) / d[i];
                if t > 0.0 && t < 1.0 && n < knots.len() {
                    knots[n] = t;
                    n += 1;
                }
            }
        }
    }
    let knots = &mut knots[..n];
    knots.sort_unstable_by(|a, b| a.total_cmp(b));
    let (mut best_t, mut best) = (0.0, dist2(0.0));
    for w in knots.windows(2) {
        let (ta, tb) = (w[0], w[1]);
        if tb <= ta {
            continue;
        }
        let mid = p0 + d * (0.5 * (ta + tb));
        let (mut num, mut den) = (0.0, 0.0);
        for i in 0..3 {
            let c = if mid[i] > he[i] {
                he[i]
            } else if mid[i] < -he[i] {
                -he[i]
            } else {
                continue;
            };
            num += d[i] * (p0[i] - c);
            den += d[i] * d[i];
        }
        // With no axis beyond the box the piece lies inside it: its midpoint is at distance
        // exactly zero, where a break point, computed by a division, might miss by an ulp.
        let t = if den > 0.0 {
            (-num / den).max(ta).min(tb)
        } else {
            0.5 * (ta + tb)
        };
        let f = dist2(t);
        if f < best {
            best = f;
            best_t = t;
        }
    }
    best_t
}

/// Least-penetration axis of a segment that touches or enters the box (box frame): the
/// box's face normals and the cross products of the segment with the box's edges. Along a
/// unit axis l the box spans ±ρ, ρ = Σ h_i |l_i|, the segment [s_min, s_max]; pushing the
/// segment to the +l side takes ρ − s_min, to the −l side s_max + ρ. The normal points from
/// the capsule to the box: −l when the capsule goes to the +l side. Face axes win near-ties
/// (as in `box_box`). Returns the normal and which kind of axis gave it.
fn segment_box_sat(seg: [Vec3; 2], he: Vec3) -> (Vec3, Found) {
    let axes = [Vec3::X, Vec3::Y, Vec3::Z];
    let depth = |l: Vec3| {
        let rho = he.x * l.x.abs() + he.y * l.y.abs() + he.z * l.z.abs();
        let (a, b) = (seg[0].dot(l), seg[1].dot(l));
        let (up, down) = (rho - a.min(b), a.max(b) + rho);
        if up <= down {
            (up, -l)
        } else {
            (down, l)
        }
    };
    let mut face = (Real::INFINITY, Vec3::Y);
    for &e in &axes {
        let cand = depth(e);
        if cand.0 < face.0 {
            face = cand;
        }
    }
    let mut edge = (Real::INFINITY, Vec3::Y, 0);
    if let Some(u) = direction(seg[1] - seg[0]) {
        for (j, &e) in axes.iter().enumerate() {
            let l = u.cross(e);
            let len = l.length();
            if len > EDGE_SIN {
                let (dep, n) = depth(l / len);
                if dep < edge.0 {
                    edge = (dep, n, j);
                }
            }
        }
    }
    let tol = REL_TOL * face.0.abs() + ABS_TOL * he.max_element();
    if edge.0 < face.0 - tol {
        (edge.1, Found::Edge(edge.2))
    } else {
        (face.1, Found::Face)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closest_segments_of_crossing_parallel_and_degenerate() {
        let (s, t) = closest_segments(
            Vec3::new(-1.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.5, 1.0, -1.0),
            Vec3::new(0.5, 1.0, 1.0),
        );
        assert!((s - 0.75).abs() < 1e-6 && (t - 0.5).abs() < 1e-6);
        // Parallel: a valid pair at the common perpendicular distance, no NaN.
        let (s, t) = closest_segments(
            Vec3::ZERO,
            Vec3::X,
            Vec3::new(0.5, 1.0, 0.0),
            Vec3::new(1.5, 1.0, 0.0),
        );
        let gap = Vec3::new(0.5, 1.0, 0.0).lerp(Vec3::new(1.5, 1.0, 0.0), t) - Vec3::X * s;
        assert!((gap.length() - 1.0).abs() < 1e-6);
        let (s, t) = closest_segments(Vec3::ONE, Vec3::ONE, Vec3::ONE, Vec3::ONE);
        assert_eq!((s, t), (0.0, 0.0));
    }

    #[test]
    fn segment_box_distance_is_exact() {
        let he = Vec3::new(1.0, 1.0, 1.0);
        // Diagonal past a vertex: closest to the corner (1, 1, 1) at t with x = y = z.
        let p0 = Vec3::new(3.0, 1.0, 2.0);
        let p1 = Vec3::new(1.0, 3.0, 2.0);
        let t = segment_box_closest(p0, p1, he);
        assert!((t - 0.5).abs() < 1e-6, "{t}");
        // Through the box: distance zero somewhere inside.
        let t = segment_box_closest(Vec3::new(-3.0, 0.0, 0.0), Vec3::new(3.0, 0.0, 0.0), he);
        let x = Vec3::new(-3.0 + 6.0 * t, 0.0, 0.0);
        assert!(x.x.abs() <= 1.0);
    }
}
