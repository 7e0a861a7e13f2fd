//! Any convex shape against a plane (half-space).
//! PLACEHOLDER: being written; signature fixed.
#![allow(unused_variables)]

use super::Manifold;
use crate::geometry::{Convex, Pose};
use crate::math::{Real, Vec3};

/// Convex `a` at `pa` against the half-space n·x ≤ offset of the plane body at `pb`
/// (`normal` unit, in the plane body's frame). The manifold's normal points from A into
/// the plane, i.e. −n in world.
#[allow(clippy::too_many_arguments)]
pub fn convex_plane(
    a: &Convex,
    pa: &Pose,
    normal: Vec3,
    offset: Real,
    pb: &Pose,
    margin: Real,
    out: &mut Manifold,
) -> bool {
    false
}
