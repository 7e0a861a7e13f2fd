//! Rigid transforms.

use crate::math::{Quat, Vec3};

/// A rigid transform, local to world: p_world = rotation · p_local + position.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    /// Translation (m).
    pub position: Vec3,
    /// Rotation (unit quaternion).
    pub rotation: Quat,
}

impl Default for Pose {
    fn default() -> Self {
        Pose::IDENTITY
    }
}

impl Pose {
    /// No translation, no rotation.
    pub const IDENTITY: Pose = Pose {
        position: Vec3::ZERO,
        rotation: Quat::IDENTITY,
    };

    /// A pose from its parts.
    pub fn new(position: Vec3, rotation: Quat) -> Pose {
        Pose { position, rotation }
    }

    /// A pure translation.
    pub fn from_translation(position: Vec3) -> Pose {
        Pose {
            position,
            rotation: Quat::IDENTITY,
        }
    }

    /// Local point to world.
    #[inline]
    pub fn transform_point(&self, p: Vec3) -> Vec3 {
        self.rotation * p + self.position
    }

    /// World point to local.
    #[inline]
    pub fn inverse_transform_point(&self, p: Vec3) -> Vec3 {
        self.rotation.inverse() * (p - self.position)
    }

    /// Local direction to world.
    #[inline]
    pub fn transform_vector(&self, v: Vec3) -> Vec3 {
        self.rotation * v
    }

    /// World direction to local.
    #[inline]
    pub fn inverse_transform_vector(&self, v: Vec3) -> Vec3 {
        self.rotation.inverse() * v
    }

    /// The inverse transform.
    pub fn inverse(&self) -> Pose {
        let r = self.rotation.inverse();
        Pose {
            position: -(r * self.position),
            rotation: r,
        }
    }

    /// `self ∘ other`: first `other`, then `self` (a child pose inside a parent).
    pub fn mul(&self, other: &Pose) -> Pose {
        Pose {
            position: self.transform_point(other.position),
            rotation: (self.rotation * other.rotation).normalize(),
        }
    }
}

crate::codec::codec_struct!(Pose { position, rotation });
