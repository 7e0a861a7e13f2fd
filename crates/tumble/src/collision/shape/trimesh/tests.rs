//! Mesh adjacency and edge kinds on a grid, and a hierarchy that finds every triangle once.

use super::*;

fn grid(n: usize) -> TriMesh {
    let mut v = Vec::new();
    for z in 0..=n {
        for x in 0..=n {
            v.push(Vec3::new(x as Real, 0.0, z as Real));
        }
    }
    let mut idx = Vec::new();
    let w = (n + 1) as u32;
    for z in 0..n as u32 {
        for x in 0..n as u32 {
            let a = z * w + x;
            idx.push([a, a + w, a + w + 1]);
            idx.push([a, a + w + 1, a + 1]);
        }
    }
    TriMesh::new(v, idx).unwrap()
}

#[test]
fn grid_is_flat_inside_and_open_at_the_border() {
    let m = grid(3);
    assert_eq!(m.normal(0), Some(Vec3::Y));
    let mut kinds = [0usize; 4];
    for i in 0..m.len() {
        for k in m.edge_kinds(i).unwrap() {
            kinds[k as usize] += 1;
        }
    }
    // 18 triangles, 54 edge sides: 12 on the border, the other 42 in flat pairs.
    assert_eq!(kinds, [12, 0, 42, 0]);
}

#[test]
fn hierarchy_finds_every_triangle_once() {
    let m = grid(20);
    let mut seen = vec![0; m.len()];
    m.for_each_triangle_in(&m.local_aabb(), |i| seen[i] += 1);
    assert!(seen.iter().all(|&s| s == 1));
}
