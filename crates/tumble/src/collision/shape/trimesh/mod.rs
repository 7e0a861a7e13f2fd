//! Triangle meshes (static geometry) with their own bounding-volume hierarchy, triangle
//! adjacency and edge convexity.
//!
//! The hierarchy is a binary tree of boxes built once, top-down with the binned surface-area
//! heuristic (SAH), and stored flat: the two children of a node sit next to each other, so
//! a node needs only the index of the first one. Queries walk it with a fixed-size stack.
//!
//! Adjacency pairs the triangles that share an edge (by vertex *position*, so meshes whose
//! vertices are duplicated per triangle still connect), and each shared edge gets a signed
//! bend angle: how far the neighbour's face turns away (convex, > 0) or towards (concave,
//! < 0) this triangle's front side. The narrow phase uses it to reject contact normals that
//! come from internal edges a smooth surface does not have.
//!
//! Layout: this file holds the mesh, its queries and the triangle geometry they share with
//! height fields; `build.rs` the one-time adjacency and hierarchy builds; `tests.rs` the
//! tests.

mod build;
#[cfg(test)]
mod tests;

use crate::collision::geometry::Aabb;
use crate::error::{Error, Result};
use crate::math::{Real, Vec3, EPSILON};
pub(crate) use build::padded;

/// How two triangles meet along an edge, seen from one of them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EdgeKind {
    /// No neighbour (or more than one, or an inconsistently wound one): an open border.
    Boundary,
    /// The neighbour bends away from the front side (a ridge).
    Convex,
    /// The neighbour lies in the same plane, to within [`FLAT_EDGE_ANGLE`].
    Flat,
    /// The neighbour bends towards the front side (a valley).
    Concave,
}

/// Edges whose faces differ by less than this angle (rad) are classed as flat. Only the
/// classification uses it; collision works with the exact bend angle.
pub const FLAT_EDGE_ANGLE: Real = 1e-3;

/// Bend angle stored for boundary edges, where the surface simply ends: the narrow phase
/// lets contact normals tilt out over them (up to a quarter turn).
pub(crate) const BOUNDARY_BEND: Real = Real::INFINITY;

/// Leaves hold at most this many triangles once the SAH prefers not to split further.
const MAX_LEAF: usize = 4;
/// Bins per axis for the SAH sweep; 16 is the usual point of diminishing returns.
const BINS: usize = 16;
/// Below this depth splits follow the SAH; deeper ones are forced to the object median,
/// which halves the count, so the tree is at most `SAH_DEPTH + 32` deep for any u32-sized
/// mesh and the traversal stack below cannot overflow.
const SAH_DEPTH: usize = 64;
/// Traversal stack size: one entry per level is pushed at most.
const STACK: usize = 128;

/// A node of the flattened hierarchy. `count > 0`: a leaf over `order[first..first+count]`;
/// `count == 0`: an inner node whose children are `first` and `first + 1`.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Node {
    aabb: Aabb,
    first: u32,
    count: u32,
}

/// A triangle mesh: vertices and counter-clockwise (seen from the front) index triples.
/// Front faces have normals (v1 − v0) × (v2 − v0).
#[derive(Debug, Clone, PartialEq)]
pub struct TriMesh {
    vertices: Vec<Vec3>,
    indices: Vec<[u32; 3]>,
    /// Unit front normal per triangle.
    normals: Vec<Vec3>,
    /// Per triangle, the neighbour across edge k (from corner k to corner k+1).
    neighbors: Vec<[Option<u32>; 3]>,
    /// Per triangle and edge, the signed bend angle (rad) or [`BOUNDARY_BEND`].
    bends: Vec<[Real; 3]>,
    /// Exact bounds of all vertices in use.
    bounds: Aabb,
    nodes: Vec<Node>,
    /// Triangle indices in leaf order.
    order: Vec<u32>,
}

