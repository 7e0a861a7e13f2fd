//! The scalar type and the glam aliases every other module uses.
//!
//! `Real` is `f64` unless the crate is built with the `f32` feature; every vector,
//! quaternion and matrix alias follows it, so no module names a concrete float type.

#[cfg(not(feature = "f32"))]
mod precision {
    /// The scalar type of the whole engine (f64 by default).
    pub type Real = f64;
    /// A 3-vector of `Real`.
    pub type Vec3 = glam::DVec3;
    /// A unit quaternion of `Real`, stored (and written everywhere) as [x, y, z, w].
    pub type Quat = glam::DQuat;
    /// A 3x3 matrix of `Real` (column-major).
    pub type Mat3 = glam::DMat3;
    /// A 4-vector of `Real`; used for quaternion derivatives, which are not unit.
    pub type Vec4 = glam::DVec4;
    /// Machine epsilon of `Real`.
    pub const EPSILON: Real = f64::EPSILON;
    /// pi in `Real`.
    pub const PI: Real = std::f64::consts::PI;
}

#[cfg(feature = "f32")]
mod precision {
    /// The scalar type of the whole engine (f32 with the `f32` feature).
    pub type Real = f32;
    /// A 3-vector of `Real`.
    pub type Vec3 = glam::Vec3;
    /// A unit quaternion of `Real`, stored (and written everywhere) as [x, y, z, w].
    pub type Quat = glam::Quat;
    /// A 3x3 matrix of `Real` (column-major).
    pub type Mat3 = glam::Mat3;
    /// A 4-vector of `Real`; used for quaternion derivatives, which are not unit.
    pub type Vec4 = glam::Vec4;
    /// Machine epsilon of `Real`.
    pub const EPSILON: Real = f32::EPSILON;
    /// pi in `Real`.
    pub const PI: Real = std::f32::consts::PI;
}

pub use precision::*;

/// Conversions between `Real` and f64, for the computations that need f64 whatever `Real`
/// is (the hull builder, GJK's simplex).
#[cfg(not(feature = "f32"))]
pub(crate) mod wide {
    use crate::math::{Mat3, Real, Vec3};
    use glam::{DMat3, DVec3};

    pub fn vec(v: Vec3) -> DVec3 {
        v
    }
    pub fn scalar(x: Real) -> f64 {
        x
    }
    pub fn to_vec(v: DVec3) -> Vec3 {
        v
    }
    pub fn to_mat(m: DMat3) -> Mat3 {
        m
    }
}

/// Conversions between `Real` and f64, for the computations that need f64 whatever `Real`
/// is (the hull builder, GJK's simplex).
#[cfg(feature = "f32")]
pub(crate) mod wide {
    use crate::math::{Mat3, Real, Vec3};
    use glam::{DMat3, DVec3};

    pub fn vec(v: Vec3) -> DVec3 {
        v.as_dvec3()
    }
    pub fn scalar(x: Real) -> f64 {
        f64::from(x)
    }
    pub fn to_vec(v: DVec3) -> Vec3 {
        v.as_vec3()
    }
    pub fn to_mat(m: DMat3) -> Mat3 {
        m.as_mat3()
    }
}

/// Converts an `f64` literal or measurement into `Real` (a no-op in the default build).
#[inline]
pub fn real(x: f64) -> Real {
    x as Real
}

/// The cross-product matrix `[a]x`, so that `skew(a) * b == a.cross(b)`.
#[inline]
pub fn skew(a: Vec3) -> Mat3 {
    Mat3::from_cols(
        Vec3::new(0.0, a.z, -a.y),
        Vec3::new(-a.z, 0.0, a.x),
        Vec3::new(a.y, -a.x, 0.0),
    )
}

/// Two unit vectors completing unit `n` to a right-handed orthonormal basis
/// (t₁ × t₂ = n), chosen from n alone so the result does not depend on history and has no
/// branch but the sign of n.z (Duff et al., "Building an orthonormal basis, revisited").
pub fn orthonormal_basis(n: Vec3) -> [Vec3; 2] {
    let sign = if n.z >= 0.0 { 1.0 } else { -1.0 };
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    [
        Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        Vec3::new(b, sign + n.y * n.y * a, -n.y),
    ]
}

