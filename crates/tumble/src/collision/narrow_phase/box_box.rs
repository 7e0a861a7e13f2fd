//! Box against box: separating-axis test over 15 axes, then face clipping.
//!
//! Two boxes are disjoint exactly when one of 15 axes separates their projections: the
//! three face normals of each box and the nine cross products of an edge direction of one
//! with an edge direction of the other. Along a unit axis `l`, with `t` the vector from A's
//! centre to B's, the separation is
//!
//!   sep(l) = |t·l| − Σᵢ hₐᵢ |aᵢ·l| − Σⱼ h_bⱼ |bⱼ·l|,
//!
//! (centre distance minus the two projected half-widths), and the contact normal is the
//! axis of largest separation (least penetration). Everything is computed in A's frame,
//! where A's axes are the coordinate axes, so the result does not depend on the world
//! frame and A's face tests are exact.
//!
//! A face axis gives a patch: the *incident* face of the other box (the one most opposed to
//! the axis) is clipped against the four side planes of the *reference* face (Sutherland–
//! Hodgman) and the points below the reference face + margin are kept, at most four of them
//! by [`reduce`]. An edge axis gives one point: the closest points of the two edges.
//!
//! For boxes that are apart (within the margin) the best axis is only a lower bound of the
//! distance and need not name the closest features (a corner near a corner has no axis of
//! its own). Every patch point lies on both surfaces, so its separation is at least the
//! distance; when the patch's nearest point exceeds the axis separation by more than the
//! preference tolerance, or an edge pair's closest points are not inside both edges, the
//! exact closest points (vertex–box and edge–edge, 16 + 144 candidates) give one point
//! instead. Speculative contacts are then within that tolerance of the true gap, and none
//! is reported for boxes farther apart than the margin.
//!
//! Feature numbering, shared with the other box routines: vertex `i` has bit `k` set when
//! its coordinate `k` is `+h_k`; face `2k + 1` is the `+h_k` face of axis `k` and `2k` the
//! `−h_k` one; edge `4k + b` runs along axis `k`, with bit 0 of `b` the sign of axis
//! `(k+1) % 3` and bit 1 that of `(k+2) % 3`.

use super::sphere::closest_segments;
use super::{feature_id, reduce, Candidate, Manifold};
use crate::collision::geometry::Pose;
use crate::math::{Real, Vec3};

/// Feature kinds of [`feature_id`].
pub(super) const VERTEX: u32 = 0;
/// An edge (or, for round shapes, a segment of the core).
pub(super) const EDGE: u32 = 1;
/// A face.
pub(super) const FACE: u32 = 2;

/// Edge–edge axes `aᵢ × bⱼ` shorter than this (the sine of the angle between the edges)
/// are skipped: the edges are parallel and the face axes already bound that direction,
/// while the normalised cross product of nearly parallel vectors is dominated by rounding.
/// Any unit axis is a valid separating-axis test, so the threshold only guards accuracy.
pub(super) const EDGE_SIN: Real = 1e-5;
/// A candidate axis replaces the current best only if it separates more by this fraction of
/// the current separation's magnitude (plus [`ABS_TOL`]): face axes win near-ties over edge
/// axes and A's faces over B's, so a resting pair does not flip between axes from step to
/// step on rounding noise.
pub(super) const REL_TOL: Real = 0.05;
/// The absolute part of that preference, as a fraction of the smaller box's size.
pub(super) const ABS_TOL: Real = 1e-4;

const AXES: [Vec3; 3] = [Vec3::X, Vec3::Y, Vec3::Z];

/// Index of face `axis` on the positive or negative side.
pub(super) fn face_index(axis: usize, positive: bool) -> u32 {
    2 * axis as u32 + positive as u32
}

/// Index of the vertex with these coordinate signs (`true` = `+h`).
pub(super) fn vertex_index(positive: [bool; 3]) -> u32 {
    (positive[0] as u32) | ((positive[1] as u32) << 1) | ((positive[2] as u32) << 2)
}

