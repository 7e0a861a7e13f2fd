//! Convex hulls from point clouds (quickhull) and their exact mass properties.
//!
//! Topology is decided only by exact orientation predicates, so every visibility decision is
//! consistent with every other and the result is a closed, outward-oriented 2-manifold for any
//! finite input, however degenerate. Geometry is decided with a tolerance proportional to the
//! input's magnitude: a point must stand clearly outside a face to become a vertex, so face,
//! edge, interior and duplicate points, including ones perturbed by the rounding of a rotation,
//! do not end up in the hull. Coplanar triangles are then grouped into polygonal faces (for
//! collision detection), and any vertex that turns out to sit inside such a face or on an edge
//! between two of them is removed by rebuilding from the true corners.

use super::MassProperties;
use crate::error::{Error, Result};
use crate::math::{real, Real, Vec3, EPSILON};
use glam::{DMat3, DVec3};
use std::collections::{BTreeMap, BTreeSet, VecDeque};

/// The reason given for every input that does not span a volume.
const DEGENERATE: &str = "needs at least 4 points that are not all in one plane";
/// A point must be this many `Real` epsilons (times the largest coordinate magnitude) above a
/// face to count as outside it. Coordinates computed in `Real` (rotated, translated) carry a few
/// ulps of error, and a plane through three of them tilts by about as much, so exactly-flat
/// features need tens of ulps of slack to stay flat.
const OUTSIDE_ULPS: f64 = 100.0;
/// A cloud thinner than this many `Real` epsilons of its extent has no meaningful volume: any
/// hull of it would be shaped by rounding noise alone.
const DEGENERATE_ULPS: f64 = 1e3;
/// One rebuild from the corners settles every case seen; the cap only guards against a
/// tolerance pathology cycling.
const MAX_PASSES: usize = 3;
/// Marks an unset slot in index tables.
const NONE: usize = usize::MAX;

/// A convex polyhedron: its hull vertices and outward-facing (counter-clockwise seen from
/// outside) triangles indexing them.
#[derive(Debug, Clone, PartialEq)]
pub struct ConvexHull {
    vertices: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    planes: Vec<(Vec3, Real)>,
    face_loops: Vec<Vec<u32>>,
    edges: Vec<[u32; 2]>,
}

impl ConvexHull {
    /// Builds the hull of `points`.
    ///
    /// Fails with a field of `points[i]` when point `i` is not finite, and of `points` when
    /// there are fewer than 4 points or they do not span a volume (all coincident, collinear
    /// or coplanar to within about 1000 epsilons of the cloud's extent). Duplicates, interior
    /// points and points on faces or edges are allowed and never become vertices.
    pub fn from_points(points: &[Vec3]) -> Result<Self> {
        validate(points)?;
        let (pts, tol) = normalised(points);
        let mut candidates: Vec<usize> = (0..points.len()).collect();
        let mut best: Option<(Vec<[usize; 3]>, Vec<Polygon>)> = None;
        for _ in 0..MAX_PASSES {
            let tris = match build(&pts, &candidates, tol) {
                Ok(tris) => tris,
                // A rebuild from a subset cannot be worse than what it refines: keep that.
                Err(_) if best.is_some() => break,
                Err(e) => return Err(e),
            };
            let polygons = merge_coplanar(&pts, &tris, tol.outside);
            let (corners, all_corners) = corners(&tris, &polygons, pts.len());
            best = Some((tris, polygons));
            if all_corners || corners.len() < 4 {
                break;
            }
            candidates = corners;
        }
        let (tris, polygons) = best.ok_or_else(|| Error::invalid("points", DEGENERATE))?;
        Ok(assemble(points, &pts, &tris, &polygons))
    }

    /// The hull's vertices (a subset of the input points, in input order).
    pub fn vertices(&self) -> &[Vec3] {
        &self.vertices
    }

    /// Outward triangles, counter-clockwise seen from outside.
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// The planes of the hull's faces, coplanar triangles merged into one face: an outward
    /// unit normal `n` and an offset `d` with `n·x = d` on the face and `n·x <= d` inside.
    pub fn face_planes(&self) -> &[(Vec3, Real)] {
        &self.planes
    }

    /// The vertex indices around face `face` (same order as [`Self::face_planes`]),
    /// counter-clockwise seen from outside.
    ///
    /// # Panics
    /// If `face >= self.face_planes().len()`.
    pub fn face_vertices(&self, face: usize) -> &[u32] {
        &self.face_loops[face]
    }

    /// The edges between faces (each once, lower vertex index first); the diagonals that
    /// triangulate a polygonal face are not among them.
    pub fn edges(&self) -> &[[u32; 2]] {
        &self.edges
    }

    /// The vertex furthest along `dir` (the first such vertex on ties).
    pub fn support(&self, dir: Vec3) -> Vec3 {
        let mut best = self.vertices[0];
        let mut best_dot = best.dot(dir);
        for &v in &self.vertices[1..] {
            let d = v.dot(dir);
            if d > best_dot {
                best = v;
                best_dot = d;
            }
        }
        best
    }

