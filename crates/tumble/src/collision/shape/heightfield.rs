//! Height fields: a grid of heights, the usual terrain.
//!
//! The grid is its own acceleration structure: a box query maps straight to a range of
//! cells, and a ray walks the cells it crosses in order (a 2D digital differential
//! analyser, as in voxel traversal), so neither needs a tree.

use super::trimesh::{
    closest_on_triangle, edge_bend, face_normal, padded, ray_triangle, BOUNDARY_BEND,
};
use crate::collision::geometry::Aabb;
use crate::error::{check, Error, Result};
use crate::math::{Real, Vec3};

/// A regular grid of heights over the local XZ plane, centred on the origin.
///
/// Sample (row r, column c) sits at x = (c − (cols−1)/2)·scale.x,
/// z = (r − (rows−1)/2)·scale.z, y = heights[r·cols + c]·scale.y. Each grid cell is two
/// triangles; the solid lies below the surface.
///
/// Cell (r, c) spans columns c, c+1 and rows r, r+1; with pᵢⱼ the sample at row r+i,
/// column c+j its triangles are k = 0: (p00, p10, p11) and k = 1: (p00, p11, p01), split
/// along the p00–p11 diagonal and counter-clockwise seen from above, so normals point up.
#[derive(Debug, Clone, PartialEq)]
pub struct HeightField {
    heights: Vec<Real>,
    rows: usize,
    cols: usize,
    scale: Vec3,
    /// Lowest and highest scaled height, for the bounds.
    range: (Real, Real),
}

impl HeightField {
    /// Builds a height field from `rows × cols` heights (row-major); needs at least 2 × 2
    /// samples, finite heights and a positive scale.
    pub fn new(heights: Vec<Real>, rows: usize, cols: usize, scale: Vec3) -> Result<HeightField> {
        let range = checked_range(&heights, rows, cols, scale)?;
        Ok(HeightField {
            heights,
            rows,
            cols,
            scale,
            range,
        })
    }

