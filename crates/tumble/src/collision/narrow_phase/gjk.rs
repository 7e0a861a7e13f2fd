//! GJK: the distance between two convex *cores* (Gilbert–Johnson–Keerthi).
//!
//! Everything is computed in the frame of shape A, with B placed by its pose relative to A
//! ([`Pair`]): the result is then the same, to rounding, under any common rigid motion of the
//! pair, and the coordinates stay as small as the pair itself rather than as large as the
//! world.
//!
//! GJK walks a simplex (1 to 4 points) of the Minkowski difference M = A − B = {a − b}
//! towards the origin. Its closest point v to the origin is the vector between the closest
//! points of A and B, so |v| is their distance. Each step adds w = s_M(−v), the point of M
//! furthest against v, and keeps the smallest sub-simplex whose hull holds the point nearest
//! the origin. The sub-simplex is found with the *signed volumes* of Montanari, Petrinic and
//! Barbieri (2017): barycentric coordinates are ratios of signed areas/volumes, and a face
//! is only descended into when the origin lies beyond it. Those ratios never divide by a
//! Gram determinant, which is what makes Johnson's original sub-algorithm fail on thin
//! simplices.
//!
//! Termination: the lower bound v·w/|v| and the upper bound |v| of the distance meet
//! (`|v|² − v·w ≤ ε|v|²`, relative), or w is already in the simplex (polytopes: exact
//! convergence), or |v| stops decreasing (rounding), or [`MAX_ITERATIONS`] is reached; each
//! returns the best simplex seen.

use crate::collision::geometry::Pose;
use crate::collision::shape::Convex;
use crate::math::wide;
use crate::math::{real, Quat, Real, Vec3, EPSILON};

/// GJK iterations. A pair of polytopes converges exactly (a support point repeats) in a
/// handful of steps; a curved core (a cylinder's rim against another) converges linearly,
/// measured at 25 to 40 steps to the tolerance below, where rounding usually stops it.
/// The cap only guards against pathological cycling.
pub(crate) const MAX_ITERATIONS: usize = 64;

/// Relative gap between the upper and lower distance bounds at which GJK stops. The
/// distance is then that accurate; the direction between two curved surfaces about its
/// square root.
#[cfg(not(feature = "f32"))]
const REL_TOL: Real = 1e-12;
#[cfg(feature = "f32")]
const REL_TOL: Real = 1e-5;

/// Rounding in `v·w` is about `EPSILON · |v| · |w|`; a gap this many epsilons of the pair's
/// scale times |v| is noise, and the distance is as good as the precision allows.
const ABS_ULPS: Real = 16.0;

/// A closest point this many epsilons of the pair's scale from the origin means the cores
/// touch or overlap: its direction is rounding noise, so the penetration routines decide.
const TOUCH_ULPS: Real = 100.0;

/// The sub-algorithm's vectors: f64 whatever `Real` is. The points of M are differences of
/// support points as far out as the shapes are large, and a thin simplex's plane hangs on
/// its short edges: in f32, a 1 cm edge between points 28 m out (a 1 cm capsule over a 40 m
/// box) carries 3·10⁻⁴ of rounding, which tilts the plane enough to put it millimetres off
/// at the origin, and GJK stopped at the capsule's middle instead of its lower end. Taken in
/// f64 from the f32 support points, the differences are exact and the plane is the data's.
/// In f64 builds this is `Vec3` itself; in f32 it costs four widenings a solve.
type Wide = glam::DVec3;

/// A point of the Minkowski difference with the two support points it came from (A frame).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct SupportPoint {
    /// `a − b`.
    pub w: Vec3,
    /// Support point of A's core.
    pub a: Vec3,
    /// Support point of B's core.
    pub b: Vec3,
}

/// Two convex shapes seen from A's frame.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Pair<'c> {
    /// Shape A (at the identity of the working frame).
    pub a: Convex<'c>,
    /// Shape B.
    pub b: Convex<'c>,
    /// B's pose in A's frame.
    pub rel: Pose,
    /// Rotation taking A-frame directions into B's frame.
    to_b: Quat,
    /// Size of the problem (m): both shapes' bounding radii plus the distance between their
    /// origins. Tolerances are relative to it.
    pub scale: Real,
}

