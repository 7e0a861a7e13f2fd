//! The hull's mass properties, exact for its closed triangulated surface.
//!
//! Sums, over tetrahedra from the vertex centroid to each triangle, the closed-form volume,
//! first moment and covariance; the apex at an interior point keeps the terms small so they
//! cancel little. Accumulated in f64 whatever `Real` is.

use super::ConvexHull;
use crate::collision::shape::MassProperties;
use crate::math::wide;
use crate::math::{real, Real};
use glam::{DMat3, DVec3};

impl ConvexHull {
    /// Exact mass properties for a uniform `density`.
    ///
    /// Sums, over tetrahedra from the vertex centroid to each triangle, the closed-form volume,
    /// first moment and covariance ∫x xᵀ = det/120 (s sᵀ + Σ vᵢvᵢᵀ) (s the sum of the three
    /// vertices relative to the apex); signed volumes make this exact for any closed surface.
    /// Accumulates in f64 whatever `Real` is.
    pub fn mass_properties(&self, density: Real) -> MassProperties {
        let verts: Vec<DVec3> = self.vertices.iter().map(|&v| wide::vec(v)).collect();
        // Relative to an interior point the terms stay small and cancel little.
        let apex = verts.iter().sum::<DVec3>() / verts.len() as f64;
        let (mut volume, mut first, mut second) = (0.0, DVec3::ZERO, DMat3::ZERO);
        for t in &self.triangles {
            let [a, b, c] = t.map(|i| verts[i as usize] - apex);
            let det = a.dot(b.cross(c));
            let s = a + b + c;
            volume += det / 6.0;
            first += s * (det / 24.0);
            second += (outer(s, s) + outer(a, a) + outer(b, b) + outer(c, c)) * (det / 120.0);
        }
        let center = first / volume;
        let covariance = second - outer(center, center) * volume;
        let trace = covariance.x_axis.x + covariance.y_axis.y + covariance.z_axis.z;
        let inertia = DMat3::from_diagonal(DVec3::splat(trace)) - covariance;
        let rho = wide::scalar(density);
        MassProperties {
            mass: real(rho * volume),
            center: wide::to_vec(apex + center),
            inertia: wide::to_mat(inertia * rho),
        }
    }
}

fn outer(a: DVec3, b: DVec3) -> DMat3 {
    DMat3::from_cols(a * b.x, a * b.y, a * b.z)
}
