//! Closed-form contacts of round shapes: spheres and capsules, with each other and boxes.
//! PLACEHOLDER: being written; signatures fixed.
#![allow(unused_variables)]

use super::Manifold;
use crate::geometry::Pose;
use crate::math::{Real, Vec3};

/// Sphere (radius `ra`, centre at `pa`) against sphere.
pub fn sphere_sphere(
    ra: Real,
    pa: &Pose,
    rb: Real,
    pb: &Pose,
    margin: Real,
    out: &mut Manifold,
) -> bool {
    false
}
/// Sphere against capsule (along the capsule's local y).
pub fn sphere_capsule(
    r: Real,
    pa: &Pose,
    rc: Real,
    half_height: Real,
    pb: &Pose,
    margin: Real,
    out: &mut Manifold,
) -> bool {
    false
}
/// Capsule against capsule.
#[allow(clippy::too_many_arguments)]
pub fn capsule_capsule(
    ra: Real,
    ha: Real,
    pa: &Pose,
    rb: Real,
    hb: Real,
    pb: &Pose,
    margin: Real,
    out: &mut Manifold,
) -> bool {
    false
}
/// Sphere against box.
pub fn sphere_box(
    r: Real,
    pa: &Pose,
    half_extents: Vec3,
    pb: &Pose,
    margin: Real,
    out: &mut Manifold,
) -> bool {
    false
}
/// Capsule against box.
pub fn capsule_box(
    r: Real,
    h: Real,
    pa: &Pose,
    half_extents: Vec3,
    pb: &Pose,
    margin: Real,
    out: &mut Manifold,
) -> bool {
    false
}
