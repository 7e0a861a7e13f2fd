//! Shape cores as polytopes in the working frame: vertices, face planes, face loops, edges
//! and their arcs on the Gauss map, with the support and facing-feature queries the
//! separating-axis test and the clipper ask of them.
//!
//! Faces and edges are numbered by the shapes' own indices (a box's corners by the signs of
//! their coordinates, a hull's by its vertex and face order), so the feature ids built from
//! them stay the same from step to step for a resting contact.

use super::{Feature, EDGE, EDGE_SIN, FACE, FACE_COS};
use crate::collision::geometry::Pose;
use crate::collision::shape::Convex;
use crate::collision::shape::ConvexHull;
use crate::math::{Real, Vec3};

/// Box corner i has the sign of bit 0 on x, bit 1 on y, bit 2 on z. Faces +x, −x, +y, −y,
/// +z, −z, each counter-clockwise seen from outside.
const BOX_LOOPS: [[u32; 4]; 6] = [
    [1, 3, 7, 5],
    [0, 4, 6, 2],
    [2, 6, 7, 3],
    [0, 1, 5, 4],
    [4, 5, 7, 6],
    [0, 2, 3, 1],
];
/// The box's twelve edges: corners differing in one bit.
const BOX_EDGES: [[u32; 2]; 12] = [
    [0, 1],
    [0, 2],
    [0, 4],
    [1, 3],
    [1, 5],
    [2, 3],
    [2, 6],
    [3, 7],
    [4, 5],
    [4, 6],
    [5, 7],
    [6, 7],
];
const TRI_LOOPS: [[u32; 3]; 2] = [[0, 1, 2], [0, 2, 1]];
const TRI_EDGES: [[u32; 2]; 3] = [[0, 1], [1, 2], [0, 2]];
const SEG_EDGES: [[u32; 2]; 1] = [[0, 1]];

/// An edge of a polytope on the Gauss map: the arc between normals `a` and `b` (< 180°).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Arc {
    /// Index into [`Polytope::edges`].
    pub edge: usize,
    /// Normal of one face at the edge.
    pub a: Vec3,
    /// Normal of the other.
    pub b: Vec3,
}

/// Where a polytope's faces and edges come from.
#[derive(Debug, Clone, Copy)]
enum Topology<'h> {
    Box,
    Hull(&'h ConvexHull),
    Triangle,
    Segment,
    Point,
}

/// The core of a shape as a polytope placed in the working frame: vertices, face planes,
/// face loops and edges. Spheres are a point, capsules a segment; cylinders have none.
#[derive(Debug, Clone)]
pub(crate) struct Polytope<'h> {
    /// Vertices (working frame).
    pub verts: Vec<Vec3>,
    /// Face planes: outward unit normal n and offset d, n·x ≤ d inside.
    pub planes: Vec<(Vec3, Real)>,
    topo: Topology<'h>,
}

