//! General convex–convex contact: GJK for separated shapes, EPA (or SAT for polytopes)
//! for penetrating ones, then clipping of the two contact features for a full manifold.
//! PLACEHOLDER: being written; signature fixed.
#![allow(unused_variables)]

use super::Manifold;
use crate::geometry::{Convex, Pose};
use crate::math::Real;

/// Convex `a` at `pa` against convex `b` at `pb`.
pub fn convex_convex(
    a: &Convex,
    pa: &Pose,
    b: &Convex,
    pb: &Pose,
    margin: Real,
    out: &mut Manifold,
) -> bool {
    false
}
