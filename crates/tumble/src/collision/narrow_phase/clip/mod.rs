//! Contact features and their clipping: from one contact normal to up to four points.
//!
//! A *feature* is the part of a shape's surface that faces the normal: a polygon (a box or
//! hull face, a triangle, a cylinder's cap as an inscribed octagon), a segment (a capsule's
//! shaft, a cylinder's side line, a polytope edge) or a point. The two features are clipped
//! against each other: the *reference* feature (the polygon best aligned with the normal)
//! bounds a prism along the normal with its side planes, and the *incident* feature is cut
//! to that prism (Sutherland–Hodgman). Each surviving incident point q is paired with its
//! projection along the normal onto the reference plane, so both ends of every contact lie
//! on the two actual surfaces and their separation is the gap between them along the
//! normal.
//!
//! Every point carries the features that made it (an incident vertex on the reference
//! face, an incident edge crossing a reference side, a reference corner inside the incident
//! face), numbered by the shapes' own vertex and face indices, so a resting contact keeps
//! its ids from step to step.
//!
//! Layout: this file holds the features, their clipping and the selection of contact
//! points; `polytope.rs` the shape cores as polytopes the features come from; `tests.rs`
//! the tests.

mod polytope;
#[cfg(test)]
mod tests;

use super::manifold::{feature_id, Candidate};
use crate::collision::geometry::Pose;
use crate::collision::shape::Convex;
use crate::math::{Real, Vec3};
pub(crate) use polytope::{Arc, Polytope};

/// Feature kinds, as in [`feature_id`].
pub(crate) const VERTEX: u32 = 0;
/// An edge (or segment).
pub(crate) const EDGE: u32 = 1;
/// A face (or polygon).
pub(crate) const FACE: u32 = 2;

/// A polytope face counts as facing a direction when its normal is within this angle's
/// cosine of it; an edge counts as lying across it when its direction's component along it
/// is below the sine. About 5.7°: flat contacts rocking by a few degrees keep their full
/// patch (the far points come out with honest positive separations).
pub(crate) const FACE_COS: Real = 0.995;
/// See [`FACE_COS`].
pub(crate) const EDGE_SIN: Real = 0.0998;

/// B's polygon is the reference only when it is better aligned with the normal than A's by
/// this much (in cosine, about 2.6° near parallel): two faces both flat on each other tie up
/// to rounding, and the choice must not flip from step to step (the ids would).
const ALIGN_SLACK: Real = 1e-3;

/// A cylinder's cap faces a direction within 45° of its axis: past that its side is the
/// nearer feature. The cap's points then come out with their own separations, those
/// beyond the margin dropped, as a plane's contact with the cylinder makes them. With the
/// polytopes' 5.7° a coin tilted 11° and 2.9 mm into a box's face (a pile pressed it
/// there) touched at its one lowest rim point, where a plane gave four; the solver lifted
/// that point by spinning the coin, continuous collision refused the turn, and such coins
/// fell through the box's floor.
const CAP_COS: Real = std::f64::consts::FRAC_1_SQRT_2 as Real;

/// Points on a cylinder's cap polygon.
const RIM: usize = 8;
/// cos and sin of k·45°, exact to the last bit for every build.
const RIM_COS: [f64; RIM] = [
    1.0,
    std::f64::consts::FRAC_1_SQRT_2,
    0.0,
    -std::f64::consts::FRAC_1_SQRT_2,
    -1.0,
    -std::f64::consts::FRAC_1_SQRT_2,
    0.0,
    std::f64::consts::FRAC_1_SQRT_2,
];
/// Cylinder feature ids: top rim 0..8, bottom rim 8..16, then the side line's ends and the
/// single rim points.
const CYL_SIDE_TOP: u32 = 16;
const CYL_SIDE_BOTTOM: u32 = 17;
const CYL_RIM_TOP: u32 = 18;
const CYL_RIM_BOTTOM: u32 = 19;