impl<'c> Pair<'c> {
    /// The pair `a` at `pa`, `b` at `pb`, in A's frame.
    pub fn new(a: &Convex<'c>, pa: &Pose, b: &Convex<'c>, pb: &Pose) -> Pair<'c> {
        let rel = pa.inverse().mul(pb);
        let scale = bound_radius(a) + bound_radius(b) + rel.position.length();
        Pair {
            a: *a,
            b: *b,
            rel,
            to_b: rel.rotation.inverse(),
            scale: if scale > 0.0 && scale.is_finite() {
                scale
            } else {
                1.0
            },
        }
    }

    /// The support point of M = core(A) − core(B) along `d`: s_A(d) − s_B(−d).
    #[inline]
    pub fn support(&self, d: Vec3) -> SupportPoint {
        let a = self.a.core_support(d);
        let b = self
            .rel
            .transform_point(self.b.core_support(self.to_b * (-d)));
        SupportPoint { w: a - b, a, b }
    }

    /// B's core support along `d` (A frame).
    #[inline]
    pub fn support_b(&self, d: Vec3) -> Vec3 {
        self.rel.transform_point(self.b.core_support(self.to_b * d))
    }

    /// Distances below this are rounding noise (m).
    #[inline]
    pub fn touch_tol(&self) -> Real {
        TOUCH_ULPS * EPSILON * self.scale
    }

    /// Whether both poses were finite (a NaN anywhere poisons every comparison).
    pub fn is_finite(&self) -> bool {
        self.rel.position.is_finite() && self.rel.rotation.is_finite()
    }
}

/// The radius of a ball about the shape's origin holding the whole shape (m).
pub(crate) fn bound_radius(c: &Convex) -> Real {
    let r = match c {
        Convex::Sphere { radius } => *radius,
        Convex::Box { half_extents } => half_extents.length(),
        Convex::Capsule {
            radius,
            half_height,
        } => radius + half_height,
        Convex::Cylinder {
            radius,
            half_height,
        } => (radius * radius + half_height * half_height).sqrt(),
        Convex::Hull(h) => h
            .vertices()
            .iter()
            .fold(0.0, |m: Real, v| m.max(v.length())),
        Convex::Triangle(t) => t.iter().fold(0.0, |m: Real, v| m.max(v.length())),
    };
    if r.is_finite() {
        r.abs()
    } else {
        0.0
    }
}

/// Up to four support points and the barycentric weights of the closest point.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Simplex {
    pts: [SupportPoint; 4],
    lambda: [Real; 4],
    len: usize,
}

impl Simplex {
    fn single(p: SupportPoint) -> Simplex {
        let mut s = Simplex::default();
        s.pts[0] = p;
        s.lambda[0] = 1.0;
        s.len = 1;
        s
    }

    /// Keeps the sub-simplex `sub` of this one, with its weights. The points are moved
    /// only when `sub` is not a prefix (a simplex is 300 bytes; copying it whole for
    /// every candidate and step was a twelfth of a time-of-impact search).
    fn keep(&mut self, sub: &Sub) {
        if sub.idx[..sub.len]
            .iter()
            .enumerate()
            .any(|(i, &k)| k as usize != i)
        {
            let old = self.pts;
            for (p, &k) in self.pts.iter_mut().zip(&sub.idx[..sub.len]) {
                *p = old[k as usize];
            }
        }
        self.lambda = sub.lambda.map(real);
        self.len = sub.len;
    }

    /// The support points.
    pub fn points(&self) -> &[SupportPoint] {
        &self.pts[..self.len]
    }

    /// The closest points on A's and B's cores: the same weights applied to their supports.
    pub fn witnesses(&self) -> (Vec3, Vec3) {
        let mut a = Vec3::ZERO;
        let mut b = Vec3::ZERO;
        for i in 0..self.len {
            a += self.pts[i].a * self.lambda[i];
            b += self.pts[i].b * self.lambda[i];
        }
        (a, b)
    }
}

/// How a GJK run ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Status {
    /// The cores are apart; `v` is their closest vector.
    Separated,
    /// The cores are further apart than the cutoff (proved by the lower bound).
    BeyondCutoff,
    /// The cores touch or overlap: the simplex encloses (or nearly touches) the origin.
    Overlap,
}

/// The outcome of [`gjk`].
#[derive(Debug, Clone, Copy)]
pub(crate) struct Gjk {
    /// How it ended.
    pub status: Status,
    /// The final simplex (seeds EPA on overlap).
    pub simplex: Simplex,
    /// The closest point of M to the origin: (closest point on A) − (closest point on B).
    pub v: Vec3,
}

impl Gjk {
    /// Distance between the cores (m).
    pub fn distance(&self) -> Real {
        self.v.length()
    }

    /// Unit direction from A's closest point to B's: −v/|v|.
    pub fn normal(&self) -> Vec3 {
        (-self.v).normalize_or_zero()
    }
}

