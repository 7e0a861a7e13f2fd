//! Geometry shared by collision detection and queries: rigid poses, bounding boxes, rays,
//! and the support-mapped view of convex shapes that GJK and EPA work on.

mod aabb;
mod pose;

pub use aabb::Aabb;
pub use pose::Pose;

use crate::math::{Real, Vec3};

/// A ray: points `origin + t · direction`, t ≥ 0. `direction` need not be unit; hit
/// distances are in units of its length.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ray {
    /// Start (m).
    pub origin: Vec3,
    /// Direction; hits report t in multiples of its length.
    pub direction: Vec3,
}

impl Ray {
    /// A ray from `origin` along `direction`.
    pub fn new(origin: Vec3, direction: Vec3) -> Ray {
        Ray { origin, direction }
    }
    /// The point at parameter `t`.
    pub fn at(&self, t: Real) -> Vec3 {
        self.origin + self.direction * t
    }
}

/// Where a ray meets a surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RayHit {
    /// Ray parameter of the hit (distance when the direction is unit).
    pub t: Real,
    /// Outward unit surface normal at the hit, world frame.
    pub normal: Vec3,
    /// Sub-shape hit: compound child or mesh triangle index (0 for simple shapes).
    pub subshape: u32,
}
