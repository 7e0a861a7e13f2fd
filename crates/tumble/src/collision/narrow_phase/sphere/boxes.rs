//! Round shapes against boxes, in the box's frame.
//!
//! A sphere's centre is clamped to the box: outside, the clamped point is the closest box
//! point; inside, the face of least penetration is the way out. A capsule's segment gets the
//! exact closest points of segment and box; when they touch or overlap, a separating-axis
//! test over the box's face normals and the segment × box-edge directions gives the axis of
//! least penetration. A normal along a face normal clips the segment against that face (two
//! points for a capsule lying on it); otherwise there is one point.

use super::MIN_SPAN;
use super::{closest_segments, direction, direction_above_noise, magnitude, segment_feature};
use crate::collision::geometry::Pose;
use crate::collision::narrow_phase::box_box::{self, edge_index, face_index, surface_feature};
use crate::collision::narrow_phase::box_box::{ABS_TOL, EDGE, EDGE_SIN, FACE, REL_TOL, VERTEX};
use crate::collision::narrow_phase::{feature_id, Manifold};
use crate::math::{Real, Vec3};

/// A capsule–box normal within about 0.8° of a box face normal is snapped to it and the
/// segment clipped against that face: closest points over a face give exactly the face
/// normal anyway, and the snap keeps a capsule lying flat on a face at two points where
/// rounding would otherwise tilt the normal. The patch is kept only if its nearest point is
/// within the face-preference tolerance of the exact gap.
const FACE_COS: Real = 0.9999;

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
    let Some(near) = segment_box_normal(seg, r, he, margin) else {
        return false;
    };
    let n = near.n;

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
        match near.found {
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
    let (kind_a, index_a) = segment_feature(near.t);
    let (point_a, point_b, kind_b, index_b) = single_point(seg, r, he, &near, k);
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

/// The capsule–box normal and the closest points it came from, in the box's frame.
struct Nearest {
    /// Parameter of the segment's closest point.
    t: Real,
    /// The segment's closest point.
    s: Vec3,
    /// The box's closest point.
    q: Vec3,
    /// The normal, from the capsule to the box.
    n: Vec3,
    found: Found,
}

/// The exact closest points of segment and box and the normal joining them, or, when the
/// gap is rounding noise or the segment enters the box, the separating-axis test's normal;
/// `None` when the capsule is beyond the margin.
fn segment_box_normal(seg: [Vec3; 2], r: Real, he: Vec3, margin: Real) -> Option<Nearest> {
    let t = segment_box_closest(seg[0], seg[1], he);
    // The same expression as the search evaluated, so a zero distance stays zero.
    let s = seg[0] + (seg[1] - seg[0]) * t;
    let q = s.max(-he).min(he);
    // A gap of rounding noise is a touch: the separating-axis test decides its normal.
    let (n, found) = match direction_above_noise(q - s, magnitude(&[seg[0], seg[1], he])) {
        Some(n) => {
            let sep = (q - s).length() - r;
            if sep >= margin {
                return None;
            }
            (n, Found::Closest(sep))
        }
        None => segment_box_sat(seg, he),
    };
    Some(Nearest { t, s, q, n, found })
}

/// The one contact (box frame) when no face patch is taken: the capsule's surface point and
/// the box point along the normal, with the box feature's kind and index; `k` is the axis
/// the normal most runs along.
fn single_point(
    seg: [Vec3; 2],
    r: Real,
    he: Vec3,
    near: &Nearest,
    k: usize,
) -> (Vec3, Vec3, u32, u32) {
    let Nearest { s, q, n, .. } = *near;
    match near.found {
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
            let e0 = box_box::vertex(he, signs);
            signs[j] = true;
            let e1 = box_box::vertex(he, signs);
            let (ts, te) = closest_segments(seg[0], seg[1], e0, e1);
            let s = seg[0].lerp(seg[1], ts);
            (s + n * r, e0.lerp(e1, te), EDGE, edge_index(j, signs))
        }
    }
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
pub(super) fn segment_box_closest(p0: Vec3, p1: Vec3, he: Vec3) -> Real {
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
