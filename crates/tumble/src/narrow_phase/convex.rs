//! General convex–convex contact: every convex pair without a dedicated routine (hulls,
//! cylinders, triangles of meshes, and mixed pairs such as sphere–hull or box–cylinder).
//!
//! Two paths, both in the frame of shape A (so a common rigid motion of the pair changes
//! nothing but rounding):
//!
//! * **Polytope pairs** (box, hull, triangle against each other): GJK first proves most
//!   pairs apart beyond the margin in a few support calls; the rest get the separating-axis
//!   test over A's face normals, B's face normals and the cross products of edge pairs. Only
//!   edge pairs whose arcs cross on the Gauss map are tested (they are the ones that make a
//!   face of A − B; Gregorius, GDC 2013), each in O(1). The test is exact for polytopes,
//!   separated or penetrating, and names the features: a face axis clips the other shape's
//!   most anti-parallel face against that face; an edge axis gives the closest points of the
//!   two edges. Face axes win ties, A's faces before B's, within [`SAT_BIAS`] of the pair's
//!   size, so a resting contact does not flip between equivalent answers. This is the test
//!   the dedicated box–box routine makes, so a box-shaped hull gets the box's manifold.
//! * **Everything else** (a round core or a cylinder involved): GJK on the cores, then the
//!   radii subtracted. Cores apart (the usual case, including every shallow contact of a
//!   sphere or capsule) give the exact closest points and normal. Overlapping cores go to the
//!   separating-axis test when both cores are polytopes (a sphere's point or a capsule's
//!   segment against a polytope: exact) and to EPA when a cylinder is involved (its answer
//!   checked against the cylinder's axis and radial directions, towards which EPA converges
//!   slowly when the nearest boundary of A − B is a whole ring). The normal then picks a
//!   facing feature on each shape (`clip.rs`) and the two are clipped together; the deepest
//!   point itself is added when the clipped points miss its depth by more than
//!   [`WITNESS_TOL`] of the pair's size (a cylinder's cap is clipped as an octagon).
//!
//! Mixed pairs are always computed in one order (by kind) and flipped if asked the other
//! way, so swapping the pair flips the normal exactly.

use super::clip::{
    feature, features_contact, segment_closest, select, Arc, Feature, Polytope, EDGE, FACE, VERTEX,
};
use super::epa::epa;
use super::gjk::{gjk, Gjk, Pair, Status};
use super::manifold::{feature_id, reduce, Candidate, FeatureId};
use super::Manifold;
use crate::geometry::{Convex, Pose};
use crate::math::{Real, Vec3};

/// Edge directions closer to parallel than this sine make no separating axis: their
/// cross product is rounding noise, and the face axes cover parallel edges.
#[cfg(not(feature = "f32"))]
const PARALLEL_SIN: Real = 1e-6;
#[cfg(feature = "f32")]
const PARALLEL_SIN: Real = 1e-3;

/// A later axis (B's face over A's, an edge over a face) must separate by this fraction of
/// the pair's size more to be chosen: ties stay on the first, stable answer.
#[cfg(not(feature = "f32"))]
const SAT_BIAS: Real = 1e-6;
#[cfg(feature = "f32")]
const SAT_BIAS: Real = 1e-4;

/// Contact points whose scores (depth, spread) differ by less than this fraction of the
/// pair's size are treated as equal when choosing four of them, so a resting contact keeps
/// its points.
const TIE_TOL: Real = 1e-4;

/// The deepest point is added to the clipped points when they miss its depth by more than
/// this fraction of the pair's size. A cap octagon tilted by θ misses at most
/// r·sin θ·(1 − cos 22.5°) ≈ 0.076·r·θ; below the threshold (θ under about 1e-4) the
/// resting contact keeps its four points and ids rather than gain and lose one with every
/// wobble, at the price of a depth short by at most this much.
const WITNESS_TOL: Real = 1e-5;

