//! Building a mesh's derived data once, at construction: triangle adjacency with the bend
//! of every shared edge, and the bounding-volume hierarchy.
//!
//! Adjacency welds vertices by exact position, so a mesh with per-triangle vertices still
//! connects; only an edge run by exactly two triangles in opposite directions is manifold,
//! every other edge stays a boundary. The hierarchy is built top-down and iteratively with
//! the binned surface-area heuristic, into the flat node array the queries walk.

use super::{edge_bend, Node, TriMesh, BINS, BOUNDARY_BEND, MAX_LEAF, SAH_DEPTH};
use crate::collision::geometry::Aabb;
use crate::math::{Real, Vec3, EPSILON};

impl TriMesh {
    /// Pairs triangles across shared edges and measures the bend of each.
    pub(super) fn build_adjacency(&mut self) {
        let n = self.indices.len();
        // Weld vertices by exact position (−0 folded into +0) so duplicated vertices
        // connect: sort vertex indices by position and number the distinct positions.
        let canon: Vec<Vec3> = self.vertices.iter().map(|v| *v + Vec3::ZERO).collect();
        let mut by_pos: Vec<u32> = (0..canon.len() as u32).collect();
        let cmp = |a: &u32, b: &u32| {
            let (p, q) = (canon[*a as usize], canon[*b as usize]);
            p.x.total_cmp(&q.x)
                .then(p.y.total_cmp(&q.y))
                .then(p.z.total_cmp(&q.z))
        };
        by_pos.sort_by(cmp);
        let mut weld = vec![0u32; canon.len()];
        let mut id = 0u32;
        for w in 0..by_pos.len() {
            if w > 0 && cmp(&by_pos[w - 1], &by_pos[w]).is_ne() {
                id += 1;
            }
            weld[by_pos[w] as usize] = id;
        }
        // Every edge once per triangle, keyed by its welded ends in ascending order.
        let mut edges: Vec<(u32, u32, u32, u8, bool)> = Vec::with_capacity(3 * n);
        for (t, tri) in self.indices.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (weld[tri[k] as usize], weld[tri[(k + 1) % 3] as usize]);
                edges.push((a.min(b), a.max(b), t as u32, k as u8, a < b));
            }
        }
        edges.sort_unstable();
        self.neighbors = vec![[None; 3]; n];
        self.bends = vec![[BOUNDARY_BEND; 3]; n];
        let mut g = 0;
        while g < edges.len() {
            let mut h = g + 1;
            while h < edges.len() && (edges[h].0, edges[h].1) == (edges[g].0, edges[g].1) {
                h += 1;
            }
            // Exactly two triangles running the edge in opposite directions form a
            // manifold edge; anything else stays a boundary, where no normal is rejected
            // (an occasional bump is better than a body falling through).
            if h - g == 2 && edges[g].4 != edges[g + 1].4 {
                let (t, k) = (edges[g].2 as usize, edges[g].3 as usize);
                let (u, j) = (edges[g + 1].2 as usize, edges[g + 1].3 as usize);
                self.neighbors[t][k] = Some(u as u32);
                self.neighbors[u][j] = Some(t as u32);
                let tri_t = self.triangle(t);
                let tri_u = self.triangle(u);
                self.bends[t][k] = edge_bend(
                    self.normals[t],
                    tri_t[k],
                    tri_t[(k + 1) % 3],
                    self.normals[u],
                );
                self.bends[u][j] = edge_bend(
                    self.normals[u],
                    tri_u[j],
                    tri_u[(j + 1) % 3],
                    self.normals[t],
                );
            }
            g = h;
        }
    }

    /// Top-down binned-SAH build into the flat node array, iteratively (no recursion, so
    /// no stack overflow on pathological input).
    pub(super) fn build_bvh(&mut self) {
        let n = self.indices.len();
        let boxes: Vec<Aabb> = (0..n).map(|i| self.triangle_aabb(i)).collect();
        self.bounds = union_of(boxes.iter().copied());
        let centroids: Vec<Vec3> = boxes.iter().map(Aabb::center).collect();
        let mut order: Vec<u32> = (0..n as u32).collect();
        let mut nodes = vec![Node {
            aabb: boxes[0],
            first: 0,
            count: 0,
        }];
        let mut work = vec![(0usize, 0usize, n, 0usize)];
        while let Some((node, start, end, depth)) = work.pop() {
            let items = &mut order[start..end];
            let bounds = union_of(items.iter().map(|&i| boxes[i as usize]));
            nodes[node].aabb = padded(&bounds);
            let split = if items.len() <= 1 {
                None
            } else {
                choose_split(items, &boxes, &centroids, depth)
            };
            match split {
                None => {
                    nodes[node].first = start as u32;
                    nodes[node].count = (end - start) as u32;
                }
                Some(mid) => {
                    let left = nodes.len();
                    let empty = Node {
                        aabb: bounds,
                        first: 0,
                        count: 0,
                    };
                    nodes.push(empty);
                    nodes.push(empty);
                    nodes[node].first = left as u32;
                    nodes[node].count = 0;
                    work.push((left + 1, start + mid, end, depth + 1));
                    work.push((left, start, start + mid, depth + 1));
                }
            }
        }
        self.nodes = nodes;
        self.order = order;
    }
}

