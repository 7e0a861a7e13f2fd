//! Ray casts and point queries against every shape.
//! PLACEHOLDER: being written; signatures fixed.
#![allow(unused_variables)]

use crate::geometry::{Pose, Ray, RayHit};
use crate::math::{Real, Vec3};
use crate::shape::Shape;

/// The first hit of `ray` (world frame) on `shape` at `pose` with t in [0, max_t].
/// A ray that starts inside a solid shape hits at t = 0 with a zero normal when `solid`;
/// when not, it reports the boundary where it leaves (normal pointing outward). Planes,
/// meshes and height fields are hit from either side (a mesh has no inside).
pub fn cast_ray(shape: &Shape, pose: &Pose, ray: &Ray, max_t: Real, solid: bool) -> Option<RayHit> {
    None
}

/// Whether the world point lies inside (or on) the shape.
pub fn contains_point(shape: &Shape, pose: &Pose, point: Vec3) -> bool {
    false
}

/// The closest point of a shape's surface to a world point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointProjection {
    /// Closest surface point, world frame (m).
    pub point: Vec3,
    /// Whether the query point was inside the shape.
    pub inside: bool,
    /// Signed distance: positive outside, negative inside (m).
    pub distance: Real,
}

/// Projects a world point onto the shape's surface.
pub fn project_point(shape: &Shape, pose: &Pose, point: Vec3) -> Option<PointProjection> {
    None
}