/// An axis tried after EPA replaces EPA's normal only when it separates the cores by this
/// fraction of the pair's size more: EPA's own rounding is far below it, the slow
/// convergence it corrects (a nearest boundary that is a whole ring) far above.
#[cfg(not(feature = "f32"))]
const REFINE_TOL: Real = 1e-8;
#[cfg(feature = "f32")]
const REFINE_TOL: Real = 1e-5;

/// Convex `a` at `pa` against convex `b` at `pb`.
pub fn convex_convex(
    a: &Convex,
    pa: &Pose,
    b: &Convex,
    pb: &Pose,
    margin: Real,
    out: &mut Manifold,
) -> bool {
    let (sub_a, sub_b) = (out.subshape_a, out.subshape_b);
    let hit = if rank(b) < rank(a) {
        let hit = ordered(b, pb, a, pa, margin, out);
        *out = out.swapped();
        hit
    } else {
        ordered(a, pa, b, pb, margin, out)
    };
    out.subshape_a = sub_a;
    out.subshape_b = sub_b;
    hit
}

/// The order pairs are computed in: polytopes first, so they are the reference on ties.
fn rank(c: &Convex) -> u8 {
    match c {
        Convex::Box { .. } => 0,
        Convex::Hull(_) => 1,
        Convex::Triangle(_) => 2,
        Convex::Sphere { .. } => 3,
        Convex::Capsule { .. } => 4,
        Convex::Cylinder { .. } => 5,
    }
}

fn is_polytope(c: &Convex) -> bool {
    matches!(
        c,
        Convex::Box { .. } | Convex::Hull(_) | Convex::Triangle(_)
    )
}

/// `convex_convex` for one order of the pair.
fn ordered(a: &Convex, pa: &Pose, b: &Convex, pb: &Pose, margin: Real, out: &mut Manifold) -> bool {
    out.clear();
    let margin = if margin.is_nan() { 0.0 } else { margin };
    let pair = Pair::new(a, pa, b, pb);
    if !pair.is_finite() || !pa.position.is_finite() || !pa.rotation.is_finite() {
        return false;
    }
    let core_a = Polytope::of_core(a, &Pose::IDENTITY);
    let core_b = Polytope::of_core(b, &pair.rel);
    let mut cands = Vec::new();
    let normal = match (&core_a, &core_b) {
        (Some(ca), Some(cb)) if is_polytope(a) && is_polytope(b) => {
            polytope_contact(&pair, ca, cb, margin, &mut cands)
        }
        _ => generic_contact(&pair, core_a.as_ref(), core_b.as_ref(), margin, &mut cands),
    };
    let Some(n) = normal else {
        return false;
    };
    out.normal = pa.transform_vector(n);
    let world: Vec<Candidate> = cands
        .iter()
        .map(|c| Candidate {
            point_a: pa.transform_point(c.point_a),
            point_b: pa.transform_point(c.point_b),
            feature: c.feature,
        })
        .collect();
    reduce(
        &select(&world, out.normal, margin, TIE_TOL * pair.scale),
        margin,
        out,
    );
    let finite = out.normal.is_finite()
        && out
            .points()
            .iter()
            .all(|p| p.point_a.is_finite() && p.point_b.is_finite() && p.separation.is_finite());
    if !finite {
        out.clear();
        return false;
    }
    !out.is_empty()
}

/// The contact normal and the nearest (or deepest) pair of core points, working frame.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Deepest {
    /// Unit normal from A to B.
    pub normal: Vec3,
    /// Between the cores: their distance when apart, minus the depth when overlapping (m).
    pub separation: Real,
    /// On A's core.
    pub point_a: Vec3,
    /// On B's core.
    pub point_b: Vec3,
    /// The features of the two points.
    pub feature: FeatureId,
}

