//! Triangle meshes (static geometry) with their own bounding-volume hierarchy.
//! PLACEHOLDER: being written; the interface below is fixed.

use crate::error::{Error, Result};
use crate::geometry::Aabb;
use crate::math::Vec3;

/// A triangle mesh: vertices and counter-clockwise (seen from the front) index triples.
#[derive(Debug, Clone, PartialEq)]
pub struct TriMesh {
    vertices: Vec<Vec3>,
    indices: Vec<[u32; 3]>,
}

impl TriMesh {
    /// Builds the mesh and its hierarchy; fails on empty input, non-finite vertices,
    /// out-of-range indices or zero-area triangles, naming the entry.
    pub fn new(vertices: Vec<Vec3>, indices: Vec<[u32; 3]>) -> Result<TriMesh> {
        if indices.is_empty() {
            return Err(Error::invalid("indices", "must hold at least one triangle"));
        }
        Ok(TriMesh { vertices, indices })
    }
    /// Vertices, local frame.
    pub fn vertices(&self) -> &[Vec3] {
        &self.vertices
    }
    /// Triangles as index triples.
    pub fn indices(&self) -> &[[u32; 3]] {
        &self.indices
    }
    /// Triangle `i`'s corners, local frame.
    pub fn triangle(&self, i: usize) -> [Vec3; 3] {
        let [a, b, c] = self.indices[i];
        [
            self.vertices[a as usize],
            self.vertices[b as usize],
            self.vertices[c as usize],
        ]
    }
    /// Bounds of the whole mesh, local frame.
    pub fn local_aabb(&self) -> Aabb {
        Aabb::from_points(self.vertices.iter().copied())
            .unwrap_or(Aabb::new(Vec3::ZERO, Vec3::ZERO))
    }
    /// Calls `f` with the index of every triangle whose bounds overlap `aabb` (local frame).
    pub fn for_each_triangle_in(&self, aabb: &Aabb, mut f: impl FnMut(usize)) {
        for i in 0..self.indices.len() {
            if let Some(b) = Aabb::from_points(self.triangle(i)) {
                if b.overlaps(aabb) {
                    f(i);
                }
            }
        }
    }
}
