//! World-space bounding boxes of shapes, for the broad phase.

use super::Shape;
use crate::collision::geometry::{Aabb, Pose};
use crate::collision::shape::Convex;
use crate::math::{Mat3, Real, Vec3};

/// How far a plane's box reaches along the directions the plane does not bound (m). Planes
/// are infinite; the broad phase needs finite boxes, and 10⁷ m is farther than any scene
/// whose positions a float can still place to the millimetre.
pub const PLANE_EXTENT: Real = 1.0e7;

impl Shape {
    /// The tight world-space box of the shape at `pose`.
    pub fn aabb(&self, pose: &Pose) -> Aabb {
        match self {
            Shape::Sphere { radius } => Aabb::from_center(pose.position, Vec3::splat(*radius)),
            Shape::Box { half_extents } => {
                let r = Mat3::from_quat(pose.rotation);
                let abs = Mat3::from_cols(r.x_axis.abs(), r.y_axis.abs(), r.z_axis.abs());
                Aabb::from_center(pose.position, abs * *half_extents)
            }
            Shape::Capsule {
                radius,
                half_height,
            } => {
                let tip = pose.transform_vector(Vec3::new(0.0, *half_height, 0.0));
                let a = pose.position + tip;
                let b = pose.position - tip;
                Aabb::new(a.min(b), a.max(b)).expanded(*radius)
            }
            Shape::Cylinder { .. } | Shape::ConvexHull(_) => {
                let convex = Convex::from_shape(self).unwrap_or(Convex::Sphere { radius: 0.0 });
                convex_aabb(&convex, pose)
            }
            Shape::Compound(children) => children
                .iter()
                .map(|c| {
                    c.shape
                        .aabb(&pose.mul(&Pose::new(c.position, c.orientation)))
                })
                .reduce(|a, b| a.union(&b))
                .unwrap_or(Aabb::from_center(pose.position, Vec3::ZERO)),
            Shape::Plane { normal, offset } => {
                plane_aabb(pose.transform_vector(*normal), *offset, pose)
            }
            Shape::TriMesh(mesh) => {
                Aabb::from_points(mesh.vertices().iter().map(|v| pose.transform_point(*v)))
                    .unwrap_or(Aabb::from_center(pose.position, Vec3::ZERO))
            }
            Shape::HeightField(field) => field.local_aabb().mapped(|c| pose.transform_point(c)),
        }
    }
}

/// The exact box of a convex shape: its support points along ±x, ±y, ±z.
pub fn convex_aabb(convex: &Convex, pose: &Pose) -> Aabb {
    let mut min = Vec3::ZERO;
    let mut max = Vec3::ZERO;
    for axis in 0..3 {
        let mut e = Vec3::ZERO;
        e[axis] = 1.0;
        let local = pose.inverse_transform_vector(e);
        max[axis] = pose.transform_point(convex.support(local))[axis];
        min[axis] = pose.transform_point(convex.support(-local))[axis];
    }
    Aabb::new(min, max)
}

/// A plane's box: unbounded (to [`PLANE_EXTENT`]) except along a world axis its normal
/// follows, where the solid side ends at the surface.
fn plane_aabb(world_normal: Vec3, offset: Real, pose: &Pose) -> Aabb {
    let mut b = Aabb::from_center(Vec3::ZERO, Vec3::splat(PLANE_EXTENT));
    let surface = pose.position + world_normal * offset;
    for axis in 0..3 {
        let n = world_normal[axis];
        if (n.abs() - 1.0).abs() < 1e-9 {
            if n > 0.0 {
                b.max[axis] = surface[axis];
            } else {
                b.min[axis] = surface[axis];
            }
        }
    }
    b
}