/// Index of the edge along `axis` whose other two coordinates have the signs in
/// `positive` (the entry of `axis` itself is ignored).
pub(super) fn edge_index(axis: usize, positive: [bool; 3]) -> u32 {
    4 * axis as u32 + positive[(axis + 1) % 3] as u32 + 2 * (positive[(axis + 2) % 3] as u32)
}

/// The vertex of the box of half extents `he` with these coordinate signs.
pub(super) fn vertex(he: Vec3, positive: [bool; 3]) -> Vec3 {
    let s = |p: bool, h: Real| if p { h } else { -h };
    Vec3::new(
        s(positive[0], he.x),
        s(positive[1], he.y),
        s(positive[2], he.z),
    )
}

/// The feature of the box surface nearest to a point `x` outside it (box frame): with one
/// coordinate beyond the box the nearest point lies on a face, with two on an edge, with
/// three on a vertex. A point inside is attributed to the face it is closest to.
pub(super) fn surface_feature(x: Vec3, he: Vec3) -> (u32, u32) {
    let positive = [x.x >= 0.0, x.y >= 0.0, x.z >= 0.0];
    let outside = [x.x.abs() > he.x, x.y.abs() > he.y, x.z.abs() > he.z];
    match outside.iter().filter(|&&o| o).count() {
        3 => (VERTEX, vertex_index(positive)),
        2 => {
            let axis = outside.iter().position(|&o| !o).unwrap_or(0);
            (EDGE, edge_index(axis, positive))
        }
        1 => {
            let axis = outside.iter().position(|&o| o).unwrap_or(0);
            (FACE, face_index(axis, positive[axis]))
        }
        _ => {
            let mut axis = 0;
            for k in 1..3 {
                if he[k] - x[k].abs() < he[axis] - x[axis].abs() {
                    axis = k;
                }
            }
            (FACE, face_index(axis, positive[axis]))
        }
    }
}

/// A box and where it is.
#[derive(Clone, Copy)]
struct Solid<'a> {
    pose: &'a Pose,
    he: Vec3,
}

/// Which axis a query is about.
#[derive(Clone, Copy)]
enum Axis {
    FaceA(usize),
    FaceB(usize),
    Edge(usize, usize),
}

/// The separation of the boxes along an axis, and the unit axis in A's frame, turned to
/// point from A to B.
#[derive(Clone, Copy)]
struct Query {
    sep: Real,
    axis: Axis,
    dir: Vec3,
}

/// The axes of the frame `pb` seen in the frame `pa`. Written out: `AXES.map` was left
/// as a call per axis, a few percent of a pyramid's step.
fn axes_in(pa: &Pose, pb: &Pose) -> [Vec3; 3] {
    let f = |e: Vec3| pa.inverse_transform_vector(pb.transform_vector(e));
    [f(AXES[0]), f(AXES[1]), f(AXES[2])]
}

