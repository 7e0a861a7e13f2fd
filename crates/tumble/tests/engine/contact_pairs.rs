//! The closed-form contact routines (sphere, capsule, box pairs and every convex on a
//! plane) against hand-computed geometry, and the properties every manifold must have:
//! it moves with a rigid motion of both shapes, flips with the pair's order, keeps its
//! feature ids under small perturbations and never holds a NaN.
//!
//! Conventions checked throughout: the normal points from A to B, `point_a` is on A's
//! surface, `point_b` on B's, separation = (point_b − point_a)·normal.

// Casts between Real and f64 are no-ops in the default build but needed in the f32 one.
#![allow(clippy::unnecessary_cast)]

use tumble::math::PI;
use tumble::narrow_phase::{collide, swap_feature, ContactPoint, Manifold};
use tumble::prelude::*;
use tumble::Pose;

/// Positions and separations agree to this: 1e-9 m in f64, a few f32 ulps of the
/// coordinates (which reach a few metres) in f32.
fn eps() -> Real {
    if std::mem::size_of::<Real>() == 8 {
        1e-9
    } else {
        2e-5
    }
}

fn sqrt(x: Real) -> Real {
    x.sqrt()
}

fn at(x: Real, y: Real, z: Real) -> Pose {
    Pose::from_translation(Vec3::new(x, y, z))
}

fn posed(x: Real, y: Real, z: Real, rotation: Quat) -> Pose {
    Pose::new(Vec3::new(x, y, z), rotation)
}

/// A capsule lying along world x (its local y turned onto x).
fn along_x() -> Quat {
    Quat::from_rotation_z(-PI / 2.0)
}

/// Along world z.
fn along_z() -> Quat {
    Quat::from_rotation_x(PI / 2.0)
}

/// Every manifold of the pair.
fn all(a: &Shape, pa: &Pose, b: &Shape, pb: &Pose, margin: Real) -> Vec<Manifold> {
    let mut out = Vec::new();
    collide(a, pa, b, pb, margin, &mut out);
    for m in &out {
        assert_sane(m);
    }
    out
}

/// The one manifold of a pair of simple shapes, or None.
fn contact(a: &Shape, pa: Pose, b: &Shape, pb: Pose, margin: Real) -> Option<Manifold> {
    let mut out = all(a, &pa, b, &pb, margin);
    assert!(
        out.len() <= 1,
        "simple shapes give one manifold, got {out:?}"
    );
    out.pop()
}

/// No NaN, a unit normal, at least one point, separations consistent with the points.
fn assert_sane(m: &Manifold) {
    let finite = |v: Vec3| v.x.is_finite() && v.y.is_finite() && v.z.is_finite();
    assert!(finite(m.normal), "{m:?}");
    assert!((m.normal.length() - 1.0).abs() < eps(), "{m:?}");
    assert!(!m.is_empty() && m.len() <= 4, "{m:?}");
    for p in m.points() {
        assert!(finite(p.point_a) && finite(p.point_b) && p.separation.is_finite());
        assert!(((p.point_b - p.point_a).dot(m.normal) - p.separation).abs() < eps());
    }
    for (i, p) in m.points().iter().enumerate() {
        for q in &m.points()[i + 1..] {
            assert_ne!(p.feature, q.feature, "duplicate feature ids in {m:?}");
        }
    }
}

fn close(a: Vec3, b: Vec3, tol: Real) -> bool {
    (a - b).length() <= tol
}

/// `m` has `normal` and exactly the points `(point_a, point_b)` (any order); separations
/// follow from them.
#[track_caller]
fn expect(m: &Manifold, normal: Vec3, points: &[(Vec3, Vec3)]) {
    assert!(
        close(m.normal, normal, eps()),
        "normal {} != {normal}",
        m.normal
    );
    assert_eq!(m.len(), points.len(), "points of {m:#?}");
    for &(a, b) in points {
        let p = m
            .points()
            .iter()
            .find(|p| close(p.point_a, a, eps()))
            .unwrap_or_else(|| panic!("no point_a at {a} in {m:#?}"));
        assert!(close(p.point_b, b, eps()), "point_b {} != {b}", p.point_b);
        assert!((p.separation - (b - a).dot(normal)).abs() < eps());
    }
}

fn seps(m: &Manifold) -> Vec<Real> {
    m.points().iter().map(|p| p.separation).collect()
}

// ---------------------------------------------------------------- sphere and capsule

#[test]
fn sphere_sphere_touching_within_and_beyond_margin() {
    let (a, b) = (Shape::sphere(1.0), Shape::sphere(0.5));
    let c = Vec3::new(1.0, 2.0, 3.0);
    let dir = Vec3::new(2.0, 3.0, 6.0) / 7.0;
    let pa = Pose::from_translation(c);
    let at_gap = |gap: Real| Pose::from_translation(c + dir * (1.5 + gap));

    let m = contact(&a, pa, &b, at_gap(0.0), 0.01).unwrap();
    expect(&m, dir, &[(c + dir, c + dir)]);
    assert!(m.points()[0].separation.abs() < eps());

    let m = contact(&a, pa, &b, at_gap(0.05), 0.1).unwrap();
    expect(&m, dir, &[(c + dir, c + dir * 1.05)]);
    assert!((m.points()[0].separation - 0.05).abs() < eps());

    let m = contact(&a, pa, &b, at_gap(-0.2), 0.0).unwrap();
    expect(&m, dir, &[(c + dir, c + dir * 0.8)]);
    assert!((m.points()[0].separation + 0.2).abs() < eps());

    assert!(contact(&a, pa, &b, at_gap(0.15), 0.1).is_none());
    assert!(contact(&a, pa, &b, at_gap(0.05), 0.0).is_none());
}

#[test]
fn concentric_spheres_pick_a_normal() {
    let (a, b) = (Shape::sphere(1.0), Shape::sphere(0.5));
    let pose = posed(1.0, -2.0, 0.5, Quat::from_rotation_y(0.3));
    let m = contact(&a, pose, &b, pose, 0.0).unwrap();
    assert_eq!(m.len(), 1);
    assert!((m.points()[0].separation + 1.5).abs() < eps());
}

#[test]
fn sphere_capsule_shaft_and_cap() {
    let cap = Shape::capsule(0.2, 1.0);
    let ball = Shape::sphere(0.3);
    let pc = posed(0.0, 0.0, 0.0, along_x());
    // Over the shaft: the closest axis point is straight below.
    let m = contact(&ball, at(0.4, 0.45, 0.0), &cap, pc, 0.0).unwrap();
    expect(
        &m,
        -Vec3::Y,
        &[(Vec3::new(0.4, 0.15, 0.0), Vec3::new(0.4, 0.2, 0.0))],
    );
    assert!((m.points()[0].separation + 0.05).abs() < eps());
    // Beyond the end: against the cap's centre (1, 0, 0), 0.5 away along (0.6, 0.8, 0).
    let m = contact(&ball, at(1.3, 0.4, 0.0), &cap, pc, 0.01).unwrap();
    let p = Vec3::new(1.12, 0.16, 0.0);
    expect(&m, Vec3::new(-0.6, -0.8, 0.0), &[(p, p)]);
    // The other order flips.
    let m = contact(&cap, pc, &ball, at(1.3, 0.4, 0.0), 0.01).unwrap();
    expect(&m, Vec3::new(0.6, 0.8, 0.0), &[(p, p)]);
}

