//! The separating-axis test for polytope pairs (box, hull, triangle, and a sphere's point or
//! a capsule's segment as a degenerate polytope).
//!
//! Each axis d gives sep(d) = min_B x·d − max_A x·d. The candidates are A's face normals,
//! B's face normals and the cross products of edge pairs whose arcs cross on the Gauss map
//! (only those make a face of A − B; Gregorius, GDC 2013), each tested in O(1); edge pairs
//! closer to parallel than [`super::PARALLEL_SIN`] make no axis. Face axes win ties, A's
//! before B's, within [`super::SAT_BIAS`] of the pair's size, so a resting contact does not
//! flip between equivalent answers. The winning axis names the deepest features.

use super::{Deepest, PARALLEL_SIN, SAT_BIAS};
use crate::collision::narrow_phase::clip::{segment_closest, Arc, Polytope, EDGE, FACE, VERTEX};
use crate::collision::narrow_phase::manifold::feature_id;
use crate::math::{Real, Vec3};

/// A separating-axis candidate.
#[derive(Debug, Clone, Copy)]
pub(super) enum Axis {
    /// Face i of A.
    FaceA(usize),
    /// Face j of B.
    FaceB(usize),
    /// Edge i of A against edge j of B.
    Edges(usize, usize),
}

/// The best separating axis: separation along it and the normal from A to B.
#[derive(Debug, Clone, Copy)]
pub(super) struct Sat {
    pub(super) sep: Real,
    pub(super) normal: Vec3,
    pub(super) axis: Axis,
}

pub(super) enum SatOutcome {
    /// Some axis separates by more than the cutoff.
    Apart,
    /// Neither shape has a face and no two edges cross (needle against needle).
    NoAxis,
    /// The best axis.
    Found(Sat),
}

/// The separating-axis test. Each axis d gives sep(d) = min_B x·d − max_A x·d; the largest
/// over the face normals of both and the edge cross products is the exact signed distance
/// along the best direction when penetrating (these are the face normals of A − B), and a
/// lower bound of the distance when apart.
pub(super) fn sat(pa: &Polytope, pb: &Polytope, cutoff: Real, scale: Real) -> SatOutcome {
    let bias = SAT_BIAS * scale;
    let mut face_a: Option<Sat> = None;
    for (i, &(f, d)) in pa.planes.iter().enumerate() {
        let sep = pb.min_dot(f) - d;
        if sep > cutoff {
            return SatOutcome::Apart;
        }
        if face_a.is_none_or(|s| sep > s.sep) {
            face_a = Some(Sat {
                sep,
                normal: f,
                axis: Axis::FaceA(i),
            });
        }
    }
    let mut face_b: Option<Sat> = None;
    for (j, &(g, e)) in pb.planes.iter().enumerate() {
        let sep = pa.min_dot(g) - e;
        if sep > cutoff {
            return SatOutcome::Apart;
        }
        if face_b.is_none_or(|s| sep > s.sep) {
            face_b = Some(Sat {
                sep,
                normal: -g,
                axis: Axis::FaceB(j),
            });
        }
    }
    let edge = match (pa.arcs(), pb.arcs()) {
        (Some(arcs_a), Some(arcs_b)) => gauss_map_edges(pa, &arcs_a, pb, &arcs_b, cutoff),
        _ => all_edge_pairs(pa, pb, cutoff),
    };
    let edge = match edge {
        EdgeAxis::Apart => return SatOutcome::Apart,
        EdgeAxis::None => None,
        EdgeAxis::Best(sep, n, ea, eb) => Some((sep, n, ea, eb)),
    };
    let mut best = match (face_a, face_b) {
        (Some(a), Some(b)) => Some(if b.sep > a.sep + bias { b } else { a }),
        (a, b) => a.or(b),
    };
    if let Some((sep, n, ea, eb)) = edge {
        if best.is_none_or(|b| sep > b.sep + bias) {
            best = Some(Sat {
                sep,
                normal: n,
                axis: Axis::Edges(ea, eb),
            });
        }
    }
    match best {
        Some(s) if s.sep.is_finite() && s.normal.is_finite() => SatOutcome::Found(s),
        _ => SatOutcome::NoAxis,
    }
}