/// The part of a shape's surface facing a direction: 1 point, 2 (segment) or ≥ 3 (polygon,
/// counter-clockwise seen from outside), with the shape's ids for each point.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Feature {
    /// Points, working frame, on the shape's surface.
    pub pts: Vec<Vec3>,
    /// Vertex id of each point.
    pub ids: Vec<u32>,
    /// VERTEX, EDGE or FACE.
    pub kind: u32,
    /// Vertex, edge or face index.
    pub index: u32,
    /// The polygon's outward unit normal (for segments and points: the facing direction).
    pub normal: Vec3,
}

impl Feature {
    fn point(p: Vec3, id: u32, dir: Vec3) -> Feature {
        Feature {
            pts: vec![p],
            ids: vec![id],
            kind: VERTEX,
            index: id,
            normal: dir,
        }
    }
}

/// The feature of shape `c` (placed by `pose` in the working frame) facing the unit
/// direction `dir` (working frame); `core` is its polytope when it has one.
pub(crate) fn feature(c: &Convex, core: Option<&Polytope>, pose: &Pose, dir: Vec3) -> Feature {
    let r = c.radius();
    let local = pose.inverse_transform_vector(dir);
    match (c, core) {
        (
            Convex::Cylinder {
                radius,
                half_height,
            },
            _,
        ) => cylinder_feature(*radius, *half_height, pose, dir, local),
        (_, Some(p)) => p.feature(dir, r),
        // Unreachable: every other shape has a core polytope. The support point is a safe
        // answer regardless.
        (_, None) => Feature::point(pose.transform_point(c.support(local)), 0, dir),
    }
}

/// A cylinder's feature: its cap (an inscribed regular octagon at fixed angles, so the ids
/// and points do not wander with the normal) when the axis is within [`CAP_COS`] of `dir`,
/// its side line when the axis lies across `dir` within [`EDGE_SIN`], else its rim point.
fn cylinder_feature(r: Real, h: Real, pose: &Pose, dir: Vec3, local: Vec3) -> Feature {
    let len = local.length();
    let c = if len > 0.0 { local.y / len } else { 0.0 };
    if c.abs() >= CAP_COS {
        // Top cap: CCW about +y runs from +x towards −z; bottom cap the other way round.
        let (y, sz, base, face) = if c > 0.0 {
            (h, -1.0, 0, 0)
        } else {
            (-h, 1.0, RIM as u32, 1)
        };
        let pts = (0..RIM)
            .map(|k| {
                let (co, si) = (RIM_COS[k] as Real, RIM_COS[(k + 6) % RIM] as Real);
                pose.transform_point(Vec3::new(r * co, y, sz * r * si))
            })
            .collect();
        return Feature {
            pts,
            ids: (0..RIM as u32).map(|k| base + k).collect(),
            kind: FACE,
            index: face,
            normal: pose.transform_vector(Vec3::new(0.0, y.signum(), 0.0)),
        };
    }
    let radial = Vec3::new(local.x, 0.0, local.z).normalize_or_zero();
    if c.abs() <= EDGE_SIN && radial != Vec3::ZERO {
        let rim = radial * r;
        return Feature {
            pts: vec![
                pose.transform_point(rim + Vec3::new(0.0, h, 0.0)),
                pose.transform_point(rim - Vec3::new(0.0, h, 0.0)),
            ],
            ids: vec![CYL_SIDE_TOP, CYL_SIDE_BOTTOM],
            kind: EDGE,
            index: 2,
            normal: dir,
        };
    }
    let y = if local.y < 0.0 { -h } else { h };
    let id = if local.y < 0.0 {
        CYL_RIM_BOTTOM
    } else {
        CYL_RIM_TOP
    };
    Feature::point(
        pose.transform_point(radial * r + Vec3::new(0.0, y, 0.0)),
        id,
        dir,
    )
}

/// A side plane of the reference feature: points p with (p − point)·normal ≤ 0 are inside.
#[derive(Debug, Clone, Copy)]
struct Side {
    point: Vec3,
    normal: Vec3,
    /// Reference feature made where an incident edge crosses this plane.
    cross: (u32, u32),
}