impl TriMesh {
    /// Builds the mesh and its hierarchy; fails on empty input, non-finite vertices,
    /// out-of-range indices or zero-area triangles, naming the entry.
    pub fn new(vertices: Vec<Vec3>, indices: Vec<[u32; 3]>) -> Result<TriMesh> {
        if indices.is_empty() {
            return Err(Error::invalid("indices", "must hold at least one triangle"));
        }
        // Node indices are u32 and a tree has fewer than 2n nodes.
        if indices.len() > (u32::MAX / 2) as usize {
            return Err(Error::invalid(
                "indices",
                "too many triangles (at most 2^31)",
            ));
        }
        for (i, v) in vertices.iter().enumerate() {
            if !(v.x.is_finite() && v.y.is_finite() && v.z.is_finite()) {
                return Err(Error::invalid(
                    format!("vertices[{i}]"),
                    "must be finite numbers",
                ));
            }
        }
        let mut normals = Vec::with_capacity(indices.len());
        for (i, tri) in indices.iter().enumerate() {
            for &k in tri {
                if k as usize >= vertices.len() {
                    return Err(Error::invalid(
                        format!("indices[{i}]"),
                        format!(
                            "vertex index {k} out of range ({} vertices)",
                            vertices.len()
                        ),
                    ));
                }
            }
            let [a, b, c] = tri.map(|k| vertices[k as usize]);
            match face_normal(a, b, c) {
                Some(n) => normals.push(n),
                None => {
                    return Err(Error::invalid(
                        format!("indices[{i}]"),
                        "degenerate triangle (zero area)",
                    ))
                }
            }
        }
        let mut mesh = TriMesh {
            vertices,
            indices,
            normals,
            neighbors: Vec::new(),
            bends: Vec::new(),
            bounds: Aabb::new(Vec3::ZERO, Vec3::ZERO),
            nodes: Vec::new(),
            order: Vec::new(),
        };
        mesh.build_adjacency();
        mesh.build_bvh();
        Ok(mesh)
    }

    /// Checks a mesh read from a snapshot: what its queries index without checking (built,
    /// it holds by construction). Vertices finite; at least one triangle, its corners,
    /// neighbours and per-triangle lists in range; a hierarchy whose root exists, whose
    /// leaves slice `order` within it and whose inner nodes' children come after them (so
    /// a walk ends), and an `order` of triangles that exist.
    pub(crate) fn check_saved(&self) -> Result<()> {
        let (vertices, triangles) = (self.vertices.len(), self.indices.len());
        let bad = |field: String, reason: String| Err(Error::invalid(field, reason));
        if let Some(i) = self.vertices.iter().position(|v| !v.is_finite()) {
            return bad(format!("vertices[{i}]"), "must be finite numbers".into());
        }
        let lists = [self.normals.len(), self.neighbors.len(), self.bends.len()];
        if triangles == 0 || lists.iter().any(|&n| n != triangles) {
            return bad(
                "indices".into(),
                format!("{triangles} triangles, lists {lists:?}"),
            );
        }
        let outside = |t: &[u32; 3]| t.iter().any(|&k| k as usize >= vertices);
        if let Some(i) = self.indices.iter().position(outside) {
            return bad(
                format!("indices[{i}]"),
                format!("a vertex out of {vertices}"),
            );
        }
        let next = |n: &[Option<u32>; 3]| n.iter().flatten().any(|&t| t as usize >= triangles);
        if let Some(i) = self.neighbors.iter().position(next) {
            return bad(
                format!("neighbors[{i}]"),
                format!("a triangle out of {triangles}"),
            );
        }
        if let Some(i) = self.order.iter().position(|&t| t as usize >= triangles) {
            return bad(
                format!("order[{i}]"),
                format!("a triangle out of {triangles}"),
            );
        }
        let (nodes, order) = (self.nodes.len() as u64, self.order.len() as u64);
        let fits = |(i, n): (usize, &Node)| {
            let first = n.first as u64;
            if n.count > 0 {
                first + n.count as u64 <= order
            } else {
                first > i as u64 && first + 1 < nodes
            }
        };
        if let Some(i) = self.nodes.iter().enumerate().position(|x| !fits(x)) {
            return bad(format!("nodes[{i}]"), "out of the hierarchy".into());
        }
        if nodes == 0 {
            return bad("nodes".into(), "empty".into());
        }
        Ok(())
    }