#[test]
fn capsule_capsule_crossed_gives_one_point() {
    let c = Shape::capsule(0.1, 1.0);
    let m = contact(
        &c,
        posed(0.0, 0.0, 0.0, along_x()),
        &c,
        posed(0.3, 0.15, 0.0, along_z()),
        0.0,
    )
    .unwrap();
    expect(
        &m,
        Vec3::Y,
        &[(Vec3::new(0.3, 0.1, 0.0), Vec3::new(0.3, 0.05, 0.0))],
    );
    assert!((m.points()[0].separation + 0.05).abs() < eps());
}

#[test]
fn capsule_capsule_parallel_gives_two_points_spanning_the_overlap() {
    let c = Shape::capsule(0.1, 1.0);
    let m = contact(
        &c,
        posed(0.0, 0.0, 0.0, along_x()),
        &c,
        posed(0.5, 0.19, 0.0, along_x()),
        0.0,
    )
    .unwrap();
    // B spans x in [−0.5, 1.5], A [−1, 1]: the overlap is [−0.5, 1].
    expect(
        &m,
        Vec3::Y,
        &[
            (Vec3::new(-0.5, 0.1, 0.0), Vec3::new(-0.5, 0.09, 0.0)),
            (Vec3::new(1.0, 0.1, 0.0), Vec3::new(1.0, 0.09, 0.0)),
        ],
    );
    for s in seps(&m) {
        assert!((s + 0.01).abs() < eps());
    }
    // Slightly tilted (0.5°) the two points stay, with their own separations.
    let tilt = Quat::from_rotation_y(0.0087) * along_x();
    let m = contact(
        &c,
        posed(0.0, 0.0, 0.0, along_x()),
        &c,
        posed(0.5, 0.19, 0.0, tilt),
        0.01,
    )
    .unwrap();
    assert_eq!(m.len(), 2);
    // Opposite directions (anti-parallel axes) are parallel too.
    let m = contact(
        &c,
        posed(0.0, 0.0, 0.0, along_x()),
        &c,
        posed(0.5, 0.19, 0.0, Quat::from_rotation_z(PI / 2.0)),
        0.0,
    )
    .unwrap();
    assert_eq!(m.len(), 2);
}

#[test]
fn capsule_capsule_with_meeting_axes_is_finite() {
    let c = Shape::capsule(0.1, 1.0);
    // Axes cross at (0.3, 0, 0): pushed apart along the common perpendicular by 2r.
    let m = contact(
        &c,
        posed(0.0, 0.0, 0.0, along_x()),
        &c,
        posed(0.3, 0.0, 0.0, along_z()),
        0.0,
    )
    .unwrap();
    assert!(m.normal.y.abs() > 1.0 - eps());
    assert!((m.points()[0].separation + 0.2).abs() < eps());
    // Identical capsules in the same place.
    let p = posed(1.0, 2.0, 3.0, Quat::from_rotation_x(0.4));
    let m = contact(&c, p, &c, p, 0.0).unwrap();
    assert!(m.min_separation() < -0.19);
}

// ---------------------------------------------------------------- against a box

#[test]
fn sphere_box_face_edge_vertex() {
    let bx = Shape::cuboid(Vec3::new(1.0, 0.5, 2.0));
    let o = Pose::IDENTITY;
    let m = contact(&Shape::sphere(0.5), at(0.0, 0.9, 0.0), &bx, o, 0.0).unwrap();
    expect(
        &m,
        -Vec3::Y,
        &[(Vec3::new(0.0, 0.4, 0.0), Vec3::new(0.0, 0.5, 0.0))],
    );
    assert!((m.points()[0].separation + 0.1).abs() < eps());

    // Edge (x = 1, y = 0.5): centre 0.5 away along (0.3, 0.4, 0)/0.5.
    let m = contact(&Shape::sphere(0.5), at(1.3, 0.9, 0.0), &bx, o, 0.01).unwrap();
    let p = Vec3::new(1.0, 0.5, 0.0);
    expect(&m, Vec3::new(-0.6, -0.8, 0.0), &[(p, p)]);

    // Vertex (1, 0.5, 2): centre 0.7 away along (2, 3, 6)/7, radius 0.75.
    let dir = Vec3::new(2.0, 3.0, 6.0) / 7.0;
    let corner = Vec3::new(1.0, 0.5, 2.0);
    let c = corner + dir * 0.7;
    let m = contact(&Shape::sphere(0.75), Pose::from_translation(c), &bx, o, 0.0).unwrap();
    expect(&m, -dir, &[(c - dir * 0.75, corner)]);
    assert!((m.points()[0].separation + 0.05).abs() < eps());

    assert!(contact(&Shape::sphere(0.5), at(0.0, 1.2, 0.0), &bx, o, 0.1).is_none());
}

#[test]
fn sphere_inside_box_leaves_by_the_nearest_face() {
    let bx = Shape::cuboid(Vec3::new(1.0, 0.5, 2.0));
    // Depths to the faces: x 0.2, y 0.4, z 1.5: out through +x.
    let m = contact(
        &Shape::sphere(0.1),
        at(0.8, 0.1, 0.5),
        &bx,
        Pose::IDENTITY,
        0.0,
    )
    .unwrap();
    expect(
        &m,
        -Vec3::X,
        &[(Vec3::new(0.7, 0.1, 0.5), Vec3::new(1.0, 0.1, 0.5))],
    );
    assert!((m.points()[0].separation + 0.3).abs() < eps());
    // At the very centre of a cube: still one point, no NaN.
    let m = contact(
        &Shape::sphere(0.1),
        Pose::IDENTITY,
        &Shape::cuboid(Vec3::splat(0.5)),
        Pose::IDENTITY,
        0.0,
    )
    .unwrap();
    assert!((m.points()[0].separation + 0.6).abs() < eps());
}

#[test]
fn capsule_flat_on_box_gives_two_points() {
    let bx = Shape::cuboid(Vec3::new(1.0, 0.5, 1.0));
    let cap = Shape::capsule(0.1, 0.5);
    let m = contact(
        &cap,
        posed(0.2, 0.59, 0.3, along_x()),
        &bx,
        Pose::IDENTITY,
        0.0,
    )
    .unwrap();
    expect(
        &m,
        -Vec3::Y,
        &[
            (Vec3::new(-0.3, 0.49, 0.3), Vec3::new(-0.3, 0.5, 0.3)),
            (Vec3::new(0.7, 0.49, 0.3), Vec3::new(0.7, 0.5, 0.3)),
        ],
    );
    // Hanging over the edge x = 1: clipped there.
    let m = contact(
        &cap,
        posed(0.8, 0.59, 0.0, along_x()),
        &bx,
        Pose::IDENTITY,
        0.0,
    )
    .unwrap();
    expect(
        &m,
        -Vec3::Y,
        &[
            (Vec3::new(0.3, 0.49, 0.0), Vec3::new(0.3, 0.5, 0.0)),
            (Vec3::new(1.0, 0.49, 0.0), Vec3::new(1.0, 0.5, 0.0)),
        ],
    );
    // The box first: everything flips.
    let m = contact(
        &bx,
        Pose::IDENTITY,
        &cap,
        posed(0.2, 0.59, 0.3, along_x()),
        0.0,
    )
    .unwrap();
    expect(
        &m,
        Vec3::Y,
        &[
            (Vec3::new(-0.3, 0.5, 0.3), Vec3::new(-0.3, 0.49, 0.3)),
            (Vec3::new(0.7, 0.5, 0.3), Vec3::new(0.7, 0.49, 0.3)),
        ],
    );
}

