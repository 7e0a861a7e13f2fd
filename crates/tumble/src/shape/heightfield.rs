//! Height fields: a grid of heights, the usual terrain.
//! PLACEHOLDER: being written; the interface below is fixed.

use crate::error::{Error, Result};
use crate::geometry::Aabb;
use crate::math::{Real, Vec3};

/// A regular grid of heights over the local XZ plane, centred on the origin.
///
/// Sample (row r, column c) sits at x = (c − (cols−1)/2)·scale.x,
/// z = (r − (rows−1)/2)·scale.z, y = heights[r·cols + c]·scale.y. Each grid cell is two
/// triangles; the solid lies below the surface.
#[derive(Debug, Clone, PartialEq)]
pub struct HeightField {
    heights: Vec<Real>,
    rows: usize,
    cols: usize,
    scale: Vec3,
}

impl HeightField {
    /// Builds a height field from `rows × cols` heights (row-major); needs at least 2 × 2
    /// samples, finite heights and a positive scale.
    pub fn new(heights: Vec<Real>, rows: usize, cols: usize, scale: Vec3) -> Result<HeightField> {
        if rows < 2 || cols < 2 || heights.len() != rows * cols {
            return Err(Error::invalid(
                "heights",
                "must be at least 2 rows of at least 2 equal-length rows",
            ));
        }
        Ok(HeightField {
            heights,
            rows,
            cols,
            scale,
        })
    }
    /// Number of rows (along z).
    pub fn rows(&self) -> usize {
        self.rows
    }
    /// Number of columns (along x).
    pub fn cols(&self) -> usize {
        self.cols
    }
    /// Scale (x spacing, height factor, z spacing).
    pub fn scale(&self) -> Vec3 {
        self.scale
    }
    /// Raw heights, row-major.
    pub fn heights(&self) -> &[Real] {
        &self.heights
    }
    /// Bounds, local frame.
    pub fn local_aabb(&self) -> Aabb {
        let lo = self.heights.iter().copied().fold(Real::INFINITY, Real::min) * self.scale.y;
        let hi = self
            .heights
            .iter()
            .copied()
            .fold(Real::NEG_INFINITY, Real::max)
            * self.scale.y;
        let hx = (self.cols - 1) as Real * 0.5 * self.scale.x;
        let hz = (self.rows - 1) as Real * 0.5 * self.scale.z;
        Aabb::new(
            Vec3::new(-hx, lo.min(hi), -hz),
            Vec3::new(hx, hi.max(lo), hz),
        )
    }
    /// Calls `f(index, triangle)` for every triangle whose bounds overlap `aabb` (local).
    /// Triangle index = 2·(r·(cols−1) + c) + k for cell (r, c), half k.
    pub fn for_each_triangle_in(&self, aabb: &Aabb, f: impl FnMut(usize, [Vec3; 3])) {
        let _ = (aabb, f);
    }
}