/// The outer product `a bᵀ`.
#[inline]
pub fn outer(a: Vec3, b: Vec3) -> Mat3 {
    Mat3::from_cols(a * b.x, a * b.y, a * b.z)
}

/// `q` as a 4-vector [x, y, z, w].
#[inline]
pub fn quat_to_vec4(q: Quat) -> Vec4 {
    Vec4::new(q.x, q.y, q.z, q.w)
}

/// A 4-vector [x, y, z, w] as a (not necessarily unit) quaternion.
#[inline]
pub fn vec4_to_quat(v: Vec4) -> Quat {
    Quat::from_xyzw(v.x, v.y, v.z, v.w)
}

/// The quaternion rate `q̇ = ½ ω q` for a world-frame angular velocity `ω` (the seed's
/// formula), as a 4-vector so that integrators can add it to `q` component-wise.
#[inline]
pub fn quat_rate(omega: Vec3, q: Quat) -> Vec4 {
    let w = Quat::from_xyzw(omega.x, omega.y, omega.z, 0.0);
    quat_to_vec4(w * q) * 0.5
}

/// The rotation by the rotation vector `theta` (axis times angle, rad), exactly:
/// `exp(θ/2)` as a quaternion. Used where a drift must stay on the unit sphere.
#[inline]
pub fn quat_from_rotation_vector(theta: Vec3) -> Quat {
    let angle = theta.length();
    if angle < 1e-8 {
        // sin(a/2)/a = 1/2 - a²/48 + ...; the series keeps full precision near zero.
        let s = 0.5 - angle * angle / 48.0;
        Quat::from_xyzw(
            theta.x * s,
            theta.y * s,
            theta.z * s,
            1.0 - angle * angle / 8.0,
        )
        .normalize()
    } else {
        Quat::from_axis_angle(theta / angle, angle)
    }
}

/// The rotation vector (axis times angle, rad) of the unit quaternion `q`, the short way:
/// the angle is at most π (q and −q are the same rotation). The inverse of
/// [`quat_from_rotation_vector`].
#[inline]
pub fn rotation_vector(q: Quat) -> Vec3 {
    let q = if q.w < 0.0 { -q } else { q };
    let v = Vec3::new(q.x, q.y, q.z);
    let s = v.length();
    if s < 1e-8 {
        // angle / s = 2 atan2(s, w) / s = (2 / w)(1 − s²/(3w²) + ...): the first term is
        // exact to rounding here.
        return v * (2.0 / q.w);
    }
    v * (2.0 * s.atan2(q.w) / s)
}

/// True when every component is finite.
#[inline]
pub fn vec3_is_finite(v: Vec3) -> bool {
    v.x.is_finite() && v.y.is_finite() && v.z.is_finite()
}