#[test]
fn capsule_on_box_tilted_edge_vertex_and_degenerate() {
    let bx = Shape::cuboid(Vec3::new(1.0, 0.5, 1.0));
    let o = Pose::IDENTITY;
    // Tilted: the axis from (−0.5, 0.6, 0) to (0.5, 1.0, 0); only the low end is in.
    let axis = Vec3::new(1.0, 0.4, 0.0);
    let cap = Shape::capsule(0.08, axis.length() / 2.0);
    let tilt = Quat::from_rotation_arc(Vec3::Y, axis.normalize());
    let m = contact(&cap, posed(0.0, 0.8, 0.0, tilt), &bx, o, 0.05).unwrap();
    expect(
        &m,
        -Vec3::Y,
        &[(Vec3::new(-0.5, 0.52, 0.0), Vec3::new(-0.5, 0.5, 0.0))],
    );

    // Upright above the corner (1, 0.5, 1): the low end 0.35 away along (2, 3, 6)/7.
    let dir = Vec3::new(2.0, 3.0, 6.0) / 7.0;
    let corner = Vec3::new(1.0, 0.5, 1.0);
    let end = corner + dir * 0.35;
    let m = contact(
        &Shape::capsule(0.3, 0.5),
        Pose::from_translation(end + Vec3::new(0.0, 0.5, 0.0)),
        &bx,
        o,
        0.1,
    )
    .unwrap();
    expect(&m, -dir, &[(end - dir * 0.3, corner)]);
    assert!((m.points()[0].separation - 0.05).abs() < eps());

    // Across the edge x = 1, y = 0.5 (axis along z): one point, 0.5 from the edge line.
    let m = contact(
        &Shape::capsule(0.5, 0.5),
        posed(1.3, 0.9, 0.0, along_z()),
        &bx,
        o,
        0.01,
    )
    .unwrap();
    assert_eq!(m.len(), 1);
    assert!(close(m.normal, Vec3::new(-0.6, -0.8, 0.0), eps()));
    let p = m.points()[0];
    assert!(close(p.point_a, p.point_b, eps()));
    assert!((p.point_b.x - 1.0).abs() < eps() && (p.point_b.y - 0.5).abs() < eps());

    // A zero-length capsule is a sphere.
    let m = contact(&Shape::capsule(0.1, 0.0), at(0.3, 0.55, 0.2), &bx, o, 0.0).unwrap();
    expect(
        &m,
        -Vec3::Y,
        &[(Vec3::new(0.3, 0.45, 0.2), Vec3::new(0.3, 0.5, 0.2))],
    );
}

#[test]
fn capsule_through_box_leaves_by_least_penetration() {
    // The axis runs through the box at y = 0.3, beyond both x faces: out through +y,
    // depth 0.5 − 0.3 plus the radius, two points where the top face ends.
    let bx = Shape::cuboid(Vec3::new(1.0, 0.5, 1.0));
    let m = contact(
        &Shape::capsule(0.1, 2.0),
        posed(0.0, 0.3, 0.0, along_x()),
        &bx,
        Pose::IDENTITY,
        0.0,
    )
    .unwrap();
    expect(
        &m,
        -Vec3::Y,
        &[
            (Vec3::new(-1.0, 0.2, 0.0), Vec3::new(-1.0, 0.5, 0.0)),
            (Vec3::new(1.0, 0.2, 0.0), Vec3::new(1.0, 0.5, 0.0)),
        ],
    );
    for s in seps(&m) {
        assert!((s + 0.3).abs() < eps());
    }
}

// ---------------------------------------------------------------- box against box

/// The ground box of the box tests: top face at y = 0.5, 4 m wide.
fn ground() -> Shape {
    Shape::cuboid(Vec3::new(2.0, 0.5, 2.0))
}

#[test]
fn box_resting_on_box_gives_its_four_corners() {
    let cube = Shape::cuboid(Vec3::splat(0.5));
    let m = contact(&ground(), Pose::IDENTITY, &cube, at(0.3, 0.99, -0.2), 0.02).unwrap();
    let mut expected = Vec::new();
    for (x, z) in [(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)] {
        let (x, z) = (x + 0.3, z - 0.2);
        expected.push((Vec3::new(x, 0.5, z), Vec3::new(x, 0.49, z)));
    }
    expect(&m, Vec3::Y, &expected);
    for s in seps(&m) {
        assert!((s + 0.01).abs() < eps());
    }
    // Speculative: 3 cm above with a 5 cm margin, the same corners at +0.03.
    let m = contact(&ground(), Pose::IDENTITY, &cube, at(0.0, 1.03, 0.0), 0.05).unwrap();
    assert_eq!(m.len(), 4);
    for s in seps(&m) {
        assert!((s - 0.03).abs() < eps());
    }
    assert!(contact(&ground(), Pose::IDENTITY, &cube, at(0.0, 1.06, 0.0), 0.05).is_none());
}

#[test]
fn rotated_box_resting_on_box() {
    let cube = Shape::cuboid(Vec3::splat(0.5));
    let q = Quat::from_rotation_y(PI / 6.0);
    let centre = Vec3::new(0.0, 0.99, 0.0);
    let m = contact(&ground(), Pose::IDENTITY, &cube, Pose::new(centre, q), 0.02).unwrap();
    let (c, s) = ((PI / 6.0).cos(), (PI / 6.0).sin());
    let mut expected = Vec::new();
    for (x, z) in [(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)] {
        // Rotation about y: (x, z) -> (x cos + z sin, −x sin + z cos).
        let (wx, wz) = (x * c + z * s, -x * s + z * c);
        expected.push((Vec3::new(wx, 0.5, wz), Vec3::new(wx, 0.49, wz)));
    }
    expect(&m, Vec3::Y, &expected);
    // Upper box first: the reference face is now its own bottom, the points the same.
    let m = contact(&cube, Pose::new(centre, q), &ground(), Pose::IDENTITY, 0.02).unwrap();
    let swapped: Vec<_> = expected.iter().map(|&(a, b)| (b, a)).collect();
    expect(&m, -Vec3::Y, &swapped);
}

