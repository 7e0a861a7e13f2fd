//! Convex shapes against triangle meshes and height fields, triangle by triangle, without
//! catching on internal edges.
//! PLACEHOLDER: being written; signatures fixed.
#![allow(unused_variables)]

use super::Manifold;
use crate::geometry::{Convex, Pose};
use crate::math::Real;
use crate::shape::{HeightField, TriMesh};

/// Appends one manifold per touching triangle (subshape_b = triangle index).
pub fn convex_trimesh(
    a: &Convex,
    pa: &Pose,
    mesh: &TriMesh,
    pb: &Pose,
    margin: Real,
    out: &mut Vec<Manifold>,
) {
}

/// Appends one manifold per touching triangle (subshape_b = triangle index).
pub fn convex_heightfield(
    a: &Convex,
    pa: &Pose,
    field: &HeightField,
    pb: &Pose,
    margin: Real,
    out: &mut Vec<Manifold>,
) {
}