/// GJK on the cores of `pair`. Stops early with [`Status::BeyondCutoff`] once the cores are
/// proved further apart than `cutoff` (pass `Real::INFINITY` for the exact distance).
pub(crate) fn gjk(pair: &Pair, cutoff: Real) -> Gjk {
    // Start on the side of M facing the origin when the shapes are apart: the point of A − B
    // furthest along B's offset is the difference of the mutually facing extremes.
    let d0 = if pair.rel.position.length_squared() > 0.0 {
        pair.rel.position
    } else {
        Vec3::X
    };
    let w0 = pair.support(d0);
    let mut s = Simplex::single(w0);
    let mut v = w0.w;
    let mut vv = v.length_squared();
    // |v|² of the last solve, unrounded: the progress test below compares in f64, where a
    // needle triangle's real but slight progress (10⁻⁷ of |v|², f32's rounding) still shows.
    let mut vv_wide = wide::vec(v).length_squared();
    let touch = pair.touch_tol();
    let cutoff = cutoff.max(0.0);
    let mut iterations = 0;
    let status = loop {
        if vv <= touch * touch {
            break Status::Overlap;
        }
        if iterations >= MAX_ITERATIONS {
            break Status::Separated;
        }
        iterations += 1;
        let w = pair.support(-v);
        let vw = v.dot(w.w);
        // For every x in M, v·x ≥ v·w, so |x| ≥ v·w/|v|: a lower bound of the distance.
        if vw > 0.0 && vw * vw > cutoff * cutoff * vv {
            break Status::BeyondCutoff;
        }
        let gap = vv - vw;
        if gap <= (REL_TOL * vv).max(ABS_ULPS * EPSILON * pair.scale * vv.sqrt()) {
            break Status::Separated;
        }
        if s.points().iter().any(|p| p.w == w.w) {
            break Status::Separated;
        }
        // Tried in place: the previous simplex is the first `len` points, unchanged.
        s.pts[s.len] = w;
        s.len += 1;
        let sub = solve(&s);
        if sub.len == 4 {
            s.keep(&sub);
            v = Vec3::ZERO;
            break Status::Overlap;
        }
        let vv_new = sub.v.length_squared();
        if vv_new.is_nan() || vv_new >= vv_wide {
            // In exact arithmetic |v| strictly decreases; when rounding says otherwise the
            // previous simplex is as close as this precision can get.
            s.len -= 1;
            break Status::Separated;
        }
        s.keep(&sub);
        v = wide::to_vec(sub.v);
        vv = v.length_squared();
        vv_wide = vv_new;
    };
    Gjk {
        status,
        simplex: s,
        v,
    }
}

/// True when `a` and `b` are both strictly positive or both strictly negative.
#[inline]
fn same_sign(a: f64, b: f64) -> bool {
    (a > 0.0 && b > 0.0) || (a < 0.0 && b < 0.0)
}

/// A sub-simplex: the indices of the points it keeps, their weights, and its point
/// nearest the origin.
#[derive(Debug, Clone, Copy)]
struct Sub {
    idx: [u8; 4],
    lambda: [f64; 4],
    len: usize,
    v: Wide,
}

impl Sub {
    fn single(i: u8, w: Wide) -> Sub {
        Sub {
            idx: [i, 0, 0, 0],
            lambda: [1.0, 0.0, 0.0, 0.0],
            len: 1,
            v: w,
        }
    }
}

/// The sub-simplex of `s` whose hull holds the point nearest the origin, with its weights,
/// and that point.
fn solve(s: &Simplex) -> Sub {
    // a − b again, not `w`: exact in f64 from f32 supports.
    let w = s.pts.map(|p| wide::vec(p.a) - wide::vec(p.b));
    match s.len {
        1 => Sub::single(0, w[0]),
        2 => segment(&w, 0, 1),
        3 => triangle(&w, [0, 1, 2]),
        _ => tetrahedron(&w),
    }
}

/// Segment pq (indices into `w`). The origin projects to p + u (q − p) with
/// u = −p·t/t·t, t = q − p; its weights are λ_q = −p·t/t·t and λ_p = q·t/t·t (they sum to
/// (q − p)·t/t·t = 1). A weight ≤ 0 means the projection falls beyond the other end, whose
/// vertex is then closest.
fn segment(w: &[Wide; 4], p: u8, q: u8) -> Sub {
    let (wp, wq) = (w[p as usize], w[q as usize]);
    let t = wq - wp;
    let lp = wq.dot(t);
    let lq = -wp.dot(t);
    if lq <= 0.0 {
        return Sub::single(p, wp);
    }
    if lp <= 0.0 {
        return Sub::single(q, wq);
    }
    // Dividing by the sum (not by t·t) makes the weights a partition of unity exactly.
    let sum = lp + lq;
    let (kp, kq) = (lp / sum, lq / sum);
    Sub {
        idx: [p, q, 0, 0],
        lambda: [kp, kq, 0.0, 0.0],
        len: 2,
        v: wp * kp + wq * kq,
    }
}

