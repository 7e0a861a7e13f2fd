//! Convex shapes against triangle meshes and height fields, triangle by triangle, without
//! catching on internal edges.
//!
//! Each triangle near the convex goes through the general convex–convex routine as a
//! `Convex::Triangle`. A lone triangle has sharp edges all round, so that routine can
//! answer with a normal that points sideways out of an edge: correct for the triangle
//! alone, wrong where the edge is internal to a smooth surface. A box sliding over a
//! floor of many triangles would then stub its toe on every seam ("ghost collisions").
//! Each manifold is therefore checked against what the surface around the triangle allows,
//! in the manner of Jolt's active edges and Box2D's chain shapes:
//!
//! 1. **One-sided**: a convex whose middle (halfway between its extremes along the face
//!    normal) lies behind the triangle's plane is behind the surface; the triangle reports
//!    nothing, so it never pulls a body through from the back (and rule 3 never turns a
//!    back contact into a push up through the face).
//! 2. **Face contacts**: a normal within [`SNAP`] of the face normal is set exactly to the
//!    face normal (separations re-derived along it), so flat ground gives exactly vertical
//!    normals whatever the convex routine's rounding.
//!    A cylinder's points are then re-derived too, as its feature facing the face
//!    clipped to the triangle's prism: the convex routine finds them by GJK on its curved
//!    side, to its convergence only (see `collide_triangle`).
//! 3. **Edge and vertex contacts**: a normal tilted further is legitimate only where the
//!    contact lies on edges that allow the tilt. Across an edge the surface continues in
//!    the neighbouring face, bent by the edge's signed angle β (see `TriMesh`): normals may
//!    lean out over the edge by at most β (a ridge of β has exactly that fan of normals),
//!    so not at all over a flat or concave edge; a boundary edge allows up to a quarter
//!    turn (never a push towards the back). At a vertex the fans of its two edges combine.
//!    A rejected normal is replaced by the face normal and the contact re-derived: the
//!    convex's feature facing the triangle is clipped to the triangle's prism and its
//!    points within the margin kept. Over a seam that leaves exactly the part of the convex
//!    above this triangle, with the face normal; nothing if none of it is.
//! 4. **Duplicates**: a contact on a shared edge or vertex is found by every triangle
//!    there. Triangles are processed in index order and a point equal (to rounding) to one
//!    already reported with the same normal is dropped, so a sphere resting on a vertex
//!    gets one contact, not six.

use super::{convex_pair, feature_id, reduce, Candidate, ContactPoint, Manifold};
use crate::collision::geometry::{Aabb, Pose};
use crate::collision::shape::Convex;
use crate::collision::shape::{convex_aabb, ConvexHull, HeightField, TriMesh};
use crate::math::{Real, Vec3, EPSILON};

/// Largest tilt (sine of the angle) of a normal from the face normal that is taken for
/// rounding in the convex routine rather than an edge contact.
const SNAP: Real = 1e-4;
/// Slack (rad) on the edge-fan test, for the rounding of normals near its limits.
const ANGLE_TOL: Real = 1e-3;
/// A contact point within this fraction of the sizes involved from an edge is "on" it.
const FEATURE_TOL: Real = 1e-4;
/// Two manifold normals whose dot product exceeds 1 − this are the same direction.
const SAME_NORMAL: Real = 1e-6;

/// A triangle in the world frame, with the bend angles of its edges.
#[derive(Debug, Clone, Copy)]
struct Tri {
    v: [Vec3; 3],
    /// Unit front normal.
    n: Vec3,
    /// Signed bend angle per edge k (corner k to k+1): see `TriMesh`.
    bends: [Real; 3],
    index: u32,
}

impl Tri {
    fn new(local: [Vec3; 3], local_normal: Vec3, bends: [Real; 3], index: usize, pb: &Pose) -> Tri {
        Tri {
            v: local.map(|p| pb.transform_point(p)),
            n: pb.transform_vector(local_normal).normalize_or_zero(),
            bends,
            index: index as u32,
        }
    }

    /// Unit outward direction of edge k within the face plane (the inside is to the left
    /// of the edge seen from the front, so (b − a) × n points out).
    fn edge_out(&self, k: usize) -> Vec3 {
        (self.v[(k + 1) % 3] - self.v[k])
            .cross(self.n)
            .normalize_or_zero()
    }

    fn size(&self) -> Real {
        let [a, b, c] = self.v;
        (b - a).length().max((c - b).length()).max((a - c).length())
    }
}

