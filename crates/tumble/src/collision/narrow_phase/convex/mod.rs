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
//!
//! Layout: this file holds the dispatch, the GJK/EPA path and the public closest-points
//! queries; `sat.rs` the separating-axis test of polytope pairs; `tests.rs` the tests.

mod sat;
#[cfg(test)]
mod tests;

use super::clip::{feature, features_contact, select, Feature, Polytope};
use super::epa::epa;
use super::gjk::{gjk, Gjk, Pair, Status};
use super::manifold::{feature_id, reduce, Candidate, FeatureId};
use super::Manifold;
use crate::collision::geometry::Pose;
use crate::collision::shape::Convex;
use crate::math::{Real, Vec3};
use sat::{sat, sat_deepest, Axis, SatOutcome};

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
        out.swap();
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
                return Some(opposite_the_sharp_side(pair, best_axis(pair, found, &dirs)));
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

/// EPA's witnesses are its last face's weights applied to support points, so each sits on
/// its core's surface only as well as the face fits it. Where one core's support along the
/// normal is a single point (a rim, a vertex, a ball) and the other's is a line or a face (a
/// cylinder's side, a lying capsule's segment), the single point is the contact and the
/// other witness is anywhere on its feature: a cylinder's rim sunk 14 mm into another's side
/// had the side's witness 2.3 cm along it (f64), and in f32 in another place under each
/// rigid motion of the pair. That witness is put opposite the single point instead.
fn opposite_the_sharp_side(pair: &Pair, mut d: Deepest) -> Deepest {
    let n = d.normal;
    let flat_a = spread_support(|s| pair.a.core_support(s), n, pair.scale);
    let flat_b = spread_support(|s| pair.support_b(s), -n, pair.scale);
    if flat_b && !flat_a {
        d.point_b = d.point_a + n * d.separation;
    } else if flat_a && !flat_b {
        d.point_a = d.point_b - n * d.separation;
    }
    d
}

/// Whether the support along `n` is a line or a face rather than a point: tilting `n` by
/// 10⁻³ rad moves a curved surface's support by at most 10⁻³ of its radius (below `scale`),
/// but jumps across a flat feature, by its size.
fn spread_support(support: impl Fn(Vec3) -> Vec3, n: Vec3, scale: Real) -> bool {
    const TILT: Real = 1e-3;
    let p = support(n);
    let [t1, t2] = crate::math::orthonormal_basis(n);
    [t1, -t1, t2, -t2]
        .iter()
        .any(|&t| (support(n + t * TILT) - p).length() > 10.0 * TILT * scale)
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