impl<'h> Polytope<'h> {
    /// The polytope of `c`'s core placed by `pose`, or `None` for a cylinder.
    pub fn of_core(c: &Convex<'h>, pose: &Pose) -> Option<Polytope<'h>> {
        let place = |pts: &[Vec3]| pts.iter().map(|&p| pose.transform_point(p)).collect();
        let (verts, planes, topo): (Vec<Vec3>, Vec<(Vec3, Real)>, _) = match c {
            Convex::Sphere { .. } => (vec![pose.position], Vec::new(), Topology::Point),
            Convex::Capsule { half_height, .. } => {
                if *half_height > 0.0 {
                    let h = Vec3::new(0.0, *half_height, 0.0);
                    (place(&[-h, h]), Vec::new(), Topology::Segment)
                } else {
                    (vec![pose.position], Vec::new(), Topology::Point)
                }
            }
            Convex::Cylinder { .. } => return None,
            Convex::Box { half_extents: h } => {
                let corners: Vec<Vec3> = (0..8)
                    .map(|i| {
                        let s = |bit: u32| if i & bit != 0 { 1.0 } else { -1.0 };
                        Vec3::new(s(1) * h.x, s(2) * h.y, s(4) * h.z)
                    })
                    .collect();
                let axes = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
                let extents = [h.x, h.x, h.y, h.y, h.z, h.z];
                let planes = axes
                    .iter()
                    .zip(extents)
                    .map(|(&n, e)| place_plane(pose, n, e))
                    .collect();
                (place(&corners), planes, Topology::Box)
            }
            Convex::Hull(hull) => (
                place(hull.vertices()),
                hull.face_planes()
                    .iter()
                    .map(|&(n, d)| place_plane(pose, n, d))
                    .collect(),
                Topology::Hull(hull),
            ),
            Convex::Triangle(t) => {
                let v: Vec<Vec3> = place(t);
                let n = (v[1] - v[0]).cross(v[2] - v[0]).normalize_or_zero();
                // A triangle too thin to have a normal is only its edges.
                let planes = if n != Vec3::ZERO && n.is_finite() {
                    vec![(n, n.dot(v[0])), (-n, -n.dot(v[0]))]
                } else {
                    Vec::new()
                };
                (v, planes, Topology::Triangle)
            }
        };
        Some(Polytope {
            verts,
            planes,
            topo,
        })
    }

    /// The vertex indices around face `i`, counter-clockwise seen from outside.
    pub fn face_loop(&self, i: usize) -> &[u32] {
        match self.topo {
            Topology::Box => &BOX_LOOPS[i],
            Topology::Hull(h) => h.face_vertices(i),
            Topology::Triangle => &TRI_LOOPS[i],
            Topology::Segment | Topology::Point => &[],
        }
    }

    /// The edges as vertex index pairs.
    pub fn edges(&self) -> &[[u32; 2]] {
        match self.topo {
            Topology::Box => &BOX_EDGES,
            Topology::Hull(h) => h.edges(),
            Topology::Triangle => &TRI_EDGES,
            Topology::Segment => &SEG_EDGES,
            Topology::Point => &[],
        }
    }

    /// Each edge's arc on the Gauss map (the unit sphere of normals): the great-circle arc
    /// between the normals of the two faces that meet at it. A triangle, being flat, has a
    /// half circle per edge, from its front normal through the edge's outward in-plane
    /// normal to its back normal, given as two quarter arcs. `None` for segments and points
    /// (their Gauss maps are not made of arcs) or a hull whose loops do not pair up.
    pub fn arcs(&self) -> Option<Vec<Arc>> {
        match self.topo {
            Topology::Box => Some(self.box_arcs()),
            Topology::Hull(h) => self.hull_arcs(h),
            Topology::Triangle => self.triangle_arcs(),
            Topology::Segment | Topology::Point => None,
        }
    }

    /// A box's twelve arcs, each between the normals of the two faces at the edge.
    fn box_arcs(&self) -> Vec<Arc> {
        let normal = |f: usize| self.planes[f].0;
        BOX_EDGES
            .iter()
            .enumerate()
            .map(|(k, e)| {
                // The two faces across the edge are those of the two axes it does not
                // run along, on the sides its corners are on (face 2·axis, +1 if −).
                let along = e[0] ^ e[1];
                let mut f = [0; 2];
                let mut n = 0;
                for (axis, bit) in [1u32, 2, 4].into_iter().enumerate() {
                    if bit != along {
                        f[n] = 2 * axis + usize::from(e[0] & bit == 0);
                        n += 1;
                    }
                }
                Arc {
                    edge: k,
                    a: normal(f[0]),
                    b: normal(f[1]),
                }
            })
            .collect()
    }

    /// A hull's arcs, from the two faces whose loops share each edge; `None` if an edge does
    /// not border exactly two faces.
    fn hull_arcs(&self, h: &ConvexHull) -> Option<Vec<Arc>> {
        let normal = |f: usize| self.planes[f].0;
        // Edges are stored sorted by (lower, higher) vertex index; every loop side is
        // one of them, and each edge borders exactly two faces.
        let edges = h.edges();
        let mut faces = vec![[usize::MAX; 2]; edges.len()];
        for f in 0..self.planes.len() {
            let l = h.face_vertices(f);
            for k in 0..l.len() {
                let (u, v) = (l[k], l[(k + 1) % l.len()]);
                let i = edges.binary_search(&[u.min(v), u.max(v)]).ok()?;
                let slot = faces[i].iter().position(|&x| x == usize::MAX)?;
                faces[i][slot] = f;
            }
        }
        faces
            .iter()
            .enumerate()
            .map(|(k, f)| {
                (f[1] != usize::MAX).then(|| Arc {
                    edge: k,
                    a: normal(f[0]),
                    b: normal(f[1]),
                })
            })
            .collect()
    }

    /// A triangle's six quarter arcs, two per edge; `None` if an edge has no in-plane normal.
    fn triangle_arcs(&self) -> Option<Vec<Arc>> {
        let n = self.planes.first()?.0;
        let mut arcs = Vec::with_capacity(6);
        for (k, e) in TRI_EDGES.iter().enumerate() {
            let (p, q) = (self.verts[e[0] as usize], self.verts[e[1] as usize]);
            let r = self.verts[3 - e[0] as usize - e[1] as usize];
            // In plane, perpendicular to the edge, away from the third vertex.
            let mut m = (q - p).cross(n).normalize_or_zero();
            if m.dot(r - p) > 0.0 {
                m = -m;
            }
            if m == Vec3::ZERO {
                return None;
            }
            arcs.push(Arc {
                edge: k,
                a: n,
                b: m,
            });
            arcs.push(Arc {
                edge: k,
                a: m,
                b: -n,
            });
        }
        Some(arcs)
    }

    /// The vertex furthest along `d` (lowest index on ties).
    pub fn support(&self, d: Vec3) -> usize {
        let mut best = 0;
        let mut best_dot = Real::NEG_INFINITY;
        for (i, v) in self.verts.iter().enumerate() {
            let x = v.dot(d);
            if x > best_dot {
                best = i;
                best_dot = x;
            }
        }
        best
    }

    /// The smallest v·d over the vertices.
    pub fn min_dot(&self, d: Vec3) -> Real {
        self.verts
            .iter()
            .fold(Real::INFINITY, |lo, v| lo.min(v.dot(d)))
    }

    /// The smallest and largest of v·d over the vertices.
    pub fn range(&self, d: Vec3) -> (Real, Real) {
        self.verts
            .iter()
            .fold((Real::INFINITY, Real::NEG_INFINITY), |(lo, hi), v| {
                let x = v.dot(d);
                (lo.min(x), hi.max(x))
            })
    }

    /// Face `i` as a polygon feature (radius offset along `n` for round cores: none here).
    pub fn face_feature(&self, i: usize) -> Feature {
        let ids: Vec<u32> = self.face_loop(i).to_vec();
        Feature {
            pts: ids.iter().map(|&k| self.verts[k as usize]).collect(),
            ids,
            kind: FACE,
            index: i as u32,
            normal: self.planes[i].0,
        }
    }

    /// The face whose normal is furthest along `d`, with that dot product.
    pub fn best_face(&self, d: Vec3) -> Option<(usize, Real)> {
        let mut best: Option<(usize, Real)> = None;
        for (i, (n, _)) in self.planes.iter().enumerate() {
            let x = n.dot(d);
            if best.is_none_or(|(_, b)| x > b) {
                best = Some((i, x));
            }
        }
        best
    }

    /// The feature facing the unit direction `dir`: the face if one is within [`FACE_COS`],
    /// else the edge at the support vertex lying most across `dir` if within [`EDGE_SIN`],
    /// else that vertex. Points are offset by `radius` along `dir` (round cores).
    pub fn feature(&self, dir: Vec3, radius: Real) -> Feature {
        let off = dir * radius;
        if let Some((i, x)) = self.best_face(dir) {
            if x >= FACE_COS {
                return self.face_feature(i);
            }
        }
        let s = self.support(dir) as u32;
        let mut best: Option<(usize, u32, Real)> = None;
        for (k, e) in self.edges().iter().enumerate() {
            let other = if e[0] == s {
                e[1]
            } else if e[1] == s {
                e[0]
            } else {
                continue;
            };
            let u = (self.verts[other as usize] - self.verts[s as usize]).normalize_or_zero();
            if u == Vec3::ZERO {
                continue;
            }
            let c = u.dot(dir).abs();
            if best.is_none_or(|(_, _, b)| c < b) {
                best = Some((k, other, c));
            }
        }
        match best {
            Some((k, other, c)) if c <= EDGE_SIN => {
                let (i, j) = (s.min(other), s.max(other));
                Feature {
                    pts: vec![self.verts[i as usize] + off, self.verts[j as usize] + off],
                    ids: vec![i, j],
                    kind: EDGE,
                    index: k as u32,
                    normal: dir,
                }
            }
            _ => Feature::point(self.verts[s as usize] + off, s, dir),
        }
    }
}

/// A plane (n, d) of a local frame in the working frame.
fn place_plane(pose: &Pose, n: Vec3, d: Real) -> (Vec3, Real) {
    let m = pose.transform_vector(n);
    (m, d + m.dot(pose.position))
}