#[test]
fn box_tipped_on_an_edge_gives_the_edge_ends() {
    // Rotated 30° about z, its lowest edge (local x = −0.5, y = −0.5, along z) is at
    // y = centre − (0.5 sin 30° + 0.5 cos 30°).
    let cube = Shape::cuboid(Vec3::splat(0.5));
    let drop = 0.5 * (PI / 6.0).sin() + 0.5 * (PI / 6.0).cos();
    let pose = posed(0.0, 0.5 + drop - 0.01, 0.0, Quat::from_rotation_z(PI / 6.0));
    let m = contact(&ground(), Pose::IDENTITY, &cube, pose, 0.02).unwrap();
    let x = pose.transform_point(Vec3::new(-0.5, -0.5, 0.0)).x;
    expect(
        &m,
        Vec3::Y,
        &[
            (Vec3::new(x, 0.5, -0.5), Vec3::new(x, 0.49, -0.5)),
            (Vec3::new(x, 0.5, 0.5), Vec3::new(x, 0.49, 0.5)),
        ],
    );
}

#[test]
fn crossed_boxes_touch_edge_to_edge() {
    // A turned 45° about z has a top edge along z at y = √2/2; B turned 45° about x has a
    // bottom edge along x at y_B − √2/2. Shifted by (0.1, ·, 0.2) the edges cross at
    // x = 0 (A's edge) and z = 0.2 (B's edge).
    let cube = Shape::cuboid(Vec3::splat(0.5));
    let h = sqrt(2.0) / 2.0;
    let yb = 2.0 * h - 0.01;
    let pa = posed(0.0, 0.0, 0.0, Quat::from_rotation_z(PI / 4.0));
    let pb = posed(0.1, yb, 0.2, Quat::from_rotation_x(PI / 4.0));
    let m = contact(&cube, pa, &cube, pb, 0.02).unwrap();
    expect(
        &m,
        Vec3::Y,
        &[(Vec3::new(0.0, h, 0.2), Vec3::new(0.0, yb - h, 0.2))],
    );
    assert!((m.points()[0].separation + 0.01).abs() < eps());
    // Apart by 0.01 with a margin of 0.02: the same edges, a positive separation.
    let pb = posed(0.1, 2.0 * h + 0.01, 0.2, Quat::from_rotation_x(PI / 4.0));
    let m = contact(&cube, pa, &cube, pb, 0.02).unwrap();
    assert_eq!(m.len(), 1);
    assert!((m.points()[0].separation - 0.01).abs() < eps());
}

#[test]
fn box_on_its_corner_gives_one_point() {
    // The diagonal (−1, −1, −1) turned straight down: the lowest corner is √3/2 below the
    // centre, its three neighbours 1/√3 higher.
    let cube = Shape::cuboid(Vec3::splat(0.5));
    let q = Quat::from_rotation_arc(Vec3::splat(-1.0).normalize(), -Vec3::Y);
    let y = 0.5 + sqrt(3.0) / 2.0 - 0.02;
    let m = contact(
        &ground(),
        Pose::IDENTITY,
        &cube,
        posed(0.2, y, 0.1, q),
        0.05,
    )
    .unwrap();
    expect(
        &m,
        Vec3::Y,
        &[(Vec3::new(0.2, 0.5, 0.1), Vec3::new(0.2, 0.48, 0.1))],
    );
}

#[test]
fn deep_box_penetration_picks_the_shallowest_axis() {
    // Overlaps: x 2 − 1.2 = 0.8, y 2 − 0.5 = 1.5, z everything: out along x. B's −x face
    // (x = 0.2, y in [−0.5, 1.5], z in [−0.8, 0.8]) clipped to A's +x face (|y|, |z| ≤ 1).
    let a = Shape::cuboid(Vec3::splat(1.0));
    let b = Shape::cuboid(Vec3::new(1.0, 1.0, 0.8));
    let m = contact(&a, Pose::IDENTITY, &b, at(1.2, 0.5, 0.0), 0.0).unwrap();
    let mut expected = Vec::new();
    for (y, z) in [(-0.5, -0.8), (-0.5, 0.8), (1.0, -0.8), (1.0, 0.8)] {
        expected.push((Vec3::new(1.0, y, z), Vec3::new(0.2, y, z)));
    }
    expect(&m, Vec3::X, &expected);
    for s in seps(&m) {
        assert!((s + 0.8).abs() < eps());
    }
    // Concentric identical boxes: some axis, depth 2 (a full width), finite.
    let m = contact(&a, Pose::IDENTITY, &a, Pose::IDENTITY, 0.0).unwrap();
    assert!((m.min_separation() + 2.0).abs() < eps());
}

// ---------------------------------------------------------------- on a plane

fn floor() -> Shape {
    Shape::plane(Vec3::Y, 0.0)
}

#[test]
fn box_resting_and_tilted_on_a_plane() {
    let bx = Shape::cuboid(Vec3::new(0.5, 0.25, 1.0));
    let m = contact(&bx, at(1.0, 0.24, 2.0), &floor(), Pose::IDENTITY, 0.02).unwrap();
    let mut expected = Vec::new();
    for (x, z) in [(0.5, 1.0), (1.5, 1.0), (0.5, 3.0), (1.5, 3.0)] {
        expected.push((Vec3::new(x, -0.01, z), Vec3::new(x, 0.0, z)));
    }
    expect(&m, -Vec3::Y, &expected);

    // On a corner: only the lowest vertex, √3/2 below the centre of a unit cube.
    let cube = Shape::cuboid(Vec3::splat(0.5));
    let q = Quat::from_rotation_arc(Vec3::splat(-1.0).normalize(), -Vec3::Y);
    let pose = posed(0.3, sqrt(3.0) / 2.0 - 0.02, 0.0, q);
    let m = contact(&cube, pose, &floor(), Pose::IDENTITY, 0.1).unwrap();
    expect(
        &m,
        -Vec3::Y,
        &[(Vec3::new(0.3, -0.02, 0.0), Vec3::new(0.3, 0.0, 0.0))],
    );

    // The plane first: flipped.
    let m = contact(&floor(), Pose::IDENTITY, &cube, pose, 0.1).unwrap();
    expect(
        &m,
        Vec3::Y,
        &[(Vec3::new(0.3, 0.0, 0.0), Vec3::new(0.3, -0.02, 0.0))],
    );
}

#[test]
fn plane_of_a_posed_body() {
    // Local z ≤ 0.5 in a body turned so that local z is world y and raised by 1: world
    // y ≤ 1.5.
    let plane = Shape::plane(Vec3::Z, 0.5);
    let pose = posed(7.0, 1.0, -3.0, Quat::from_rotation_x(-PI / 2.0));
    let m = contact(&Shape::sphere(0.5), at(3.0, 1.9, -2.0), &plane, pose, 0.0).unwrap();
    expect(
        &m,
        -Vec3::Y,
        &[(Vec3::new(3.0, 1.4, -2.0), Vec3::new(3.0, 1.5, -2.0))],
    );
    assert!((m.points()[0].separation + 0.1).abs() < eps());
    // A non-unit normal is the same half-space.
    let scaled = Shape::plane(Vec3::Z * 2.0, 1.0);
    let m2 = contact(&Shape::sphere(0.5), at(3.0, 1.9, -2.0), &scaled, pose, 0.0).unwrap();
    assert!((m2.points()[0].separation + 0.1).abs() < eps());
}