    /// Exact mass properties for a uniform `density`.
    ///
    /// Sums, over tetrahedra from the vertex centroid to each triangle, the closed-form volume,
    /// first moment and covariance ∫x xᵀ = det/120 (s sᵀ + Σ vᵢvᵢᵀ) (s the sum of the three
    /// vertices relative to the apex); signed volumes make this exact for any closed surface.
    /// Accumulates in f64 whatever `Real` is.
    pub fn mass_properties(&self, density: Real) -> MassProperties {
        let verts: Vec<DVec3> = self.vertices.iter().map(|&v| wide::vec(v)).collect();
        // Relative to an interior point the terms stay small and cancel little.
        let apex = verts.iter().sum::<DVec3>() / verts.len() as f64;
        let (mut volume, mut first, mut second) = (0.0, DVec3::ZERO, DMat3::ZERO);
        for t in &self.triangles {
            let [a, b, c] = t.map(|i| verts[i as usize] - apex);
            let det = a.dot(b.cross(c));
            let s = a + b + c;
            volume += det / 6.0;
            first += s * (det / 24.0);
            second += (outer(s, s) + outer(a, a) + outer(b, b) + outer(c, c)) * (det / 120.0);
        }
        let center = first / volume;
        let covariance = second - outer(center, center) * volume;
        let trace = covariance.x_axis.x + covariance.y_axis.y + covariance.z_axis.z;
        let inertia = DMat3::from_diagonal(DVec3::splat(trace)) - covariance;
        let rho = wide::scalar(density);
        MassProperties {
            mass: real(rho * volume),
            center: wide::to_vec(apex + center),
            inertia: wide::to_mat(inertia * rho),
        }
    }
}

/// Conversions between `Real` and the f64 the hull computes in.
#[cfg(not(feature = "f32"))]
mod wide {
    use crate::math::{Mat3, Real, Vec3};
    use glam::{DMat3, DVec3};

    pub fn vec(v: Vec3) -> DVec3 {
        v
    }
    pub fn scalar(x: Real) -> f64 {
        x
    }
    pub fn to_vec(v: DVec3) -> Vec3 {
        v
    }
    pub fn to_mat(m: DMat3) -> Mat3 {
        m
    }
}

/// Conversions between `Real` and the f64 the hull computes in.
#[cfg(feature = "f32")]
mod wide {
    use crate::math::{Mat3, Real, Vec3};
    use glam::{DMat3, DVec3};

    pub fn vec(v: Vec3) -> DVec3 {
        v.as_dvec3()
    }
    pub fn scalar(x: Real) -> f64 {
        f64::from(x)
    }
    pub fn to_vec(v: DVec3) -> Vec3 {
        v.as_vec3()
    }
    pub fn to_mat(m: DMat3) -> Mat3 {
        m.as_mat3()
    }
}

fn outer(a: DVec3, b: DVec3) -> DMat3 {
    DMat3::from_cols(a * b.x, a * b.y, a * b.z)
}

fn validate(points: &[Vec3]) -> Result<()> {
    if let Some(i) = points.iter().position(|p| !p.is_finite()) {
        return Err(Error::invalid(
            format!("points[{i}]"),
            "must be finite numbers",
        ));
    }
    if points.len() < 4 {
        return Err(Error::invalid("points", DEGENERATE));
    }
    if u32::try_from(points.len()).is_err() {
        return Err(Error::invalid("points", "must number fewer than 2^32"));
    }
    Ok(())
}

/// Distances (in the normalised frame) that separate signal from rounding noise.
#[derive(Debug, Clone, Copy)]
struct Tolerances {
    /// How far above a face a point must be to count as outside it.
    outside: f64,
    /// How far the cloud must extend off a point, line and plane to span a volume.
    degenerate: f64,
}

/// The input in f64, scaled by a power of two so that the largest coordinate lies in
/// [0.5, 1): the scaling is exact, so exact predicates on these points are exact predicates on
/// the input, and their products can neither overflow nor (for sane inputs) underflow.
fn normalised(points: &[Vec3]) -> (Vec<DVec3>, Tolerances) {
    let wide: Vec<DVec3> = points.iter().map(|&p| wide::vec(p)).collect();
    let magnitude = wide
        .iter()
        .fold(0.0, |m: f64, p| m.max(p.abs().max_element()));
    let scale = if magnitude > 0.0 {
        pow2(-(magnitude.log2().floor() as i32) - 1)
    } else {
        1.0
    };
    let pts: Vec<DVec3> = wide.iter().map(|&p| p * scale).collect();
    let lo = pts.iter().fold(DVec3::INFINITY, |m, &p| m.min(p));
    let hi = pts.iter().fold(DVec3::NEG_INFINITY, |m, &p| m.max(p));
    let extent = (hi - lo).max_element();
    let eps = wide::scalar(EPSILON);
    // Rounding scales with the coordinates' magnitude, not the cloud's extent: a small cloud
    // far from the origin is as noisy as a large one.
    let outside = OUTSIDE_ULPS * eps * magnitude * scale;
    let degenerate = (DEGENERATE_ULPS * eps * extent).max(4.0 * outside);
    (
        pts,
        Tolerances {
            outside,
            degenerate,
        },
    )
}

/// 2^e exactly, for e clamped to the normal range.
fn pow2(e: i32) -> f64 {
    let e = e.clamp(-1022, 1023);
    f64::from_bits(((e + 1023) as u64) << 52)
}

/// (b − a) × (c − a), accurate to rounding even for slivers (see [`exact::cross`]).
fn tri_cross(pts: &[DVec3], t: [usize; 3]) -> DVec3 {
    exact::cross(pts[t[0]], pts[t[1]], pts[t[2]])
}

