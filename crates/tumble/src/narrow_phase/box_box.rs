//! Box against box: separating-axis test over 15 axes, then face clipping.
//! PLACEHOLDER: being written; signature fixed.
#![allow(unused_variables)]

use super::Manifold;
use crate::geometry::Pose;
use crate::math::{Real, Vec3};

/// Box (half extents `ha`) at `pa` against box at `pb`.
pub fn box_box(ha: Vec3, pa: &Pose, hb: Vec3, pb: &Pose, margin: Real, out: &mut Manifold) -> bool {
    false
}