    /// Checks a height field read from a snapshot as [`HeightField::new`] checks its input
    /// (every sample and cell index is computed from `rows` and `cols`), and its range as
    /// `new` computes it.
    pub(crate) fn check_saved(&self) -> Result<()> {
        let range = checked_range(&self.heights, self.rows, self.cols, self.scale)?;
        if range != self.range {
            return Err(Error::invalid("range", "is not the heights' range"));
        }
        Ok(())
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

    /// Number of triangles: two per cell.
    pub fn triangle_count(&self) -> usize {
        2 * (self.rows - 1) * (self.cols - 1)
    }

    /// Bounds, local frame.
    pub fn local_aabb(&self) -> Aabb {
        let hx = (self.cols - 1) as Real * 0.5 * self.scale.x;
        let hz = (self.rows - 1) as Real * 0.5 * self.scale.z;
        Aabb::new(
            Vec3::new(-hx, self.range.0, -hz),
            Vec3::new(hx, self.range.1, hz),
        )
    }

    /// The sample at row `r`, column `c`, local frame (in range by the callers).
    fn sample(&self, r: usize, c: usize) -> Vec3 {
        Vec3::new(
            (c as Real - (self.cols - 1) as Real * 0.5) * self.scale.x,
            self.heights[r * self.cols + c] * self.scale.y,
            (r as Real - (self.rows - 1) as Real * 0.5) * self.scale.z,
        )
    }

    /// Triangle `k` of cell (r, c) (in range by the callers).
    fn cell_triangle(&self, r: usize, c: usize, k: usize) -> [Vec3; 3] {
        let p00 = self.sample(r, c);
        let p11 = self.sample(r + 1, c + 1);
        if k == 0 {
            [p00, self.sample(r + 1, c), p11]
        } else {
            [p00, p11, self.sample(r, c + 1)]
        }
    }

    fn triangle_index(&self, r: usize, c: usize, k: usize) -> usize {
        2 * (r * (self.cols - 1) + c) + k
    }

    /// Cell (r, c) and half k of triangle `i`, if it exists.
    fn decode(&self, i: usize) -> Option<(usize, usize, usize)> {
        if i >= self.triangle_count() {
            return None;
        }
        let cell = i / 2;
        Some((cell / (self.cols - 1), cell % (self.cols - 1), i % 2))
    }

    /// Triangle `i`'s corners, local frame (index as in [`Self::for_each_triangle_in`]).
    pub fn triangle(&self, i: usize) -> Option<[Vec3; 3]> {
        self.decode(i).map(|(r, c, k)| self.cell_triangle(r, c, k))
    }

    /// Triangle `i`'s unit upward normal, local frame.
    pub fn normal(&self, i: usize) -> Option<Vec3> {
        self.triangle(i).and_then(|[a, b, c]| face_normal(a, b, c))
    }

    /// Signed bend angles (rad) of triangle `i`'s edges towards its neighbours (> 0
    /// convex, < 0 concave, +∞ on the border of the field); edge k runs from corner k to
    /// corner k + 1.
    pub(crate) fn edge_bends(&self, i: usize) -> [Real; 3] {
        let Some((r, c, k)) = self.decode(i) else {
            return [BOUNDARY_BEND; 3];
        };
        let tri = self.cell_triangle(r, c, k);
        let Some(n) = face_normal(tri[0], tri[1], tri[2]) else {
            return [BOUNDARY_BEND; 3];
        };
        // The neighbour across each edge, from the cell layout: triangle 0 borders the
        // cell to its left (−x) and the one above (+z); triangle 1 the cell to its right
        // and the one below; the two halves of a cell share the diagonal.
        let (rows, cols) = (self.rows as isize - 1, self.cols as isize - 1);
        let (ri, ci) = (r as isize, c as isize);
        let across: [(isize, isize, usize); 3] = if k == 0 {
            [(ri, ci - 1, 1), (ri + 1, ci, 1), (ri, ci, 1)]
        } else {
            [(ri, ci, 0), (ri, ci + 1, 0), (ri - 1, ci, 0)]
        };
        let mut bends = [BOUNDARY_BEND; 3];
        for (e, &(nr, nc, nk)) in across.iter().enumerate() {
            if nr < 0 || nc < 0 || nr >= rows || nc >= cols {
                continue;
            }
            let u = self.cell_triangle(nr as usize, nc as usize, nk);
            if let Some(n_u) = face_normal(u[0], u[1], u[2]) {
                bends[e] = edge_bend(n, tri[e], tri[(e + 1) % 3], n_u);
            }
        }
        bends
    }

    /// The range of cells `[lo, hi]` along one axis whose span meets `[min, max]`
    /// (coordinates already divided by the spacing and shifted so cell j spans [j, j+1]).
    fn cell_range(min: Real, max: Real, cells: usize) -> Option<(usize, usize)> {
        if min.is_nan() || max.is_nan() || max < 0.0 || min > cells as Real {
            return None;
        }
        Some((cell_of(min, cells), cell_of(max, cells)))
    }

    /// Calls `f(index, triangle)` for every triangle whose bounds overlap `aabb` (local).
    /// Triangle index = 2·(r·(cols−1)+c) + k for cell (r, c), half k.
    pub fn for_each_triangle_in(&self, aabb: &Aabb, mut f: impl FnMut(usize, [Vec3; 3])) {
        if !self.local_aabb().overlaps(aabb) {
            return; // also every query holding a NaN
        }
        let (cx, cz) = (self.cols - 1, self.rows - 1);
        let (ox, oz) = (cx as Real * 0.5, cz as Real * 0.5);
        let Some((c0, c1)) = Self::cell_range(
            aabb.min.x / self.scale.x + ox,
            aabb.max.x / self.scale.x + ox,
            cx,
        ) else {
            return;
        };
        let Some((r0, r1)) = Self::cell_range(
            aabb.min.z / self.scale.z + oz,
            aabb.max.z / self.scale.z + oz,
            cz,
        ) else {
            return;
        };
        for r in r0..=r1 {
            for c in c0..=c1 {
                for k in 0..2 {
                    let tri = self.cell_triangle(r, c, k);
                    let [a, b, d] = tri;
                    let bounds = Aabb::new(a.min(b).min(d), a.max(b).max(d));
                    if bounds.overlaps(aabb) {
                        f(self.triangle_index(r, c, k), tri);
                    }
                }
            }
        }
    }

    /// Surface height (local y) above the local point (x, z), or `None` outside the grid.
    pub fn height_at(&self, x: Real, z: Real) -> Option<Real> {
        let (cx, cz) = (self.cols - 1, self.rows - 1);
        let fx = x / self.scale.x + cx as Real * 0.5;
        let fz = z / self.scale.z + cz as Real * 0.5;
        if fx.is_nan() || fz.is_nan() || fx < 0.0 || fz < 0.0 {
            return None;
        }
        if fx > cx as Real || fz > cz as Real {
            return None;
        }
        let (c, r) = (cell_of(fx, cx), cell_of(fz, cz));
        // Position within the cell, u along x and v along z, both in [0, 1].
        let (u, v) = (fx - c as Real, fz - r as Real);
        let h = |i: usize, j: usize| self.heights[(r + i) * self.cols + c + j] * self.scale.y;
        let (h00, h01, h10, h11) = (h(0, 0), h(0, 1), h(1, 0), h(1, 1));
        // Triangle 0 (p00, p10, p11) covers v ≥ u, triangle 1 (p00, p11, p01) u ≥ v; both
        // planes interpolate linearly between their corners.
        Some(if v >= u {
            h00 + (h10 - h00) * v + (h11 - h10) * u
        } else {
            h00 + (h01 - h00) * u + (h11 - h01) * v
        })
    }

    /// The nearest crossing of `origin + t·dir`, t in [0, max_t], with the surface from
    /// either side (local frame): `(t, triangle index)`.
    ///
    /// Walks the cells under the ray in order, so the first cell with a hit holds the
    /// nearest one; the walk costs one step per cell crossed, at most rows + cols.
    pub fn cast_ray(&self, origin: Vec3, dir: Vec3, max_t: Real) -> Option<(Real, usize)> {
        if max_t.is_nan() || max_t < 0.0 {
            return None;
        }
        let (t0, t1) = padded(&self.local_aabb()).ray_interval(origin, dir, max_t)?;
        let (cx, cz) = (self.cols - 1, self.rows - 1);
        let (ox, oz) = (cx as Real * 0.5, cz as Real * 0.5);
        let start = origin + dir * t0;
        let mut c = cell_of(start.x / self.scale.x + ox, cx) as isize;
        let mut r = cell_of(start.z / self.scale.z + oz, cz) as isize;
        let step_c: isize = if dir.x > 0.0 { 1 } else { -1 };
        let step_r: isize = if dir.z > 0.0 { 1 } else { -1 };
        // Parameter at which the ray leaves the current cell's column (row) span,
        // recomputed from the boundary each step rather than accumulated, so rounding
        // does not build up along long rays.
        let exit = |cell: isize, step: isize, o: Real, d: Real, spacing: Real, off: Real| {
            if d == 0.0 {
                return Real::INFINITY;
            }
            let edge = (cell + if step > 0 { 1 } else { 0 }) as Real - off;
            (edge * spacing - o) / d
        };
        for _ in 0..self.rows + self.cols + 2 {
            let mut best: Option<(Real, usize)> = None;
            for k in 0..2 {
                let tri = self.cell_triangle(r as usize, c as usize, k);
                if let Some(t) = ray_triangle(origin, dir, &tri, max_t) {
                    if best.is_none_or(|(bt, _)| t < bt) {
                        best = Some((t, self.triangle_index(r as usize, c as usize, k)));
                    }
                }
            }
            if best.is_some() {
                return best;
            }
            let tc = exit(c, step_c, origin.x, dir.x, self.scale.x, ox);
            let tr = exit(r, step_r, origin.z, dir.z, self.scale.z, oz);
            if tc.min(tr) > t1 || tc.min(tr).is_nan() {
                return None;
            }
            if tc <= tr {
                c += step_c;
            } else {
                r += step_r;
            }
            if c < 0 || r < 0 || c >= cx as isize || r >= cz as isize {
                return None;
            }
        }
        None
    }

    /// The closest point of the surface to the local point `p`: `(point, triangle)`.
    pub fn closest_point(&self, p: Vec3) -> Option<(Vec3, usize)> {
        // The surface point straight above or below p (clamped onto the grid) bounds the
        // distance, so only triangles within that distance need a look.
        let b = self.local_aabb();
        let (x, z) = (p.x.clamp(b.min.x, b.max.x), p.z.clamp(b.min.z, b.max.z));
        let y = self.height_at(x, z)?;
        let bound = (Vec3::new(x, y, z) - p).length();
        // A little slack: the bound itself must not be culled by rounding.
        let reach = bound * (1.0 + 1e-6) + Real::EPSILON;
        let mut best: Option<(Real, Vec3, usize)> = None;
        self.for_each_triangle_in(&Aabb::from_center(p, Vec3::splat(reach)), |i, tri| {
            let q = closest_on_triangle(p, &tri);
            let d2 = (q - p).length_squared();
            if best.is_none_or(|(bd, _, _)| d2 < bd) {
                best = Some((d2, q, i));
            }
        });
        best.map(|(_, q, i)| (q, i))
    }
}

/// The cell holding the shifted coordinate `f`, clamped to `[0, cells − 1]`.
fn cell_of(f: Real, cells: usize) -> usize {
    let last = cells - 1;
    if f.is_nan() || f <= 0.0 {
        0
    } else if f >= last as Real {
        last
    } else {
        f.floor() as usize
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn triangles_face_up_and_index_as_documented() {
        let f = HeightField::new(vec![0.0, 1.0, 2.0, 3.0, 4.0, 5.0], 2, 3, Vec3::ONE).unwrap();
        assert_eq!(f.triangle_count(), 4);
        for i in 0..4 {
            assert!(f.normal(i).unwrap().y > 0.0);
        }
        assert_eq!(f.triangle(4), None);
        // Height 1 at (r 0, c 1), at x = 0, z = −0.5.
        assert_eq!(f.height_at(0.0, -0.5), Some(1.0));
        assert_eq!(f.height_at(0.5, 0.0), Some(3.0));
    }
}

/// [`HeightField::new`]'s checks of its input, and the lowest and highest scaled height.
fn checked_range(heights: &[Real], rows: usize, cols: usize, scale: Vec3) -> Result<(Real, Real)> {
    if rows < 2 || cols < 2 {
        return Err(Error::invalid(
            "heights",
            format!("needs at least 2 rows and 2 columns (got {rows} × {cols})"),
        ));
    }
    if rows.checked_mul(cols) != Some(heights.len()) {
        return Err(Error::invalid(
            "heights",
            format!(
                "must hold rows × cols = {rows} × {cols} values (got {})",
                heights.len()
            ),
        ));
    }
    // Triangle indices are reported as u32.
    if (rows - 1).saturating_mul(cols - 1) > (u32::MAX / 2) as usize {
        return Err(Error::invalid(
            "heights",
            "too many cells (at most 2^31 triangles)",
        ));
    }
    check::positive_vec3("scale", scale)?;
    let mut range = (Real::INFINITY, Real::NEG_INFINITY);
    for (k, &h) in heights.iter().enumerate() {
        // Scaled heights must stay finite too, or the surface would hold infinities.
        if !(h * scale.y).is_finite() {
            return Err(Error::invalid(
                format!("heights[{k}]"),
                "must be a finite number",
            ));
        }
        range = (range.0.min(h * scale.y), range.1.max(h * scale.y));
    }
    let hx = (cols - 1) as Real * 0.5 * scale.x;
    let hz = (rows - 1) as Real * 0.5 * scale.z;
    if !(hx.is_finite() && hz.is_finite()) {
        return Err(Error::invalid("scale", "makes the grid infinitely wide"));
    }
    Ok(range)
}

crate::codec::codec_struct!(HeightField {
    heights,
    rows,
    cols,
    scale,
    range
});
