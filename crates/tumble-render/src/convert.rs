//! The engine's `Real` (f64, or f32 behind a feature) to the f32 that pictures use.

/// A vector in f32.
#[allow(clippy::unnecessary_cast)] // a no-op in the f32 build, a narrowing in the f64 one
pub fn vec3(v: tumble::Vec3) -> glam::Vec3 {
    glam::Vec3::new(v.x as f32, v.y as f32, v.z as f32)
}

/// A rotation in f32.
#[allow(clippy::unnecessary_cast)]
pub fn quat(q: tumble::Quat) -> glam::Quat {
    glam::Quat::from_xyzw(q.x as f32, q.y as f32, q.z as f32, q.w as f32).normalize()
}

/// A scalar in f32.
#[allow(clippy::unnecessary_cast)]
pub fn real(x: tumble::Real) -> f32 {
    x as f32
}