/// How the edge leaving a clipped polygon vertex came about.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Tag {
    /// Part of the incident polygon's edge starting at this vertex id.
    Incident(u32),
    /// Part of the reference side plane with this index.
    Side(usize),
}

/// A clipped point with the incident and reference features that made it.
#[derive(Debug, Clone, Copy)]
struct Clipped {
    p: Vec3,
    inc: (u32, u32),
    reff: (u32, u32),
    next: Tag,
}

/// The side planes of `reference`: for a polygon, through each edge e_j and containing
/// `axis` (the normal pointing out of the reference face), with outward normal e_j × axis
/// (for a loop counter-clockwise about axis, e × axis points away from the interior); for a
/// segment, the planes through its ends perpendicular to it.
fn sides(reference: &Feature, axis: Vec3) -> Vec<Side> {
    let p = &reference.pts;
    if p.len() == 2 {
        let u = p[1] - p[0];
        return vec![
            Side {
                point: p[0],
                normal: -u,
                cross: (VERTEX, reference.ids[0]),
            },
            Side {
                point: p[1],
                normal: u,
                cross: (VERTEX, reference.ids[1]),
            },
        ];
    }
    (0..p.len())
        .map(|j| Side {
            point: p[j],
            normal: (p[(j + 1) % p.len()] - p[j]).cross(axis),
            cross: (EDGE, reference.ids[j]),
        })
        .collect()
}

/// Sutherland–Hodgman: the incident polygon cut by each side plane in turn. The output
/// edge after an exit point runs along the side plane; the edge after an entry point
/// continues the edge that entered.
fn clip_polygon(incident: &Feature, reference: &Feature, planes: &[Side]) -> Vec<Clipped> {
    let mut poly: Vec<Clipped> = incident
        .pts
        .iter()
        .zip(&incident.ids)
        .map(|(&p, &id)| Clipped {
            p,
            inc: (VERTEX, id),
            reff: (reference.kind, reference.index),
            next: Tag::Incident(id),
        })
        .collect();
    for (j, s) in planes.iter().enumerate() {
        if poly.is_empty() {
            break;
        }
        let dist = |c: &Clipped| (c.p - s.point).dot(s.normal);
        let mut out = Vec::with_capacity(poly.len() + 2);
        for i in 0..poly.len() {
            let (p, q) = (poly[i], poly[(i + 1) % poly.len()]);
            let (dp, dq) = (dist(&p), dist(&q));
            let crossing = |next: Tag| {
                let t = dp / (dp - dq);
                let (inc, reff) = match p.next {
                    Tag::Incident(e) => ((EDGE, e), s.cross),
                    Tag::Side(k) => ((incident.kind, incident.index), corner(planes, k, j)),
                };
                Clipped {
                    p: p.p + (q.p - p.p) * t,
                    inc,
                    reff,
                    next,
                }
            };
            match (dp <= 0.0, dq <= 0.0) {
                (true, true) => out.push(q),
                (true, false) => out.push(crossing(Tag::Side(j))),
                (false, true) => {
                    out.push(crossing(p.next));
                    out.push(q);
                }
                (false, false) => {}
            }
        }
        poly = out;
    }
    poly
}

/// The reference feature where side planes k and j meet: the shared corner of adjacent
/// sides, else a pair code.
fn corner(planes: &[Side], k: usize, j: usize) -> (u32, u32) {
    let m = planes.len();
    if (k + 1) % m == j {
        (VERTEX, planes[j].cross.1)
    } else if (j + 1) % m == k {
        (VERTEX, planes[k].cross.1)
    } else {
        (
            VERTEX,
            0x2000 | ((k as u32 & 0x3f) << 6) | (j as u32 & 0x3f),
        )
    }
}