    /// Whether [`TriMesh::new`] takes the triangle `a b c`: one of non-zero area by its
    /// test (no two edges parallel to rounding), so that importers can drop the others
    /// (sliver faces of exported meshes) before building.
    pub fn has_area(a: Vec3, b: Vec3, c: Vec3) -> bool {
        face_normal(a, b, c).is_some()
    }

    /// Vertices, local frame.
    pub fn vertices(&self) -> &[Vec3] {
        &self.vertices
    }

    /// Triangles as index triples.
    pub fn indices(&self) -> &[[u32; 3]] {
        &self.indices
    }

    /// Number of triangles.
    pub fn len(&self) -> usize {
        self.indices.len()
    }

    /// Always false: a mesh holds at least one triangle.
    pub fn is_empty(&self) -> bool {
        self.indices.is_empty()
    }

    /// Triangle `i`'s corners, local frame.
    ///
    /// # Panics
    /// If `i >= self.len()`; [`Self::get_triangle`] returns `None` instead.
    pub fn triangle(&self, i: usize) -> [Vec3; 3] {
        let [a, b, c] = self.indices[i];
        [
            self.vertices[a as usize],
            self.vertices[b as usize],
            self.vertices[c as usize],
        ]
    }

    /// Triangle `i`'s corners, local frame, or `None` if out of range.
    pub fn get_triangle(&self, i: usize) -> Option<[Vec3; 3]> {
        // Indices were checked against the vertex count on construction.
        self.indices
            .get(i)
            .map(|t| t.map(|k| self.vertices[k as usize]))
    }

    /// Triangle `i`'s unit front normal, local frame.
    pub fn normal(&self, i: usize) -> Option<Vec3> {
        self.normals.get(i).copied()
    }

    /// The triangles across triangle `i`'s edges (edge k runs from corner k to corner
    /// k + 1); `None` on a boundary edge.
    pub fn neighbors(&self, i: usize) -> Option<[Option<u32>; 3]> {
        self.neighbors.get(i).copied()
    }

    /// How triangle `i` meets its neighbours along its three edges.
    pub fn edge_kinds(&self, i: usize) -> Option<[EdgeKind; 3]> {
        self.bends.get(i).map(|b| b.map(edge_kind))
    }

    /// Signed bend angles of triangle `i`'s edges (rad; > 0 convex, < 0 concave, +∞ on
    /// boundaries).
    pub(crate) fn edge_bends(&self, i: usize) -> [Real; 3] {
        self.bends.get(i).copied().unwrap_or([BOUNDARY_BEND; 3])
    }

    /// Bounds of the whole mesh, local frame.
    pub fn local_aabb(&self) -> Aabb {
        self.bounds
    }

    /// Calls `f` with the index of every triangle whose bounds overlap `aabb` (local frame).
    /// Triangles come in hierarchy order, each once.
    pub fn for_each_triangle_in(&self, aabb: &Aabb, mut f: impl FnMut(usize)) {
        self.walk(
            |b| b.overlaps(aabb),
            |i| {
                if self.triangle_aabb(i).overlaps(aabb) {
                    f(i);
                }
            },
        );
    }

    /// The nearest crossing of the segment `origin + t·dir`, t in [0, max_t], with any
    /// triangle from either side: `(t, triangle index)`, the lower index on exact ties.
    pub fn cast_ray(&self, origin: Vec3, dir: Vec3, max_t: Real) -> Option<(Real, usize)> {
        if max_t.is_nan() || max_t < 0.0 {
            return None;
        }
        let mut best: Option<(Real, usize)> = None;
        let mut stack = [0u32; STACK];
        let mut sp = 1; // stack[0] = root
        while sp > 0 {
            sp -= 1;
            let node = self.nodes[stack[sp] as usize];
            let limit = best.map_or(max_t, |b| b.0);
            if node.aabb.ray_interval(origin, dir, limit).is_none() {
                continue;
            }
            if node.count > 0 {
                for &tri in self.leaf(&node) {
                    let i = tri as usize;
                    let Some(t) = ray_triangle(origin, dir, &self.triangle(i), limit) else {
                        continue;
                    };
                    let better = match best {
                        None => true,
                        Some((bt, bi)) => t < bt || (t == bt && i < bi),
                    };
                    if better {
                        best = Some((t, i));
                    }
                }
                continue;
            }
            // Push the farther child first so the nearer one is searched first and
            // shrinks the limit for the other.
            let (l, r) = (node.first, node.first + 1);
            let tl = self.nodes[l as usize].aabb.ray_interval(origin, dir, limit);
            let tr = self.nodes[r as usize].aabb.ray_interval(origin, dir, limit);
            let (near, far) = match (tl, tr) {
                (Some(a), Some(b)) if b.0 < a.0 => (r, Some(l)),
                (Some(_), Some(_)) => (l, Some(r)),
                (Some(_), None) => (l, None),
                (None, Some(_)) => (r, None),
                (None, None) => continue,
            };
            if let Some(far) = far {
                push(&mut stack, &mut sp, far);
            }
            push(&mut stack, &mut sp, near);
        }
        best
    }