/// Box (half extents `ha`) at `pa` against box at `pb`.
pub fn box_box(ha: Vec3, pa: &Pose, hb: Vec3, pb: &Pose, margin: Real, out: &mut Manifold) -> bool {
    // B's axes and centre in A's frame.
    let b_axes = axes_in(pa, pb);
    let t = pa.inverse_transform_point(pb.position);
    let Some([Some(face_a), Some(face_b), edge]) = separating_axes(ha, hb, &b_axes, t, margin)
    else {
        return false; // separated by the margin (or non-finite input)
    };
    let scale = ha.max_element().min(hb.max_element());
    let tol = |q: Query| REL_TOL * q.sep.abs() + ABS_TOL * scale;
    let beats = |cand: Query, incumbent: Query| cand.sep > incumbent.sep + tol(incumbent);
    let face = if beats(face_b, face_a) {
        face_b
    } else {
        face_a
    };
    let chosen = match edge {
        Some(e) if beats(e, face) => e,
        _ => face,
    };

    let a = Solid { pose: pa, he: ha };
    let b = Solid { pose: pb, he: hb };
    let edges = |i, j| EdgePair {
        i,
        j,
        b_axes,
        t,
        hb,
    };
    let apart = chosen.sep > 0.0;
    let touching = match chosen.axis {
        Axis::FaceA(k) => face_contact(a, b, (k, chosen.dir[k] > 0.0), true, margin, out),
        // B's reference face faces A: its outward normal is −dir.
        Axis::FaceB(k) => {
            let positive = chosen.dir.dot(b_axes[k]) < 0.0;
            face_contact(b, a, (k, positive), false, margin, out)
        }
        Axis::Edge(i, j) => edge_contact(a, &edges(i, j), chosen.dir, apart, margin, out),
    };
    // The separation along the axis is a lower bound of the distance and the patch's
    // points lie on both surfaces, so: min patch separation ≥ distance ≥ axis separation.
    // When the two agree to the preference tolerance the patch holds the closest features.
    if touching && (!apart || out.min_separation() <= chosen.sep + tol(chosen)) {
        return true;
    }
    // The axis did not name the closest features: the edges' closest points are not
    // inside both edges, or the face patch missed the closest point or came out empty (the
    // low part of the incident face lies beyond the reference face's sides, a box near the
    // rim of another). Apart, the exact closest points take over; overlapping (rare: the
    // patch of an overlapping pair is not empty in practice), the best edge axis.
    out.clear();
    if apart {
        return closest_contact(a, b, margin, out);
    }
    match edge {
        Some(Query {
            axis: Axis::Edge(i, j),
            dir,
            ..
        }) => edge_contact(a, &edges(i, j), dir, false, margin, out),
        _ => false,
    }
}

/// The best axis of each family (A's faces, B's faces, edge pairs), or `None` as soon as
/// an axis separates the boxes by `margin` or more: then there is nothing to report. Ties
/// keep the first axis, so the choice is deterministic.
fn separating_axes(
    ha: Vec3,
    hb: Vec3,
    b_axes: &[Vec3; 3],
    t: Vec3,
    margin: Real,
) -> Option<[Option<Query>; 3]> {
    let extent_a = |l: Vec3| ha.x * l.x.abs() + ha.y * l.y.abs() + ha.z * l.z.abs();
    let extent_b = |l: Vec3| {
        hb.x * l.dot(b_axes[0]).abs()
            + hb.y * l.dot(b_axes[1]).abs()
            + hb.z * l.dot(b_axes[2]).abs()
    };
    let query = |l: Vec3, axis: Axis| {
        let d = t.dot(l);
        Query {
            sep: d.abs() - extent_a(l) - extent_b(l),
            axis,
            dir: if d < 0.0 { -l } else { l },
        }
    };
    let mut best: [Option<Query>; 3] = [None; 3];
    let mut offer = |slot: usize, q: Query| {
        match best[slot] {
            Some(b) if q.sep <= b.sep => {}
            _ => best[slot] = Some(q),
        }
        q.sep < margin
    };
    for k in 0..3 {
        if !offer(0, query(AXES[k], Axis::FaceA(k))) || !offer(1, query(b_axes[k], Axis::FaceB(k)))
        {
            return None;
        }
    }
    for (i, &e) in AXES.iter().enumerate() {
        for (j, &b) in b_axes.iter().enumerate() {
            let l = e.cross(b);
            let len = l.length();
            if len > EDGE_SIN && !offer(2, query(l / len, Axis::Edge(i, j))) {
                return None;
            }
        }
    }
    Some(best)
}

/// One vertex of the polygon being clipped, in the reference box's frame.
#[derive(Clone, Copy, Default)]
struct ClipVertex {
    p: Vec3,
    /// Feature of the incident box (kind, index) that made this point.
    kind: u32,
    index: u32,
    /// The edge from this vertex to the next: an incident-box edge index (0..12), or
    /// 12 + the reference side plane (0..4) the polygon runs along after a clip.
    edge: u32,
}