/// Appends one manifold per touching triangle (subshape_b = triangle index).
pub fn convex_trimesh(
    a: &Convex,
    pa: &Pose,
    mesh: &TriMesh,
    pb: &Pose,
    margin: Real,
    out: &mut Vec<Manifold>,
) {
    let Some(query) = query_box(a, pa, pb, margin) else {
        return;
    };
    let mut found = Vec::new();
    mesh.for_each_triangle_in(&query, |i| found.push(i));
    // Index order makes the result (and which duplicate survives) independent of the
    // hierarchy's layout.
    found.sort_unstable();
    let start = out.len();
    for i in found {
        let (Some(v), Some(n)) = (mesh.get_triangle(i), mesh.normal(i)) else {
            continue;
        };
        let tri = Tri::new(v, n, mesh.edge_bends(i), i, pb);
        collide_triangle(a, pa, &tri, margin, out, start);
    }
}

/// Appends one manifold per touching triangle (subshape_b = triangle index).
pub fn convex_heightfield(
    a: &Convex,
    pa: &Pose,
    field: &HeightField,
    pb: &Pose,
    margin: Real,
    out: &mut Vec<Manifold>,
) {
    let Some(query) = query_box(a, pa, pb, margin) else {
        return;
    };
    let mut found = Vec::new();
    field.for_each_triangle_in(&query, |i, v| found.push((i, v)));
    found.sort_unstable_by_key(|f| f.0);
    let start = out.len();
    for (i, v) in found {
        let Some(n) = field.normal(i) else {
            continue;
        };
        let tri = Tri::new(v, n, field.edge_bends(i), i, pb);
        collide_triangle(a, pa, &tri, margin, out, start);
    }
}

/// The convex's world box grown by the margin, seen in the mesh frame (the box around its
/// eight corners there).
fn query_box(a: &Convex, pa: &Pose, pb: &Pose, margin: Real) -> Option<Aabb> {
    let world = convex_aabb(a, pa).expanded(margin.max(0.0));
    let local = world.mapped(|c| pb.inverse_transform_point(c));
    let finite = |v: Vec3| v.x.is_finite() && v.y.is_finite() && v.z.is_finite();
    (finite(local.min) && finite(local.max)).then_some(local)
}

/// The world point of `a` farthest along the world direction `dir`.
fn support(a: &Convex, pa: &Pose, dir: Vec3) -> Vec3 {
    pa.transform_point(a.support(pa.inverse_transform_vector(dir)))
}

/// One triangle: the convex routine, then the four rules of the module comment.
fn collide_triangle(
    a: &Convex,
    pa: &Pose,
    tri: &Tri,
    margin: Real,
    out: &mut Vec<Manifold>,
    start: usize,
) {
    let n = tri.n;
    if n == Vec3::ZERO {
        return;
    }
    // Rule 1: one-sided.
    let top = n.dot(support(a, pa, n) - tri.v[0]);
    let bottom = n.dot(support(a, pa, -n) - tri.v[0]);
    if top + bottom < 0.0 || top.is_nan() || bottom.is_nan() {
        return;
    }
    let mut m = Manifold::default();
    let touching = convex_pair(
        a,
        pa,
        &Convex::Triangle(tri.v),
        &Pose::IDENTITY,
        margin,
        &mut m,
    );
    if !touching || m.is_empty() {
        return;
    }
    let size = (top - bottom).abs() + tri.size();
    let push = -m.normal; // the direction the triangle pushes the convex
    match judge(push, tri, &m, size) {
        // A cylinder's contact comes from GJK on its curved side, whose witness is only as
        // good as its convergence (f32, 36 m out: 1.9 mm along the roll, so a spinning
        // wheel's point moved away from the face at 0.3 m/s and the solver let it fall),
        // and its side line lying on an edge two triangles share was clipped away by
        // both. Its feature facing the face, clipped to the prism with a little slack, is
        // exact: the two ends of its side line, or its cap's corners. Where none of it
        // lies over this triangle, the neighbour under it reports the contact; GJK's
        // point here, a millimetre off the line, carried a wheel's load and lifted it.
        Verdict::Face if matches!(a, Convex::Cylinder { .. }) => {
            m = face_contact(a, pa, tri, margin);
        }
        // Rule 2: rounding of a face contact; keep the points, fix the normal.
        Verdict::Face => snap_to_face(&mut m, n, margin),
        Verdict::Edge => {}
        Verdict::Ghost => m = face_contact(a, pa, tri, margin),
    }
    if m.is_empty() || !(m.normal.x.is_finite() && m.normal.y.is_finite() && m.normal.z.is_finite())
    {
        return;
    }
    m.subshape_b = tri.index;
    // Rule 4: duplicates of contacts an earlier triangle already reported (or that the
    // convex routine listed twice, as a clipped corner lying exactly on a clipping edge).
    let tol = FEATURE_TOL * size + 1e3 * EPSILON * max_coordinate(&m);
    let same = |a: &ContactPoint, b: &ContactPoint| {
        (a.point_a - b.point_a).length() <= tol && (a.point_b - b.point_b).length() <= tol
    };
    let earlier = &out[start..];
    let normal = m.normal;
    let mut kept: Vec<ContactPoint> = Vec::with_capacity(m.len());
    m.retain(|p| {
        let seen = kept.iter().any(|q| same(p, q))
            || earlier.iter().any(|e| {
                e.normal.dot(normal) >= 1.0 - SAME_NORMAL && e.points().iter().any(|q| same(p, q))
            });
        if !seen {
            kept.push(*p);
        }
        !seen
    });
    if !m.is_empty() {
        out.push(m);
    }
}