#[test]
fn round_shapes_on_a_plane() {
    let m = contact(
        &Shape::sphere(0.5),
        at(1.0, 0.45, 2.0),
        &floor(),
        Pose::IDENTITY,
        0.0,
    );
    expect(
        &m.unwrap(),
        -Vec3::Y,
        &[(Vec3::new(1.0, -0.05, 2.0), Vec3::new(1.0, 0.0, 2.0))],
    );
    assert!(contact(
        &Shape::sphere(0.5),
        at(0.0, 0.65, 0.0),
        &floor(),
        Pose::IDENTITY,
        0.1
    )
    .is_none());

    // Capsule lying: both ends.
    let cap = Shape::capsule(0.2, 1.0);
    let m = contact(
        &cap,
        posed(0.0, 0.19, 0.0, along_x()),
        &floor(),
        Pose::IDENTITY,
        0.0,
    );
    expect(
        &m.unwrap(),
        -Vec3::Y,
        &[
            (Vec3::new(-1.0, -0.01, 0.0), Vec3::new(-1.0, 0.0, 0.0)),
            (Vec3::new(1.0, -0.01, 0.0), Vec3::new(1.0, 0.0, 0.0)),
        ],
    );
    // Standing: the lower end.
    let m = contact(&cap, at(0.0, 1.19, 0.0), &floor(), Pose::IDENTITY, 0.05);
    expect(
        &m.unwrap(),
        -Vec3::Y,
        &[(Vec3::new(0.0, -0.01, 0.0), Vec3::new(0.0, 0.0, 0.0))],
    );
    // Zero length: one point, not two identical ones.
    let m = contact(
        &Shape::capsule(0.2, 0.0),
        at(0.0, 0.19, 0.0),
        &floor(),
        Pose::IDENTITY,
        0.0,
    );
    assert_eq!(m.unwrap().len(), 1);
}

#[test]
fn cylinder_standing_lying_and_tilted_on_a_plane() {
    let cyl = Shape::cylinder(0.5, 1.0);
    // Standing on its cap: four rim points.
    let m = contact(&cyl, at(0.0, 0.99, 0.0), &floor(), Pose::IDENTITY, 0.02).unwrap();
    let mut expected = Vec::new();
    for (x, z) in [(0.5, 0.0), (0.0, 0.5), (-0.5, 0.0), (0.0, -0.5)] {
        expected.push((Vec3::new(x, -0.01, z), Vec3::new(x, 0.0, z)));
    }
    expect(&m, -Vec3::Y, &expected);

    // On its side (axis along z, rolled by 0.3 about it): the lowest line's two ends.
    let q = along_z() * Quat::from_rotation_y(0.3);
    let m = contact(
        &cyl,
        posed(0.0, 0.49, 0.0, q),
        &floor(),
        Pose::IDENTITY,
        0.02,
    )
    .unwrap();
    expect(
        &m,
        -Vec3::Y,
        &[
            (Vec3::new(0.0, -0.01, -1.0), Vec3::new(0.0, 0.0, -1.0)),
            (Vec3::new(0.0, -0.01, 1.0), Vec3::new(0.0, 0.0, 1.0)),
        ],
    );

    // Tilted by 0.3 about z: the lowest point of the lower rim, at
    // c − u h − R (cos 0.3, sin 0.3, 0) with axis u = (−sin 0.3, cos 0.3, 0).
    let (s, c) = (Real::sin(0.3), Real::cos(0.3));
    let u = Vec3::new(-s, c, 0.0);
    let low_offset = -u * 1.0 - Vec3::new(c, s, 0.0) * 0.5;
    let centre = Vec3::new(0.0, -low_offset.y - 0.01, 0.0);
    let pose = Pose::new(centre, Quat::from_rotation_z(0.3));
    let m = contact(&cyl, pose, &floor(), Pose::IDENTITY, 0.02).unwrap();
    let low = centre + low_offset;
    expect(&m, -Vec3::Y, &[(low, Vec3::new(low.x, 0.0, low.z))]);
}

#[test]
fn hulls_on_a_plane() {
    // A square pyramid on its base: the four base corners.
    let pyramid = Shape::convex_hull(&[
        Vec3::new(-1.0, 0.0, -1.0),
        Vec3::new(1.0, 0.0, -1.0),
        Vec3::new(1.0, 0.0, 1.0),
        Vec3::new(-1.0, 0.0, 1.0),
        Vec3::new(0.0, 2.0, 0.0),
    ])
    .unwrap();
    let m = contact(
        &pyramid,
        at(0.0, -0.01, 0.0),
        &floor(),
        Pose::IDENTITY,
        0.02,
    )
    .unwrap();
    let mut expected = Vec::new();
    for (x, z) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
        expected.push((Vec3::new(x, -0.01, z), Vec3::new(x, 0.0, z)));
    }
    expect(&m, -Vec3::Y, &expected);
    // Upside down on its apex: one point.
    let m = contact(
        &pyramid,
        posed(0.0, 1.99, 0.0, Quat::from_rotation_x(PI)),
        &floor(),
        Pose::IDENTITY,
        0.02,
    )
    .unwrap();
    expect(
        &m,
        -Vec3::Y,
        &[(Vec3::new(0.0, -0.01, 0.0), Vec3::new(0.0, 0.0, 0.0))],
    );
    // A hexagonal prism on a hexagon: four of the six base corners, spread out.
    let mut pts = Vec::new();
    for k in 0..6 {
        let a = k as Real * PI / 3.0;
        pts.push(Vec3::new(a.cos(), -0.5, a.sin()));
        pts.push(Vec3::new(a.cos(), 0.5, a.sin()));
    }
    let prism = Shape::convex_hull(&pts).unwrap();
    let m = contact(&prism, at(0.0, 0.49, 0.0), &floor(), Pose::IDENTITY, 0.02).unwrap();
    assert_eq!(m.len(), 4);
    for p in m.points() {
        assert!((p.point_a.y + 0.01).abs() < eps() && p.point_b.y.abs() < eps());
        assert!((Vec3::new(p.point_a.x, 0.0, p.point_a.z).length() - 1.0).abs() < eps());
    }
    // Spread: the four span more than a triangle's worth of the hexagon.
    let a: Vec<Vec3> = m.points().iter().map(|p| p.point_a).collect();
    let area =
        (a[1] - a[0]).cross(a[2] - a[0]).length() + (a[3] - a[0]).cross(a[2] - a[0]).length();
    assert!(area > 1.5, "{area}");
}

// ---------------------------------------------------------------- properties