/// The nearest or deepest points of the cores of `pair`, or `None` once GJK proves the cores
/// further apart than `cutoff`.
pub(crate) fn deepest(
    pair: &Pair,
    core_a: Option<&Polytope>,
    core_b: Option<&Polytope>,
    cutoff: Real,
) -> Option<Deepest> {
    resolve(pair, &gjk(pair, cutoff), core_a, core_b)
}

/// [`deepest`] after its GJK run `g`: the cores are only read when they overlap.
fn resolve(
    pair: &Pair,
    g: &Gjk,
    core_a: Option<&Polytope>,
    core_b: Option<&Polytope>,
) -> Option<Deepest> {
    match g.status {
        Status::BeyondCutoff => None,
        Status::Separated => {
            let (pa, pb) = g.simplex.witnesses();
            Some(Deepest {
                normal: g.normal(),
                separation: g.distance(),
                point_a: pa,
                point_b: pb,
                feature: 0,
            })
        }
        Status::Overlap => {
            if let (Some(a), Some(b)) = (core_a, core_b) {
                if let SatOutcome::Found(s) = sat(a, b, Real::INFINITY, pair.scale) {
                    return Some(sat_deepest(a, b, &s));
                }
            } else if let Some(p) = epa(pair, &g.simplex) {
                let found = Deepest {
                    normal: p.normal,
                    separation: -p.depth,
                    point_a: p.point_a,
                    point_b: p.point_b,
                    feature: 0,
                };
                // EPA converges slowly where the nearest boundary of A − B is a whole ring
                // (a core sunk radially into a cylinder, near its axis); there the radial
                // direction through the other core, or the axis, is the answer.
                let mut dirs = Vec::with_capacity(6);
                cylinder_axes(
                    &pair.a,
                    &Pose::IDENTITY,
                    &[pair.rel.position, p.point_b],
                    &mut dirs,
                );
                cylinder_axes(&pair.b, &pair.rel, &[Vec3::ZERO, p.point_a], &mut dirs);
                return Some(best_axis(pair, found, &dirs));
            }
            let start = Deepest {
                normal: Vec3::X,
                separation: Real::NEG_INFINITY,
                point_a: Vec3::ZERO,
                point_b: pair.rel.position,
                feature: 0,
            };
            let r = pair.rel.rotation;
            let dirs = [
                -g.v,
                pair.rel.position,
                Vec3::X,
                Vec3::Y,
                Vec3::Z,
                r * Vec3::X,
                r * Vec3::Y,
                r * Vec3::Z,
            ];
            Some(best_axis(pair, start, &dirs))
        }
    }
}

/// A cylinder's axis and the radial directions from its axis through `points` (working
/// frame), appended to `out`; nothing for other shapes.
fn cylinder_axes(c: &Convex, pose: &Pose, points: &[Vec3], out: &mut Vec<Vec3>) {
    if let Convex::Cylinder { .. } = c {
        let u = pose.transform_vector(Vec3::Y);
        out.push(u);
        for q in points {
            let r = *q - pose.position;
            out.push(r - u * r.dot(u));
        }
    }
}

/// The best of `start` and the axes `dirs` (each both ways) by direct support projection,
/// sep(d) = min_B x·d − max_A x·d. Every axis's overlap bounds the depth from above and is
/// the overlap along it, so the largest separation is the best answer among them. `start`
/// is replaced only by an axis better by [`REFINE_TOL`] of the pair's size, so a converged
/// answer is not traded for one equal to rounding. Witnesses: `start`'s, when it has them,
/// moved along the new axis onto each shape's supporting plane (they stay in the contact
/// region; a support point on a flat face could be any of its corners), else the two
/// support points. Used when no exact method applies (flat Minkowski differences, EPA
/// broken down) and to check EPA against the axes it converges slowly to.
fn best_axis(pair: &Pair, start: Deepest, dirs: &[Vec3]) -> Deepest {
    let mut best = start;
    let mut best_sep = start.separation + REFINE_TOL * pair.scale;
    for d in dirs {
        let d = d.normalize_or_zero();
        if d == Vec3::ZERO || !d.is_finite() {
            continue;
        }
        for s in [d, -d] {
            let a = pair.a.core_support(s);
            let b = pair.support_b(-s);
            let sep = (b - a).dot(s);
            if sep > best_sep {
                best_sep = sep;
                let (point_a, point_b) = if start.separation.is_finite() {
                    (
                        start.point_a + s * (a - start.point_a).dot(s),
                        start.point_b + s * (b - start.point_b).dot(s),
                    )
                } else {
                    (a, b)
                };
                best = Deepest {
                    normal: s,
                    separation: sep,
                    point_a,
                    point_b,
                    feature: 0,
                };
            }
        }
    }
    if !best.separation.is_finite() {
        best.separation = 0.0;
    }
    best
}

