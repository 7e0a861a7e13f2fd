//! Time of impact and shape casts for convex shapes.
//! PLACEHOLDER: being written; signatures fixed.
#![allow(unused_variables)]

use crate::geometry::{Convex, Pose};
use crate::math::{Real, Vec3};

/// A rigid motion over [0, 1]: the pose at the start and constant linear and angular
/// velocity (per unit of the sweep parameter), rotation about the centre `local_center`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sweep {
    /// Pose at parameter 0.
    pub start: Pose,
    /// Displacement of the centre over the whole sweep (m).
    pub translation: Vec3,
    /// Rotation vector over the whole sweep (rad, world frame).
    pub rotation: Vec3,
    /// Centre of rotation in the shape's local frame (its centre of mass).
    pub local_center: Vec3,
}

/// The first moment two moving convex shapes come within `target` of each other.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Toi {
    /// Sweep parameter in [0, 1].
    pub t: Real,
    /// Unit normal from A to B at that moment, world frame.
    pub normal: Vec3,
    /// Witness points on A and B at that moment.
    pub point_a: Vec3,
    /// Witness point on B.
    pub point_b: Vec3,
}

/// Conservative advancement: the first t in [0, 1] at which the distance between A and B
/// drops to `target` (> 0 keeps a safety gap), or `None` if they never get that close.
/// Shapes already closer than `target` at t = 0 return t = 0.
pub fn time_of_impact(
    a: &Convex,
    sweep_a: &Sweep,
    b: &Convex,
    sweep_b: &Sweep,
    target: Real,
) -> Option<Toi> {
    None
}

/// A linear shape cast's hit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShapeCastHit {
    /// Fraction of `translation` travelled before contact, in [0, 1].
    pub t: Real,
    /// Unit contact normal on the target, pointing towards the cast shape, world frame.
    pub normal: Vec3,
    /// Contact point, world frame.
    pub point: Vec3,
}

/// Sweeps convex `a` from `pose_a` along `translation` (no rotation) against convex `b` at
/// rest at `pose_b`: the first contact, or `None` if the sweep misses.
pub fn cast_shape(
    a: &Convex,
    pose_a: &Pose,
    translation: Vec3,
    b: &Convex,
    pose_b: &Pose,
) -> Option<ShapeCastHit> {
    None
}
