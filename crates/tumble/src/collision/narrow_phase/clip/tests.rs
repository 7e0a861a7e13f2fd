//! Feature loops face outward, and clipping and segment closest points give the exact
//! overlap.

use super::*;

#[test]
fn box_loops_face_outward() {
    let c = Convex::Box {
        half_extents: Vec3::new(1.0, 2.0, 3.0),
    };
    let p = Polytope::of_core(&c, &Pose::IDENTITY).unwrap();
    for i in 0..6 {
        let l = p.face_loop(i);
        let v = |k: usize| p.verts[l[k] as usize];
        let n = (v(1) - v(0)).cross(v(2) - v(0)).normalize();
        assert!((n - p.planes[i].0).length() < 1e-6, "face {i}");
        for k in 0..4 {
            assert!((v(k).dot(n) - p.planes[i].1).abs() < 1e-6);
        }
    }
}

#[test]
fn cylinder_caps_face_outward() {
    for dir in [Vec3::Y, -Vec3::Y] {
        let f = cylinder_feature(1.0, 2.0, &Pose::IDENTITY, dir, dir);
        let n = (f.pts[1] - f.pts[0]).cross(f.pts[2] - f.pts[0]);
        assert!(n.dot(dir) > 0.0);
        assert!((f.normal - dir).length() < 1e-6);
        for p in &f.pts {
            assert!(((p.x * p.x + p.z * p.z).sqrt() - 1.0).abs() < 1e-6);
        }
    }
}

#[test]
fn square_on_square_clips_to_overlap() {
    let c = Convex::Box {
        half_extents: Vec3::ONE,
    };
    let a = Polytope::of_core(&c, &Pose::IDENTITY).unwrap();
    let b = Polytope::of_core(&c, &Pose::from_translation(Vec3::new(1.0, 1.9, 0.5))).unwrap();
    let mut out = Vec::new();
    clip(
        &a.face_feature(2),
        &b.face_feature(3),
        Vec3::Y,
        true,
        &mut out,
    );
    assert_eq!(out.len(), 4);
    for c in &out {
        assert!((c.point_a.y - 1.0).abs() < 1e-6);
        assert!((c.point_b.y - 0.9).abs() < 1e-6);
        assert!(c.point_a.x >= -1e-6 && c.point_a.x <= 1.0 + 1e-6);
        assert!(c.point_a.z >= -0.5 - 1e-6 && c.point_a.z <= 1.0 + 1e-6);
    }
}

#[test]
fn closest_points_of_segments() {
    let (p, q) = segment_closest(
        Vec3::new(-1.0, 0.0, 0.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.5, 1.0, -1.0),
        Vec3::new(0.5, 1.0, 1.0),
    );
    assert!((p - Vec3::new(0.5, 0.0, 0.0)).length() < 1e-6);
    assert!((q - Vec3::new(0.5, 1.0, 0.0)).length() < 1e-6);
}