/// A separating-axis candidate.
#[derive(Debug, Clone, Copy)]
enum Axis {
    /// Face i of A.
    FaceA(usize),
    /// Face j of B.
    FaceB(usize),
    /// Edge i of A against edge j of B.
    Edges(usize, usize),
}

/// The best separating axis: separation along it and the normal from A to B.
#[derive(Debug, Clone, Copy)]
struct Sat {
    sep: Real,
    normal: Vec3,
    axis: Axis,
}

enum SatOutcome {
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
fn sat(pa: &Polytope, pb: &Polytope, cutoff: Real, scale: Real) -> SatOutcome {
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
fn sat_deepest(pa: &Polytope, pb: &Polytope, s: &Sat) -> Deepest {
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

/// The face of `p` most aligned with `dir`, or its facing edge or vertex if it has none.
fn incident(p: &Polytope, dir: Vec3) -> Feature {
    match p.best_face(dir) {
        Some((i, _)) => p.face_feature(i),
        None => p.feature(dir, 0.0),
    }
}

/// Polytope against polytope by the separating-axis test; candidates in the working frame.
fn polytope_contact(
    pair: &Pair,
    ca: &Polytope,
    cb: &Polytope,
    margin: Real,
    cands: &mut Vec<Candidate>,
) -> Option<Vec3> {
    // Most pairs the broad phase passes are apart: GJK proves it in a few support calls,
    // where the separating-axis test would try every face and edge pair.
    if gjk(pair, margin.max(0.0)).status == Status::BeyondCutoff {
        return None;
    }
    let s = match sat(ca, cb, margin, pair.scale) {
        SatOutcome::Apart => return None,
        SatOutcome::NoAxis => return generic_contact(pair, Some(ca), Some(cb), margin, cands),
        SatOutcome::Found(s) => s,
    };
    let n = s.normal;
    match s.axis {
        Axis::FaceA(i) => super::clip::clip(&ca.face_feature(i), &incident(cb, -n), n, true, cands),
        Axis::FaceB(j) => super::clip::clip(&cb.face_feature(j), &incident(ca, n), n, false, cands),
        Axis::Edges(..) => {}
    }
    // An edge axis, or clipping that lost the deepest vertex: the deepest pair itself.
    if !cands
        .iter()
        .any(|c| (c.point_b - c.point_a).dot(n) <= margin)
    {
        let d = sat_deepest(ca, cb, &s);
        cands.push(Candidate {
            point_a: d.point_a,
            point_b: d.point_b,
            feature: d.feature,
        });
    }
    Some(n)
}

/// Any pair through GJK (then SAT or EPA) on the cores, feature selection and clipping.
fn generic_contact(
    pair: &Pair,
    core_a: Option<&Polytope>,
    core_b: Option<&Polytope>,
    margin: Real,
    cands: &mut Vec<Candidate>,
) -> Option<Vec3> {
    let (ra, rb) = (pair.a.radius(), pair.b.radius());
    let deep = deepest(pair, core_a, core_b, margin + ra + rb)?;
    let n = deep.normal;
    let sep = deep.separation - ra - rb;
    if sep.is_nan() || sep > margin || !n.is_finite() {
        return None;
    }
    let fa = feature(&pair.a, core_a, &Pose::IDENTITY, n);
    let fb = feature(&pair.b, core_b, &pair.rel, -n);
    features_contact(&fa, &fb, n, cands);
    // The deepest point itself, when the clipped points miss it by more than rounding
    // (an octagonal cap tilted on a face: the deepest rim point lies between corners). It
    // goes first, so that the selection's tie rule picks it as the anchor.
    let deepest_clipped = cands
        .iter()
        .map(|c| (c.point_b - c.point_a).dot(n))
        .fold(Real::INFINITY, Real::min);
    if cands.is_empty() || sep < deepest_clipped - WITNESS_TOL * pair.scale {
        cands.insert(
            0,
            Candidate {
                point_a: deep.point_a + n * ra,
                point_b: deep.point_b - n * rb,
                feature: feature_id(fa.kind, fa.index, fb.kind, fb.index),
            },
        );
    }
    Some(n)
}

/// The signed distance between two convex shapes and the points that realise it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClosestPoints {
    /// Distance between the surfaces (m): positive apart, negative overlapping (then minus
    /// the penetration depth along `normal`).
    pub distance: Real,
    /// Unit normal from A to B, world frame: moving B by `−distance · normal` makes the
    /// shapes just touch.
    pub normal: Vec3,
    /// The point of A's surface nearest B (deepest in B when overlapping), world frame (m).
    pub point_a: Vec3,
    /// The point of B's surface nearest A, world frame (m).
    pub point_b: Vec3,
}

/// The signed distance between convex `a` at `pa` and convex `b` at `pb`: GJK on the cores
/// (exact for polytopes and round shapes; for cylinders to 1e-12 relative in distance, the
/// normal between two curved surfaces to about 1e-6 rad, 1e-3 in f32), then the radii
/// subtracted; overlapping cores go to the separating-axis test (polytope cores) or EPA
/// (cylinders). Never NaN: non-finite poses give an infinite distance.
pub fn closest_points(a: &Convex, pa: &Pose, b: &Convex, pb: &Pose) -> ClosestPoints {
    let Some(pair) = finite_pair(a, pa, b, pb) else {
        return ClosestPoints {
            distance: Real::INFINITY,
            normal: Vec3::X,
            point_a: Vec3::ZERO,
            point_b: Vec3::ZERO,
        };
    };
    // The cores as polytopes (two heap lists each) serve only overlapping cores; apart,
    // the usual case (every step of a time-of-impact search), GJK's answer is final.
    let g = gjk(&pair, Real::INFINITY);
    let d = if g.status == Status::Overlap {
        let core_a = Polytope::of_core(a, &Pose::IDENTITY);
        let core_b = Polytope::of_core(b, &pair.rel);
        resolve(&pair, &g, core_a.as_ref(), core_b.as_ref())
    } else {
        resolve(&pair, &g, None, None)
    };
    let d = d.unwrap_or(Deepest {
        normal: Vec3::X,
        separation: Real::INFINITY,
        point_a: Vec3::ZERO,
        point_b: pair.rel.position,
        feature: 0,
    });
    let (ra, rb) = (a.radius(), b.radius());
    ClosestPoints {
        distance: d.separation - ra - rb,
        normal: pa.transform_vector(d.normal),
        point_a: pa.transform_point(d.point_a + d.normal * ra),
        point_b: pa.transform_point(d.point_b - d.normal * rb),
    }
}

/// Whether convex `a` at `pa` and `b` at `pb` are at most `limit` apart, overlapping
/// included: [`closest_points`]`.distance <= limit`, by GJK alone, stopped once it proves
/// the answer either way. Overlapping cores need no depth (the separating-axis test that
/// `closest_points` runs for them, with its polytopes, was most of the cost of asking this
/// about bodies that end a sweep interpenetrating).
pub(crate) fn within(a: &Convex, pa: &Pose, b: &Convex, pb: &Pose, limit: Real) -> bool {
    let Some(pair) = finite_pair(a, pa, b, pb) else {
        return false;
    };
    let rounding = a.radius() + b.radius();
    let g = gjk(&pair, limit + rounding);
    match g.status {
        Status::BeyondCutoff => false,
        Status::Overlap => true,
        Status::Separated => g.distance() - rounding <= limit,
    }
}

/// The pair in A's frame, or `None` when a pose is not finite (no distance to find).
fn finite_pair<'a>(a: &'a Convex, pa: &Pose, b: &'a Convex, pb: &Pose) -> Option<Pair<'a>> {
    let pair = Pair::new(a, pa, b, pb);
    (pair.is_finite() && pa.position.is_finite() && pa.rotation.is_finite()).then_some(pair)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Exact-arithmetic answers to rounding: f64 or f32.
    const EPS: Real = if std::mem::size_of::<Real>() == 8 {
        1e-9
    } else {
        2e-5
    };

    fn cube() -> Convex<'static> {
        Convex::Box {
            half_extents: Vec3::splat(0.5),
        }
    }

    #[test]
    fn resting_boxes_by_sat() {
        let pb = Pose::from_translation(Vec3::new(0.1, 0.99, 0.0));
        let c = cube();
        let mut pair = Pair::new(&c, &Pose::IDENTITY, &c, &pb);
        pair.scale = 1.0;
        let ca = Polytope::of_core(&c, &Pose::IDENTITY).unwrap();
        let cb = Polytope::of_core(&c, &pair.rel).unwrap();
        let mut cands = Vec::new();
        let n = polytope_contact(&pair, &ca, &cb, 0.0, &mut cands).unwrap();
        assert!((n - Vec3::Y).length() < 1e-6);
        assert_eq!(cands.len(), 4);
        for c in &cands {
            assert!(((c.point_b - c.point_a).dot(n) + 0.01).abs() < 1e-6);
        }
    }

    #[test]
    fn edge_on_edge_by_sat() {
        // Two cubes turned 45° about crossing axes meet edge to edge.
        let c = cube();
        let s = (0.5 as Real).sqrt();
        let pa = Pose::new(
            Vec3::ZERO,
            crate::math::Quat::from_rotation_z(std::f64::consts::FRAC_PI_4 as Real),
        );
        let pb = Pose::new(
            Vec3::new(0.0, 2.0 * s - 0.02, 0.0),
            crate::math::Quat::from_rotation_x(std::f64::consts::FRAC_PI_4 as Real),
        );
        let cp = closest_points(&c, &pa, &c, &pb);
        assert!((cp.distance + 0.02).abs() < 1e-5, "{cp:?}");
        assert!((cp.normal - Vec3::Y).length() < 1e-5);
        let mut m = Manifold::default();
        assert!(convex_convex(&c, &pa, &c, &pb, 0.0, &mut m));
        assert_eq!(m.len(), 1);
        assert!((m.points()[0].separation + 0.02).abs() < 1e-5);
    }

    fn tri() -> Convex<'static> {
        // Counter-clockwise seen from +y: its front normal is +y.
        Convex::Triangle([
            Vec3::new(-2.0, 0.0, 2.0),
            Vec3::new(2.0, 0.0, 2.0),
            Vec3::new(0.0, 0.0, -2.0),
        ])
    }