/// Pairs with unambiguous contacts: each point's features are decided with room to spare,
/// so a rigid motion (which only adds rounding) cannot change them.
fn configurations() -> Vec<(&'static str, Shape, Pose, Shape, Pose, Real)> {
    let cube = Shape::cuboid(Vec3::splat(0.5));
    let bx = Shape::cuboid(Vec3::new(1.0, 0.5, 1.0));
    let cap = Shape::capsule(0.1, 1.0);
    let h = sqrt(2.0) / 2.0;
    let corner_down = Quat::from_rotation_arc(Vec3::splat(-1.0).normalize(), -Vec3::Y);
    let dir = Vec3::new(2.0, 3.0, 6.0) / 7.0;
    let pyramid = Shape::convex_hull(&[
        Vec3::new(-1.0, 0.0, -1.0),
        Vec3::new(1.0, 0.0, -1.0),
        Vec3::new(1.0, 0.0, 1.0),
        Vec3::new(-1.0, 0.0, 1.0),
        Vec3::new(0.0, 2.0, 0.0),
    ])
    .unwrap();
    let o = Pose::IDENTITY;
    vec![
        (
            "sphere-sphere",
            Shape::sphere(1.0),
            o,
            Shape::sphere(0.5),
            Pose::from_translation(dir * 1.45),
            0.0,
        ),
        (
            "sphere-capsule",
            Shape::sphere(0.3),
            at(1.3, 0.35, 0.1),
            Shape::capsule(0.2, 1.0),
            posed(0.0, 0.0, 0.0, along_x()),
            0.0,
        ),
        (
            "capsules crossed",
            cap.clone(),
            posed(0.0, 0.0, 0.0, along_x()),
            cap.clone(),
            posed(0.3, 0.15, 0.0, along_z()),
            0.0,
        ),
        (
            "capsules parallel",
            cap.clone(),
            posed(0.0, 0.0, 0.0, along_x()),
            cap.clone(),
            posed(0.5, 0.19, 0.0, along_x()),
            0.0,
        ),
        (
            "sphere-box face",
            Shape::sphere(0.5),
            at(0.1, 0.9, 0.2),
            bx.clone(),
            o,
            0.0,
        ),
        (
            "sphere-box edge",
            Shape::sphere(0.5),
            at(1.3, 0.8, 0.2),
            bx.clone(),
            o,
            0.0,
        ),
        (
            "sphere-box vertex",
            Shape::sphere(0.75),
            Pose::from_translation(Vec3::new(1.0, 0.5, 1.0) + dir * 0.7),
            bx.clone(),
            o,
            0.0,
        ),
        (
            "sphere in box",
            Shape::sphere(0.1),
            at(0.8, 0.1, 0.3),
            bx.clone(),
            o,
            0.0,
        ),
        (
            "capsule flat on box",
            Shape::capsule(0.1, 0.5),
            posed(0.2, 0.59, 0.3, along_x()),
            bx.clone(),
            o,
            0.0,
        ),
        (
            "capsule over box edge",
            Shape::capsule(0.1, 0.5),
            posed(0.8, 0.59, 0.0, along_x()),
            bx.clone(),
            o,
            0.0,
        ),
        (
            "capsule over box corner",
            Shape::capsule(0.3, 0.5),
            Pose::from_translation(Vec3::new(1.0, 1.0, 1.0) + dir * 0.35),
            bx.clone(),
            o,
            0.1,
        ),
        (
            "capsule through box",
            Shape::capsule(0.1, 2.0),
            posed(0.0, 0.3, 0.0, along_x()),
            bx.clone(),
            o,
            0.0,
        ),
        (
            "box on box",
            ground(),
            o,
            cube.clone(),
            at(0.3, 0.99, -0.2),
            0.02,
        ),
        (
            "turned box on box",
            ground(),
            o,
            cube.clone(),
            posed(0.0, 0.99, 0.0, Quat::from_rotation_y(0.5)),
            0.02,
        ),
        (
            "boxes edge to edge",
            cube.clone(),
            posed(0.0, 0.0, 0.0, Quat::from_rotation_z(PI / 4.0)),
            cube.clone(),
            posed(0.1, 2.0 * h - 0.01, 0.2, Quat::from_rotation_x(PI / 4.0)),
            0.02,
        ),
        (
            "box on its corner",
            ground(),
            o,
            cube.clone(),
            posed(0.2, 0.5 + sqrt(3.0) / 2.0 - 0.02, 0.1, corner_down),
            0.05,
        ),
        (
            "boxes deep",
            Shape::cuboid(Vec3::splat(1.0)),
            o,
            Shape::cuboid(Vec3::new(1.0, 1.0, 0.8)),
            at(1.2, 0.5, 0.0),
            0.0,
        ),
        (
            "box on plane",
            Shape::cuboid(Vec3::new(0.5, 0.25, 1.0)),
            at(1.0, 0.24, 2.0),
            floor(),
            o,
            0.02,
        ),
        (
            "box corner on plane",
            cube.clone(),
            posed(0.3, sqrt(3.0) / 2.0 - 0.02, 0.0, corner_down),
            floor(),
            o,
            0.1,
        ),
        (
            "capsule on plane",
            cap.clone(),
            posed(0.0, 0.09, 0.0, along_x()),
            floor(),
            o,
            0.0,
        ),
        (
            "cylinder standing",
            Shape::cylinder(0.5, 1.0),
            at(0.0, 0.99, 0.0),
            floor(),
            o,
            0.02,
        ),
        (
            "cylinder lying",
            Shape::cylinder(0.5, 1.0),
            posed(0.0, 0.49, 0.0, along_z() * Quat::from_rotation_y(0.3)),
            floor(),
            o,
            0.02,
        ),
        (
            "pyramid on plane",
            pyramid,
            at(0.0, -0.01, 0.0),
            floor(),
            o,
            0.02,
        ),
    ]
}

/// A deterministic stream of numbers in [−1, 1) (64-bit LCG, Knuth's constants).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> Real {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0) as Real
    }
    fn motion(&mut self) -> Pose {
        let q = loop {
            let q = Quat::from_xyzw(self.next(), self.next(), self.next(), self.next());
            if q.length() > 0.2 {
                break q.normalize();
            }
        };
        Pose::new(Vec3::new(self.next(), self.next(), self.next()) * 5.0, q)
    }
}

fn find(m: &Manifold, feature: u32) -> ContactPoint {
    *m.points()
        .iter()
        .find(|p| p.feature == feature)
        .unwrap_or_else(|| panic!("no feature {feature:#x} in {m:#?}"))
}

#[test]
fn manifolds_move_with_a_rigid_motion_of_both_shapes() {
    let mut rng = Rng(7);
    let tol = 3.0 * eps();
    for (name, a, pa, b, pb, margin) in configurations() {
        let m = contact(&a, pa, &b, pb, margin).unwrap_or_else(|| panic!("{name}: no contact"));
        for _ in 0..8 {
            let t = rng.motion();
            let moved = contact(&a, t.mul(&pa), &b, t.mul(&pb), margin)
                .unwrap_or_else(|| panic!("{name}: no contact after moving"));
            assert!(
                close(moved.normal, t.transform_vector(m.normal), tol),
                "{name}: normal"
            );
            assert_eq!(moved.len(), m.len(), "{name}");
            for p in m.points() {
                let q = find(&moved, p.feature);
                assert!(
                    close(q.point_a, t.transform_point(p.point_a), tol),
                    "{name}: point_a"
                );
                assert!(
                    close(q.point_b, t.transform_point(p.point_b), tol),
                    "{name}: point_b"
                );
                assert!(
                    (q.separation - p.separation).abs() < tol,
                    "{name}: separation"
                );
            }
        }
    }
}

