//! Quickhull construction: the triangles of the hull of a candidate set of points.
//!
//! A deterministic initial simplex from the extreme points, then each face's outside set is
//! consumed one furthest point at a time: the faces visible from it (decided by the exact
//! [`super::exact::side`] predicate, so the visible region is always a consistent disc), their
//! horizon, and a cone of new faces from the horizon to the point. A point joins a face's
//! outside set only if it stands more than the outside tolerance above it.

use super::{exact, tri_plane, Tolerances, DEGENERATE, NONE};
use crate::error::{Error, Result};
use glam::DVec3;
use std::collections::VecDeque;

/// Four points spanning a clear volume, chosen deterministically from the extremes, or `None`
/// when the candidates are (to tolerance) coincident, collinear or coplanar.
fn initial_simplex(pts: &[DVec3], cand: &[usize], tol: f64) -> Option<[usize; 4]> {
    let mut ext = [cand[0]; 6];
    for &i in cand {
        for axis in 0..3 {
            if pts[i][axis] < pts[ext[2 * axis]][axis] {
                ext[2 * axis] = i;
            }
            if pts[i][axis] > pts[ext[2 * axis + 1]][axis] {
                ext[2 * axis + 1] = i;
            }
        }
    }
    let mut pair = (ext[0], ext[1], -1.0);
    for (k, &i) in ext.iter().enumerate() {
        for &j in &ext[k + 1..] {
            let d = pts[i].distance_squared(pts[j]);
            if d > pair.2 {
                pair = (i, j, d);
            }
        }
    }
    let (a, b, d2) = pair;
    if d2.sqrt() <= tol {
        return None;
    }
    let dir = (pts[b] - pts[a]).normalize();
    let c = farthest(cand, |i| (pts[i] - pts[a]).cross(dir).length(), tol)?;
    let n = (pts[b] - pts[a]).cross(pts[c] - pts[a]).normalize();
    let d = farthest(cand, |i| n.dot(pts[i] - pts[a]).abs(), tol)?;
    Some([a, b, c, d])
}

/// The candidate maximising `measure` (the first on ties), if that maximum exceeds `tol`.
fn farthest(cand: &[usize], measure: impl Fn(usize) -> f64, tol: f64) -> Option<usize> {
    let mut best = (cand[0], measure(cand[0]));
    for &i in &cand[1..] {
        let m = measure(i);
        if m > best.1 {
            best = (i, m);
        }
    }
    (best.1 > tol).then_some(best.0)
}

/// The triangles (point indices) of the hull of the candidates.
pub(super) fn build(pts: &[DVec3], cand: &[usize], tol: Tolerances) -> Result<Vec<[usize; 3]>> {
    let simplex = initial_simplex(pts, cand, tol.degenerate)
        .ok_or_else(|| Error::invalid("points", DEGENERATE))?;
    let mut qh = Quickhull::new(pts, tol.outside);
    let first = qh.add_simplex(simplex);
    for &p in cand {
        if !simplex.contains(&p) {
            qh.assign(p, &first);
        }
    }
    let mut queue: VecDeque<usize> = first.into_iter().collect();
    while let Some(f) = queue.pop_front() {
        for g in qh.step(f)? {
            if !qh.faces[g].outside.is_empty() {
                queue.push_back(g);
            }
        }
    }
    Ok(qh.faces.iter().filter(|f| f.alive).map(|f| f.v).collect())
}

/// A triangle of the hull under construction.
struct Face {
    /// Vertices, counter-clockwise seen from outside.
    v: [usize; 3],
    /// `adj[i]` is the face across the edge from `v[i]` to `v[(i + 1) % 3]`.
    adj: [usize; 3],
    normal: DVec3,
    offset: f64,
    /// Points clearly above this face and not yet in the hull.
    outside: Vec<usize>,
    alive: bool,
    /// The visibility pass that last classified this face, and its verdict.
    stamp: u32,
    visible: bool,
}

/// A directed edge of the visible region's boundary, with the face beyond it.
#[derive(Clone, Copy)]
struct HorizonEdge {
    a: usize,
    b: usize,
    outer: usize,
}

struct Quickhull<'a> {
    pts: &'a [DVec3],
    tol: f64,
    faces: Vec<Face>,
    round: u32,
    /// Horizon chaining scratch, indexed by point: the edge starting there.
    next: Vec<usize>,
}

impl<'a> Quickhull<'a> {
    fn new(pts: &'a [DVec3], tol: f64) -> Self {
        Quickhull {
            pts,
            tol,
            faces: Vec::new(),
            round: 0,
            next: vec![NONE; pts.len()],
        }
    }

    fn push_face(&mut self, v: [usize; 3], adj: [usize; 3]) -> usize {
        let (normal, offset) = tri_plane(self.pts, v);
        let face = Face {
            v,
            adj,
            normal,
            offset,
            outside: Vec::new(),
            alive: true,
            stamp: 0,
            visible: false,
        };
        self.faces.push(face);
        self.faces.len() - 1
    }

    /// The tetrahedron's four faces, oriented by the exact sign of its volume.
    fn add_simplex(&mut self, [a, b, c, d]: [usize; 4]) -> Vec<usize> {
        let p = self.pts;
        let (b, c) = if exact::side(p[a], p[b], p[c], p[d]) > 0 {
            (c, b)
        } else {
            (b, c)
        };
        // Faces 0..4 = (a,b,c), (a,d,b), (b,d,c), (c,d,a); adjacency worked out by hand.
        self.push_face([a, b, c], [1, 2, 3]);
        self.push_face([a, d, b], [3, 2, 0]);
        self.push_face([b, d, c], [1, 3, 0]);
        self.push_face([c, d, a], [2, 1, 0]);
        vec![0, 1, 2, 3]
    }

