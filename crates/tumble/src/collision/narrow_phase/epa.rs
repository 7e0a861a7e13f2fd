//! EPA: the penetration depth and normal of two overlapping cores (expanding polytope).
//!
//! When GJK finds the origin inside M = A − B, the smallest translation separating the
//! cores is the distance d from the origin to the boundary of M, along the outward normal m
//! of the nearest boundary point: moving A by −d·m (or B by +d·m) makes them touch. So m is
//! the contact normal from A to B and d the depth.
//!
//! EPA grows a polytope inside M that contains the origin: take the face nearest the origin,
//! ask for M's support point w along that face's normal; if w lies no further out than the
//! face (to a tolerance) the face is on M's boundary and we are done; otherwise every face
//! w can see is removed and the hole is closed with a fan of triangles from the horizon to w.
//!
//! Here EPA is used only for pairs with a cylinder (curved, full-dimensional): polytope
//! pairs and round cores (points, segments) against polytopes go through the exact
//! separating-axis test in `convex.rs` instead, which also names the touching features.
//!
//! Robustness: the visible region is found by flooding from the nearest face across the
//! face adjacency, so it is connected and its boundary (the horizon) is checked to be one
//! simple loop before anything is changed; a new face that would be degenerate or leave the
//! origin outside stops the expansion with the best face so far. Iterations are bounded by
//! [`MAX_ITERATIONS`] (one vertex each).

use super::gjk::{Pair, Simplex, SupportPoint};
use crate::math::{Real, Vec3};

/// Expansion steps (vertices added). A contact region curved in one or two directions
/// (cylinder side or rim against anything) converges to the tolerance below in about 20 to
/// 40 steps: each new vertex halves the angle a face spans near the nearest point, and the
/// gap of a chord shrinks as the square of that angle. Only a nearest boundary that is a
/// whole ring (two coaxial cylinders, sunk radially into each other) needs more; there
/// the polytope of this many vertices inscribes the ring to about cos(π/32), and the depth
/// is taken as the overlap along the final normal instead (see `penetration`).
pub(crate) const MAX_ITERATIONS: usize = 64;

/// Convergence: a face is on the boundary when the support point along its normal is no
/// further out than this fraction of the pair's scale. The depth is then that accurate and
/// the normal, on a curved region, about its square root (a chord of angle φ on a radius R
/// lies R·φ²/8 inside): 1e-6 rad here, 1e-3 in f32.
#[cfg(not(feature = "f32"))]
const REL_TOL: Real = 1e-12;
#[cfg(feature = "f32")]
const REL_TOL: Real = 1e-6;

/// The penetration of two cores, in A's frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Penetration {
    /// Unit normal from A to B (M's outward normal at its boundary point nearest the origin).
    pub normal: Vec3,
    /// Depth along the normal (m), ≥ 0.
    pub depth: Real,
    /// Deepest point of A's core in B.
    pub point_a: Vec3,
    /// Deepest point of B's core in A.
    pub point_b: Vec3,
}

#[derive(Debug, Clone, Copy)]
struct Face {
    /// Vertex indices, counter-clockwise seen from outside.
    v: [usize; 3],
    /// `adj[k]`: the face across edge v[k] → v[k+1].
    adj: [usize; 3],
    /// Outward unit normal.
    n: Vec3,
    /// Signed distance of the plane from the origin.
    d: Real,
    alive: bool,
}

/// The face through three points, if it is not degenerate.
fn make_face(verts: &[SupportPoint], v: [usize; 3]) -> Option<Face> {
    let (a, b, c) = (verts[v[0]].w, verts[v[1]].w, verts[v[2]].w);
    let n = (b - a).cross(c - a).normalize_or_zero();
    if n == Vec3::ZERO || !n.is_finite() {
        return None;
    }
    Some(Face {
        v,
        adj: [usize::MAX; 3],
        n,
        // The mean of the three offsets treats the vertices alike.
        d: n.dot(a + b + c) / 3.0,
        alive: true,
    })
}