/// The best edge–edge axis.
enum EdgeAxis {
    /// It separates by more than the cutoff.
    Apart,
    /// No edge pair gives an axis.
    None,
    /// Separation, normal (A to B), and the edges of A and B.
    Best(Real, Vec3, usize, usize),
}

/// An arc with the normal of its great circle, b × a, precomputed.
struct GaussArc {
    a: Vec3,
    b: Vec3,
    bxa: Vec3,
    edge: usize,
}

impl GaussArc {
    fn new(a: Vec3, b: Vec3, edge: usize) -> GaussArc {
        GaussArc {
            a,
            b,
            bxa: b.cross(a),
            edge,
        }
    }
}

/// Whether arc (a, b) of A and arc (c, d) of −B cross on the Gauss map, i.e. whether the
/// two edges make a face of A − B, whose normal is then their cross product (Gregorius,
/// "The separating axis test between convex polyhedra", GDC 2013). They cross when c and
/// d lie on opposite sides of the plane of a and b, a and b on opposite sides of the plane
/// of c and d, and the arcs lie in the same hemisphere (the last sign test rejects the
/// antipodal crossing of the two great circles). The first test rejects most pairs.
#[inline]
fn minkowski_face(p: &GaussArc, q: &GaussArc) -> bool {
    let cba = q.a.dot(p.bxa);
    let dba = q.b.dot(p.bxa);
    if cba * dba >= 0.0 {
        return false;
    }
    let adc = p.a.dot(q.bxa);
    let bdc = p.b.dot(q.bxa);
    adc * bdc < 0.0 && cba * bdc > 0.0
}

/// Edge axes through the Gauss map: only edge pairs making a face of A − B, each in O(1):
/// the axis lies on A's arc, so orient it towards a + b, and then A's edge is A's support
/// along it and B's edge B's support against it, so sep = axis·(q − p) for any p on A's edge
/// and q on B's.
fn gauss_map_edges(
    pa: &Polytope,
    arcs_a: &[Arc],
    pb: &Polytope,
    arcs_b: &[Arc],
    cutoff: Real,
) -> EdgeAxis {
    let ga: Vec<GaussArc> = arcs_a
        .iter()
        .map(|r| GaussArc::new(r.a, r.b, r.edge))
        .collect();
    // B's normals enter A − B negated.
    let gb: Vec<GaussArc> = arcs_b
        .iter()
        .map(|r| GaussArc::new(-r.a, -r.b, r.edge))
        .collect();
    let mut best = EdgeAxis::None;
    let mut best_sep = Real::NEG_INFINITY;
    for ra in &ga {
        let ea = pa.edges()[ra.edge];
        let (p0, p1) = (pa.verts[ea[0] as usize], pa.verts[ea[1] as usize]);
        let ua = p1 - p0;
        for rb in &gb {
            if !minkowski_face(ra, rb) {
                continue;
            }
            let eb = pb.edges()[rb.edge];
            let (q0, q1) = (pb.verts[eb[0] as usize], pb.verts[eb[1] as usize]);
            let ub = q1 - q0;
            let c = ua.cross(ub);
            let len = c.length();
            if len <= PARALLEL_SIN * ua.length() * ub.length() || len == 0.0 {
                continue;
            }
            let mut n = c / len;
            if n.dot(ra.a + ra.b) < 0.0 {
                n = -n;
            }
            let sep = n.dot(q0 - p0);
            if sep > cutoff {
                return EdgeAxis::Apart;
            }
            if sep > best_sep {
                best_sep = sep;
                best = EdgeAxis::Best(sep, n, ra.edge, rb.edge);
            }
        }
    }
    best
}

