//! Closest points of segments (crossing, parallel, degenerate) and the exact segment–box
//! distance.

use super::boxes::segment_box_closest;
use super::*;

#[test]
fn closest_segments_of_crossing_parallel_and_degenerate() {
    let (s, t) = closest_segments(
        Vec3::new(-1.0, 0.0, 0.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.5, 1.0, -1.0),
        Vec3::new(0.5, 1.0, 1.0),
    );
    assert!((s - 0.75).abs() < 1e-6 && (t - 0.5).abs() < 1e-6);
    // Parallel: a valid pair at the common perpendicular distance, no NaN.
    let (s, t) = closest_segments(
        Vec3::ZERO,
        Vec3::X,
        Vec3::new(0.5, 1.0, 0.0),
        Vec3::new(1.5, 1.0, 0.0),
    );
    let gap = Vec3::new(0.5, 1.0, 0.0).lerp(Vec3::new(1.5, 1.0, 0.0), t) - Vec3::X * s;
    assert!((gap.length() - 1.0).abs() < 1e-6);
    let (s, t) = closest_segments(Vec3::ONE, Vec3::ONE, Vec3::ONE, Vec3::ONE);
    assert_eq!((s, t), (0.0, 0.0));
}

#[test]
fn segment_box_distance_is_exact() {
    let he = Vec3::new(1.0, 1.0, 1.0);
    // Diagonal past a vertex: closest to the corner (1, 1, 1) at t with x = y = z.
    let p0 = Vec3::new(3.0, 1.0, 2.0);
    let p1 = Vec3::new(1.0, 3.0, 2.0);
    let t = segment_box_closest(p0, p1, he);
    assert!((t - 0.5).abs() < 1e-6, "{t}");
    // Through the box: distance zero somewhere inside.
    let t = segment_box_closest(Vec3::new(-3.0, 0.0, 0.0), Vec3::new(3.0, 0.0, 0.0), he);
    let x = Vec3::new(-3.0 + 6.0 * t, 0.0, 0.0);
    assert!(x.x.abs() <= 1.0);
}