/// Penetration normal and depth of the overlapping cores of `pair`, starting from GJK's
/// final simplex. `None` when no proper polytope could be built (M is flat) or the
/// expansion broke down before the first face was trusted; the caller then falls back to a
/// separating-axis estimate.
pub(crate) fn epa(pair: &Pair, simplex: &Simplex) -> Option<Penetration> {
    let tol = REL_TOL * pair.scale;
    let inside_tol = 10.0 * pair.touch_tol();
    let mut verts: Vec<SupportPoint> = seed(pair, simplex)?.to_vec();
    let mut faces: Vec<Face> = Vec::with_capacity(4 + 4 * MAX_ITERATIONS);
    for v in [[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]] {
        let f = make_face(&verts, v)?;
        if f.d < -inside_tol {
            return None; // the origin is not inside the seed: nothing below would be valid
        }
        faces.push(f);
    }
    link_tetrahedron(&mut faces);
    let mut best = nearest(&faces)?;
    for _ in 0..MAX_ITERATIONS {
        let next = nearest(&faces)?;
        // Growing a convex polytope never brings its boundary nearer the origin. If the
        // nearest face did come nearer, rounding has folded a sliver face inwards (seen in
        // f32 once the gaps reach the last few bits): stop with the face before it.
        if faces[next].d < faces[best].d - inside_tol {
            break;
        }
        best = next;
        let f = faces[best];
        let w = pair.support(f.n);
        if w.w.dot(f.n) - f.d <= tol {
            break;
        }
        verts.push(w);
        if !expand(&mut verts, &mut faces, best, inside_tol) {
            verts.pop();
            break;
        }
    }
    // Faces are only ever marked dead, never removed, so `best` still names its face.
    let f = faces[best];
    Some(penetration(&verts, &f, pair.support(f.n).w.dot(f.n)))
}

/// The live face nearest the origin (lowest index on ties, for determinism).
fn nearest(faces: &[Face]) -> Option<usize> {
    let mut best: Option<usize> = None;
    for (i, f) in faces.iter().enumerate() {
        if f.alive && best.is_none_or(|b| f.d < faces[b].d) {
            best = Some(i);
        }
    }
    best
}

/// Normal, depth and witness points from the nearest face. The face's distance d bounds
/// the depth from below (the polytope lies inside M); M's support along the normal,
/// h = max over M of x·n, is the overlap of the shapes along n, the translation that
/// actually separates them along it. The two agree to the tolerance on convergence; when
/// the iteration bound cuts EPA short (a nearest boundary that is a whole ring, as for two
/// coaxial cylinders) h is the answer that is consistent with the normal, so it is the
/// depth reported. Witnesses: the origin's projection p = n·d onto the face, with
/// barycentric weights from the sub-triangle areas measured along n, applied to both
/// shapes' support points, then moved apart along n by half of h − d each.
fn penetration(verts: &[SupportPoint], f: &Face, h: Real) -> Penetration {
    let [a, b, c] = f.v.map(|i| verts[i]);
    let p = f.n * f.d;
    let area = |x: Vec3, y: Vec3, z: Vec3| (y - x).cross(z - x).dot(f.n);
    let mut l = [
        area(p, b.w, c.w).max(0.0),
        area(a.w, p, c.w).max(0.0),
        area(a.w, b.w, p).max(0.0),
    ];
    let sum = l[0] + l[1] + l[2];
    if sum > 0.0 && sum.is_finite() {
        l = l.map(|x| x / sum);
    } else {
        l = [1.0 / 3.0; 3];
    }
    let depth = if h.is_finite() { f.d.max(h) } else { f.d };
    let shift = f.n * (0.5 * (depth - f.d));
    Penetration {
        normal: f.n,
        depth: depth.max(0.0),
        point_a: a.a * l[0] + b.a * l[1] + c.a * l[2] + shift,
        point_b: a.b * l[0] + b.b * l[1] + c.b * l[2] - shift,
    }
}