/// The incident segment cut to the side planes: its parameter range [t0, t1] shrinks at
/// each plane it crosses.
fn clip_segment(incident: &Feature, reference: &Feature, planes: &[Side]) -> Vec<Clipped> {
    let (p0, p1) = (incident.pts[0], incident.pts[1]);
    let (mut t0, mut t1): (Real, Real) = (0.0, 1.0);
    let (mut c0, mut c1) = (None, None);
    for s in planes {
        let d0 = (p0 - s.point).dot(s.normal);
        let d1 = (p1 - s.point).dot(s.normal);
        if d0 > 0.0 && d1 > 0.0 {
            return Vec::new();
        }
        if d0 > 0.0 {
            let t = d0 / (d0 - d1);
            if t > t0 {
                t0 = t;
                c0 = Some(s.cross);
            }
        } else if d1 > 0.0 {
            let t = d0 / (d0 - d1);
            if t < t1 {
                t1 = t;
                c1 = Some(s.cross);
            }
        }
    }
    if t0 > t1 {
        return Vec::new();
    }
    let edge = (EDGE, incident.index);
    let face = (reference.kind, reference.index);
    let end = |t: Real, cross: Option<(u32, u32)>, id: u32| Clipped {
        p: p0 + (p1 - p0) * t,
        inc: if cross.is_some() { edge } else { (VERTEX, id) },
        reff: cross.unwrap_or(face),
        next: Tag::Side(0),
    };
    let mut out = vec![end(t0, c0, incident.ids[0])];
    if t1 > t0 {
        out.push(end(t1, c1, incident.ids[1]));
    }
    out
}

/// Appends the contacts of `incident` clipped against `reference` along the normal `n`
/// (working frame, A to B). `ref_is_a` says which shape the reference feature belongs to.
/// The reference must be a polygon or a segment; the incident a polygon or a segment.
pub(crate) fn clip(
    reference: &Feature,
    incident: &Feature,
    n: Vec3,
    ref_is_a: bool,
    out: &mut Vec<Candidate>,
) {
    // The normal pointing out of the reference side, and the reference plane (r0, f).
    let axis = if ref_is_a { n } else { -n };
    let f = if reference.pts.len() >= 3 {
        reference.normal
    } else {
        axis
    };
    let nf = n.dot(f);
    if reference.pts.len() < 2 || incident.pts.len() < 2 || nf == 0.0 || !nf.is_finite() {
        return;
    }
    let planes = sides(reference, axis);
    let clipped = if incident.pts.len() >= 3 {
        clip_polygon(incident, reference, &planes)
    } else {
        clip_segment(incident, reference, &planes)
    };
    let r0 = reference.pts[0];
    for c in clipped {
        // Along n onto the reference plane: (q − t n − r0)·f = 0 gives t = (q − r0)·f / n·f.
        let on_ref = c.p - n * ((c.p - r0).dot(f) / nf);
        let cand = if ref_is_a {
            Candidate {
                point_a: on_ref,
                point_b: c.p,
                feature: feature_id(c.reff.0, c.reff.1, c.inc.0, c.inc.1),
            }
        } else {
            Candidate {
                point_a: c.p,
                point_b: on_ref,
                feature: feature_id(c.inc.0, c.inc.1, c.reff.0, c.reff.1),
            }
        };
        if cand.point_a.is_finite() && cand.point_b.is_finite() {
            out.push(cand);
        }
    }
}

/// Contacts between two facing features along `n` (A to B): polygon against polygon (the
/// better aligned one is the reference, A within [`ALIGN_SLACK`]), polygon against segment (the polygon
/// is), or nearly parallel segments (A's is). Point features and crossing segments make no
/// candidates here: the caller's single deepest point covers them.
pub(crate) fn features_contact(fa: &Feature, fb: &Feature, n: Vec3, out: &mut Vec<Candidate>) {
    let (la, lb) = (fa.pts.len(), fb.pts.len());
    if la >= 3 && lb >= 3 {
        if fa.normal.dot(n) + ALIGN_SLACK >= -fb.normal.dot(n) {
            clip(fa, fb, n, true, out);
        } else {
            clip(fb, fa, n, false, out);
        }
    } else if la >= 3 && lb == 2 {
        clip(fa, fb, n, true, out);
    } else if la == 2 && lb >= 3 {
        clip(fb, fa, n, false, out);
    } else if la == 2 && lb == 2 {
        let (ua, ub) = (fa.pts[1] - fa.pts[0], fb.pts[1] - fb.pts[0]);
        if ua.cross(ub).length() <= EDGE_SIN * ua.length() * ub.length() {
            clip(fa, fb, n, true, out);
        }
    }
}