#[test]
fn swapping_the_pair_flips_the_normal_and_swaps_the_points() {
    for (name, a, pa, b, pb, margin) in configurations() {
        let ab = contact(&a, pa, &b, pb, margin).unwrap();
        let ba = contact(&b, pb, &a, pa, margin).unwrap_or_else(|| panic!("{name}"));
        assert!(close(ba.normal, -ab.normal, eps()), "{name}: normal");
        assert_eq!(ab.len(), ba.len(), "{name}");
        for p in ab.points() {
            let q = ba
                .points()
                .iter()
                .find(|q| close(q.point_b, p.point_a, eps()))
                .unwrap_or_else(|| panic!("{name}: {p:?} not in {ba:#?}"));
            assert!(close(q.point_a, p.point_b, eps()), "{name}");
            assert!((q.separation - p.separation).abs() < eps(), "{name}");
        }
        // Where the table swaps the pair (different kinds), the ids swap exactly too.
        if std::mem::discriminant(&a) != std::mem::discriminant(&b) {
            for p in ab.points() {
                find(&ba, swap_feature(p.feature));
            }
        }
    }
}

#[test]
fn feature_ids_persist_under_small_perturbations() {
    let mut rng = Rng(11);
    for (name, a, pa, b, pb, margin) in configurations() {
        let ids = |m: &Manifold| {
            let mut v: Vec<u32> = m.points().iter().map(|p| p.feature).collect();
            v.sort_unstable();
            v
        };
        let base = ids(&contact(&a, pa, &b, pb, margin).unwrap());
        for _ in 0..4 {
            // A jiggle of a resting body: 1e-5 m and about 1e-4 rad.
            let axis = Vec3::new(rng.next(), rng.next(), rng.next()).normalize_or(Vec3::X);
            let nudge = Pose::new(
                Vec3::new(rng.next(), rng.next(), rng.next()) * 1e-5,
                Quat::from_axis_angle(axis, 1e-4),
            );
            // Nudge A about its own centre.
            let moved = Pose::new(pa.position + nudge.position, nudge.rotation * pa.rotation);
            let m = contact(&a, moved, &b, pb, margin).unwrap_or_else(|| panic!("{name}"));
            assert_eq!(ids(&m), base, "{name}");
        }
    }
}

#[test]
fn degenerate_inputs_never_give_nan() {
    let shapes = [
        Shape::sphere(0.5),
        Shape::capsule(0.3, 0.0),
        Shape::capsule(0.3, 1.0),
        Shape::cuboid(Vec3::new(0.5, 0.2, 0.7)),
    ];
    let poses = [
        Pose::IDENTITY,
        posed(0.0, 0.0, 0.0, Quat::from_rotation_x(PI / 2.0)),
        posed(
            0.0,
            0.0,
            0.0,
            Quat::from_rotation_arc(Vec3::Y, Vec3::ONE.normalize()),
        ),
        at(0.0, 1.0, 0.0),
        at(0.0, 0.0, 0.7),
        at(0.5, 0.2, 0.7),
    ];
    for a in &shapes {
        for b in &shapes {
            for pa in &poses {
                for pb in &poses {
                    // `all` checks every manifold for NaN, unit normals and consistency.
                    all(a, pa, b, pb, 0.1);
                }
            }
        }
        for pa in &poses {
            all(a, pa, &floor(), &Pose::IDENTITY, 0.1);
            all(&floor(), &Pose::IDENTITY, a, pa, 0.1);
        }
    }
    for pa in &poses {
        all(
            &Shape::cylinder(0.5, 0.5),
            pa,
            &floor(),
            &Pose::IDENTITY,
            0.1,
        );
    }
    // Coincident centres report the full overlap.
    let m = contact(&shapes[1], Pose::IDENTITY, &shapes[2], Pose::IDENTITY, 0.0).unwrap();
    assert!((m.min_separation() + 0.6).abs() < eps());
}

// ---------------------------------------------------------------- against brute force

/// Minimum of a convex function on [0, 1] by ternary search: slow, but independent of
/// the closed forms under test.
fn minimise(f: impl Fn(Real) -> Real) -> Real {
    let (mut lo, mut hi): (Real, Real) = (0.0, 1.0);
    for _ in 0..60 {
        let (m1, m2) = (lo + (hi - lo) / 3.0, hi - (hi - lo) / 3.0);
        if f(m1) < f(m2) {
            hi = m2;
        } else {
            lo = m1;
        }
    }
    f(0.5 * (lo + hi)).min(f(0.0)).min(f(1.0))
}

/// Distance from `p` to the solid box `he` at `pose`.
fn point_box(p: Vec3, he: Vec3, pose: &Pose) -> Real {
    let l = pose.inverse_transform_point(p);
    (l - l.max(-he).min(he)).length()
}

