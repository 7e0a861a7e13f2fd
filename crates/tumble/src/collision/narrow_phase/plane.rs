//! Any convex shape against a plane (half-space).
//!
//! With N the plane's unit outward normal and D its offset in world (the solid side is
//! N·x ≤ D), a point x of the convex stands h(x) = N·x − D above the surface, its
//! projection on the surface is x − h N, and with the manifold normal −N (from the convex
//! into the plane) the separation of the pair (x, x − h N) is (−h N)·(−N) = h. So every
//! routine only has to name the candidate points of the convex's lowest feature; those with
//! h < margin are kept, at most four of them (by [`reduce`]).
//!
//! The plane is feature face 0 on its side; the convex's points are vertices numbered by
//! shape: box corners as in `box_box.rs`, capsule ends 0 (local −y) and 1, hull and triangle
//! vertices by index, cylinder rim points 4·cap + direction (cap 0 at local −y), and a lying
//! cylinder's lowest rim points 8 + cap.

use super::box_box::{vertex, vertex_index, FACE, VERTEX};
use super::sphere::{direction, TINY};
use super::{feature_id, reduce, Candidate, Manifold};
use crate::collision::geometry::Pose;
use crate::collision::shape::{Convex, SIDE_SIN};
use crate::math::{Real, Vec3};

/// A cylinder tilted by less than this (sine of the angle between its axis and the plane
/// normal) stands flat on its cap: its rim is represented by four fixed points alone. A
/// fixed rim point is then at most R·sinθ·(1 − cos 45°) ≈ 3e-5 R higher than the true
/// lowest rim point, and the points do not wander round the rim with the rounding noise
/// of an upright body's tilt direction.
const FLAT_SIN: Real = 1e-4;

/// The four fixed rim directions of a cylinder, (x, z) in its local frame.
const RIM: [(Real, Real); 4] = [(1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0)];

/// Convex `a` at `pa` against the half-space n·x ≤ offset of the plane body at `pb`
/// (`normal` unit, in the plane body's frame). The manifold's normal points from A into
/// the plane, i.e. −n in world.
#[allow(clippy::too_many_arguments)]
pub fn convex_plane(
    a: &Convex,
    pa: &Pose,
    normal: Vec3,
    offset: Real,
    pb: &Pose,
    margin: Real,
    out: &mut Manifold,
) -> bool {
    // A normal that is not unit still defines the half-space (n/|n|)·x ≤ offset/|n|.
    let len = normal.length();
    if !(len > TINY && len.is_finite()) {
        return false;
    }
    let n = direction(pb.transform_vector(normal / len)).unwrap_or(Vec3::Y);
    // n_local·x_local ≤ offset with x_world = R x_local + p: N·(x_world − p) ≤ offset.
    let d = offset / len + n.dot(pb.position);
    out.normal = -n;
    let plane = Plane { n, d };

    let mut cands = Vec::new();
    match *a {
        Convex::Sphere { radius } => {
            cands.extend(plane.contact(pa.position - n * radius, 0, margin));
        }
        Convex::Capsule {
            radius,
            half_height,
        } => {
            // Both ends; a zero-length capsule is a sphere with one.
            let ends = if half_height > TINY { 2 } else { 1 };
            for end in 0..ends {
                let y = if end == 0 { -half_height } else { half_height };
                let centre = pa.transform_point(Vec3::new(0.0, y, 0.0));
                cands.extend(plane.contact(centre - n * radius, end, margin));
            }
        }
        Convex::Box { half_extents } => {
            for v in 0..8u32 {
                let signs = [v & 1 != 0, v & 2 != 0, v & 4 != 0];
                let x = pa.transform_point(vertex(half_extents, signs));
                cands.extend(plane.contact(x, vertex_index(signs), margin));
            }
        }
        Convex::Cylinder {
            radius,
            half_height,
        } => cylinder(radius, half_height, pa, &plane, margin, &mut cands),
        Convex::Hull(hull) => {
            for (i, &v) in hull.vertices().iter().enumerate() {
                cands.extend(plane.contact(pa.transform_point(v), i as u32, margin));
            }
        }
        Convex::Triangle(t) => {
            for (i, &v) in t.iter().enumerate() {
                cands.extend(plane.contact(pa.transform_point(v), i as u32, margin));
            }
        }
    }
    reduce(&cands, margin, out);
    !out.is_empty()
}

/// The plane in world: N·x = D.
struct Plane {
    n: Vec3,
    d: Real,
}

