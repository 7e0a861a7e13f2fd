//! Convex hulls from point clouds (quickhull) and their exact mass properties.
//! PLACEHOLDER: being written; the interface below is fixed.

use super::MassProperties;
use crate::error::{Error, Result};
use crate::math::{Real, Vec3};

/// A convex polyhedron: its hull vertices and outward-facing (counter-clockwise seen from
/// outside) triangles indexing them.
#[derive(Debug, Clone, PartialEq)]
pub struct ConvexHull {
    vertices: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
}

impl ConvexHull {
    /// Builds the hull of `points`.
    pub fn from_points(points: &[Vec3]) -> Result<Self> {
        let _ = points;
        Err(Error::invalid(
            "points",
            "convex hulls are not implemented yet",
        ))
    }

    /// The hull's vertices (a subset of the input points).
    pub fn vertices(&self) -> &[Vec3] {
        &self.vertices
    }

    /// Outward triangles, counter-clockwise seen from outside.
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// Exact mass properties for a uniform `density`.
    pub fn mass_properties(&self, density: Real) -> MassProperties {
        let _ = density;
        MassProperties::diagonal(1.0, Vec3::ONE)
    }
}
