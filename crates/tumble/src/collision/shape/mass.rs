//! Mass properties: mass, centre of mass, and the inertia tensor about the centre of mass.
//!
//! Closed forms for the primitives; hulls integrate exactly over tetrahedra (hull.rs);
//! compounds add children with the parallel-axis theorem after rotating each tensor
//! (`I' = R I Rᵀ`) into the parent frame.

use crate::math::{outer, Mat3, Quat, Real, Vec3, PI};

/// Mass (kg), centre of mass (m, local frame) and inertia tensor (kg·m², about the centre
/// of mass, local axes).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MassProperties {
    /// Total mass (kg).
    pub mass: Real,
    /// Centre of mass in the local frame (m).
    pub center: Vec3,
    /// Inertia tensor about `center`, in local axes (kg·m²).
    pub inertia: Mat3,
}

impl MassProperties {
    /// Solid sphere: I = 2/5 m r².
    pub fn sphere(density: Real, radius: Real) -> Self {
        let mass = density * 4.0 / 3.0 * PI * radius.powi(3);
        let i = 0.4 * mass * radius * radius;
        Self::diagonal(mass, Vec3::splat(i))
    }

    /// Solid box with half extents (a, b, c): I_xx = m/3 (b² + c²) and so on.
    pub fn cuboid(density: Real, h: Vec3) -> Self {
        let mass = density * 8.0 * h.x * h.y * h.z;
        let (x2, y2, z2) = (h.x * h.x, h.y * h.y, h.z * h.z);
        Self::diagonal(mass, Vec3::new(y2 + z2, x2 + z2, x2 + y2) * (mass / 3.0))
    }

    /// Solid cylinder along y: I_yy = m r²/2, I_xx = I_zz = m (r²/4 + h²/3), h the half height.
    pub fn cylinder(density: Real, radius: Real, half_height: Real) -> Self {
        let mass = density * PI * radius * radius * 2.0 * half_height;
        let r2 = radius * radius;
        let side = mass * (r2 / 4.0 + half_height * half_height / 3.0);
        Self::diagonal(mass, Vec3::new(side, 0.5 * mass * r2, side))
    }

    /// Capsule along y: the shaft as a cylinder plus two hemispheres, each hemisphere's
    /// tensor shifted from its own centre of mass (3r/8 from its flat face) to the origin.
    /// The shifted hemisphere terms sum to m_s (2r²/5 + h² + 3hr/4) about a transverse axis.
    pub fn capsule(density: Real, radius: Real, half_height: Real) -> Self {
        let r = radius;
        let h = half_height;
        let m_cyl = density * PI * r * r * 2.0 * h;
        let m_sph = density * 4.0 / 3.0 * PI * r * r * r;
        let axial = m_cyl * r * r / 2.0 + m_sph * 0.4 * r * r;
        let side =
            m_cyl * (r * r / 4.0 + h * h / 3.0) + m_sph * (0.4 * r * r + h * h + 0.75 * h * r);
        Self::diagonal(m_cyl + m_sph, Vec3::new(side, axial, side))
    }

    /// A body with its centre of mass at the origin and principal axes along x, y, z.
    pub fn diagonal(mass: Real, moments: Vec3) -> Self {
        MassProperties {
            mass,
            center: Vec3::ZERO,
            inertia: Mat3::from_diagonal(moments),
        }
    }

    /// The same body seen from a parent frame in which its frame sits at `position`,
    /// rotated by `rotation`: the centre moves, the tensor turns as R I Rᵀ.
    pub fn transformed(&self, position: Vec3, rotation: Quat) -> Self {
        let r = Mat3::from_quat(rotation);
        MassProperties {
            mass: self.mass,
            center: position + rotation * self.center,
            inertia: r * self.inertia * r.transpose(),
        }
    }

    /// The tensor about a point displaced by `d` from the centre of mass (parallel-axis
    /// theorem): I + m (|d|² E − d dᵀ).
    pub fn inertia_about(&self, d: Vec3) -> Mat3 {
        self.inertia + (Mat3::from_diagonal(Vec3::splat(d.dot(d))) - outer(d, d)) * self.mass
    }

    /// Several bodies rigidly joined: masses add, the centre is the mass-weighted mean
    /// (the seed's r_CM = Σ m_i r_i / m) and each tensor is shifted to that centre.
    pub fn sum(parts: impl IntoIterator<Item = MassProperties>) -> Self {
        let parts: Vec<MassProperties> = parts.into_iter().collect();
        let mass: Real = parts.iter().map(|p| p.mass).sum();
        let center = parts
            .iter()
            .fold(Vec3::ZERO, |acc, p| acc + p.center * p.mass)
            / mass;
        let inertia = parts.iter().fold(Mat3::ZERO, |acc, p| {
            acc + p.inertia_about(p.center - center)
        });
        MassProperties {
            mass,
            center,
            inertia,
        }
    }

    /// The same shape scaled to a total `mass` (uniform density assumed).
    pub fn with_mass(&self, mass: Real) -> Self {
        let k = mass / self.mass;
        MassProperties {
            mass,
            center: self.center,
            inertia: self.inertia * k,
        }
    }
}