/// Eigen-decomposition of a symmetric 3x3 matrix by cyclic Jacobi rotations.
///
/// Returns the eigenvalues and a proper rotation (det = +1) whose columns are the matching
/// unit eigenvectors, so `m = R diag(λ) Rᵀ`. Jacobi is chosen over the closed-form cubic
/// because it stays accurate for the nearly repeated eigenvalues of symmetric bodies.
#[allow(clippy::needless_range_loop)] // index loops mirror the rotation formulas
pub fn symmetric_eigen(m: Mat3) -> (Vec3, Mat3) {
    let mut a = [[0.0 as Real; 3]; 3];
    for (c, col) in [m.x_axis, m.y_axis, m.z_axis].iter().enumerate() {
        a[0][c] = col.x;
        a[1][c] = col.y;
        a[2][c] = col.z;
    }
    // Symmetrise: callers pass tensors built by sums that may differ in the last bit.
    for i in 0..3 {
        for j in (i + 1)..3 {
            let s = 0.5 * (a[i][j] + a[j][i]);
            a[i][j] = s;
            a[j][i] = s;
        }
    }
    let mut v = [[1.0 as Real, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for _sweep in 0..32 {
        let off = a[0][1].abs() + a[0][2].abs() + a[1][2].abs();
        let scale = a[0][0].abs() + a[1][1].abs() + a[2][2].abs();
        if off <= scale * EPSILON * 0.5 || off == 0.0 {
            break;
        }
        for (p, q) in [(0usize, 1usize), (0, 2), (1, 2)] {
            if a[p][q] == 0.0 {
                continue;
            }
            let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
            let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            let t = if theta == 0.0 { 1.0 } else { t };
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            for k in 0..3 {
                let akp = a[k][p];
                let akq = a[k][q];
                a[k][p] = c * akp - s * akq;
                a[k][q] = s * akp + c * akq;
            }
            for k in 0..3 {
                let apk = a[p][k];
                let aqk = a[q][k];
                a[p][k] = c * apk - s * aqk;
                a[q][k] = s * apk + c * aqk;
            }
            for row in v.iter_mut() {
                let vkp = row[p];
                let vkq = row[q];
                row[p] = c * vkp - s * vkq;
                row[q] = s * vkp + c * vkq;
            }
        }
    }
    let values = Vec3::new(a[0][0], a[1][1], a[2][2]);
    let mut r = Mat3::from_cols(
        Vec3::new(v[0][0], v[1][0], v[2][0]),
        Vec3::new(v[0][1], v[1][1], v[2][1]),
        Vec3::new(v[0][2], v[1][2], v[2][2]),
    );
    if r.determinant() < 0.0 {
        r.z_axis = -r.z_axis;
    }
    (values, r)
}

/// Asks the CPU to bring `x`'s bytes into its nearest cache ahead of their use: a hint
/// that changes no result. For lists walked in an order the hardware cannot guess (the
/// solver prepares the contacts in colour order, which jumps through the contact list).
#[inline(always)]
pub(crate) fn prefetch<T>(x: &T) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        let p = (x as *const T).cast::<i8>();
        for offset in (0..std::mem::size_of::<T>()).step_by(64) {
            // SAFETY: a prefetch neither reads nor writes memory as far as the program can
            // tell and never faults, whatever the address (this one lies inside `x`, a live
            // reference); `_mm_prefetch` needs SSE, which every x86_64 CPU has.
            unsafe { _mm_prefetch::<_MM_HINT_T0>(p.wrapping_add(offset)) };
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = x;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eigen_reconstructs_a_rotated_diagonal_tensor() {
        let rot = Mat3::from_quat(Quat::from_euler(glam::EulerRot::XYZ, 0.3, -1.1, 2.0));
        let d = Mat3::from_diagonal(Vec3::new(1.0, 2.5, 4.0));
        let m = rot * d * rot.transpose();
        let (values, axes) = symmetric_eigen(m);
        let back = axes * Mat3::from_diagonal(values) * axes.transpose();
        let tol = 100.0 * EPSILON * 4.0;
        for (a, b) in [
            (back.x_axis, m.x_axis),
            (back.y_axis, m.y_axis),
            (back.z_axis, m.z_axis),
        ] {
            assert!((a - b).abs().max_element() < tol, "{a} vs {b}");
        }
        let mut sorted = [values.x, values.y, values.z];
        sorted.sort_by(|a, b| a.partial_cmp(b).unwrap());
        assert!((sorted[0] - 1.0).abs() < tol && (sorted[2] - 4.0).abs() < tol);
        assert!((axes.determinant() - 1.0).abs() < tol);
    }

    #[test]
    fn rotation_vector_matches_axis_angle_and_small_angle_series() {
        let axis = Vec3::new(1.0, 2.0, -0.5).normalize();
        let q = quat_from_rotation_vector(axis * 0.7);
        let r = Quat::from_axis_angle(axis, 0.7);
        assert!(q.dot(r).abs() > 1.0 - 10.0 * EPSILON);
        let tiny = quat_from_rotation_vector(axis * 1e-9);
        let v = tiny * Vec3::X;
        let expect = Vec3::X + (axis * 1e-9).cross(Vec3::X);
        assert!((v - expect).length() < 1e-15 + 10.0 * EPSILON);
    }
}