/// Builds a tetrahedron of support points holding the origin (within rounding) from GJK's
/// final simplex, whose hull holds the origin but may be of any dimension 0 to 3: each
/// missing dimension is filled by the support point along a direction off the current
/// point, line or plane. Faces are oriented outward. `None` if M itself is flat.
fn seed(pair: &Pair, simplex: &Simplex) -> Option<[SupportPoint; 4]> {
    let eps = pair.touch_tol();
    let mut pts: Vec<SupportPoint> = Vec::with_capacity(4);
    for &p in simplex.points() {
        try_add(&mut pts, p, eps);
    }
    if pts.is_empty() {
        pts.push(pair.support(Vec3::X));
    }
    while pts.len() < 4 {
        let added = search_directions(&pts)
            .into_iter()
            .flatten()
            .any(|d| try_add(&mut pts, pair.support(d), eps));
        if !added {
            return None;
        }
    }
    let mut t = [pts[0], pts[1], pts[2], pts[3]];
    // With V = (w1 − w0)·((w2 − w0) × (w3 − w0)) < 0 the faces listed in `epa` face outward
    // (w3 lies below face 012, whose normal then points away from it); swap to get there.
    let vol = (t[1].w - t[0].w).dot((t[2].w - t[0].w).cross(t[3].w - t[0].w));
    if vol > 0.0 {
        t.swap(1, 2);
    }
    Some(t)
}

/// Directions that may find a point off the affine hull of `pts` (in order of preference).
fn search_directions(pts: &[SupportPoint]) -> [Option<Vec3>; 6] {
    let axes = [Vec3::X, Vec3::Y, Vec3::Z];
    let mut out = [None; 6];
    match pts.len() {
        1 => {
            for (i, e) in axes.iter().enumerate() {
                out[2 * i] = Some(*e);
                out[2 * i + 1] = Some(-*e);
            }
        }
        2 => {
            let u = pts[1].w - pts[0].w;
            for (i, e) in axes.iter().enumerate() {
                let c = u.cross(*e);
                if c.length_squared() > 0.0 {
                    out[2 * i] = Some(c);
                    out[2 * i + 1] = Some(-c);
                }
            }
        }
        3 => {
            let n = (pts[1].w - pts[0].w).cross(pts[2].w - pts[0].w);
            if n.length_squared() > 0.0 {
                out[0] = Some(n);
                out[1] = Some(-n);
            }
        }
        _ => {}
    }
    out
}

/// Adds `p` if it raises the dimension of the hull of `pts` by more than `eps`.
fn try_add(pts: &mut Vec<SupportPoint>, p: SupportPoint, eps: Real) -> bool {
    let ok = match pts.len() {
        0 => true,
        1 => (p.w - pts[0].w).length() > eps,
        2 => {
            let u = (pts[1].w - pts[0].w).normalize_or_zero();
            u != Vec3::ZERO && (p.w - pts[0].w).cross(u).length() > eps
        }
        3 => {
            let n = (pts[1].w - pts[0].w)
                .cross(pts[2].w - pts[0].w)
                .normalize_or_zero();
            n != Vec3::ZERO && (p.w - pts[0].w).dot(n).abs() > eps
        }
        _ => false,
    };
    if ok {
        pts.push(p);
    }
    ok
}

/// Fills the adjacency of the initial four faces: the face across edge a → b is the one
/// holding the edge b → a.
fn link_tetrahedron(faces: &mut [Face]) {
    for i in 0..faces.len() {
        for k in 0..3 {
            let (a, b) = (faces[i].v[k], faces[i].v[(k + 1) % 3]);
            if let Some(j) =
                (0..faces.len()).find(|&j| j != i && edge_index(&faces[j], b, a).is_some())
            {
                faces[i].adj[k] = j;
            }
        }
    }
}

/// The index k with g.v[k] = a and g.v[k+1] = b.
fn edge_index(g: &Face, a: usize, b: usize) -> Option<usize> {
    (0..3).find(|&k| g.v[k] == a && g.v[(k + 1) % 3] == b)
}