    #[test]
    fn box_resting_on_a_triangle() {
        let pb = Pose::new(
            Vec3::new(0.1, 0.5 - 0.002, 0.3),
            crate::math::Quat::from_rotation_y(0.5),
        );
        let mut m = Manifold::default();
        assert!(convex_convex(
            &tri(),
            &Pose::IDENTITY,
            &cube(),
            &pb,
            0.01,
            &mut m
        ));
        assert!((m.normal - Vec3::Y).length() < EPS, "{m:?}");
        assert_eq!(m.len(), 4);
        for p in m.points() {
            assert!((p.separation + 0.002).abs() < EPS, "{m:?}");
            assert!(p.point_a.y.abs() < EPS);
        }
        // The other order flips the normal and keeps the points.
        let mut r = Manifold::default();
        assert!(convex_convex(
            &cube(),
            &pb,
            &tri(),
            &Pose::IDENTITY,
            0.01,
            &mut r
        ));
        assert!((r.normal + Vec3::Y).length() < EPS);
        assert!((r.min_separation() - m.min_separation()).abs() < EPS);
    }

    #[test]
    fn box_edge_across_a_triangle_edge() {
        // A cube turned 45° about z, its lower edge crossing the triangle's edge x = −1 ... z.
        let t = Convex::Triangle([
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(1.0, 0.0, -1.0),
            Vec3::new(-1.0, 0.0, -1.0),
        ]);
        let h = (0.5 as Real) * (2.0 as Real).sqrt();
        let pb = Pose::new(
            Vec3::new(0.0, h - 0.01, 0.0),
            crate::math::Quat::from_rotation_z(std::f64::consts::FRAC_PI_4 as Real),
        );
        let mut m = Manifold::default();
        assert!(convex_convex(
            &t,
            &Pose::IDENTITY,
            &cube(),
            &pb,
            0.0,
            &mut m
        ));
        assert!((m.normal - Vec3::Y).length() < EPS, "{m:?}");
        assert!((m.min_separation() + 0.01).abs() < EPS, "{m:?}");
        // The box's bottom edge (along z) clipped to the triangle.
        assert_eq!(m.len(), 2, "{m:?}");
        for p in m.points() {
            assert!(p.point_b.x.abs() < EPS && p.point_b.z.abs() <= 0.5 + EPS);
        }
    }

