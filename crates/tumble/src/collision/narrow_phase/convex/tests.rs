//! Convex–convex contacts by the separating-axis test: boxes resting and edge on edge, and
//! boxes, spheres and capsules against a mesh triangle.

use super::*;

/// Exact-arithmetic answers to rounding: f64 or f32.
const EPS: Real = if std::mem::size_of::<Real>() == 8 {
    1e-9
} else {
    2e-5
};

fn cube() -> Convex<'static> {
    Convex::Box {
        half_extents: Vec3::splat(0.5),
    }
}

#[test]
fn resting_boxes_by_sat() {
    let pb = Pose::from_translation(Vec3::new(0.1, 0.99, 0.0));
    let c = cube();
    let mut pair = Pair::new(&c, &Pose::IDENTITY, &c, &pb);
    pair.scale = 1.0;
    let ca = Polytope::of_core(&c, &Pose::IDENTITY).unwrap();
    let cb = Polytope::of_core(&c, &pair.rel).unwrap();
    let mut cands = Vec::new();
    let n = polytope_contact(&pair, &ca, &cb, 0.0, &mut cands).unwrap();
    assert!((n - Vec3::Y).length() < 1e-6);
    assert_eq!(cands.len(), 4);
    for c in &cands {
        assert!(((c.point_b - c.point_a).dot(n) + 0.01).abs() < 1e-6);
    }
}

#[test]
fn edge_on_edge_by_sat() {
    // Two cubes turned 45° about crossing axes meet edge to edge.
    let c = cube();
    let s = (0.5 as Real).sqrt();
    let pa = Pose::new(
        Vec3::ZERO,
        crate::math::Quat::from_rotation_z(std::f64::consts::FRAC_PI_4 as Real),
    );
    let pb = Pose::new(
        Vec3::new(0.0, 2.0 * s - 0.02, 0.0),
        crate::math::Quat::from_rotation_x(std::f64::consts::FRAC_PI_4 as Real),
    );
    let cp = closest_points(&c, &pa, &c, &pb);
    assert!((cp.distance + 0.02).abs() < 1e-5, "{cp:?}");
    assert!((cp.normal - Vec3::Y).length() < 1e-5);
    let mut m = Manifold::default();
    assert!(convex_convex(&c, &pa, &c, &pb, 0.0, &mut m));
    assert_eq!(m.len(), 1);
    assert!((m.points()[0].separation + 0.02).abs() < 1e-5);
}

fn tri() -> Convex<'static> {
    // Counter-clockwise seen from +y: its front normal is +y.
    Convex::Triangle([
        Vec3::new(-2.0, 0.0, 2.0),
        Vec3::new(2.0, 0.0, 2.0),
        Vec3::new(0.0, 0.0, -2.0),
    ])
}

#[test]
fn box_resting_on_a_triangle() {
    let pb = Pose::new(
        Vec3::new(0.1, 0.5 - 0.002, 0.3),
        crate::math::Quat::from_rotation_y(0.5),
    );
    let mut m = Manifold::default();
    assert!(convex_convex(
        &tri(),
        &Pose::IDENTITY,
        &cube(),
        &pb,
        0.01,
        &mut m
    ));
    assert!((m.normal - Vec3::Y).length() < EPS, "{m:?}");
    assert_eq!(m.len(), 4);
    for p in m.points() {
        assert!((p.separation + 0.002).abs() < EPS, "{m:?}");
        assert!(p.point_a.y.abs() < EPS);
    }
    // The other order flips the normal and keeps the points.
    let mut r = Manifold::default();
    assert!(convex_convex(
        &cube(),
        &pb,
        &tri(),
        &Pose::IDENTITY,
        0.01,
        &mut r
    ));
    assert!((r.normal + Vec3::Y).length() < EPS);
    assert!((r.min_separation() - m.min_separation()).abs() < EPS);
}

#[test]
fn box_edge_across_a_triangle_edge() {
    // A cube turned 45° about z, its lower edge crossing the triangle's edge x = −1 ... z.
    let t = Convex::Triangle([
        Vec3::new(0.0, 0.0, 1.0),
        Vec3::new(1.0, 0.0, -1.0),
        Vec3::new(-1.0, 0.0, -1.0),
    ]);
    let h = (0.5 as Real) * (2.0 as Real).sqrt();
    let pb = Pose::new(
        Vec3::new(0.0, h - 0.01, 0.0),
        crate::math::Quat::from_rotation_z(std::f64::consts::FRAC_PI_4 as Real),
    );
    let mut m = Manifold::default();
    assert!(convex_convex(
        &t,
        &Pose::IDENTITY,
        &cube(),
        &pb,
        0.0,
        &mut m
    ));
    assert!((m.normal - Vec3::Y).length() < EPS, "{m:?}");
    assert!((m.min_separation() + 0.01).abs() < EPS, "{m:?}");
    // The box's bottom edge (along z) clipped to the triangle.
    assert_eq!(m.len(), 2, "{m:?}");
    for p in m.points() {
        assert!(p.point_b.x.abs() < EPS && p.point_b.z.abs() <= 0.5 + EPS);
    }
}