/// Adds the last vertex of `verts` to the polytope, starting from the visible face `start`.
/// Changes nothing and returns false if the result would be invalid.
fn expand(verts: &mut [SupportPoint], faces: &mut Vec<Face>, start: usize, inside: Real) -> bool {
    let wi = verts.len() - 1;
    let w = verts[wi].w;
    // Flood the visible region: 1 visible, 2 hidden, 0 not yet seen.
    let mut state = vec![0u8; faces.len()];
    let mut stack = vec![start];
    state[start] = 1;
    // Horizon edges (a → b of a visible face) with the hidden face across them.
    let mut horizon: Vec<(usize, usize, usize)> = Vec::new();
    while let Some(g) = stack.pop() {
        for k in 0..3 {
            let h = faces[g].adj[k];
            if h >= faces.len() || !faces[h].alive {
                return false; // broken adjacency: refuse rather than corrupt
            }
            if state[h] == 0 {
                let visible = w.dot(faces[h].n) - faces[h].d > 0.0;
                state[h] = if visible { 1 } else { 2 };
                if visible {
                    stack.push(h);
                    continue;
                }
            }
            if state[h] == 2 {
                horizon.push((faces[g].v[k], faces[g].v[(k + 1) % 3], h));
            }
        }
    }
    // The horizon must be one simple loop: each vertex starts exactly one edge and ends one,
    // and following the edges from the first visits them all.
    let n = horizon.len();
    if n < 3 {
        return false;
    }
    let mut links = Vec::with_capacity(n);
    for &(a, b, _) in &horizon {
        let next: Vec<usize> = (0..n).filter(|&j| horizon[j].0 == b).collect();
        let prev: Vec<usize> = (0..n).filter(|&j| horizon[j].1 == a).collect();
        if next.len() != 1 || prev.len() != 1 {
            return false;
        }
        links.push((next[0], prev[0]));
    }
    let mut at = 0;
    for step in 1..=n {
        at = links[at].0;
        if at == 0 && step < n {
            return false; // more than one loop
        }
    }
    if at != 0 {
        return false;
    }
    let mut fresh = Vec::with_capacity(n);
    for &(a, b, _) in &horizon {
        match make_face(verts, [a, b, wi]) {
            Some(f) if f.d >= -inside => fresh.push(f),
            _ => return false,
        }
    }
    // Commit: retire the visible faces, append the fan and stitch it in.
    for (i, s) in state.iter().enumerate() {
        if *s == 1 {
            faces[i].alive = false;
        }
    }
    let base = faces.len();
    for (k, &(a, b, h)) in horizon.iter().enumerate() {
        let mut f = fresh[k];
        // Edge a → b borders the hidden face; b → w borders the new face starting at b;
        // w → a borders the new face ending at a.
        let (next, prev) = links[k];
        f.adj = [h, base + next, base + prev];
        if let Some(j) = edge_index(&faces[h], b, a) {
            faces[h].adj[j] = base + k;
        }
        faces.push(f);
    }
    true
}

#[cfg(test)]
mod tests {
    use super::super::gjk::{gjk, Status};
    use super::*;
    use crate::collision::geometry::Pose;
    use crate::collision::shape::Convex;

    #[test]
    fn cylinder_in_box_depth() {
        let cyl = Convex::Cylinder {
            radius: 0.5,
            half_height: 1.0,
        };
        let bx = Convex::Box {
            half_extents: Vec3::new(2.0, 0.5, 2.0),
        };
        // Cylinder standing on the box, sunk 0.1 into its top face.
        let pb = Pose::from_translation(Vec3::new(0.1, 1.4, -0.2));
        let pair = Pair::new(&bx, &Pose::IDENTITY, &cyl, &pb);
        let g = gjk(&pair, Real::INFINITY);
        assert_eq!(g.status, Status::Overlap);
        let p = epa(&pair, &g.simplex).unwrap();
        assert!((p.depth - 0.1).abs() < 1e-6, "{p:?}");
        assert!((p.normal - Vec3::Y).length() < 1e-6, "{p:?}");
    }

    #[test]
    fn coincident_cylinders() {
        let cyl = Convex::Cylinder {
            radius: 0.5,
            half_height: 1.0,
        };
        let pair = Pair::new(&cyl, &Pose::IDENTITY, &cyl, &Pose::IDENTITY);
        let g = gjk(&pair, Real::INFINITY);
        assert_eq!(g.status, Status::Overlap);
        let p = epa(&pair, &g.simplex).unwrap();
        // M is a cylinder of radius 1 and half height 2: the nearest boundary is the whole
        // side, which the polytope only inscribes, but the overlap along its normal is 1.
        assert!((p.depth - 1.0).abs() < 1e-6, "{p:?}");
        assert!(p.normal.y.abs() < 1e-2, "{p:?}");
    }
}