/// At most four of `cands` (those with separation ≤ `margin` along `n`), chosen by the
/// rule of [`super::reduce`] (deepest, farthest from it, largest triangle, most area added)
/// but with near-ties going to the earlier candidate: a score within `tol` (m; times the
/// span for areas) of the best counts as the best. On a flat patch every point is equally
/// deep up to rounding, and without the slack the rounding of each step would pick a
/// different subset, with different feature ids, breaking warm starting.
pub(crate) fn select(cands: &[Candidate], n: Vec3, margin: Real, tol: Real) -> Vec<Candidate> {
    let sep = |c: &Candidate| (c.point_b - c.point_a).dot(n);
    let kept: Vec<Candidate> = cands.iter().filter(|c| sep(c) <= margin).copied().collect();
    if kept.len() <= 4 {
        return kept;
    }
    let pick = |score: &dyn Fn(&Candidate) -> Real, slack: Real| {
        let max = kept.iter().map(score).fold(Real::NEG_INFINITY, Real::max);
        kept.iter()
            .position(|c| score(c) >= max - slack)
            .unwrap_or(0)
    };
    let i0 = pick(&|c| -sep(c), tol);
    let p0 = kept[i0].point_a;
    let i1 = pick(&|c| (c.point_a - p0).length(), tol);
    let p1 = kept[i1].point_a;
    let span = (p1 - p0).length();
    let area = |a: Vec3, b: Vec3, c: Vec3| (b - a).cross(c - a).dot(n);
    let i2 = pick(&|c| area(p0, p1, c.point_a).abs(), tol * span);
    let p2 = kept[i2].point_a;
    let sign = area(p0, p1, p2).signum();
    let i3 = pick(
        &|c| {
            let q = c.point_a;
            -(sign * area(p0, p1, q))
                .min(sign * area(p1, p2, q))
                .min(sign * area(p2, p0, q))
        },
        tol * span,
    );
    let mut out: Vec<Candidate> = Vec::with_capacity(4);
    for i in [i0, i1, i2, i3] {
        if !out.contains(&kept[i]) {
            out.push(kept[i]);
        }
    }
    out
}

/// The closest points of segments [p0, p1] and [q0, q1] (Ericson, Real-Time Collision
/// Detection 5.1.9): minimise |p0 + s u − q0 − t v|² over the unit square. Parallel
/// segments take s = 0 (then clamp t), which is one of the closest pairs.
pub(crate) fn segment_closest(p0: Vec3, p1: Vec3, q0: Vec3, q1: Vec3) -> (Vec3, Vec3) {
    let (u, v, r) = (p1 - p0, q1 - q0, p0 - q0);
    let (a, e, f) = (u.dot(u), v.dot(v), v.dot(r));
    let (s, t) = if a <= 0.0 && e <= 0.0 {
        (0.0, 0.0)
    } else if a <= 0.0 {
        (0.0, (f / e).clamp(0.0, 1.0))
    } else {
        let c = u.dot(r);
        if e <= 0.0 {
            ((-c / a).clamp(0.0, 1.0), 0.0)
        } else {
            let b = u.dot(v);
            let denom = a * e - b * b;
            let mut s = if denom > 0.0 {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let mut t = (b * s + f) / e;
            if t < 0.0 {
                t = 0.0;
                s = (-c / a).clamp(0.0, 1.0);
            } else if t > 1.0 {
                t = 1.0;
                s = ((b - c) / a).clamp(0.0, 1.0);
            }
            (s, t)
        }
    };
    (p0 + u * s, q0 + v * t)
}