/// Edge axes without a Gauss map (segments): every pair of distinct edge directions, each
/// orientation, by full projection. Then the touching edges of the best pair: A's furthest
/// along the normal, B's furthest against it (both ends count, so a whole edge wins over a
/// vertex).
fn all_edge_pairs(pa: &Polytope, pb: &Polytope, cutoff: Real) -> EdgeAxis {
    let (dirs_a, groups_a) = edge_directions(pa);
    let (dirs_b, groups_b) = edge_directions(pb);
    let mut edge: Option<(Real, Vec3, usize, usize)> = None;
    for (ga, ua) in dirs_a.iter().enumerate() {
        for (gb, ub) in dirs_b.iter().enumerate() {
            let c = ua.cross(*ub);
            let len = c.length();
            if len <= PARALLEL_SIN {
                continue;
            }
            let c = c / len;
            let (alo, ahi) = pa.range(c);
            let (blo, bhi) = pb.range(c);
            // Either orientation of the axis may be the separating one.
            let (sep, n) = if blo - ahi >= alo - bhi {
                (blo - ahi, c)
            } else {
                (alo - bhi, -c)
            };
            if sep > cutoff {
                return EdgeAxis::Apart;
            }
            if edge.is_none_or(|e| sep > e.0) {
                edge = Some((sep, n, ga, gb));
            }
        }
    }
    let Some((sep, n, ga, gb)) = edge else {
        return EdgeAxis::None;
    };
    let pick = |p: &Polytope, groups: &[usize], g: usize, s: Real| {
        let mut pick: Option<(usize, Real)> = None;
        for (k, e) in p.edges().iter().enumerate() {
            if groups[k] != g {
                continue;
            }
            let x = s * (p.verts[e[0] as usize] + p.verts[e[1] as usize]).dot(n);
            if pick.is_none_or(|(_, b)| x > b) {
                pick = Some((k, x));
            }
        }
        pick.map_or(0, |(k, _)| k)
    };
    EdgeAxis::Best(
        sep,
        n,
        pick(pa, &groups_a, ga, 1.0),
        pick(pb, &groups_b, gb, -1.0),
    )
}

/// The distinct edge directions (unit) of a polytope, and each edge's direction index
/// (`usize::MAX` for zero-length edges).
fn edge_directions(p: &Polytope) -> (Vec<Vec3>, Vec<usize>) {
    let mut dirs: Vec<Vec3> = Vec::new();
    let mut groups = Vec::with_capacity(p.edges().len());
    for e in p.edges() {
        let u = (p.verts[e[1] as usize] - p.verts[e[0] as usize]).normalize_or_zero();
        if u == Vec3::ZERO || !u.is_finite() {
            groups.push(usize::MAX);
            continue;
        }
        match dirs
            .iter()
            .position(|d| d.cross(u).length() <= PARALLEL_SIN)
        {
            Some(g) => groups.push(g),
            None => {
                groups.push(dirs.len());
                dirs.push(u);
            }
        }
    }
    (dirs, groups)
}

/// The deepest points along a separating axis: for a face of one shape, the other's
/// deepest vertex and its projection onto the face plane; for two edges, their closest
/// points.
pub(super) fn sat_deepest(pa: &Polytope, pb: &Polytope, s: &Sat) -> Deepest {
    let (point_a, point_b, feature) = match s.axis {
        Axis::FaceA(i) => {
            let (f, d) = pa.planes[i];
            let k = pb.support(-f);
            let q = pb.verts[k];
            let fid = feature_id(FACE, i as u32, VERTEX, k as u32);
            (q - f * (q.dot(f) - d), q, fid)
        }
        Axis::FaceB(j) => {
            let (g, e) = pb.planes[j];
            let k = pa.support(-g);
            let q = pa.verts[k];
            let fid = feature_id(VERTEX, k as u32, FACE, j as u32);
            (q, q - g * (q.dot(g) - e), fid)
        }
        Axis::Edges(i, j) => {
            let (ea, eb) = (pa.edges()[i], pb.edges()[j]);
            let (p, q) = segment_closest(
                pa.verts[ea[0] as usize],
                pa.verts[ea[1] as usize],
                pb.verts[eb[0] as usize],
                pb.verts[eb[1] as usize],
            );
            (p, q, feature_id(EDGE, i as u32, EDGE, j as u32))
        }
    };
    Deepest {
        normal: s.normal,
        separation: s.sep,
        point_a,
        point_b,
        feature,
    }
}