/// Unit normal and offset of a triangle's plane; a zero normal (and so zero distances) for a
/// triangle too thin to have one.
fn tri_plane(pts: &[DVec3], t: [usize; 3]) -> (DVec3, f64) {
    let n = tri_cross(pts, t).normalize_or_zero();
    let centroid = (pts[t[0]] + pts[t[1]] + pts[t[2]]) / 3.0;
    (n, n.dot(centroid))
}

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
fn build(pts: &[DVec3], cand: &[usize], tol: Tolerances) -> Result<Vec<[usize; 3]>> {
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

/// A polygonal face: coplanar triangles and their boundary, counter-clockwise from outside.
#[derive(Debug)]
struct Polygon {
    tris: Vec<usize>,
    boundary: Vec<usize>,
}

/// For each triangle, the triangle across each of its edges (same convention as `Face::adj`).
fn tri_adjacency(tris: &[[usize; 3]]) -> Vec<[usize; 3]> {
    let mut by_edge = BTreeMap::new();
    for (t, v) in tris.iter().enumerate() {
        for i in 0..3 {
            by_edge.insert((v[i], v[(i + 1) % 3]), t);
        }
    }
    tris.iter()
        .map(|v| {
            [0, 1, 2].map(|i| {
                by_edge
                    .get(&(v[(i + 1) % 3], v[i]))
                    .copied()
                    .unwrap_or(NONE)
            })
        })
        .collect()
}

/// Groups triangles into planar faces. Regions grow from the largest triangles (whose planes
/// are the most accurate) and take a neighbour only if all its vertices lie within `tol` of the
/// seed's plane, so a gently curved surface never drifts into one face.
fn merge_coplanar(pts: &[DVec3], tris: &[[usize; 3]], tol: f64) -> Vec<Polygon> {
    let adj = tri_adjacency(tris);
    let area: Vec<f64> = tris.iter().map(|&t| tri_cross(pts, t).length()).collect();
    let mut order: Vec<usize> = (0..tris.len()).collect();
    order.sort_by(|&a, &b| area[b].total_cmp(&area[a]).then(a.cmp(&b)));
    let mut region = vec![NONE; tris.len()];
    let mut polygons = Vec::new();
    for seed in order {
        if region[seed] != NONE {
            continue;
        }
        let id = polygons.len();
        let members = grow_region(pts, tris, &adj, &mut region, (seed, id), tol);
        match boundary_loop(tris, &adj, &region, &members, id) {
            Some(boundary) => polygons.push(Polygon {
                tris: members,
                boundary,
            }),
            None => split_region(tris, &mut region, &members, &mut polygons),
        }
    }
    polygons
}

fn grow_region(
    pts: &[DVec3],
    tris: &[[usize; 3]],
    adj: &[[usize; 3]],
    region: &mut [usize],
    (seed, id): (usize, usize),
    tol: f64,
) -> Vec<usize> {
    let (n, offset) = tri_plane(pts, tris[seed]);
    region[seed] = id;
    let mut members = vec![seed];
    // A triangle with no plane of its own says nothing about its neighbours' plane.
    if n == DVec3::ZERO {
        return members;
    }
    let mut i = 0;
    while i < members.len() {
        for &u in &adj[members[i]] {
            if u != NONE
                && region[u] == NONE
                && tris[u]
                    .iter()
                    .all(|&v| (n.dot(pts[v]) - offset).abs() <= tol)
            {
                region[u] = id;
                members.push(u);
            }
        }
        i += 1;
    }
    members
}

/// The region's boundary as one loop, or `None` if it is not a disc.
fn boundary_loop(
    tris: &[[usize; 3]],
    adj: &[[usize; 3]],
    region: &[usize],
    members: &[usize],
    id: usize,
) -> Option<Vec<usize>> {
    let mut next = BTreeMap::new();
    let mut start = NONE;
    for &t in members {
        for i in 0..3 {
            let u = adj[t][i];
            if u == NONE || region[u] != id {
                let (a, b) = (tris[t][i], tris[t][(i + 1) % 3]);
                if next.insert(a, b).is_some() {
                    // Two boundary edges leave one vertex: the region is pinched there.
                    return None;
                }
                if start == NONE {
                    start = a;
                }
            }
        }
    }
    let mut boundary = vec![start];
    let mut v = *next.get(&start)?;
    while v != start && boundary.len() < next.len() {
        boundary.push(v);
        v = *next.get(&v)?;
    }
    (v == start && boundary.len() == next.len()).then_some(boundary)
}

/// Falls back to one face per triangle, which is always valid.
fn split_region(
    tris: &[[usize; 3]],
    region: &mut [usize],
    members: &[usize],
    polygons: &mut Vec<Polygon>,
) {
    for &t in members {
        region[t] = polygons.len();
        polygons.push(Polygon {
            tris: vec![t],
            boundary: tris[t].to_vec(),
        });
    }
}

/// The vertices on at least three faces (the true corners), sorted, and whether every vertex
/// is one. A vertex on one face lies inside it and a vertex on two lies on the edge between
/// them (two planes meet in a line): neither is needed.
fn corners(tris: &[[usize; 3]], polygons: &[Polygon], n: usize) -> (Vec<usize>, bool) {
    let mut last = vec![NONE; n];
    let mut count = vec![0u32; n];
    for (id, poly) in polygons.iter().enumerate() {
        for &v in poly.tris.iter().flat_map(|&t| &tris[t]) {
            if last[v] != id {
                last[v] = id;
                count[v] += 1;
            }
        }
    }
    let used = count.iter().filter(|&&c| c > 0).count();
    let corners: Vec<usize> = (0..n).filter(|&v| count[v] >= 3).collect();
    let all = corners.len() == used;
    (corners, all)
}

/// The public hull: vertices compacted in input order, faces' planes in input coordinates.
fn assemble(
    points: &[Vec3],
    pts: &[DVec3],
    tris: &[[usize; 3]],
    polygons: &[Polygon],
) -> ConvexHull {
    let mut used: Vec<usize> = tris.iter().flatten().copied().collect();
    used.sort_unstable();
    used.dedup();
    let mut index = vec![u32::MAX; points.len()];
    for (k, &i) in used.iter().enumerate() {
        // `validate` bounds the point count by u32::MAX.
        index[i] = k as u32;
    }
    let face_loops: Vec<Vec<u32>> = polygons
        .iter()
        .map(|p| p.boundary.iter().map(|&i| index[i]).collect())
        .collect();
    ConvexHull {
        vertices: used.iter().map(|&i| points[i]).collect(),
        triangles: tris.iter().map(|t| t.map(|i| index[i])).collect(),
        planes: polygons
            .iter()
            .map(|p| polygon_plane(points, pts, tris, p))
            .collect(),
        edges: feature_edges(&face_loops),
        face_loops,
    }
}

/// The face's plane: the normal of its vector area (exact for a planar polygon, and weighted
/// towards its large triangles if rounding bent it), and the offset of its highest vertex so
/// that the whole hull lies on the inner side.
fn polygon_plane(
    points: &[Vec3],
    pts: &[DVec3],
    tris: &[[usize; 3]],
    poly: &Polygon,
) -> (Vec3, Real) {
    let area: DVec3 = poly.tris.iter().map(|&t| tri_cross(pts, tris[t])).sum();
    let n = area.normalize_or_zero();
    let offset = poly
        .tris
        .iter()
        .flat_map(|&t| tris[t])
        .map(|v| n.dot(wide::vec(points[v])))
        .fold(f64::NEG_INFINITY, f64::max);
    (wide::to_vec(n), real(offset))
}

fn feature_edges(loops: &[Vec<u32>]) -> Vec<[u32; 2]> {
    let mut edges = BTreeSet::new();
    for l in loops {
        for (k, &a) in l.iter().enumerate() {
            let b = l[(k + 1) % l.len()];
            edges.insert([a.min(b), a.max(b)]);
        }
    }
    edges.into_iter().collect()
}

/// The exact sign of the orientation determinant, after Shewchuk: a floating-point filter
/// settles almost every query and the rest are evaluated exactly with non-overlapping
/// floating-point expansions. Exactness is what keeps the hull's visibility decisions mutually
/// consistent, and so its topology valid, when points are (nearly) coplanar.
mod exact {
    use glam::DVec3;

    /// Sign (−1, 0, 1) of (b − a) × (c − a) · (p − a): positive when `p` is strictly above
    /// the plane of the counter-clockwise triangle (a, b, c). Coordinates must be small enough
    /// that products of three differences neither overflow nor underflow.
    pub fn side(a: DVec3, b: DVec3, c: DVec3, p: DVec3) -> i8 {
        let (ad, bd, cd) = (a - p, b - p, c - p);
        let det = ad.x * (bd.y * cd.z - bd.z * cd.y)
            + bd.x * (cd.y * ad.z - cd.z * ad.y)
            + cd.x * (ad.y * bd.z - ad.z * bd.y);
        let permanent = ((bd.y * cd.z).abs() + (bd.z * cd.y).abs()) * ad.x.abs()
            + ((cd.y * ad.z).abs() + (cd.z * ad.y).abs()) * bd.x.abs()
            + ((ad.y * bd.z).abs() + (ad.z * bd.y).abs()) * cd.x.abs();
        // Shewchuk bounds this evaluation's error by (7 + 56ε)ε·permanent, ε = 2⁻⁵³.
        let bound = 8.0 * f64::EPSILON * permanent;
        // det = (a − p)·((b − p) × (c − p)) is the negated side.
        if det > bound {
            -1
        } else if det < -bound {
            1
        } else {
            -exact_sign(a, b, c, p)
        }
    }

    /// (b − a) × (c − a) in double-double arithmetic, rounded once at the end. The plain
    /// float cross product of a sliver cancels to noise, and its plane, tilted by that noise,
    /// would misplace points far away along it; here the error stays near one ulp of the result.
    pub fn cross(a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
        let u = [0, 1, 2].map(|i| two_diff_dd(b[i], a[i]));
        let v = [0, 1, 2].map(|i| two_diff_dd(c[i], a[i]));
        let component = |i: usize, j: usize| {
            let (p, q) = (mul_dd(u[i], v[j]), mul_dd(u[j], v[i]));
            let (s, e) = two_sum(p.0, -q.0);
            s + (e + (p.1 - q.1))
        };
        DVec3::new(component(1, 2), component(2, 0), component(0, 1))
    }

    /// a − b as an unevaluated (high, low) pair.
    fn two_diff_dd(a: f64, b: f64) -> (f64, f64) {
        let x = a - b;
        let bv = a - x;
        let av = x + bv;
        (x, (a - av) + (bv - b))
    }

    /// The product of two (high, low) pairs to about 106 bits (the low·low term is below that).
    fn mul_dd(x: (f64, f64), y: (f64, f64)) -> (f64, f64) {
        let (p, e) = two_product(x.0, y.0);
        two_sum(p, e + (x.0 * y.1 + x.1 * y.0))
    }

    /// Sign of (a − p)·((b − p) × (c − p)), exactly.
    fn exact_sign(a: DVec3, b: DVec3, c: DVec3, p: DVec3) -> i8 {
        let d = |u: DVec3| [0, 1, 2].map(|i| two_diff(u[i], p[i]));
        let ([adx, ady, adz], [bdx, bdy, bdz], [cdx, cdy, cdz]) = (d(a), d(b), d(c));
        let bc = sub(&mul(&bdy, &cdz), &mul(&bdz, &cdy));
        let ca = sub(&mul(&cdy, &adz), &mul(&cdz, &ady));
        let ab = sub(&mul(&ady, &bdz), &mul(&adz, &bdy));
        let det = add(&add(&mul(&adx, &bc), &mul(&bdx, &ca)), &mul(&cdx, &ab));
        // Components grow in magnitude and do not overlap, so the last one sets the sign.
        match det.last() {
            Some(&x) if x > 0.0 => 1,
            Some(&x) if x < 0.0 => -1,
            _ => 0,
        }
    }

    /// Expansions: non-overlapping components in increasing magnitude, zeros dropped.
    type Expansion = Vec<f64>;

    fn two_sum(a: f64, b: f64) -> (f64, f64) {
        let x = a + b;
        let bv = x - a;
        let av = x - bv;
        (x, (a - av) + (b - bv))
    }

    fn two_diff(a: f64, b: f64) -> Expansion {
        let (x, y) = two_diff_dd(a, b);
        [y, x].into_iter().filter(|&c| c != 0.0).collect()
    }

    /// Veltkamp's split of a double into two 26-bit halves, for exact products without FMA.
    fn split(a: f64) -> (f64, f64) {
        let c = 134_217_729.0 * a;
        let hi = c - (c - a);
        (hi, a - hi)
    }

    fn two_product(a: f64, b: f64) -> (f64, f64) {
        let x = a * b;
        let ((ah, al), (bh, bl)) = (split(a), split(b));
        let err = x - ah * bh - al * bh - ah * bl;
        (x, al * bl - err)
    }

    fn push(h: &mut Expansion, x: f64) {
        if x != 0.0 {
            h.push(x);
        }
    }

    /// e + b (Shewchuk's Grow-Expansion).
    fn grow(e: &[f64], b: f64) -> Expansion {
        let mut h = Vec::with_capacity(e.len() + 1);
        let mut q = b;
        for &ei in e {
            let (s, err) = two_sum(q, ei);
            push(&mut h, err);
            q = s;
        }
        push(&mut h, q);
        h
    }

    fn add(e: &[f64], f: &[f64]) -> Expansion {
        f.iter().fold(e.to_vec(), |h, &fi| grow(&h, fi))
    }

    fn sub(e: &[f64], f: &[f64]) -> Expansion {
        let neg: Expansion = f.iter().map(|&x| -x).collect();
        add(e, &neg)
    }

    /// e·b (Shewchuk's Scale-Expansion).
    fn scale(e: &[f64], b: f64) -> Expansion {
        let mut h = Vec::with_capacity(2 * e.len());
        let Some((&e0, rest)) = e.split_first() else {
            return h;
        };
        let (mut q, err) = two_product(e0, b);
        push(&mut h, err);
        for &ei in rest {
            let (p1, p0) = two_product(ei, b);
            let (s, err) = two_sum(q, p0);
            push(&mut h, err);
            let (s2, err2) = two_sum(p1, s);
            push(&mut h, err2);
            q = s2;
        }
        push(&mut h, q);
        h
    }

    fn mul(e: &[f64], f: &[f64]) -> Expansion {
        f.iter().fold(Vec::new(), |h, &fi| add(&h, &scale(e, fi)))
    }

    #[cfg(test)]
    mod tests {
        use super::*;

        #[test]
        fn exact_sign_is_zero_for_exactly_coplanar_points_where_floats_lose_it() {
            // The plane z = x/4 + y/8 far from the origin; every coordinate is exact.
            let on = |x: f64, y: f64| DVec3::new(x, y, x / 4.0 + y / 8.0);
            let big = 2f64.powi(40);
            let (a, b, c) = (on(big, 3.0), on(big + 1.0, big), on(7.0, big + 5.0));
            let p = on(big * 0.5 + 0.25, big * 0.75 + 0.5);
            assert_eq!(side(a, b, c, p), 0);
            let up = p + DVec3::new(0.0, 0.0, 2f64.powi(-10));
            assert_eq!(side(a, b, c, up), 1);
            assert_eq!(side(a, c, b, up), -1);
        }

        #[test]
        fn near_coplanar_signs_are_consistent_under_permutation() {
            let mut s = 0x9E37_79B9_7F4A_7C15u64;
            let mut rnd = move || {
                s ^= s << 13;
                s ^= s >> 7;
                s ^= s << 17;
                (s >> 11) as f64 / (1u64 << 53) as f64
            };
            for _ in 0..2000 {
                let mut pt = || {
                    let (x, y) = (rnd() * 10.0 - 5.0, rnd() * 10.0 - 5.0);
                    DVec3::new(x, y, 0.3 * x - 0.7 * y + 0.1)
                };
                let (a, b, c, p) = (pt(), pt(), pt(), pt());
                let s0 = side(a, b, c, p);
                assert_eq!(s0, side(b, c, a, p));
                assert_eq!(s0, side(c, a, b, p));
                assert_eq!(s0, -side(b, a, c, p));
                // Swapping the query point with a vertex flips the sign of the determinant.
                assert_eq!(s0, -side(p, b, c, a));
            }
        }

        #[test]
        fn sliver_cross_products_match_exact_arithmetic() {
            let mut s = 0x2545_F491_4F6C_DD1Du64;
            let mut rnd = move || {
                s ^= s << 13;
                s ^= s >> 7;
                s ^= s << 17;
                (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
            };
            for k in 0..2000 {
                let a = DVec3::new(rnd(), rnd(), rnd()) * 7.0;
                let b = DVec3::new(rnd(), rnd(), rnd()) * 7.0;
                // Within about 1e-15 .. 1e-3 of the line ab: the float cross product of the
                // thinnest of these has no correct digit.
                let off = DVec3::new(rnd(), rnd(), rnd()) * 10f64.powi(-3 - k % 13);
                let c = a + (b - a) * rnd() + off;
                let d = |u: f64, v: f64| two_diff(u, v);
                let (u, v) = (
                    [0, 1, 2].map(|i| d(b[i], a[i])),
                    [0, 1, 2].map(|i| d(c[i], a[i])),
                );
                let exact = |i: usize, j: usize| -> f64 {
                    sub(&mul(&u[i], &v[j]), &mul(&u[j], &v[i])).iter().sum()
                };
                let expect = DVec3::new(exact(1, 2), exact(2, 0), exact(0, 1));
                let got = cross(a, b, c);
                assert!((got - expect).length() <= 4.0 * f64::EPSILON * expect.length());
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{Mat3, Quat, PI};
    use proptest::prelude::*;

    /// Slack for "on or inside the hull": ten times the construction tolerance.
    fn inside_tol(points: &[Vec3]) -> Real {
        let m = points
            .iter()
            .fold(0.0 as Real, |m, p| m.max(p.abs().max_element()));
        10.0 * OUTSIDE_ULPS as Real * EPSILON * m
    }

    fn close(a: Real, b: Real, rel: Real) -> bool {
        (a - b).abs() <= rel * a.abs().max(b.abs()).max(1.0)
    }

    fn assert_mat_close(a: Mat3, b: Mat3, tol: Real) {
        let d = (a - b)
            .to_cols_array()
            .iter()
            .fold(0.0 as Real, |m, x| m.max(x.abs()));
        assert!(d <= tol, "{a} vs {b}");
    }

    /// A valid hull of `points`: closed, convex, outward and holding every point.
    fn check_hull(hull: &ConvexHull, points: &[Vec3]) {
        check_topology(hull);
        check_geometry(hull, points);
    }

    /// Every edge used once in each direction, V − E + F = 2, every vertex used.
    fn check_topology(hull: &ConvexHull) {
        let mut directed = BTreeMap::new();
        for t in hull.triangles() {
            for i in 0..3 {
                *directed.entry((t[i], t[(i + 1) % 3])).or_insert(0) += 1;
            }
        }
        for (&(a, b), &n) in &directed {
            assert_eq!(n, 1, "edge {a}->{b} used {n} times");
            assert_eq!(directed.get(&(b, a)), Some(&1), "edge {a}->{b} has no twin");
        }
        let (v, e, f) = (
            hull.vertices().len(),
            directed.len() / 2,
            hull.triangles().len(),
        );
        assert_eq!(v as i64 - e as i64 + f as i64, 2, "Euler characteristic");
        let mut used = vec![false; v];
        hull.triangles()
            .iter()
            .flatten()
            .for_each(|&i| used[i as usize] = true);
        assert!(used.iter().all(|&u| u), "unused vertex");
    }

    /// Positive volume (outward), unit face normals, faces through their vertices, every
    /// input point on the inner side of every face, vertices drawn from the input.
    fn check_geometry(hull: &ConvexHull, points: &[Vec3]) {
        assert!(hull.mass_properties(1.0).mass > 0.0, "not outward");
        let tol = inside_tol(points);
        for (k, &(n, d)) in hull.face_planes().iter().enumerate() {
            assert!((n.length() - 1.0).abs() < 1e3 * EPSILON, "normal {n}");
            for &p in points {
                assert!(
                    n.dot(p) <= d + tol,
                    "point {p} above face {k} by {}",
                    n.dot(p) - d
                );
            }
            for &i in hull.face_vertices(k) {
                let h = n.dot(hull.vertices()[i as usize]) - d;
                assert!(h.abs() <= tol, "face {k} vertex off its plane by {h}");
            }
        }
        for v in hull.vertices() {
            assert!(points.contains(v), "vertex {v} not an input point");
        }
    }

    /// The corners, face centres, edge midpoints and some interior points of a box.
    fn box_cloud(h: Vec3) -> Vec<Vec3> {
        let mut pts = Vec::new();
        for x in [-1.0, 0.0, 1.0] {
            for y in [-1.0, 0.0, 1.0] {
                for z in [-1.0, 0.0, 1.0] {
                    pts.push(Vec3::new(x, y, z) * h);
                }
            }
        }
        pts.push(h * 0.5);
        pts.push(h * -0.25);
        pts
    }

    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> Real {
            // splitmix64
            self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^= z >> 31;
            real((z >> 11) as f64 / (1u64 << 53) as f64)
        }
        fn on_sphere(&mut self) -> Vec3 {
            loop {
                let v = Vec3::new(self.next(), self.next(), self.next()) * 2.0 - Vec3::ONE;
                if v.length_squared() > 0.01 && v.length_squared() <= 1.0 {
                    return v.normalize();
                }
            }
        }
    }

    #[test]
    fn box_with_face_edge_and_interior_points_has_only_its_corners() {
        let h = Vec3::new(1.0, 2.0, 3.0);
        let pts = box_cloud(h);
        let hull = ConvexHull::from_points(&pts).unwrap();
        check_hull(&hull, &pts);
        assert_eq!(hull.vertices().len(), 8);
        assert_eq!(hull.triangles().len(), 12);
        assert_eq!(hull.face_planes().len(), 6);
        assert_eq!(hull.edges().len(), 12);
        assert!((0..6).all(|f| hull.face_vertices(f).len() == 4));
        let density = 2.5;
        let mp = hull.mass_properties(density);
        let expect = MassProperties::cuboid(density, h);
        let rel = 100.0 * EPSILON;
        assert!(close(mp.mass, density * 8.0 * h.x * h.y * h.z, rel));
        assert!(mp.center.length() <= rel * h.length());
        assert_mat_close(
            mp.inertia,
            expect.inertia,
            rel * expect.inertia.x_axis.x.abs(),
        );
        assert!(close(
            mp.inertia.x_axis.x,
            mp.mass / 3.0 * (h.y * h.y + h.z * h.z),
            rel
        ));
    }

    #[test]
    fn rotated_translated_box_keeps_mass_moves_centre_and_turns_inertia() {
        let h = Vec3::new(0.5, 1.5, 2.0);
        let q = Quat::from_euler(glam::EulerRot::XYZ, 0.3, -1.1, 2.0);
        let t = Vec3::new(3.0, -7.0, 11.0);
        let pts: Vec<Vec3> = box_cloud(h).iter().map(|&p| t + q * p).collect();
        let hull = ConvexHull::from_points(&pts).unwrap();
        check_hull(&hull, &pts);
        assert_eq!(
            hull.vertices().len(),
            8,
            "rounded face/edge points must not be vertices"
        );
        assert_eq!(hull.face_planes().len(), 6);
        let mp = hull.mass_properties(1.0);
        let expect = MassProperties::cuboid(1.0, h).transformed(t, q);
        let rel = 1e3 * EPSILON;
        assert!(close(mp.mass, expect.mass, rel));
        assert!((mp.center - t).length() <= rel * t.length());
        assert_mat_close(
            mp.inertia,
            expect.inertia,
            rel * expect.inertia.z_axis.z.abs(),
        );
    }

    #[test]
    fn regular_tetrahedron_matches_closed_form() {
        let pts = [
            Vec3::new(1.0, 1.0, 1.0),
            Vec3::new(1.0, -1.0, -1.0),
            Vec3::new(-1.0, 1.0, -1.0),
            Vec3::new(-1.0, -1.0, 1.0),
        ];
        let hull = ConvexHull::from_points(&pts).unwrap();
        check_hull(&hull, &pts);
        assert_eq!((hull.vertices().len(), hull.triangles().len()), (4, 4));
        let a: Real = (8.0 as Real).sqrt();
        let volume = a.powi(3) / (6.0 * (2.0 as Real).sqrt());
        let mp = hull.mass_properties(3.0);
        let rel = 100.0 * EPSILON;
        assert!(
            close(mp.mass, 3.0 * volume, rel),
            "{} vs {}",
            mp.mass,
            3.0 * volume
        );
        assert!(mp.center.length() <= rel);
        // A regular tetrahedron's inertia is isotropic: m a²/20 about any axis.
        let i = mp.mass * a * a / 20.0;
        assert_mat_close(mp.inertia, Mat3::from_diagonal(Vec3::splat(i)), rel * i);
    }

    #[test]
    fn sphere_points_give_growing_inscribed_volume_and_contain_every_point() {
        let mut rng = Rng(7);
        let ball = 4.0 / 3.0 * PI;
        let mut last = 0.0;
        for n in [50, 400, 3000] {
            let pts: Vec<Vec3> = (0..n).map(|_| rng.on_sphere()).collect();
            let hull = ConvexHull::from_points(&pts).unwrap();
            check_hull(&hull, &pts);
            let v = hull.mass_properties(1.0).mass;
            assert!(v > last && v < ball, "n = {n}: volume {v}, ball {ball}");
            last = v;
        }
        assert!(last > 0.99 * ball, "{last} vs {ball}");
    }

    #[test]
    fn cylinder_rings_with_cap_centres_keep_every_ring_point() {
        let (r, hh, n) = (0.7, 1.3, 64);
        let mut pts = vec![Vec3::new(0.0, hh, 0.0), Vec3::new(0.0, -hh, 0.0)];
        for y in [hh, -hh] {
            for k in 0..n {
                let a = 2.0 * PI * k as Real / n as Real;
                pts.push(Vec3::new(r * a.cos(), y, r * a.sin()));
            }
        }
        let hull = ConvexHull::from_points(&pts).unwrap();
        check_hull(&hull, &pts);
        assert_eq!(hull.vertices().len(), 2 * n);
        assert_eq!(hull.face_planes().len(), n + 2);
        let polygon = 0.5 * n as Real * r * r * (2.0 * PI / n as Real).sin();
        let v = hull.mass_properties(1.0).mass;
        assert!(close(v, polygon * 2.0 * hh, 100.0 * EPSILON), "{v}");
    }

    #[test]
    fn rotated_lattice_reduces_to_a_cube() {
        let q = Quat::from_euler(glam::EulerRot::ZYX, 0.7, 0.2, -0.4);
        let mut pts = Vec::new();
        for i in 0..5 {
            for j in 0..5 {
                for k in 0..5 {
                    pts.push(q * Vec3::new(i as Real, j as Real, k as Real) + Vec3::splat(100.0));
                }
            }
        }
        let hull = ConvexHull::from_points(&pts).unwrap();
        check_hull(&hull, &pts);
        assert_eq!((hull.vertices().len(), hull.triangles().len()), (8, 12));
        assert!(close(hull.mass_properties(1.0).mass, 64.0, 1e4 * EPSILON));
    }

    #[test]
    fn thin_but_real_slab_is_accepted() {
        let mut rng = Rng(3);
        let pts: Vec<Vec3> = (0..200)
            .map(|_| Vec3::new(rng.next(), rng.next(), rng.next() * 0.01))
            .collect();
        let hull = ConvexHull::from_points(&pts).unwrap();
        check_hull(&hull, &pts);
    }

    #[test]
    fn output_is_deterministic_and_independent_of_input_order() {
        let mut rng = Rng(11);
        let pts: Vec<Vec3> = (0..300).map(|_| rng.on_sphere() * rng.next()).collect();
        let a = ConvexHull::from_points(&pts).unwrap();
        assert_eq!(a, ConvexHull::from_points(&pts).unwrap());
        let reversed: Vec<Vec3> = pts.iter().rev().copied().collect();
        let b = ConvexHull::from_points(&reversed).unwrap();
        let key = |h: &ConvexHull| {
            let mut v: Vec<[Real; 3]> = h.vertices().iter().map(|p| p.to_array()).collect();
            v.sort_by(|x, y| x.partial_cmp(y).unwrap());
            v
        };
        assert_eq!(key(&a), key(&b));
        assert!(close(
            a.mass_properties(1.0).mass,
            b.mass_properties(1.0).mass,
            100.0 * EPSILON
        ));
    }

    #[test]
    fn support_picks_the_extreme_vertex() {
        let hull = ConvexHull::from_points(&box_cloud(Vec3::new(1.0, 2.0, 3.0))).unwrap();
        assert_eq!(
            hull.support(Vec3::new(1.0, -1.0, 0.1)),
            Vec3::new(1.0, -2.0, 3.0)
        );
    }

    fn field_of(points: &[Vec3]) -> String {
        ConvexHull::from_points(points)
            .unwrap_err()
            .field()
            .to_string()
    }

    #[test]
    fn invalid_inputs_name_the_field() {
        let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
        assert_eq!(field_of(&tri), "points");
        assert_eq!(field_of(&[]), "points");
        let flat: Vec<Vec3> = (0..20)
            .map(|i| Vec3::new(i as Real % 5.0, i as Real / 5.0, 2.0))
            .collect();
        assert_eq!(field_of(&flat), "points");
        let tilted: Vec<Vec3> = flat
            .iter()
            .map(|&p| Quat::from_rotation_x(0.3) * p + Vec3::splat(9.0))
            .collect();
        assert_eq!(field_of(&tilted), "points");
        let line: Vec<Vec3> = (0..10)
            .map(|i| Vec3::new(1.0, 2.0, 3.0) * i as Real)
            .collect();
        assert_eq!(field_of(&line), "points");
        assert_eq!(field_of(&[Vec3::new(1.0, 2.0, 3.0); 10]), "points");
        let mut with_nan = box_cloud(Vec3::ONE);
        with_nan[3].y = Real::NAN;
        assert_eq!(field_of(&with_nan), "points[3]");
        with_nan[0].x = Real::INFINITY;
        assert_eq!(field_of(&with_nan), "points[0]");
        // Off the plane by a few ulps (rounding noise, well under the 1e3-epsilon tolerance):
        // still flat. A hundred times the tolerance is a real, if thin, solid.
        let lifted = |h: Real| -> Vec<Vec3> {
            let step = |i: usize| Vec3::Z * (i % 2) as Real * h * EPSILON;
            flat.iter().enumerate().map(|(i, &p)| p + step(i)).collect()
        };
        assert_eq!(field_of(&lifted(10.0)), "points");
        let solid = lifted(1e5);
        check_hull(&ConvexHull::from_points(&solid).unwrap(), &solid);
    }

    fn cloud(raw: &[(Real, Real, Real)], scale: Real, offset: Vec3) -> Vec<Vec3> {
        raw.iter()
            .map(|&(x, y, z)| Vec3::new(x, y, z) * scale + offset)
            .collect()
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(200))]

        #[test]
        fn random_clouds_give_closed_outward_hulls_holding_every_point(
            raw in prop::collection::vec((-1.0 as Real..1.0, -1.0 as Real..1.0, -1.0 as Real..1.0), 8..120),
            scale in 1e-2 as Real..1e2,
            offset in (-1e2 as Real..1e2, -1e2 as Real..1e2, -1e2 as Real..1e2),
        ) {
            let pts = cloud(&raw, scale, Vec3::new(offset.0, offset.1, offset.2));
            let hull = ConvexHull::from_points(&pts).unwrap();
            check_hull(&hull, &pts);
        }

        #[test]
        fn grid_clouds_with_duplicates_and_coplanar_runs_are_valid_or_flat(
            raw in prop::collection::vec((-3i32..=3, -3i32..=3, -3i32..=3), 4..60),
            angle in 0.0 as Real..3.0,
        ) {
            let q = Quat::from_euler(glam::EulerRot::XYZ, angle, 0.5 * angle, 0.3);
            let pts: Vec<Vec3> =
                raw.iter().map(|&(x, y, z)| q * Vec3::new(x as Real, y as Real, z as Real)).collect();
            match ConvexHull::from_points(&pts) {
                Ok(hull) => check_hull(&hull, &pts),
                Err(e) => {
                    prop_assert_eq!(e.field(), "points");
                    prop_assert!(grid_is_flat(&raw), "rejected a solid cloud");
                }
            }
        }
    }

    /// Whether integer points lie in one plane, in exact integer arithmetic.
    fn grid_is_flat(raw: &[(i32, i32, i32)]) -> bool {
        let p: Vec<[i64; 3]> = raw
            .iter()
            .map(|&(x, y, z)| [x.into(), y.into(), z.into()])
            .collect();
        let sub = |a: [i64; 3], b: [i64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
        let cross = |a: [i64; 3], b: [i64; 3]| {
            [
                a[1] * b[2] - a[2] * b[1],
                a[2] * b[0] - a[0] * b[2],
                a[0] * b[1] - a[1] * b[0],
            ]
        };
        let dot = |a: [i64; 3], b: [i64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        for &b in &p {
            for &c in &p {
                let n = cross(sub(b, p[0]), sub(c, p[0]));
                if n != [0, 0, 0] {
                    return p.iter().all(|&d| dot(n, sub(d, p[0])) == 0);
                }
            }
        }
        true
    }
}