/// A convex polygon of at most eight vertices: a quadrilateral clipped by four half-planes
/// gains at most one vertex per plane.
#[derive(Clone, Copy, Default)]
struct Polygon {
    v: [ClipVertex; 8],
    len: usize,
}

impl Polygon {
    fn push(&mut self, v: ClipVertex) {
        if self.len < self.v.len() {
            self.v[self.len] = v;
            self.len += 1;
        }
    }

    fn vertices(&self) -> &[ClipVertex] {
        &self.v[..self.len]
    }

    /// Sutherland–Hodgman against the half-plane `dist(p) ≤ 0`. An edge P→Q that leaves
    /// the half-plane is cut at I = P + (Q − P) dP/(dP − dQ) (dP and dQ have opposite
    /// signs, so the denominator is not zero). The cut point is named after the edge it cut
    /// and the plane, which is what makes its feature id persist from step to step.
    /// The result goes to `out` (emptied first) rather than a returned value: a polygon is
    /// 320 bytes, and zeroing and copying one per plane showed in profiles.
    fn clip(&self, dist: impl Fn(Vec3) -> Real, plane: u32, out: &mut Polygon) {
        out.len = 0;
        let vs = self.vertices();
        for (i, p) in vs.iter().enumerate() {
            let q = vs[(i + 1) % vs.len()];
            let (dp, dq) = (dist(p.p), dist(q.p));
            let cut = |edge: u32| ClipVertex {
                p: p.p + (q.p - p.p) * (dp / (dp - dq)),
                kind: EDGE,
                index: 16 + 4 * p.edge + plane,
                edge,
            };
            match (dp <= 0.0, dq <= 0.0) {
                (true, true) => out.push(q),
                // Leaving: the polygon now runs along the clipping plane.
                (true, false) => out.push(cut(12 + plane)),
                // Entering: the rest of P→Q is still the same edge.
                (false, true) => {
                    out.push(cut(p.edge));
                    out.push(q);
                }
                (false, false) => {}
            }
        }
    }
}

/// Face contact: `face = (k, positive)` of `rf` is the reference face, the other box
/// `inc` supplies the incident face. `ref_is_a` says which of the pair `rf` is.
fn face_contact(
    rf: Solid,
    inc: Solid,
    face: (usize, bool),
    ref_is_a: bool,
    margin: Real,
    out: &mut Manifold,
) -> bool {
    let (k, positive) = face;
    let sk = if positive { 1.0 } else { -1.0 };
    let mut poly = incident_face(&rf, &inc, k, sk);
    clip_to_side_planes(&mut poly, &rf, k);

    // Keep what lies below the reference face + margin: depth = sk·x_k − h_k is the signed
    // height above the face plane, i.e. the separation, since the point on the reference
    // face is the projection of the incident point onto the face plane.
    let ref_face = face_index(k, positive);
    let mut cands = [Candidate {
        point_a: Vec3::ZERO,
        point_b: Vec3::ZERO,
        feature: 0,
    }; 8];
    let mut n = 0;
    for v in poly.vertices() {
        if sk * v.p[k] - rf.he[k] < margin {
            let mut on_ref = v.p;
            on_ref[k] = sk * rf.he[k];
            let (ref_point, inc_point) = (
                rf.pose.transform_point(on_ref),
                rf.pose.transform_point(v.p),
            );
            cands[n] = if ref_is_a {
                Candidate {
                    point_a: ref_point,
                    point_b: inc_point,
                    feature: feature_id(FACE, ref_face, v.kind, v.index),
                }
            } else {
                Candidate {
                    point_a: inc_point,
                    point_b: ref_point,
                    feature: feature_id(v.kind, v.index, FACE, ref_face),
                }
            };
            n += 1;
        }
    }
    let normal = rf.pose.transform_vector(AXES[k] * sk);
    out.normal = if ref_is_a { normal } else { -normal };
    reduce(&cands[..n], margin, out);
    !out.is_empty()
}