/// Distance between segments (p is convex along the first, so the search is exact).
fn segment_segment(p0: Vec3, p1: Vec3, q0: Vec3, q1: Vec3) -> Real {
    let d = q1 - q0;
    minimise(|s| {
        let p = p0.lerp(p1, s);
        let t = if d.length_squared() > 0.0 {
            ((p - q0).dot(d) / d.length_squared()).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (q0 + d * t - p).length()
    })
}

fn box_edges(he: Vec3, pose: &Pose) -> Vec<(Vec3, Vec3)> {
    let corner = |v: usize| {
        let s = |bit: usize, h: Real| if v & bit != 0 { h } else { -h };
        pose.transform_point(Vec3::new(s(1, he.x), s(2, he.y), s(4, he.z)))
    };
    let mut edges = Vec::new();
    for a in 0..8usize {
        for bit in [1usize, 2, 4] {
            if a & bit == 0 {
                edges.push((corner(a), corner(a | bit)));
            }
        }
    }
    edges
}

/// Does segment p0–p1 meet the solid box (slab clipping)?
fn segment_meets_box(p0: Vec3, p1: Vec3, he: Vec3, pose: &Pose) -> bool {
    let (a, b) = (
        pose.inverse_transform_point(p0),
        pose.inverse_transform_point(p1),
    );
    let d = b - a;
    let (mut lo, mut hi): (Real, Real) = (0.0, 1.0);
    for i in 0..3 {
        if d[i] == 0.0 {
            if a[i].abs() > he[i] {
                return false;
            }
        } else {
            let (t0, t1) = ((-he[i] - a[i]) / d[i], (he[i] - a[i]) / d[i]);
            lo = lo.max(t0.min(t1));
            hi = hi.min(t0.max(t1));
        }
    }
    lo <= hi
}

/// Checks a manifold against the exact distance `d` of the pair (negative: overlapping,
/// not measured): nothing when d ≥ margin; otherwise a manifold whose closest point is
/// never nearer than the shapes are and, when apart, not farther by more than the
/// face-preference tolerance (5% of the gap plus 1e-4 of the size) allows.
fn check_against(out: &[Manifold], d: Option<Real>, margin: Real, size: Real, what: &str) {
    match d {
        Some(d) if d >= margin => assert!(out.is_empty(), "{what}: d = {d}: {out:?}"),
        Some(d) => {
            let m = out
                .first()
                .unwrap_or_else(|| panic!("{what}: d = {d}, no contact"));
            let ms = m.min_separation();
            assert!(ms >= d - eps() * 10.0, "{what}: {ms} < {d}");
            assert!(
                ms <= d + 0.05 * d.abs() + 2e-4 * size + eps() * 10.0,
                "{what}: {ms} vs {d}"
            );
        }
        None => {
            let m = out
                .first()
                .unwrap_or_else(|| panic!("{what}: overlap, no contact"));
            assert!(m.min_separation() <= eps() * 10.0, "{what}: {m:?}");
        }
    }
}

#[test]
fn random_box_pairs_against_brute_force() {
    let mut rng = Rng(3);
    let margin = 0.1;
    let mut checked = 0;
    for _ in 0..3000 {
        let mut size =
            || Vec3::new(rng.next(), rng.next(), rng.next()).abs() * 0.8 + Vec3::splat(0.2);
        let (ha, hb) = (size(), size());
        let pa = Pose::new(Vec3::ZERO, rng.motion().rotation);
        let pb = rng.motion();
        let pb = Pose::new(pb.position * 0.4, pb.rotation);
        let (ea, eb) = (box_edges(ha, &pa), box_edges(hb, &pb));
        let overlap = ea.iter().any(|&(p, q)| segment_meets_box(p, q, hb, &pb))
            || eb.iter().any(|&(p, q)| segment_meets_box(p, q, ha, &pa));
        let d = (!overlap).then(|| {
            let mut d = Real::INFINITY;
            for &(p, q) in &ea {
                d = d.min(point_box(p, hb, &pb)).min(point_box(q, hb, &pb));
                for &(u, v) in &eb {
                    d = d.min(segment_segment(p, q, u, v));
                }
            }
            for &(p, q) in &eb {
                d = d.min(point_box(p, ha, &pa)).min(point_box(q, ha, &pa));
            }
            d
        });
        let out = all(&Shape::cuboid(ha), &pa, &Shape::cuboid(hb), &pb, margin);
        check_against(
            &out,
            d,
            margin,
            ha.max_element().min(hb.max_element()),
            "boxes",
        );
        checked += (d.unwrap_or(0.0) < margin) as usize;
    }
    assert!(checked > 500, "{checked}");
}

#[test]
fn random_capsule_pairs_against_brute_force() {
    let mut rng = Rng(9);
    let margin = 0.1;
    for i in 0..3000 {
        let r = 0.05 + 0.3 * rng.next().abs();
        let h = if i % 5 == 0 { 0.0 } else { rng.next().abs() };
        let pa = rng.motion();
        let pa = Pose::new(pa.position * 0.4, pa.rotation);
        let (p0, p1) = (
            pa.transform_point(Vec3::new(0.0, -h, 0.0)),
            pa.transform_point(Vec3::new(0.0, h, 0.0)),
        );
        // Against a box.
        let he = Vec3::new(rng.next(), rng.next(), rng.next()).abs() * 0.8 + Vec3::splat(0.2);
        let pb = Pose::new(Vec3::ZERO, rng.motion().rotation);
        let core = minimise(|t| point_box(p0.lerp(p1, t), he, &pb));
        // A core distance within rounding of zero may be an overlap: only checked as one.
        let d = (core > 100.0 * eps()).then_some(core - r);
        let out = all(&Shape::capsule(r, h), &pa, &Shape::cuboid(he), &pb, margin);
        check_against(&out, d, margin, he.max_element(), "capsule-box");

        // Against a capsule, half the time nearly parallel to it.
        let rb = 0.05 + 0.3 * rng.next().abs();
        let hb = if i % 7 == 0 { 0.0 } else { rng.next().abs() };
        let qb = if i % 2 == 0 {
            pa.rotation * Quat::from_rotation_x(0.01 * rng.next())
        } else {
            rng.motion().rotation
        };
        let pb = Pose::new(
            pa.position + Vec3::new(rng.next(), rng.next(), rng.next()),
            qb,
        );
        let (q0, q1) = (
            pb.transform_point(Vec3::new(0.0, -hb, 0.0)),
            pb.transform_point(Vec3::new(0.0, hb, 0.0)),
        );
        let d = segment_segment(p0, p1, q0, q1) - r - rb;
        let out = all(
            &Shape::capsule(r, h),
            &pa,
            &Shape::capsule(rb, hb),
            &pb,
            margin,
        );
        check_against(&out, Some(d), margin, r + rb, "capsules");
    }
}

#[test]
fn random_convexes_on_planes_reach_their_lowest_point() {
    let mut rng = Rng(17);
    let margin = 0.1;
    let hull = Shape::convex_hull(&[
        Vec3::new(-1.0, 0.0, -1.0),
        Vec3::new(1.0, 0.0, -1.0),
        Vec3::new(1.0, 0.0, 1.0),
        Vec3::new(-1.0, 0.0, 1.0),
        Vec3::new(0.0, 2.0, 0.0),
    ])
    .unwrap();
    let shapes = [
        Shape::sphere(0.4),
        Shape::capsule(0.3, 0.7),
        Shape::cuboid(Vec3::new(0.3, 0.5, 0.8)),
        Shape::cylinder(0.5, 0.6),
        hull,
    ];
    for i in 0..4000 {
        let shape = &shapes[i % shapes.len()];
        let convex = tumble::Convex::from_shape(shape).unwrap();
        let plane_pose = rng.motion();
        let normal = Vec3::new(rng.next(), rng.next(), rng.next()).normalize_or(Vec3::Y);
        let offset = rng.next();
        let n = plane_pose.transform_vector(normal);
        let pose = rng.motion();
        // The exact lowest point: the support point along −N.
        let low = pose.transform_point(convex.support(pose.inverse_transform_vector(-n)));
        // Put the shape's lowest point at a random height in [−0.2, 0.2].
        let d = offset + n.dot(plane_pose.position);
        let height = 0.2 * rng.next();
        let pose = Pose::new(
            pose.position + n * (height - (n.dot(low) - d)),
            pose.rotation,
        );
        let plane = Shape::plane(normal, offset);
        let out = all(shape, &pose, &plane, &plane_pose, margin);
        // Random tilts are never within 1e-4 of upright, where a cylinder's fixed rim points
        // would stand slightly above its lowest point: exact for every shape.
        check_against(&out, Some(height), margin, 1.0, shape.kind_name());
        if let Some(m) = out.first() {
            assert!(close(m.normal, -n, eps()));
            assert!((m.min_separation() - height).abs() < 10.0 * eps());
        }
    }
}
