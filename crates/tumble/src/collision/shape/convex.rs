//! Convex shapes seen through their support function, the one operation GJK, EPA, shape
//! casts and time of impact need.
//!
//! Round shapes are split into a *core* (a point for a sphere, a segment for a capsule)
//! and a radius: GJK runs on the cores, which are polytopes and converge exactly, and the
//! radius is subtracted afterwards. That is both faster and far more accurate than
//! iterating on a curved surface.

use crate::collision::shape::{ConvexHull, Shape};
use crate::math::{Real, Vec3};

/// A convex shape in its own local frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Convex<'a> {
    /// Ball of `radius` about the origin.
    Sphere {
        /// Radius (m).
        radius: Real,
    },
    /// Box of half extents about the origin.
    Box {
        /// Half extents (m).
        half_extents: Vec3,
    },
    /// Capsule along y: segment from −h to +h swept by `radius`.
    Capsule {
        /// Radius (m).
        radius: Real,
        /// Half the shaft length (m).
        half_height: Real,
    },
    /// Cylinder along y.
    Cylinder {
        /// Radius (m).
        radius: Real,
        /// Half the length (m).
        half_height: Real,
    },
    /// A convex polyhedron.
    Hull(&'a ConvexHull),
    /// A triangle (of a mesh or height field), counter-clockwise seen from its front.
    Triangle([Vec3; 3]),
}

impl<'a> Convex<'a> {
    /// The convex view of `shape`, or `None` for shapes that are not convex solids
    /// (compounds, planes, meshes, height fields).
    pub fn from_shape(shape: &'a Shape) -> Option<Convex<'a>> {
        Some(match shape {
            Shape::Sphere { radius } => Convex::Sphere { radius: *radius },
            Shape::Box { half_extents } => Convex::Box {
                half_extents: *half_extents,
            },
            Shape::Capsule {
                radius,
                half_height,
            } => Convex::Capsule {
                radius: *radius,
                half_height: *half_height,
            },
            Shape::Cylinder {
                radius,
                half_height,
            } => Convex::Cylinder {
                radius: *radius,
                half_height: *half_height,
            },
            Shape::ConvexHull(h) => Convex::Hull(h),
            _ => return None,
        })
    }

    /// The farthest point of the whole shape along `dir` (local frame).
    pub fn support(&self, dir: Vec3) -> Vec3 {
        let core = self.core_support(dir);
        let r = self.radius();
        if r == 0.0 {
            return core;
        }
        let len = dir.length();
        if len > 0.0 {
            core + dir * (r / len)
        } else {
            core + Vec3::new(r, 0.0, 0.0)
        }
    }

    /// The farthest point of the core along `dir`.
    pub fn core_support(&self, dir: Vec3) -> Vec3 {
        let sign = |x: Real| if x < 0.0 { -1.0 } else { 1.0 };
        match self {
            Convex::Sphere { .. } => Vec3::ZERO,
            Convex::Capsule { half_height, .. } => Vec3::new(0.0, sign(dir.y) * half_height, 0.0),
            Convex::Box { half_extents } => Vec3::new(
                sign(dir.x) * half_extents.x,
                sign(dir.y) * half_extents.y,
                sign(dir.z) * half_extents.z,
            ),
            Convex::Cylinder {
                radius,
                half_height,
            } => {
                let radial = Vec3::new(dir.x, 0.0, dir.z);
                let len = radial.length();
                let rim = if len > 0.0 {
                    radial * (radius / len)
                } else {
                    Vec3::ZERO
                };
                rim + Vec3::new(0.0, sign(dir.y) * half_height, 0.0)
            }
            Convex::Hull(h) => h.support(dir),
            Convex::Triangle(t) => {
                let d = [t[0].dot(dir), t[1].dot(dir), t[2].dot(dir)];
                let i = if d[0] >= d[1] && d[0] >= d[2] {
                    0
                } else if d[1] >= d[2] {
                    1
                } else {
                    2
                };
                t[i]
            }
        }
    }

    /// The radius swept around the core (zero for polytopes and cylinders).
    pub fn radius(&self) -> Real {
        match self {
            Convex::Sphere { radius } | Convex::Capsule { radius, .. } => *radius,
            _ => 0.0,
        }
    }
}
