//! Rotational drifts: how q moves over a step once the angular momentum is fixed.
//!
//! A torque-free body conserves L (world) and its energy ½ Πᵀ I⁻¹ Π (Π = body-frame L).
//! The plain update q += ½ h ω q keeps neither: it leaves the unit sphere and, renormalised,
//! pumps energy in, which at game steps ends with a box spinning about the wrong axis.
//!
//! Instead the drift splits the free-body Hamiltonian H = Σᵢ Πᵢ² / 2Iᵢ into its three
//! principal terms. Each term alone is solved exactly: the body turns about principal axis
//! i at the constant rate Πᵢ/Iᵢ. Composed symmetrically (Strang: ½ 1, ½ 2, 3, ½ 2, ½ 1)
//! the drift is second order, symplectic, time-reversible, keeps world L exactly (every
//! sub-flow does) and keeps the energy error bounded for all time.

use crate::body::{Body, BodyKind};
use crate::math::{quat_from_rotation_vector, Quat, Real, Vec3};

/// Orientation after a step `h` of a body whose angular momentum stays `l` over it
/// (`w` is used for kinematic bodies, whose spin is prescribed).
pub(crate) fn drift(body: &Body, q: Quat, l: Vec3, w: Vec3, h: Real) -> Quat {
    match body.kind {
        BodyKind::Static => q,
        BodyKind::Kinematic => exact_spin(w, q, h),
        BodyKind::Dynamic if body.planar => {
            // The seed's 2D rule: θ₊ = θ + h L_z / I_zz about world z.
            exact_spin(Vec3::new(0.0, 0.0, l.z / body.planar_inertia), q, h)
        }
        BodyKind::Dynamic => free_rotor(body, q, l, h),
    }
}

/// Rotation at a constant world angular velocity `w` for `h`: q₊ = exp(h w / 2) q.
#[inline]
pub(crate) fn exact_spin(w: Vec3, q: Quat, h: Real) -> Quat {
    (quat_from_rotation_vector(w * h) * q).normalize()
}

/// The symmetric principal-axis splitting of the torque-free rotor.
fn free_rotor(body: &Body, mut q: Quat, l: Vec3, h: Real) -> Quat {
    let axes = [
        body.principal_axes.x_axis,
        body.principal_axes.y_axis,
        body.principal_axes.z_axis,
    ];
    let moments = body.principal_moments;
    let moment = |i: usize| [moments.x, moments.y, moments.z][i];
    for (i, fraction) in [(0usize, 0.5), (1, 0.5), (2, 1.0), (1, 0.5), (0, 0.5)] {
        // Π along axis i is constant during its own sub-flow: the body turns about that
        // axis, which leaves the component of Π along it unchanged.
        let pi = (q.inverse() * l).dot(axes[i]);
        let angle = fraction * h * pi / moment(i);
        q *= Quat::from_axis_angle(axes[i], angle);
    }
    q.normalize()
}