    /// The closest point of the mesh surface to `p` (local frame): `(point, triangle)`,
    /// the lower index on exact ties.
    pub fn closest_point(&self, p: Vec3) -> Option<(Vec3, usize)> {
        let mut best: Option<(Real, Vec3, usize)> = None;
        let mut stack = [0u32; STACK];
        let mut sp = 1;
        while sp > 0 {
            sp -= 1;
            let node = self.nodes[stack[sp] as usize];
            if let Some((d2, _, _)) = best {
                if aabb_distance_squared(&node.aabb, p) > d2 {
                    continue;
                }
            }
            if node.count > 0 {
                for &tri in self.leaf(&node) {
                    let i = tri as usize;
                    let q = closest_on_triangle(p, &self.triangle(i));
                    let d2 = (q - p).length_squared();
                    let better = match best {
                        None => true,
                        Some((bd, _, bi)) => d2 < bd || (d2 == bd && i < bi),
                    };
                    if better {
                        best = Some((d2, q, i));
                    }
                }
                continue;
            }
            let (l, r) = (node.first, node.first + 1);
            let dl = aabb_distance_squared(&self.nodes[l as usize].aabb, p);
            let dr = aabb_distance_squared(&self.nodes[r as usize].aabb, p);
            let (near, far) = if dr < dl { (r, l) } else { (l, r) };
            push(&mut stack, &mut sp, far);
            push(&mut stack, &mut sp, near);
        }
        best.map(|(_, q, i)| (q, i))
    }

    /// The point of triangle `tri` closest to `p`; shared with the point queries.
    pub(crate) fn closest_point_on_triangle(p: Vec3, tri: &[Vec3; 3]) -> Vec3 {
        closest_on_triangle(p, tri)
    }

    fn leaf(&self, node: &Node) -> &[u32] {
        let start = node.first as usize;
        &self.order[start..start + node.count as usize]
    }

    fn triangle_aabb(&self, i: usize) -> Aabb {
        let [a, b, c] = self.triangle(i);
        Aabb::new(a.min(b).min(c), a.max(b).max(c))
    }

    /// Depth-first walk: descends into nodes whose box passes `enter`, calls `leaf_fn` for
    /// every triangle of the leaves reached.
    fn walk(&self, enter: impl Fn(&Aabb) -> bool, mut leaf_fn: impl FnMut(usize)) {
        let mut stack = [0u32; STACK];
        let mut sp = 1;
        while sp > 0 {
            sp -= 1;
            let node = self.nodes[stack[sp] as usize];
            if !enter(&node.aabb) {
                continue;
            }
            if node.count > 0 {
                for &tri in self.leaf(&node) {
                    leaf_fn(tri as usize);
                }
            } else {
                push(&mut stack, &mut sp, node.first + 1);
                push(&mut stack, &mut sp, node.first);
            }
        }
    }
}

/// Pushes onto a traversal stack. The build bounds the depth well below [`STACK`]; should
/// that ever fail, the subtree is dropped rather than panicking.
#[inline]
fn push(stack: &mut [u32; STACK], sp: &mut usize, node: u32) {
    if let Some(slot) = stack.get_mut(*sp) {
        *slot = node;
        *sp += 1;
    }
}