/// Rule 2: a face contact's normal set to the face's (`-n`, from the convex to the
/// triangle), its separations re-derived along it; points beyond `margin` dropped.
fn snap_to_face(m: &mut Manifold, n: Vec3, margin: Real) {
    m.normal = -n;
    for p in m.points_mut() {
        p.separation = (p.point_b - p.point_a).dot(-n);
    }
    m.retain(|p| p.separation <= margin);
}

fn max_coordinate(m: &Manifold) -> Real {
    m.points()
        .iter()
        .map(|p| {
            p.point_a
                .abs()
                .max_element()
                .max(p.point_b.abs().max_element())
        })
        .fold(0.0, Real::max)
}

/// What a manifold's normal turns out to be.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Verdict {
    /// The face normal up to rounding.
    Face,
    /// A tilt the surface allows at the contact's edges (rule 3).
    Edge,
    /// A tilt the surface does not have there: an internal-edge artefact.
    Ghost,
}

/// Classifies the push direction (unit, triangle towards convex) of manifold `m`.
///
/// Where the contact lies on edge k, the surface's normals there fan from the face normal
/// n towards the edge's outward direction o_k by the edge's bend β_k (none for flat and
/// concave edges; a quarter turn at most on a boundary). At a vertex the fans of both edges
/// combine. So the push's tilt t (its part in the face plane) must be a combination
/// a·o_k (+ b·o_j) with non-negative coefficients, each within its edge's fan.
fn judge(push: Vec3, tri: &Tri, m: &Manifold, size: Real) -> Verdict {
    let n = tri.n;
    let along = push.dot(n);
    let t = push - n * along;
    if along > 0.0 && t.length() <= SNAP {
        return Verdict::Face;
    }
    // Which edges do the contact points lie on? Only those that bend away can tilt.
    let tol = FEATURE_TOL * size;
    let mut active = [(Vec3::ZERO, 0.0); 3];
    let mut count = 0;
    for k in 0..3 {
        let (a, b) = (tri.v[k], tri.v[(k + 1) % 3]);
        let bend = tri.bends[k].min(std::f64::consts::FRAC_PI_2 as Real);
        let on_edge = m
            .points()
            .iter()
            .any(|p| segment_distance(p.point_b, a, b) <= tol);
        if on_edge && bend > ANGLE_TOL {
            active[count] = (tri.edge_out(k), bend);
            count += 1;
        }
    }
    let active = &active[..count];
    let slack = ANGLE_TOL.sin();
    // A coefficient of tilt towards an edge is allowed if it leans out (not in) and stays
    // within that edge's fan.
    let fits = |c: Real, bend: Real| c >= -slack && c.atan2(along) <= bend + ANGLE_TOL;
    for &(o, bend) in active {
        // One edge: the tilt must point straight out over it.
        let c = t.dot(o);
        if (t - o * c).length() <= slack && fits(c, bend) {
            return Verdict::Edge;
        }
    }
    for (i, &(o1, b1)) in active.iter().enumerate() {
        for &(o2, b2) in &active[i + 1..] {
            // Two edges (a vertex): t = a·o1 + b·o2, solved in the face plane, where two
            // edges of a triangle are never parallel.
            let d = o1.dot(o2);
            let det = 1.0 - d * d;
            if det <= 1e-6 {
                continue;
            }
            let (t1, t2) = (t.dot(o1), t.dot(o2));
            let (a, b) = ((t1 - d * t2) / det, (t2 - d * t1) / det);
            if fits(a, b1) && fits(b, b2) {
                return Verdict::Edge;
            }
        }
    }
    Verdict::Ghost
}