    #[test]
    fn sphere_on_a_triangle() {
        let s = Convex::Sphere { radius: 0.5 };
        let cases = [
            // (centre, separation, normal from the triangle to the sphere)
            (Vec3::new(0.3, 0.45, 0.2), -0.05, Vec3::Y),
            (Vec3::new(0.0, -0.48, 0.0), -0.02, -Vec3::Y),
            (
                Vec3::new(0.0, 0.3, 2.4),
                0.5 - 0.5,
                Vec3::new(0.0, 0.6, 0.8),
            ),
            (Vec3::new(0.0, 0.0, 0.0), -0.5, Vec3::Y),
        ];
        for (c, sep, n) in cases {
            let mut m = Manifold::default();
            let hit = convex_convex(
                &tri(),
                &Pose::IDENTITY,
                &s,
                &Pose::from_translation(c),
                0.01,
                &mut m,
            );
            assert!(hit, "{c}");
            assert_eq!(m.len(), 1);
            assert!((m.points()[0].separation - sep).abs() < EPS, "{c}: {m:?}");
            if c.y != 0.0 {
                assert!((m.normal - n).length() < EPS, "{c}: {m:?}");
            } else {
                assert!(m.normal.x.abs() < EPS && m.normal.z.abs() < EPS);
            }
        }
    }

    #[test]
    fn capsule_lying_on_a_triangle() {
        let cap = Convex::Capsule {
            radius: 0.2,
            half_height: 0.5,
        };
        let pc = Pose::new(
            Vec3::new(0.0, 0.2 - 0.001, 0.0),
            crate::math::Quat::from_rotation_x(std::f64::consts::FRAC_PI_2 as Real),
        );
        let mut m = Manifold::default();
        assert!(convex_convex(
            &tri(),
            &Pose::IDENTITY,
            &cap,
            &pc,
            0.0,
            &mut m
        ));
        assert_eq!(m.len(), 2, "{m:?}");
        for p in m.points() {
            assert!((p.separation + 0.001).abs() < EPS);
            assert!((p.point_b.z.abs() - 0.5).abs() < EPS);
        }
    }
}
