//! Polygonal faces from the hull's triangles: coplanar triangles merged into discs, the true
//! corners (vertices on three or more faces) that a rebuild keeps, and the public hull
//! assembled from them, with each face's plane and the feature edges between faces.

use super::{tri_cross, tri_plane, ConvexHull, NONE};
use crate::math::wide;
use crate::math::{real, Real, Vec3};
use glam::DVec3;
use std::collections::{BTreeMap, BTreeSet};

/// A polygonal face: coplanar triangles and their boundary, counter-clockwise from outside.
#[derive(Debug)]
pub(super) struct Polygon {
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
pub(super) fn merge_coplanar(pts: &[DVec3], tris: &[[usize; 3]], tol: f64) -> Vec<Polygon> {
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
pub(super) fn corners(tris: &[[usize; 3]], polygons: &[Polygon], n: usize) -> (Vec<usize>, bool) {
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
pub(super) fn assemble(
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