/// Unit normal of (a, b, c) from (b − a) × (c − a), or `None` when the triangle has no
/// area. The edges are scaled to unit size first so huge or tiny coordinates neither
/// overflow nor underflow, and "no area" means the sine of the corner angle is within a
/// few rounding errors of zero, i.e. the corners are collinear as far as `Real` can tell.
pub(crate) fn face_normal(a: Vec3, b: Vec3, c: Vec3) -> Option<Vec3> {
    let (e1, e2) = (b - a, c - a);
    let s = e1.abs().max_element().max(e2.abs().max_element());
    if s.is_nan() || s <= 0.0 || !s.is_finite() {
        return None;
    }
    let (e1, e2) = (e1 / s, e2 / s);
    let cross = e1.cross(e2);
    let len = cross.length();
    let collinear = len <= 16.0 * EPSILON * e1.length() * e2.length();
    if collinear || !len.is_finite() {
        return None;
    }
    Some(cross / len)
}

/// Signed angle (rad) by which the neighbour's face (normal `n_u`) turns away from the
/// face with normal `n` across its edge a→b: positive when the surface folds away from
/// the front side (convex), negative when it folds towards it (concave).
pub(crate) fn edge_bend(n: Vec3, a: Vec3, b: Vec3, n_u: Vec3) -> Real {
    // Outward direction of the edge within the face plane: faces are counter-clockwise
    // seen from the front, so the inside lies to the left of a→b and (b − a) × n points
    // out. A convex neighbour's normal leans towards it.
    let out = (b - a).cross(n).normalize_or_zero();
    n_u.dot(out).atan2(n_u.dot(n))
}

fn edge_kind(bend: Real) -> EdgeKind {
    if bend == BOUNDARY_BEND {
        EdgeKind::Boundary
    } else if bend > FLAT_EDGE_ANGLE {
        EdgeKind::Convex
    } else if bend < -FLAT_EDGE_ANGLE {
        EdgeKind::Concave
    } else {
        EdgeKind::Flat
    }
}

/// Ray parameter where `origin + t·dir` crosses the triangle (either side), t in
/// [0, max_t]. Möller–Trumbore with a few ulps of slack on the barycentric bounds so a ray
/// through a shared edge cannot slip between two triangles.
pub(crate) fn ray_triangle(origin: Vec3, dir: Vec3, tri: &[Vec3; 3], max_t: Real) -> Option<Real> {
    let e1 = tri[1] - tri[0];
    let e2 = tri[2] - tri[0];
    let p = dir.cross(e2);
    let det = e1.dot(p);
    if det == 0.0 || !det.is_finite() {
        return None; // parallel to the plane (or degenerate input)
    }
    let inv = 1.0 / det;
    let s = origin - tri[0];
    let u = s.dot(p) * inv;
    let slack = 64.0 * EPSILON;
    if u.is_nan() || u < -slack || u > 1.0 + slack {
        return None;
    }
    let q = s.cross(e1);
    let v = dir.dot(q) * inv;
    if v.is_nan() || v < -slack || u + v > 1.0 + slack {
        return None;
    }
    let t = e2.dot(q) * inv;
    if t >= 0.0 && t <= max_t {
        Some(t)
    } else {
        None
    }
}

/// The point of triangle `tri` closest to `p` (Ericson, Real-Time Collision Detection
/// §5.1.5: Voronoi regions of the corners, then the edges, then the face).
pub(crate) fn closest_on_triangle(p: Vec3, tri: &[Vec3; 3]) -> Vec3 {
    let [a, b, c] = *tri;
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = va + vb + vc;
    if denom.is_nan() || denom <= 0.0 || !denom.is_finite() {
        return a; // cannot happen for a triangle with area; never divide by zero
    }
    a + ab * (vb / denom) + ac * (vc / denom)
}

/// Squared distance from `p` to the box (0 inside).
pub(crate) fn aabb_distance_squared(b: &Aabb, p: Vec3) -> Real {
    let q = p.clamp(b.min, b.max);
    (q - p).length_squared()
}

crate::codec::codec_struct!(Node { aabb, first, count });
crate::codec::codec_struct!(TriMesh {
    vertices,
    indices,
    normals,
    neighbors,
    bends,
    bounds,
    nodes,
    order
});