/// Triangle abc (indices into `w`) with normal n = (b − a) × (c − a). The origin's
/// projection onto the plane has weights proportional to the signed areas of the
/// sub-triangles it makes, measured along n: λ_a ∝ ((b − o) × (c − o))·n for any o on the
/// normal line through the origin, and since o is parallel to n the o terms drop out:
/// λ_a ∝ (b × c)·n, λ_b ∝ (c × a)·n, λ_c ∝ (a × b)·n, whose sum is
/// ((b − a) × (c − a))·n = n·n. All of one sign: the projection is inside. Otherwise the
/// nearest point lies on an edge facing away from a negative weight's vertex.
fn triangle(w: &[Wide; 4], t: [u8; 3]) -> Sub {
    let (wa, wb, wc) = (w[t[0] as usize], w[t[1] as usize], w[t[2] as usize]);
    let n = plane_normal(wa, wb, wc);
    let nn = n.length_squared();
    // b × c = b × (c − b), and so on: an edge (short on a thin triangle) in place of a
    // second far vertex keeps the products, and their rounding, small.
    let cof = [
        wb.cross(wc - wb).dot(n),
        wc.cross(wa - wc).dot(n),
        wa.cross(wb - wa).dot(n),
    ];
    let det = cof[0] + cof[1] + cof[2];
    let inside = nn > 0.0 && cof.iter().all(|&k| same_sign(det, k));
    if inside {
        // The projection of the origin onto the plane, computed directly: its direction is
        // exactly the plane normal, which keeps a contact normal on a flat face exact.
        return Sub {
            idx: [t[0], t[1], t[2], 0],
            lambda: [cof[0] / det, cof[1] / det, cof[2] / det, 0.0],
            len: 3,
            v: n * (wa.dot(n) / nn),
        };
    }
    let mut best: Option<Sub> = None;
    for k in 0..3 {
        if nn > 0.0 && same_sign(det, cof[k]) {
            continue;
        }
        let cand = segment(w, t[(k + 1) % 3], t[(k + 2) % 3]);
        if best.is_none_or(|b| cand.v.length_squared() < b.v.length_squared()) {
            best = Some(cand);
        }
    }
    best.unwrap_or(Sub::single(t[0], wa))
}

/// (b − a) × (c − a), which equals (c − b) × (a − b) and (a − c) × (b − c), taken about
/// the vertex opposite the longest edge. Crossing the two long edges of a thin triangle
/// cancels products of their lengths down to its area, and the normal keeps only the
/// rounding left over (a 1 cm by 28 m triangle loses about three more digits than the
/// short edge and one long one do).
fn plane_normal(a: Wide, b: Wide, c: Wide) -> Wide {
    let (ab, bc, ca) = (b - a, c - b, a - c);
    let (lab, lbc, lca) = (
        ab.length_squared(),
        bc.length_squared(),
        ca.length_squared(),
    );
    if lbc >= lab && lbc >= lca {
        ab.cross(-ca)
    } else if lca >= lab {
        bc.cross(-ab)
    } else {
        ca.cross(-bc)
    }
}