#[test]
fn sphere_on_a_triangle() {
    let s = Convex::Sphere { radius: 0.5 };
    let cases = [
        // (centre, separation, normal from the triangle to the sphere)
        (Vec3::new(0.3, 0.45, 0.2), -0.05, Vec3::Y),
        (Vec3::new(0.0, -0.48, 0.0), -0.02, -Vec3::Y),
        (
            Vec3::new(0.0, 0.3, 2.4),
            0.5 - 0.5,
            Vec3::new(0.0, 0.6, 0.8),
        ),
        (Vec3::new(0.0, 0.0, 0.0), -0.5, Vec3::Y),
    ];
    for (c, sep, n) in cases {
        let mut m = Manifold::default();
        let hit = convex_convex(
            &tri(),
            &Pose::IDENTITY,
            &s,
            &Pose::from_translation(c),
            0.01,
            &mut m,
        );
        assert!(hit, "{c}");
        assert_eq!(m.len(), 1);
        assert!((m.points()[0].separation - sep).abs() < EPS, "{c}: {m:?}");
        if c.y != 0.0 {
            assert!((m.normal - n).length() < EPS, "{c}: {m:?}");
        } else {
            assert!(m.normal.x.abs() < EPS && m.normal.z.abs() < EPS);
        }
    }
}

#[test]
fn capsule_lying_on_a_triangle() {
    let cap = Convex::Capsule {
        radius: 0.2,
        half_height: 0.5,
    };
    let pc = Pose::new(
        Vec3::new(0.0, 0.2 - 0.001, 0.0),
        crate::math::Quat::from_rotation_x(std::f64::consts::FRAC_PI_2 as Real),
    );
    let mut m = Manifold::default();
    assert!(convex_convex(
        &tri(),
        &Pose::IDENTITY,
        &cap,
        &pc,
        0.0,
        &mut m
    ));
    assert_eq!(m.len(), 2, "{m:?}");
    for p in m.points() {
        assert!((p.separation + 0.001).abs() < EPS);
        assert!((p.point_b.z.abs() - 0.5).abs() < EPS);
    }
}

/// A small capsule just over or into a large box's top face, at many orientations: the
/// distance is the lower end's height less the radius. On a box 40 m across, f32's GJK
/// once stopped at the capsule's middle, 3 mm off (its simplex solved in f32, see
/// `gjk::Wide`); the error now stays at the rounding of the box's corners in the capsule's
/// frame, a few epsilons of their distance (measured: 68 µm at 141 m in f32, 2·10⁻¹⁴ m in
/// f64; 1 µm for the 1 m box in f32, GJK's relative tolerance).
#[test]
fn small_capsule_over_a_large_box() {
    let (r, hh) = (0.005, 0.005);
    let a = Convex::Capsule {
        radius: r,
        half_height: hh,
    };
    for half in [0.5, 5.0, 20.0, 100.0] {
        let b = Convex::Box {
            half_extents: Vec3::new(half, 0.005, half),
        };
        let pb = Pose::new(Vec3::new(0.0, -0.005, 0.0), crate::math::Quat::IDENTITY);
        let allowed = 8.0 * crate::math::EPSILON * (half * Real::sqrt(2.0) + 1.0);
        for k in 0..400 {
            let k = k as Real;
            let axis = Vec3::new((1.3 * k).sin(), (0.7 * k).cos(), (2.1 * k).sin() + 0.1);
            let q = crate::math::Quat::from_axis_angle(axis.normalize(), 0.37 * k);
            let height = 0.011 * ((0.9 * k).sin() * 0.5 + 0.5) - 0.002;
            let centre = Vec3::new(0.3 * (1.1 * k).sin(), height, 0.3 * (1.7 * k).cos());
            let c = closest_points(&a, &Pose::new(centre, q), &b, &pb);
            let lowest = centre.y - (q * Vec3::Y).y.abs() * hh - r;
            let err = (c.distance - lowest).abs();
            assert!(
                err < allowed,
                "box {half}, case {k}: {} for {lowest}",
                c.distance
            );
        }
    }
}