/// Reorders `items` and returns the size of the left part, or `None` to make a leaf.
fn choose_split(
    items: &mut [u32],
    boxes: &[Aabb],
    centroids: &[Vec3],
    depth: usize,
) -> Option<usize> {
    let count = items.len();
    let cb = union_of(items.iter().map(|&i| {
        let c = centroids[i as usize];
        Aabb::new(c, c)
    }));
    let extent = cb.max - cb.min;
    if depth < SAH_DEPTH {
        match sah_split(items, boxes, centroids, &cb) {
            Some((axis, bin)) => {
                let lo = cb.min[axis];
                let scale = BINS as Real / extent[axis];
                let mut mid = 0;
                for i in 0..count {
                    if bin_of(centroids[items[i] as usize][axis], lo, scale) <= bin {
                        items.swap(i, mid);
                        mid += 1;
                    }
                }
                if mid > 0 && mid < count {
                    return Some(mid);
                }
            }
            // A leaf is cheaper than any split.
            None if count <= MAX_LEAF => return None,
            // Every centroid in one point: no plane separates them, split by count.
            None => {}
        }
    } else if count <= MAX_LEAF {
        return None;
    }
    // Object median along the widest centroid axis; ties broken by index so the order is
    // fully determined.
    let axis = if extent.x >= extent.y && extent.x >= extent.z {
        0
    } else if extent.y >= extent.z {
        1
    } else {
        2
    };
    items.sort_unstable_by(|a, b| {
        centroids[*a as usize][axis]
            .total_cmp(&centroids[*b as usize][axis])
            .then(a.cmp(b))
    });
    Some(count / 2)
}

/// The best SAH split as (axis, last bin of the left side), or `None` when keeping a leaf
/// is cheaper (or nothing can be split: all centroids coincide).
fn sah_split(
    items: &[u32],
    boxes: &[Aabb],
    centroids: &[Vec3],
    cb: &Aabb,
) -> Option<(usize, usize)> {
    let count = items.len();
    let parent_area = union_of(items.iter().map(|&i| boxes[i as usize])).surface_area();
    let mut best: Option<(Real, usize, usize)> = None;
    for axis in [0, 1, 2] {
        let extent = cb.max[axis] - cb.min[axis];
        if extent.is_nan() || extent <= 0.0 {
            continue;
        }
        let scale = BINS as Real / extent;
        let mut bin_box: [Option<Aabb>; BINS] = [None; BINS];
        let mut bin_count = [0usize; BINS];
        for &i in items {
            let b = bin_of(centroids[i as usize][axis], cb.min[axis], scale);
            bin_count[b] += 1;
            let tb = boxes[i as usize];
            bin_box[b] = Some(bin_box[b].map_or(tb, |x| x.union(&tb)));
        }
        // Sweep from the right to know each suffix's area, then from the left.
        let mut right_area = [0.0 as Real; BINS];
        let mut acc: Option<Aabb> = None;
        for b in (1..BINS).rev() {
            acc = merge(acc, bin_box[b]);
            right_area[b] = acc.map_or(0.0, |a| a.surface_area());
        }
        let mut left: Option<Aabb> = None;
        let mut left_count = 0;
        for b in 0..BINS - 1 {
            left = merge(left, bin_box[b]);
            left_count += bin_count[b];
            let right_count = count - left_count;
            if left_count == 0 || right_count == 0 {
                continue;
            }
            let cost = left.map_or(0.0, |a| a.surface_area()) * left_count as Real
                + right_area[b + 1] * right_count as Real;
            if best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, axis, b));
            }
        }
    }
    let (cost, axis, bin) = best?;
    // Splitting pays when the expected triangle tests drop by more than one node visit.
    let leaf_cost = parent_area * count as Real;
    // (Written so that a NaN cost, from overflowing coordinates, makes a leaf.)
    let split_pays = cost + parent_area < leaf_cost;
    if count <= MAX_LEAF && !split_pays {
        return None;
    }
    Some((axis, bin))
}

fn bin_of(x: Real, lo: Real, scale: Real) -> usize {
    let b = ((x - lo) * scale) as usize; // saturating: NaN and negatives give 0
    b.min(BINS - 1)
}

fn merge(a: Option<Aabb>, b: Option<Aabb>) -> Option<Aabb> {
    match (a, b) {
        (Some(a), Some(b)) => Some(a.union(&b)),
        (a, None) => a,
        (None, b) => b,
    }
}

/// A node's box grown by a few ulps of its coordinates, so that a ray or box meeting a
/// triangle exactly on the node's boundary is not culled by the rounding of the slab test.
pub(crate) fn padded(b: &Aabb) -> Aabb {
    let scale = b.min.abs().max(b.max.abs()).max_element();
    b.expanded(8.0 * EPSILON * scale)
}

fn union_of(boxes: impl Iterator<Item = Aabb>) -> Aabb {
    boxes
        .reduce(|a, b| a.union(&b))
        .unwrap_or(Aabb::new(Vec3::ZERO, Vec3::ZERO))
}