/// Tetrahedron of the four points of `w`: the weight of vertex k is the signed volume of
/// the tetrahedron with the origin in its place over the whole signed volume (their sum).
/// All of one sign: the origin is inside. Otherwise descend into each face whose opposite
/// weight is not of that sign.
fn tetrahedron(w: &[Wide; 4]) -> Sub {
    // The volume with the origin in place of one vertex, a · ((b − a) × (c − a)) for the
    // face abc, with that face's normal taken as `triangle` takes it (an alternating form:
    // the second and fourth change sign with the permutation that brings the origin first).
    let vol = |a: Wide, b: Wide, c: Wide| a.dot(plane_normal(a, b, c));
    let cof = [
        vol(w[1], w[2], w[3]),
        -vol(w[0], w[2], w[3]),
        vol(w[0], w[1], w[3]),
        -vol(w[0], w[1], w[2]),
    ];
    let det = cof[0] + cof[1] + cof[2] + cof[3];
    if cof.iter().all(|&k| same_sign(det, k)) {
        return Sub {
            idx: [0, 1, 2, 3],
            lambda: cof.map(|k| k / det),
            len: 4,
            v: Wide::ZERO,
        };
    }
    let mut best: Option<Sub> = None;
    for k in 0..4u8 {
        if same_sign(det, cof[k as usize]) {
            continue;
        }
        let cand = triangle(w, [(k + 1) % 4, (k + 2) % 4, (k + 3) % 4]);
        if best.is_none_or(|b| cand.v.length_squared() < b.v.length_squared()) {
            best = Some(cand);
        }
    }
    best.unwrap_or(Sub::single(0, w[0]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn segment_interior_and_ends() {
        let two = |p: Wide, q: Wide| segment(&[p, q, Wide::ZERO, Wide::ZERO], 0, 1);
        let s = two(Wide::new(-1.0, 1.0, 0.0), Wide::new(3.0, 1.0, 0.0));
        assert_eq!(s.len, 2);
        assert!((s.v - Wide::new(0.0, 1.0, 0.0)).length() < 1e-6);
        let s = two(Wide::new(1.0, 1.0, 0.0), Wide::new(3.0, 1.0, 0.0));
        assert_eq!(s.len, 1);
        assert_eq!(s.v, Wide::new(1.0, 1.0, 0.0));
        // Degenerate: both points equal.
        assert_eq!(two(Wide::ONE, Wide::ONE).len, 1);
    }

    #[test]
    fn triangle_regions() {
        let t = [
            Wide::new(-1.0, -1.0, 2.0),
            Wide::new(2.0, -1.0, 2.0),
            Wide::new(-1.0, 2.0, 2.0),
        ];
        let three = |a: Wide, b: Wide, c: Wide| triangle(&[a, b, c, Wide::ZERO], [0, 1, 2]);
        let s = three(t[0], t[1], t[2]);
        assert_eq!(s.len, 3);
        assert!((s.v - Wide::new(0.0, 0.0, 2.0)).length() < 1e-6);
        // Shifted so the origin projects beyond the edge t0–t1.
        let off = Wide::new(0.0, 3.0, 0.0);
        let s = three(t[0] + off, t[1] + off, t[2] + off);
        assert_eq!(s.len, 2);
        assert!((s.v - Wide::new(0.0, 2.0, 2.0)).length() < 1e-6);
        // Collinear: no NaN, nearest vertex.
        let s = three(Wide::X, Wide::X * 2.0, Wide::X * 3.0);
        assert_eq!(s.v, Wide::X);
    }

    #[test]
    fn tetrahedron_inside_and_outside() {
        let t = [
            Wide::new(1.0, 0.0, -1.0),
            Wide::new(-1.0, 1.0, -1.0),
            Wide::new(-1.0, -1.0, -1.0),
            Wide::new(0.0, 0.0, 1.0),
        ];
        let s = tetrahedron(&t);
        assert_eq!(s.len, 4);
        assert_eq!(s.v, Wide::ZERO);
        let sum: f64 = s.lambda.iter().sum();
        assert!((sum - 1.0).abs() < 1e-6);
        let off = Wide::new(0.0, 0.0, 2.0);
        let s = tetrahedron(&t.map(|p| p + off));
        assert_eq!(s.len, 3);
        assert!((s.v - Wide::new(0.0, 0.0, 1.0)).length() < 1e-6);
        // Flat: no NaN.
        let flat = [Wide::X, Wide::Y, -Wide::X, -Wide::Y].map(|p| p + off);
        assert!((tetrahedron(&flat).v - off).length() < 1e-6);
    }

    #[test]
    fn box_distance_and_overlap() {
        let a = Convex::Box {
            half_extents: Vec3::ONE,
        };
        let pair = Pair::new(
            &a,
            &Pose::IDENTITY,
            &a,
            &Pose::from_translation(Vec3::new(3.5, 0.2, -0.1)),
        );
        let g = gjk(&pair, Real::INFINITY);
        assert_eq!(g.status, Status::Separated);
        assert!((g.distance() - 1.5).abs() < 1e-6);
        assert!((g.normal() - Vec3::X).length() < 1e-6);
        let pair = Pair::new(
            &a,
            &Pose::IDENTITY,
            &a,
            &Pose::from_translation(Vec3::new(1.5, 0.2, -0.1)),
        );
        assert_eq!(gjk(&pair, Real::INFINITY).status, Status::Overlap);
        let pair = Pair::new(
            &a,
            &Pose::IDENTITY,
            &a,
            &Pose::from_translation(Vec3::new(30.0, 0.0, 0.0)),
        );
        assert_eq!(gjk(&pair, 1.0).status, Status::BeyondCutoff);
    }
}
