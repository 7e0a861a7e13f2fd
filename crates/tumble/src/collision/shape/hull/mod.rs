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
//!
//! Layout: this file holds the public [`ConvexHull`], input validation and the normalised
//! frame with its tolerances; `build.rs` the quickhull construction, `exact.rs` the exact
//! predicates, `faces.rs` the polygonal faces and the assembly of the result, `mass.rs` the
//! mass properties, `tests.rs` the tests.

mod build;
mod exact;
mod faces;
mod mass;
#[cfg(test)]
mod tests;

use crate::error::{Error, Result};
use crate::math::{wide, Real, Vec3, EPSILON};
use build::build;
use faces::{assemble, corners, merge_coplanar, Polygon};
use glam::DVec3;

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

    /// Checks a hull read from a snapshot: what collision and mass code index without
    /// checking (built, it holds by construction). Finite vertices, at least one; every
    /// triangle, face loop and edge naming vertices that exist; one plane per face loop,
    /// each loop a polygon.
    pub(crate) fn check_saved(&self) -> Result<()> {
        let n = self.vertices.len();
        let bad = |field: String, reason: String| Err(Error::invalid(field, reason));
        if n == 0 || self.triangles.is_empty() || self.planes.is_empty() {
            return bad("vertices".into(), "an empty hull".into());
        }
        if let Some(i) = self.vertices.iter().position(|v| !v.is_finite()) {
            return bad(format!("vertices[{i}]"), "must be finite numbers".into());
        }
        let out = |k: &u32| *k as usize >= n;
        if let Some(i) = self.triangles.iter().position(|t| t.iter().any(out)) {
            return bad(format!("triangles[{i}]"), format!("a vertex out of {n}"));
        }
        if let Some(i) = self.edges.iter().position(|e| e.iter().any(out)) {
            return bad(format!("edges[{i}]"), format!("a vertex out of {n}"));
        }
        let faces = self.planes.len();
        if self.face_loops.len() != faces {
            let loops = self.face_loops.len();
            return bad(
                "face_loops".into(),
                format!("{loops} loops for {faces} planes"),
            );
        }
        let polygon = |l: &Vec<u32>| l.len() >= 3 && !l.iter().any(out);
        if let Some(i) = self.face_loops.iter().position(|l| !polygon(l)) {
            return bad(
                format!("face_loops[{i}]"),
                format!("not a polygon of {n} vertices"),
            );
        }
        Ok(())
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

crate::codec::codec_struct!(ConvexHull {
    vertices,
    triangles,
    planes,
    face_loops,
    edges
});