/// Distance from `p` to the segment a–b.
fn segment_distance(p: Vec3, a: Vec3, b: Vec3) -> Real {
    let ab = b - a;
    let len2 = ab.length_squared();
    let s = if len2 > 0.0 {
        ((p - a).dot(ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + ab * s - p).length()
}

/// The contact of the convex with the triangle along the face normal alone: the convex's
/// feature facing the triangle (a face, segment or point), clipped to the prism over the
/// triangle, keeping the points within `margin` of the plane.
fn face_contact(a: &Convex, pa: &Pose, tri: &Tri, margin: Real) -> Manifold {
    let n = tri.n;
    let mut m = Manifold::new(-n);
    let feature = incident_feature(a, pa, -n);
    // The prism's side planes, o_k·(x − v_k) ≤ slack: a few ulps of slack keep a point
    // exactly on a shared edge in both neighbours (the duplicate is dropped later) rather
    // than in neither.
    let slack = 100.0 * EPSILON * (tri.size() + tri.v[0].abs().max_element());
    let planes: [(Vec3, Real); 3] = std::array::from_fn(|k| {
        let o = tri.edge_out(k);
        (o, o.dot(tri.v[k]) + slack)
    });
    let clipped = clip(&feature, &planes);
    let candidates: Vec<Candidate> = clipped
        .iter()
        .filter_map(|&(q, feature)| {
            let h = n.dot(q - tri.v[0]);
            (h <= margin).then(|| Candidate {
                point_a: q,
                point_b: q - n * h,
                feature,
            })
        })
        .collect();
    reduce(&candidates, margin, &mut m);
    m
}

/// A point of a clipped feature with its feature id (vertex of the convex: (0, vertex,
/// face, 0); crossing of the convex's edge j with the triangle's side k: (1, j, 1, k)).
type Tagged = (Vec3, u32);

/// The convex's face, edge or vertex most nearly facing the world direction `dir`, as a
/// cyclic polygon (one or two points for a vertex or segment), world frame.
fn incident_feature(a: &Convex, pa: &Pose, dir: Vec3) -> Vec<Tagged> {
    let d = pa.inverse_transform_vector(dir);
    match a {
        Convex::Box { half_extents: h } => to_world(pa, box_face(*h, d)),
        Convex::Hull(hull) => {
            hull_face(hull, pa, d).unwrap_or_else(|| to_world(pa, vec![a.support(d)]))
        }
        Convex::Capsule {
            radius,
            half_height,
        } => to_world(pa, capsule_feature(*radius, *half_height, d)),
        Convex::Cylinder {
            radius,
            half_height,
        } => to_world(pa, cylinder_feature(*radius, *half_height, d)),
        Convex::Triangle(t) => to_world(pa, t.to_vec()),
        Convex::Sphere { .. } => to_world(pa, vec![a.support(d)]),
    }
}

/// Points of the convex's frame to world, numbered by their order in the feature (for
/// features whose points carry no vertex index of their own).
fn to_world(pa: &Pose, pts: Vec<Vec3>) -> Vec<Tagged> {
    pts.into_iter()
        .enumerate()
        .map(|(i, p)| (pa.transform_point(p), feature_id(0, i as u32, 2, 0)))
        .collect()
}

/// The box face most nearly along the local direction `d`: its four corners (local frame).
fn box_face(h: Vec3, d: Vec3) -> Vec<Vec3> {
    let ax = if d.x.abs() >= d.y.abs() && d.x.abs() >= d.z.abs() {
        0
    } else if d.y.abs() >= d.z.abs() {
        1
    } else {
        2
    };
    let (b, c) = ((ax + 1) % 3, (ax + 2) % 3);
    let s = if d[ax] < 0.0 { -1.0 } else { 1.0 };
    let corner = |u: Real, v: Real| {
        let mut p = Vec3::ZERO;
        p[ax] = s * h[ax];
        p[b] = u * h[b];
        p[c] = v * h[c];
        p
    };
    vec![
        corner(-1.0, -1.0),
        corner(1.0, -1.0),
        corner(1.0, 1.0),
        corner(-1.0, 1.0),
    ]
}

/// The hull face whose normal is most nearly along the local direction `d` (the first on
/// ties), world frame, numbered by the hull's vertex indices; `None` for a hull without faces.
fn hull_face(hull: &ConvexHull, pa: &Pose, d: Vec3) -> Option<Vec<Tagged>> {
    let mut best: Option<(usize, Real)> = None;
    for (i, (n, _)) in hull.face_planes().iter().enumerate() {
        let score = n.dot(d);
        if best.is_none_or(|(_, s)| score > s) {
            best = Some((i, score));
        }
    }
    let (f, _) = best?;
    let v = hull.vertices();
    Some(
        hull.face_vertices(f)
            .iter()
            .filter_map(|&k| {
                v.get(k as usize)
                    .map(|&p| (pa.transform_point(p), feature_id(0, k, 2, 0)))
            })
            .collect(),
    )
}

/// A capsule's facing feature (local frame): its shaft offset by the radius towards `d`, or
/// one point if it has no shaft.
fn capsule_feature(radius: Real, half_height: Real, d: Vec3) -> Vec<Vec3> {
    let off = d.normalize_or_zero() * radius;
    let top = Vec3::new(0.0, half_height, 0.0);
    if half_height > 0.0 {
        vec![top + off, -top + off]
    } else {
        vec![off]
    }
}

/// A cylinder's facing feature (local frame): its cap when `d` runs mostly along the axis,
/// otherwise the side line towards `d`.
fn cylinder_feature(radius: Real, half_height: Real, d: Vec3) -> Vec<Vec3> {
    let radial = Vec3::new(d.x, 0.0, d.z).normalize_or_zero();
    let u = if radial == Vec3::ZERO {
        Vec3::X
    } else {
        radial
    };
    let cap = if d.y < 0.0 { -half_height } else { half_height };
    if d.y.abs() >= std::f64::consts::FRAC_1_SQRT_2 as Real * d.length() {
        // Facing mostly along the axis: the cap, as an octagon whose first corner
        // is the exact support point (so a slightly tilted cylinder still reports
        // its lowest point).
        let w = Vec3::new(-u.z, 0.0, u.x);
        (0..8)
            .map(|k| {
                let ang = k as Real * std::f64::consts::FRAC_PI_4 as Real;
                (u * ang.cos() + w * ang.sin()) * radius + Vec3::new(0.0, cap, 0.0)
            })
            .collect()
    } else {
        let rim = u * radius;
        vec![
            rim + Vec3::new(0.0, half_height, 0.0),
            rim - Vec3::new(0.0, half_height, 0.0),
        ]
    }
}

/// Clips a point, segment or convex polygon to the half-spaces o·x ≤ d.
fn clip(feature: &[Tagged], planes: &[(Vec3, Real); 3]) -> Vec<Tagged> {
    let inside = |p: Vec3| planes.iter().all(|&(o, d)| o.dot(p) <= d);
    match feature.len() {
        0 => Vec::new(),
        1 => feature.iter().copied().filter(|f| inside(f.0)).collect(),
        2 => {
            // Parametric clip of the segment.
            let (p, q) = (feature[0].0, feature[1].0);
            let (mut s0, mut s1): (Real, Real) = (0.0, 1.0);
            let (mut id0, mut id1) = (feature[0].1, feature[1].1);
            for (k, &(o, d)) in planes.iter().enumerate() {
                let (dp, dq) = (o.dot(p) - d, o.dot(q) - d);
                if dp > 0.0 && dq > 0.0 {
                    return Vec::new();
                }
                if dp > 0.0 || dq > 0.0 {
                    let s = dp / (dp - dq);
                    let id = feature_id(1, 0, 1, k as u32);
                    if dp > 0.0 {
                        if s > s0 {
                            s0 = s;
                            id0 = id;
                        }
                    } else if s < s1 {
                        s1 = s;
                        id1 = id;
                    }
                }
            }
            if s0 > s1 {
                return Vec::new();
            }
            vec![(p + (q - p) * s0, id0), (p + (q - p) * s1, id1)]
        }
        _ => {
            // Sutherland–Hodgman, one side plane at a time.
            let mut poly: Vec<Tagged> = feature.to_vec();
            let count = poly.len() as u32;
            for (k, &(o, d)) in planes.iter().enumerate() {
                if poly.is_empty() {
                    break;
                }
                let mut next = Vec::with_capacity(poly.len() + 1);
                for i in 0..poly.len() {
                    let (p, q) = (poly[i], poly[(i + 1) % poly.len()]);
                    let (dp, dq) = (o.dot(p.0) - d, o.dot(q.0) - d);
                    if dp <= 0.0 {
                        next.push(p);
                    }
                    if (dp <= 0.0) != (dq <= 0.0) {
                        let s = dp / (dp - dq);
                        let edge = (i as u32) % count.max(1);
                        next.push((p.0 + (q.0 - p.0) * s, feature_id(1, edge, 1, k as u32)));
                    }
                }
                poly = next;
            }
            poly
        }
    }
}
