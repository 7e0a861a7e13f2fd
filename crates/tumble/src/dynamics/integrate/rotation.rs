//! Rotational drifts: how q moves over a step once the angular momentum is fixed.
//!
//! A torque-free body conserves L (world) and its energy ½ Πᵀ I⁻¹ Π (Π = body-frame L).
//! The plain update q += ½ dt ω q keeps neither: it leaves the unit sphere and, renormalised,
//! pumps energy in, which at game steps ends with a box spinning about the wrong axis.
//!
//! Instead the drift splits the free-body Hamiltonian H = Σᵢ Πᵢ² / 2Iᵢ into its three
//! principal terms. Each term alone is solved exactly: the body turns about principal axis
//! i at the constant rate Πᵢ/Iᵢ. Composed symmetrically (Strang: ½ 1, ½ 2, 3, ½ 2, ½ 1)
//! the drift is second order, symplectic, time-reversible, keeps world L exactly (every
//! sub-flow does) and keeps the energy error bounded for all time.

use crate::dynamics::body::{Body, BodyKind};
use crate::math::{quat_from_rotation_vector, Quat, Real, Vec3};

/// Orientation after a step `dt` of a body whose angular momentum stays `l` over it
/// (`w` is used for kinematic bodies, whose spin is prescribed).
pub(crate) fn drift(body: &Body, q: Quat, l: Vec3, w: Vec3, dt: Real) -> Quat {
    match body.kind {
        BodyKind::Static => q,
        BodyKind::Kinematic => exact_spin(w, q, dt),
        BodyKind::Dynamic if body.planar => {
            // The seed's 2D rule: θ₊ = θ + dt L_z / I_zz about world z.
            exact_spin(Vec3::new(0.0, 0.0, l.z / body.planar_inertia), q, dt)
        }
        // A ball-like body (all principal moments equal) keeps ω = L/I constant while
        // torque-free: one exact rotation, where the splitting would take five.
        BodyKind::Dynamic if body.isotropic => exact_spin(l / body.principal_moments.x, q, dt),
        BodyKind::Dynamic => free_rotor(body, q, l, dt),
    }
}

/// Rotation at a constant world angular velocity `w` for `dt`: q₊ = exp(dt w / 2) q.
#[inline]
pub(crate) fn exact_spin(w: Vec3, q: Quat, dt: Real) -> Quat {
    (quat_from_rotation_vector(w * dt) * q).normalize()
}

/// The symmetric principal-axis splitting of the torque-free rotor.
///
/// Works in the principal frame, where each sub-flow is a rotation about a coordinate
/// axis: Π (body-frame L) turns backwards by the angle while the body turns forwards, so
/// one sin/cos pair per sub-flow serves both and no quaternion rotates a vector in the loop.
fn free_rotor(body: &Body, q: Quat, l: Vec3, dt: Real) -> Quat {
    let to_principal = body.principal_rotation;
    let mut pi = (q * to_principal).inverse() * l;
    let inv = body.principal_moments.recip();
    // Accumulated rotation in the principal frame, as [x, y, z, w].
    let mut acc = [0.0 as Real, 0.0, 0.0, 1.0];
    for (axis, fraction) in [(0usize, 0.5), (1, 0.5), (2, 1.0), (1, 0.5), (0, 0.5)] {
        let rate = [pi.x * inv.x, pi.y * inv.y, pi.z * inv.z][axis];
        let (s, c) = (0.5 * fraction * dt * rate).sin_cos();
        // Turning the body by +θ about e_axis turns Π by −θ: cos θ = c² − s², sin θ = 2sc.
        let (cos, sin) = (c * c - s * s, 2.0 * s * c);
        pi = match axis {
            0 => Vec3::new(pi.x, cos * pi.y + sin * pi.z, -sin * pi.y + cos * pi.z),
            1 => Vec3::new(cos * pi.x - sin * pi.z, pi.y, sin * pi.x + cos * pi.z),
            _ => Vec3::new(cos * pi.x + sin * pi.y, -sin * pi.x + cos * pi.y, pi.z),
        };
        acc = multiply_by_axis_rotation(acc, axis, s, c);
    }
    let acc = Quat::from_xyzw(acc[0], acc[1], acc[2], acc[3]);
    (q * (to_principal * acc * to_principal.inverse())).normalize()
}

/// `a * (c + s e_axis)`: a quaternion times the half-angle rotation about a coordinate axis.
#[inline]
fn multiply_by_axis_rotation(a: [Real; 4], axis: usize, s: Real, c: Real) -> [Real; 4] {
    let [x, y, z, w] = a;
    match axis {
        0 => [x * c + w * s, y * c + z * s, z * c - y * s, w * c - x * s],
        1 => [x * c - z * s, y * c + w * s, z * c + x * s, w * c - y * s],
        _ => [x * c + y * s, y * c - x * s, z * c + w * s, w * c - z * s],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axis_rotation_product_matches_glam() {
        let a = Quat::from_xyzw(0.1, -0.7, 0.3, 0.6).normalize();
        for (axis, e) in [Vec3::X, Vec3::Y, Vec3::Z].into_iter().enumerate() {
            let (s, c) = (0.35 as Real).sin_cos();
            let r = multiply_by_axis_rotation([a.x, a.y, a.z, a.w], axis, s, c);
            let expect = a * Quat::from_axis_angle(e, 0.7);
            let got = Quat::from_xyzw(r[0], r[1], r[2], r[3]);
            assert!(
                (got - expect).length() < 1e-6,
                "axis {axis}: {got} vs {expect}"
            );
        }
    }
}