    fn distance(&self, f: usize, p: usize) -> f64 {
        let face = &self.faces[f];
        face.normal.dot(self.pts[p]) - face.offset
    }

    /// Gives `p` to the face it is furthest above, if it is clearly above any; otherwise it is
    /// inside (to tolerance) and is dropped for good.
    fn assign(&mut self, p: usize, faces: &[usize]) {
        let mut best = (NONE, self.tol);
        for &f in faces {
            let d = self.distance(f, p);
            if d > best.1 {
                best = (f, d);
            }
        }
        if best.0 != NONE {
            self.faces[best.0].outside.push(p);
        }
    }

    /// Adds the furthest outside point of face `f` to the hull; returns the faces whose
    /// outside sets may need work.
    fn step(&mut self, f: usize) -> Result<Vec<usize>> {
        if !self.faces[f].alive || self.faces[f].outside.is_empty() {
            return Ok(Vec::new());
        }
        let (k, eye) = self.furthest_outside(f);
        let fv = self.faces[f].v.map(|i| self.pts[i]);
        if exact::side(fv[0], fv[1], fv[2], self.pts[eye]) <= 0 {
            // Rounding in the face's plane claimed it; exactly, it is not outside.
            self.faces[f].outside.swap_remove(k);
            return Ok(vec![f]);
        }
        let visible = self.visible_from(f, eye);
        let horizon = self.horizon(&visible).ok_or_else(|| {
            Error::invalid("points", "are too nearly degenerate to build a convex hull")
        })?;
        let mut orphans = Vec::new();
        for &g in &visible {
            let face = &mut self.faces[g];
            face.alive = false;
            orphans.extend(face.outside.drain(..).filter(|&p| p != eye));
        }
        let cone = self.add_cone(eye, &horizon);
        for p in orphans {
            self.assign(p, &cone);
        }
        Ok(cone)
    }

    fn furthest_outside(&self, f: usize) -> (usize, usize) {
        let outside = &self.faces[f].outside;
        let mut best = (0, self.distance(f, outside[0]));
        for (k, &p) in outside.iter().enumerate().skip(1) {
            let d = self.distance(f, p);
            if d > best.1 {
                best = (k, d);
            }
        }
        (best.0, outside[best.0])
    }

    /// The faces `eye` is strictly above, grown from `seed` across edges. Exact predicates
    /// make this region a topological disc, as it is for exact convex polyhedra.
    fn visible_from(&mut self, seed: usize, eye: usize) -> Vec<usize> {
        self.round += 1;
        let round = self.round;
        self.faces[seed].stamp = round;
        self.faces[seed].visible = true;
        let mut list = vec![seed];
        let mut i = 0;
        while i < list.len() {
            for g in self.faces[list[i]].adj {
                if self.faces[g].stamp == round {
                    continue;
                }
                let [a, b, c] = self.faces[g].v.map(|v| self.pts[v]);
                let vis = exact::side(a, b, c, self.pts[eye]) > 0;
                self.faces[g].stamp = round;
                self.faces[g].visible = vis;
                if vis {
                    list.push(g);
                }
            }
            i += 1;
        }
        list
    }

    /// The boundary of the visible region as one closed, ordered loop, or `None` if it is not
    /// a single simple loop (which exact predicates should rule out).
    fn horizon(&mut self, visible: &[usize]) -> Option<Vec<HorizonEdge>> {
        let mut edges = Vec::new();
        for &f in visible {
            let face = &self.faces[f];
            for (i, &g) in face.adj.iter().enumerate() {
                // Every neighbour of a visible face was classified in this pass.
                if !self.faces[g].visible {
                    edges.push(HorizonEdge {
                        a: face.v[i],
                        b: face.v[(i + 1) % 3],
                        outer: g,
                    });
                }
            }
        }
        let mut simple = !edges.is_empty();
        for (k, e) in edges.iter().enumerate() {
            simple &= self.next[e.a] == NONE;
            self.next[e.a] = k;
        }
        let mut ordered = Vec::with_capacity(edges.len());
        let mut k = 0;
        while simple && ordered.len() < edges.len() {
            ordered.push(edges[k]);
            k = self.next[edges[k].b];
            // Back at the start early means a second loop elsewhere.
            simple &= k != NONE && (k != 0 || ordered.len() == edges.len());
        }
        for e in &edges {
            self.next[e.a] = NONE;
        }
        simple.then_some(ordered)
    }

    /// Fans new faces from `eye` to the ordered horizon and stitches them in.
    fn add_cone(&mut self, eye: usize, horizon: &[HorizonEdge]) -> Vec<usize> {
        let h = horizon.len();
        let base = self.faces.len();
        for (k, e) in horizon.iter().enumerate() {
            let (next, prev) = (base + (k + 1) % h, base + (k + h - 1) % h);
            let f = self.push_face([e.a, e.b, eye], [e.outer, next, prev]);
            let outer = &mut self.faces[e.outer];
            if let Some(j) = (0..3).find(|&j| outer.v[j] == e.b && outer.v[(j + 1) % 3] == e.a) {
                outer.adj[j] = f;
            }
        }
        (base..base + h).collect()
    }
}