/// The incident box's face most anti-parallel to the reference normal sk·e_k, in the
/// reference box's frame, its corners tagged with their vertex and edge ids.
fn incident_face(rf: &Solid, inc: &Solid, k: usize, sk: Real) -> Polygon {
    // The incident box in the reference frame.
    let axes = axes_in(rf.pose, inc.pose);
    let centre = rf.pose.inverse_transform_point(inc.pose.position);

    // Incident face: the axis most parallel to the reference normal sk·e_k, on the side
    // whose outward normal opposes it (axis·(sk e_k) < 0 → the +h face).
    let mut j = 0;
    for m in 1..3 {
        if axes[m][k].abs() > axes[j][k].abs() {
            j = m;
        }
    }
    let inc_positive = axes[j][k] * sk < 0.0;
    let (j1, j2) = ((j + 1) % 3, (j + 2) % 3);
    let mut poly = Polygon::default();
    // Around the face: (+,+), (−,+), (−,−), (+,−) in (j1, j2); consecutive corners differ
    // in one sign, along j1 then j2 alternately, which names the edge between them.
    let corners = [(true, true), (false, true), (false, false), (true, false)];
    for (m, &(s1, s2)) in corners.iter().enumerate() {
        let mut signs = [false; 3];
        signs[j] = inc_positive;
        signs[j1] = s1;
        signs[j2] = s2;
        let local = vertex(inc.he, signs);
        let along = if m % 2 == 0 { j1 } else { j2 };
        poly.push(ClipVertex {
            p: centre + axes[0] * local.x + axes[1] * local.y + axes[2] * local.z,
            kind: VERTEX,
            index: vertex_index(signs),
            edge: edge_index(along, signs),
        });
    }
    poly
}

/// Clips `poly` to the side planes of the reference face on axis `k`: s·x_a ≤ h_a for the
/// two other axes a.
fn clip_to_side_planes(poly: &mut Polygon, rf: &Solid, k: usize) {
    let mut spare = Polygon::default();
    for plane in 0..4u32 {
        let a = if plane < 2 { (k + 1) % 3 } else { (k + 2) % 3 };
        let s = if plane % 2 == 0 { 1.0 } else { -1.0 };
        let h = rf.he[a];
        poly.clip(|p| s * p[a] - h, plane, &mut spare);
        std::mem::swap(poly, &mut spare);
    }
}

/// The two edge directions of an edge–edge axis, with B's axes and centre in A's frame.
struct EdgePair {
    i: usize,
    j: usize,
    b_axes: [Vec3; 3],
    t: Vec3,
    hb: Vec3,
}

impl EdgePair {
    /// B's corner with these signs, in A's frame.
    fn b_point(&self, signs: [bool; 3]) -> Vec3 {
        let local = vertex(self.hb, signs);
        self.t + self.b_axes[0] * local.x + self.b_axes[1] * local.y + self.b_axes[2] * local.z
    }
}