impl Plane {
    /// The contact of the convex's surface point `x` (its vertex `index`), if it stands
    /// less than `margin` above the plane.
    fn contact(&self, x: Vec3, index: u32, margin: Real) -> Option<Candidate> {
        let h = self.n.dot(x) - self.d;
        (h < margin).then(|| Candidate {
            point_a: x,
            point_b: x - self.n * h,
            feature: feature_id(VERTEX, index, FACE, 0),
        })
    }
}

/// A cylinder's lowest points: on each cap's rim the point lowest along −N, plus fixed rim
/// points, so that a cylinder standing on a cap gets a patch and one lying on its side gets
/// the two ends of its lowest line.
///
/// On a cap (centre c, axis u, radius R) the rim point c + R w, |w| = 1, w ⊥ u, is lowest
/// for w along the projection of −N onto the cap plane, w ∝ −N + u (N·u); its length is the
/// sine of the tilt. The rim is represented by four fixed directions (local ±x, ±z); when the
/// tilt is not negligible the one nearest to the lowest direction is replaced by it, which
/// keeps the other three, and their feature ids, where they are.
fn cylinder(
    radius: Real,
    half_height: Real,
    pa: &Pose,
    plane: &Plane,
    margin: Real,
    cands: &mut Vec<Candidate>,
) {
    let (ax, ay, az) = (
        pa.transform_vector(Vec3::X),
        pa.transform_vector(Vec3::Y),
        pa.transform_vector(Vec3::Z),
    );
    let w = -plane.n + ay * plane.n.dot(ay);
    let (wx, wz) = (w.dot(ax), w.dot(az));
    let tilt = (wx * wx + wz * wz).sqrt();
    if plane.n.dot(ay).abs() < SIDE_SIN {
        // Lying on its side: the line of its two lowest rim points, as a capsule's, with
        // ids of their own (8, 9) that do not change as it rolls. Fixed rim points coming
        // round within the margin were body-fixed corners on a surface the solver treats
        // as round (`Shape::round_toward`): a rolling cylinder ran 0.18 mm low with them.
        let low = (wx / tilt, wz / tilt);
        for cap in 0..2u32 {
            let y = if cap == 0 { -half_height } else { half_height };
            let p = pa.transform_point(Vec3::new(radius * low.0, y, radius * low.1));
            cands.extend(plane.contact(p, 8 + cap, margin));
        }
        return;
    }
    let mut rim = RIM;
    if tilt > FLAT_SIN {
        let low = (wx / tilt, wz / tilt);
        let mut nearest = 0;
        for (m, &(x, z)) in RIM.iter().enumerate() {
            let (bx, bz) = RIM[nearest];
            if x * low.0 + z * low.1 > bx * low.0 + bz * low.1 {
                nearest = m;
            }
        }
        rim[nearest] = low;
    }
    for cap in 0..2u32 {
        let y = if cap == 0 { -half_height } else { half_height };
        for (m, &(x, z)) in rim.iter().enumerate() {
            let p = pa.transform_point(Vec3::new(radius * x, y, radius * z));
            cands.extend(plane.contact(p, 4 * cap + m as u32, margin));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn triangle_on_plane_reports_its_low_vertices() {
        let tri = Convex::Triangle([
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 0.5, 1.0),
        ]);
        let pose = Pose::from_translation(Vec3::new(0.0, 0.01, 0.0));
        let mut m = Manifold::default();
        assert!(convex_plane(
            &tri,
            &pose,
            Vec3::Y,
            0.0,
            &Pose::IDENTITY,
            0.05,
            &mut m
        ));
        assert_eq!(m.normal, -Vec3::Y);
        assert_eq!(m.len(), 2);
        for (p, x) in m.points().iter().zip([0.0, 1.0]) {
            assert!((p.point_a - Vec3::new(x, 0.01, 0.0)).length() < 1e-6);
            assert!((p.point_b - Vec3::new(x, 0.0, 0.0)).length() < 1e-6);
            assert!((p.separation - 0.01).abs() < 1e-6);
        }
        // Lowered into the plane, all three are in.
        let pose = Pose::from_translation(Vec3::new(0.0, -0.6, 0.0));
        let mut m = Manifold::default();
        assert!(convex_plane(
            &tri,
            &pose,
            Vec3::Y,
            0.0,
            &Pose::IDENTITY,
            0.0,
            &mut m
        ));
        assert_eq!(m.len(), 3);
        assert!((m.min_separation() + 0.6).abs() < 1e-6);
    }

    #[test]
    fn degenerate_plane_normal_reports_nothing() {
        let mut m = Manifold::default();
        let s = Convex::Sphere { radius: 1.0 };
        assert!(!convex_plane(
            &s,
            &Pose::IDENTITY,
            Vec3::ZERO,
            0.0,
            &Pose::IDENTITY,
            0.1,
            &mut m
        ));
    }
}