/// Edge contact along `dir` (A's frame, from A to B): the edge of A along axis `i` that is
/// farthest along `dir`, the edge of B along `j` farthest along −dir, and the closest points
/// of the two. When the closest points are inside both edges they are opposite each other
/// along `dir` (it is perpendicular to both edges) and differ by the axis's separation.
/// Otherwise the edges' projections do not cross and the gap along the axis understates the
/// points' distance; with `need_crossing` (boxes apart) that returns false so the caller
/// can find the true closest points instead.
fn edge_contact(
    a: Solid,
    edges: &EdgePair,
    dir: Vec3,
    need_crossing: bool,
    margin: Real,
    out: &mut Manifold,
) -> bool {
    let (i, j) = (edges.i, edges.j);
    let mut sa = [dir.x >= 0.0, dir.y >= 0.0, dir.z >= 0.0];
    sa[i] = false;
    let a0 = vertex(a.he, sa);
    sa[i] = true;
    let a1 = vertex(a.he, sa);
    let b = &edges.b_axes;
    let mut sb = [
        dir.dot(b[0]) <= 0.0,
        dir.dot(b[1]) <= 0.0,
        dir.dot(b[2]) <= 0.0,
    ];
    sb[j] = false;
    let b0 = edges.b_point(sb);
    sb[j] = true;
    let b1 = edges.b_point(sb);
    let (s, u) = closest_segments(a0, a1, b0, b1);
    let inside = |x: Real| x > 0.0 && x < 1.0;
    if need_crossing && !(inside(s) && inside(u)) {
        return false;
    }
    let point_a = a.pose.transform_point(a0.lerp(a1, s));
    let point_b = a.pose.transform_point(b0.lerp(b1, u));
    out.normal = a.pose.transform_vector(dir);
    if (point_b - point_a).dot(out.normal) < margin {
        out.push(
            point_a,
            point_b,
            feature_id(EDGE, edge_index(i, sa), EDGE, edge_index(j, sb)),
        );
    }
    !out.is_empty()
}

/// The exact closest features of two boxes that are apart but within the margin, by GJK
/// (the boxes' surfaces are polytopes, where it is exact and takes a few iterations; the
/// brute force over 16 corner–box and 144 edge–edge distances it replaces cost ten times
/// more, paid by every pair of neighbours touching along an edge, as in a pyramid).
fn closest_contact(a: Solid, b: Solid, margin: Real, out: &mut Manifold) -> bool {
    let ca = crate::collision::shape::Convex::Box { half_extents: a.he };
    let cb = crate::collision::shape::Convex::Box { half_extents: b.he };
    let cp = super::closest_points(&ca, a.pose, &cb, b.pose);
    if !(cp.distance > 0.0 && cp.distance < margin) {
        return false; // touching to rounding (not apart after all), or beyond the margin
    }
    // Points on the surface sit at ±h along the axes of their face, edge or vertex; shrink
    // the box a hair so those coordinates count as "beyond" it and name the feature.
    let shrink = 1.0 - 1e3 * crate::math::EPSILON;
    let (ka, ia) = surface_feature(a.pose.inverse_transform_point(cp.point_a), a.he * shrink);
    let (kb, ib) = surface_feature(b.pose.inverse_transform_point(cp.point_b), b.he * shrink);
    out.normal = cp.normal;
    out.push(cp.point_a, cp.point_b, feature_id(ka, ia, kb, ib));
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn feature_numbering_is_a_bijection() {
        let mut seen = std::collections::BTreeSet::new();
        for axis in 0..3 {
            for bits in 0..4u32 {
                let mut p = [false; 3];
                p[(axis + 1) % 3] = bits & 1 != 0;
                p[(axis + 2) % 3] = bits & 2 != 0;
                assert!(seen.insert(edge_index(axis, p)));
            }
        }
        assert_eq!(seen.len(), 12);
        assert!(seen.iter().all(|&e| e < 12));
        for v in 0..8u32 {
            let p = [v & 1 != 0, v & 2 != 0, v & 4 != 0];
            assert_eq!(vertex_index(p), v);
        }
    }

    #[test]
    fn surface_features_of_points_outside() {
        let he = Vec3::new(1.0, 2.0, 3.0);
        assert_eq!(
            surface_feature(Vec3::new(0.0, 3.0, 0.0), he),
            (FACE, face_index(1, true))
        );
        assert_eq!(
            surface_feature(Vec3::new(-2.0, 3.0, 0.0), he),
            (EDGE, edge_index(2, [false, true, false]))
        );
        assert_eq!(
            surface_feature(Vec3::new(2.0, -3.0, 4.0), he),
            (VERTEX, vertex_index([true, false, true]))
        );
        assert_eq!(
            surface_feature(Vec3::new(0.9, 0.0, 0.0), he),
            (FACE, face_index(0, true))
        );
    }
}
