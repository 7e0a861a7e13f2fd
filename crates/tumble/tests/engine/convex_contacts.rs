//! The general convex–convex narrow phase (GJK, EPA/SAT, clipping) and the convex time of
//! impact, against closed forms and against the dedicated pair routines.

use tumble::narrow_phase::{closest_points, collide, Manifold};
use tumble::query::{cast_shape, time_of_impact, Sweep};
use tumble::{Convex, Pose, Quat, Real, Shape, Vec3};

/// `f64_tol` in the default build, `f32_tol` in the single-precision one.
fn tol(f64_tol: f64, f32_tol: f64) -> Real {
    if std::mem::size_of::<Real>() == 8 {
        f64_tol as Real
    } else {
        f32_tol as Real
    }
}

fn close(a: Real, b: Real, eps: Real) -> bool {
    (a - b).abs() <= eps
}

fn vclose(a: Vec3, b: Vec3, eps: Real) -> bool {
    (a - b).length() <= eps
}

fn cube_points(h: Vec3) -> Vec<Vec3> {
    (0..8)
        .map(|i| {
            Vec3::new(
                if i & 1 != 0 { h.x } else { -h.x },
                if i & 2 != 0 { h.y } else { -h.y },
                if i & 4 != 0 { h.z } else { -h.z },
            )
        })
        .collect()
}

fn cube_hull(h: Vec3) -> Shape {
    Shape::convex_hull(&cube_points(h)).unwrap()
}

fn at(x: Real, y: Real, z: Real) -> Pose {
    Pose::from_translation(Vec3::new(x, y, z))
}

fn contacts(a: &Shape, pa: &Pose, b: &Shape, pb: &Pose, margin: Real) -> Vec<Manifold> {
    let mut out = Vec::new();
    collide(a, pa, b, pb, margin, &mut out);
    out
}

/// The single manifold of a pair of simple shapes.
fn manifold(a: &Shape, pa: &Pose, b: &Shape, pb: &Pose, margin: Real) -> Manifold {
    let out = contacts(a, pa, b, pb, margin);
    assert_eq!(out.len(), 1, "expected one manifold, got {out:?}");
    out[0]
}

/// A deterministic pseudo-random sequence in [−1, 1) (64-bit LCG, top bits).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> Real {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0) as Real
    }
    fn vec(&mut self) -> Vec3 {
        Vec3::new(self.next(), self.next(), self.next())
    }
    fn rotation(&mut self) -> Quat {
        let axis = (self.vec() + Vec3::new(0.0, 0.0, 1e-3)).normalize();
        Quat::from_axis_angle(axis, 3.0 * self.next())
    }
    fn pose(&mut self, spread: Real) -> Pose {
        Pose::new(self.vec() * spread, self.rotation())
    }
}

/// The points of a manifold sorted by position, for order-free comparison.
fn sorted_points(m: &Manifold) -> Vec<(Vec3, Vec3, Real)> {
    let mut p: Vec<_> = m
        .points()
        .iter()
        .map(|c| (c.point_a, c.point_b, c.separation))
        .collect();
    p.sort_by(|x, y| {
        let k = |v: Vec3| (v.x * 1e3 + v.y) * 1e3 + v.z;
        k(x.0).partial_cmp(&k(y.0)).unwrap()
    });
    p
}

fn assert_same_manifold(a: &Manifold, b: &Manifold, eps: Real) {
    assert!(vclose(a.normal, b.normal, eps), "normals {a:?} / {b:?}");
    assert_eq!(a.len(), b.len(), "point counts {a:?} / {b:?}");
    for (p, q) in sorted_points(a).iter().zip(sorted_points(b).iter()) {
        assert!(vclose(p.0, q.0, eps), "point_a {a:?} / {b:?}");
        assert!(vclose(p.1, q.1, eps), "point_b {a:?} / {b:?}");
        assert!(close(p.2, q.2, eps), "separation {a:?} / {b:?}");
    }
}

fn assert_finite(m: &Manifold) {
    assert!(m.normal.is_finite() && close(m.normal.length(), 1.0, tol(1e-9, 1e-4)));
    for p in m.points() {
        assert!(p.point_a.is_finite() && p.point_b.is_finite() && p.separation.is_finite());
    }
}

// ---------------------------------------------------------------------------------------
// GJK distances against closed forms.

#[test]
fn gjk_sphere_sphere() {
    let eps = tol(1e-9, 1e-5);
    let (ra, rb) = (0.3, 0.45);
    let a = Convex::Sphere { radius: ra };
    let b = Convex::Sphere { radius: rb };
    let (ca, cb) = (Vec3::new(0.2, -1.0, 0.5), Vec3::new(1.7, 0.4, -0.3));
    let cp = closest_points(&a, &at(ca.x, ca.y, ca.z), &b, &at(cb.x, cb.y, cb.z));
    let d = (cb - ca).length();
    let n = (cb - ca) / d;
    assert!(close(cp.distance, d - ra - rb, eps), "{cp:?}");
    assert!(vclose(cp.normal, n, eps));
    assert!(vclose(cp.point_a, ca + n * ra, eps));
    assert!(vclose(cp.point_b, cb - n * rb, eps));
    // Overlapping spheres (cores apart): the signed distance is still exact.
    let cp = closest_points(&a, &at(0.0, 0.0, 0.0), &b, &at(0.5, 0.0, 0.0));
    assert!(close(cp.distance, 0.5 - 0.75, eps), "{cp:?}");
}

#[test]
fn gjk_boxes_axis_aligned() {
    let eps = tol(1e-9, 1e-5);
    let a = Convex::Box {
        half_extents: Vec3::new(1.0, 0.5, 0.25),
    };
    let b = Convex::Box {
        half_extents: Vec3::new(0.3, 0.2, 0.1),
    };
    // Face to face along x: the gap between the faces.
    let cp = closest_points(&a, &Pose::IDENTITY, &b, &at(1.8, 0.1, -0.05));
    assert!(close(cp.distance, 0.5, eps), "{cp:?}");
    assert!(vclose(cp.normal, Vec3::X, eps));
    assert!(close(cp.point_a.x, 1.0, eps) && close(cp.point_b.x, 1.5, eps));
    // Corner to corner: the per-axis gaps combine by Pythagoras.
    let c = Vec3::new(1.0 + 0.3 + 0.3, 0.5 + 0.2 + 0.4, -(0.25 + 0.1 + 1.2));
    let cp = closest_points(&a, &Pose::IDENTITY, &b, &at(c.x, c.y, c.z));
    let gap = Vec3::new(0.3, 0.4, -1.2);
    assert!(close(cp.distance, gap.length(), eps), "{cp:?}");
    assert!(vclose(cp.point_a, Vec3::new(1.0, 0.5, -0.25), eps));
    assert!(vclose(cp.point_b, Vec3::new(1.0, 0.5, -0.25) + gap, eps));
    // Edge to edge (overlapping in z only).
    let cp = closest_points(&a, &Pose::IDENTITY, &b, &at(1.5, 1.0, 0.0));
    assert!(close(cp.distance, (0.2 as Real).hypot(0.3), eps), "{cp:?}");
}

#[test]
fn gjk_point_triangle() {
    let eps = tol(1e-9, 1e-5);
    let tri = Convex::Triangle([
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(2.0, 0.0, 0.0),
        Vec3::new(0.0, 2.0, 0.0),
    ]);
    let point = Convex::Sphere { radius: 0.0 };
    let pose = Pose::new(
        Vec3::new(0.3, -0.2, 1.0),
        Quat::from_axis_angle(Vec3::new(1.0, 2.0, 3.0).normalize(), 0.7),
    );
    let world = |p: Vec3| pose.transform_point(p);
    // (point, closest point on the triangle): face interior, edge, vertex regions.
    let cases = [
        (Vec3::new(0.5, 0.5, 0.8), Vec3::new(0.5, 0.5, 0.0)),
        (Vec3::new(1.5, 1.5, -0.3), Vec3::new(1.0, 1.0, 0.0)),
        (Vec3::new(1.0, -1.0, 0.4), Vec3::new(1.0, 0.0, 0.0)),
        (Vec3::new(-1.0, -0.5, 0.2), Vec3::new(0.0, 0.0, 0.0)),
        (Vec3::new(3.0, -0.5, 0.0), Vec3::new(2.0, 0.0, 0.0)),
    ];
    for (p, q) in cases {
        let cp = closest_points(&tri, &pose, &point, &Pose::from_translation(world(p)));
        assert!(close(cp.distance, (p - q).length(), eps), "{p}: {cp:?}");
        assert!(vclose(cp.point_a, world(q), eps), "{p}: {cp:?}");
        assert!(vclose(cp.point_b, world(p), eps));
    }
}

#[test]
fn gjk_segment_segment() {
    let eps = tol(1e-9, 1e-5);
    // Capsules of zero radius are segments along their local y.
    let seg = |h: Real| Convex::Capsule {
        radius: 0.0,
        half_height: h,
    };
    let along_x = Quat::from_rotation_z(-std::f64::consts::FRAC_PI_2 as Real);
    // Skew and perpendicular, crossing at their middles: the common perpendicular.
    let cp = closest_points(
        &seg(1.0),
        &Pose::IDENTITY,
        &seg(2.0),
        &Pose::new(Vec3::new(0.0, 0.3, 1.5), along_x),
    );
    assert!(close(cp.distance, 1.5, eps), "{cp:?}");
    assert!(vclose(cp.point_a, Vec3::new(0.0, 0.3, 0.0), eps));
    assert!(vclose(cp.point_b, Vec3::new(0.0, 0.3, 1.5), eps));
    // B beyond A's end: the end point of A to B's interior.
    let cp = closest_points(
        &seg(1.0),
        &Pose::IDENTITY,
        &seg(2.0),
        &Pose::new(Vec3::new(0.5, 1.8, 0.6), along_x),
    );
    assert!(close(cp.distance, (0.8 as Real).hypot(0.6), eps), "{cp:?}");
    assert!(vclose(cp.point_a, Vec3::new(0.0, 1.0, 0.0), eps));
    // Parallel and offset: the perpendicular distance.
    let cp = closest_points(&seg(1.0), &Pose::IDENTITY, &seg(0.5), &at(0.6, 0.2, 0.8));
    assert!(close(cp.distance, 1.0, eps), "{cp:?}");
}

// ---------------------------------------------------------------------------------------
// Manifolds: hulls against the dedicated box routines and closed forms.

#[test]
fn hull_on_hull_matches_box_on_box() {
    let eps = tol(1e-9, 2e-5);
    let (h1, h2) = (Vec3::new(1.0, 0.5, 1.0), Vec3::new(0.3, 0.2, 0.4));
    let (hull1, hull2) = (cube_hull(h1), cube_hull(h2));
    let (box1, box2) = (Shape::cuboid(h1), Shape::cuboid(h2));
    let yaw = Quat::from_rotation_y(0.3);
    for depth in [0.001, 0.0, -0.004] {
        let pa = Pose::IDENTITY;
        let pb = Pose::new(Vec3::new(0.2, 0.5 + 0.2 - depth, -0.1), yaw);
        let m = manifold(&hull1, &pa, &hull2, &pb, 0.01);
        assert_eq!(m.len(), 4, "{m:?}");
        assert!(vclose(m.normal, Vec3::Y, eps));
        for p in m.points() {
            assert!(close(p.separation, -depth, eps), "{m:?}");
            assert!(close(p.point_a.y, 0.5, eps));
            // Each point is a bottom corner of the small box.
            let local = pb.inverse_transform_point(p.point_b);
            assert!(vclose(local.abs(), h2, eps), "{local}");
        }
        let reference = manifold(&box1, &pa, &box2, &pb, 0.01);
        assert_same_manifold(&m, &reference, eps);
        // The same under a common motion, both ways.
        let motion = Pose::new(Vec3::new(3.0, -2.0, 1.0), Quat::from_rotation_x(0.4));
        let (qa, qb) = (motion.mul(&pa), motion.mul(&pb));
        assert_same_manifold(
            &manifold(&hull1, &qa, &hull2, &qb, 0.01),
            &manifold(&box1, &qa, &box2, &qb, 0.01),
            eps,
        );
    }
}

#[test]
fn hull_against_box_deep_penetration() {
    let eps = tol(1e-9, 2e-5);
    let h = Vec3::ONE;
    let hull = cube_hull(h);
    let bx = Shape::cuboid(h);
    // Overlap 0.8 along y, 1.7 along x, 1.9 along z: y is the way out.
    let pb = at(0.3, 1.2, 0.1);
    for (a, b) in [(&hull, &hull), (&hull, &bx), (&bx, &hull)] {
        let m = manifold(a, &Pose::IDENTITY, b, &pb, 0.0);
        assert!(vclose(m.normal, Vec3::Y, eps), "{m:?}");
        assert!(close(m.min_separation(), -0.8, eps), "{m:?}");
        assert_eq!(m.len(), 4);
    }
    // Tilted: the same answer as the dedicated box–box test.
    let pb = Pose::new(Vec3::new(0.3, 1.5, 0.1), Quat::from_rotation_z(0.2));
    let m = manifold(&hull, &Pose::IDENTITY, &hull, &pb, 0.0);
    let reference = manifold(&bx, &Pose::IDENTITY, &bx, &pb, 0.0);
    assert!(vclose(m.normal, reference.normal, eps));
    assert!(close(m.min_separation(), reference.min_separation(), eps));
}

/// The exact sphere–box contact: the closest point of the box to the centre (or, inside,
/// the nearest face).
fn sphere_box_closed_form(h: Vec3, c: Vec3, r: Real) -> (Vec3, Real) {
    let q = c.clamp(-h, h);
    if q != c {
        let d = (c - q).length();
        return ((q - c) / d, d - r); // normal from the sphere to the box
    }
    let gaps = h - c.abs();
    let axis = if gaps.x <= gaps.y && gaps.x <= gaps.z {
        0
    } else if gaps.y <= gaps.z {
        1
    } else {
        2
    };
    let mut n = Vec3::ZERO;
    n[axis] = if c[axis] < 0.0 { -1.0 } else { 1.0 };
    (-n, -gaps[axis] - r)
}

#[test]
fn sphere_on_hull_matches_sphere_on_box() {
    let eps = tol(1e-9, 2e-5);
    let h = Vec3::new(1.0, 0.5, 0.75);
    let (hull, bx) = (cube_hull(h), Shape::cuboid(h));
    let r = 0.3;
    let sphere = Shape::sphere(r);
    let pose_box = Pose::new(Vec3::new(0.5, -1.0, 2.0), Quat::from_rotation_y(0.6));
    let centres = [
        Vec3::new(0.2, 0.79, -0.1),  // above a face, shallow
        Vec3::new(1.1, 0.6, 0.2),    // beside an edge
        Vec3::new(1.15, 0.62, 0.85), // near a corner
        Vec3::new(0.9, 0.1, 0.3),    // centre inside, nearest face +x
        Vec3::new(0.0, 0.0, 0.7),    // centre inside, nearest face +z
    ];
    for c in centres {
        let ps = Pose::from_translation(pose_box.transform_point(c));
        let m = manifold(&sphere, &ps, &hull, &pose_box, 0.05);
        assert_eq!(m.len(), 1);
        let (n_local, sep) = sphere_box_closed_form(h, c, r);
        assert!(close(m.points()[0].separation, sep, eps), "{c}: {m:?}");
        assert!(
            vclose(m.normal, pose_box.transform_vector(n_local), eps),
            "{c}: {m:?}"
        );
        let reference = manifold(&sphere, &ps, &bx, &pose_box, 0.05);
        assert_same_manifold(&m, &reference, eps);
    }
}

#[test]
fn cylinder_standing_on_box() {
    let eps = tol(1e-9, 2e-5);
    let (r, hh) = (0.3, 0.5);
    let cyl = Shape::cylinder(r, hh);
    let floor = Shape::cuboid(Vec3::new(2.0, 0.5, 2.0));
    let centre = Vec3::new(0.4, 0.5 + hh - 0.002, -0.3);
    let pc = Pose::new(centre, Quat::from_rotation_y(0.25));
    for margin in [0.0, 0.01] {
        let m = manifold(&floor, &Pose::IDENTITY, &cyl, &pc, margin);
        assert!(vclose(m.normal, Vec3::Y, eps), "{m:?}");
        assert_eq!(m.len(), 4);
        for p in m.points() {
            assert!(close(p.separation, -0.002, eps), "{m:?}");
            assert!(close(p.point_a.y, 0.5, eps));
            assert!(close(p.point_b.y, 0.498, eps));
            let radial = Vec3::new(p.point_b.x - centre.x, 0.0, p.point_b.z - centre.z);
            assert!(close(radial.length(), r, eps), "off the rim: {p:?}");
        }
        // The other order: the same contact seen from the cylinder.
        let flipped = manifold(&cyl, &pc, &floor, &Pose::IDENTITY, margin);
        assert_same_manifold(&flipped.swapped(), &m, eps);
    }
    // A speculative gap is reported with its positive separation.
    let up = Pose::new(centre + Vec3::new(0.0, 0.012, 0.0), pc.rotation);
    let m = manifold(&floor, &Pose::IDENTITY, &cyl, &up, 0.02);
    assert_eq!(m.len(), 4);
    for p in m.points() {
        assert!(close(p.separation, 0.01, eps), "{m:?}");
    }
    assert!(contacts(&floor, &Pose::IDENTITY, &cyl, &up, 0.005).is_empty());
    // Tilted 3° so that the lowest rim point lies midway between two corners of the cap
    // octagon (local angle 22.5°): it is still reported exactly. The lowest rim point of a
    // disc tilted by θ lies r·sin θ below its centre, which lies h·cos θ below the
    // cylinder's.
    let theta = (3.0 as Real).to_radians();
    let alpha = (112.5 as Real).to_radians();
    let tilt = Quat::from_axis_angle(Vec3::new(alpha.cos(), 0.0, alpha.sin()), theta);
    let y = 0.5 - 0.002 + hh * theta.cos() + r * theta.sin();
    let tilted = Pose::new(Vec3::new(0.4, y, -0.3), pc.rotation * tilt);
    let m = manifold(&floor, &Pose::IDENTITY, &cyl, &tilted, 0.0);
    assert!(vclose(m.normal, Vec3::Y, eps), "{m:?}");
    assert!(close(m.min_separation(), -0.002, eps), "{m:?}");
    for p in m.points() {
        let local = tilted.inverse_transform_point(p.point_b);
        assert!(close(local.y, -hh, eps) && close(local.x.hypot(local.z), r, eps));
    }
}

#[test]
fn cylinder_lying_on_box() {
    let eps = tol(1e-9, 2e-5);
    let (r, hh) = (0.25, 0.6);
    let cyl = Shape::cylinder(r, hh);
    let floor = Shape::cuboid(Vec3::new(2.0, 0.5, 2.0));
    // Axis along x; a small roll about it must not matter.
    let rot =
        Quat::from_rotation_x(0.37) * Quat::from_rotation_z(std::f64::consts::FRAC_PI_2 as Real);
    let pc = Pose::new(Vec3::new(0.1, 0.5 + r - 0.003, 0.2), rot);
    let m = manifold(&cyl, &pc, &floor, &Pose::IDENTITY, 0.0);
    assert!(vclose(m.normal, -Vec3::Y, eps), "{m:?}");
    assert_eq!(m.len(), 2, "{m:?}");
    let mut xs: Vec<Real> = m.points().iter().map(|p| p.point_a.x).collect();
    xs.sort_by(|a, b| a.partial_cmp(b).unwrap());
    assert!(
        close(xs[0], 0.1 - hh, eps) && close(xs[1], 0.1 + hh, eps),
        "{m:?}"
    );
    for p in m.points() {
        assert!(close(p.separation, -0.003, eps));
        assert!(close(p.point_a.z, 0.2, eps));
        assert!(close(p.point_b.y, 0.5, eps));
    }
}

#[test]
fn capsule_lying_on_hull() {
    let eps = tol(1e-9, 2e-5);
    let hull = cube_hull(Vec3::new(2.0, 0.5, 2.0));
    let cap = Shape::capsule(0.2, 0.7);
    let rot = Quat::from_rotation_x(std::f64::consts::FRAC_PI_2 as Real);
    let pc = Pose::new(Vec3::new(0.3, 0.5 + 0.2 - 0.001, 0.0), rot);
    let m = manifold(&hull, &Pose::IDENTITY, &cap, &pc, 0.0);
    assert!(vclose(m.normal, Vec3::Y, eps));
    assert_eq!(m.len(), 2, "{m:?}");
    for p in m.points() {
        assert!(close(p.separation, -0.001, eps));
        assert!(close(p.point_b.z.abs(), 0.7, eps));
    }
}

#[test]
fn cylinder_deep_in_box_by_epa() {
    let eps = tol(1e-6, 1e-4);
    let cyl = Shape::cylinder(0.3, 0.5);
    let floor = Shape::cuboid(Vec3::new(2.0, 0.5, 2.0));
    // Sunk 0.3 into the top face, tilted 2° so one rim point is deepest.
    let tilt = 2.0 * std::f64::consts::PI as Real / 180.0;
    let rot = Quat::from_rotation_z(tilt);
    let bottom = 0.5 * tilt.cos() + 0.3 * tilt.sin();
    let pc = Pose::new(Vec3::new(0.0, 0.5 - 0.3 + bottom, 0.0), rot);
    let m = manifold(&floor, &Pose::IDENTITY, &cyl, &pc, 0.0);
    assert!(vclose(m.normal, Vec3::Y, eps), "{m:?}");
    assert!(close(m.min_separation(), -0.3, eps), "{m:?}");
    assert!(m.len() >= 3, "{m:?}");
}

#[test]
fn cylinder_against_cylinder_side_by_side() {
    // EPA on two curved sides: the depth converges fast, the normal as its square root.
    let (eps, eps_n) = (tol(1e-9, 1e-4), tol(1e-5, 5e-3));
    let cyl = Shape::cylinder(0.4, 1.0);
    let pb = at(0.79, 0.3, 0.0);
    let m = manifold(&cyl, &Pose::IDENTITY, &cyl, &pb, 0.0);
    assert!(vclose(m.normal, Vec3::X, eps_n), "{m:?}");
    assert_eq!(m.len(), 2, "{m:?}");
    for p in m.points() {
        assert!(close(p.separation, -0.01, eps), "{m:?}");
        assert!(close(p.point_a.x, 0.4, eps));
        assert!(close(p.point_a.z, 0.0, eps_n));
    }
    let mut ys: Vec<Real> = m.points().iter().map(|p| p.point_a.y).collect();
    ys.sort_by(|a, b| a.partial_cmp(b).unwrap());
    assert!(close(ys[0], -0.7, eps) && close(ys[1], 1.0, eps), "{m:?}");
}

// ---------------------------------------------------------------------------------------
// Symmetries and robustness.

fn pair_shapes() -> Vec<(Shape, Shape)> {
    vec![
        (
            cube_hull(Vec3::new(0.5, 0.4, 0.3)),
            cube_hull(Vec3::new(0.3, 0.6, 0.2)),
        ),
        (
            Shape::cuboid(Vec3::new(0.5, 0.4, 0.3)),
            Shape::cylinder(0.3, 0.4),
        ),
        (Shape::sphere(0.4), cube_hull(Vec3::new(0.5, 0.4, 0.3))),
        (
            Shape::capsule(0.2, 0.4),
            cube_hull(Vec3::new(0.5, 0.4, 0.3)),
        ),
        (Shape::cylinder(0.3, 0.5), Shape::cylinder(0.2, 0.3)),
        (Shape::sphere(0.3), Shape::cylinder(0.3, 0.4)),
        (Shape::capsule(0.2, 0.3), Shape::cylinder(0.3, 0.4)),
    ]
}

/// Random poses for the pair, then B moved along the contact normal until the shapes
/// overlap by about `depth` (a gap when negative): the configurations contacts live in.
fn near_contact(rng: &mut Lcg, a: &Shape, b: &Shape, depth: Real) -> (Pose, Pose) {
    let (ca, cb) = (
        Convex::from_shape(a).unwrap(),
        Convex::from_shape(b).unwrap(),
    );
    let pa = rng.pose(0.3);
    let mut pb = rng.pose(0.3);
    for _ in 0..3 {
        let cp = closest_points(&ca, &pa, &cb, &pb);
        pb.position += cp.normal * (-cp.distance - depth);
    }
    (pa, pb)
}

/// Whether the pair has a curved surface, whose normals GJK/EPA find to about the square
/// root of their distance tolerance rather than exactly (rim against rim: ~1e-6 rad, 1e-3
/// in f32).
fn curved(a: &Shape, b: &Shape) -> bool {
    matches!(a, Shape::Cylinder { .. }) || matches!(b, Shape::Cylinder { .. })
}

#[test]
fn invariant_under_a_common_rigid_motion() {
    let mut rng = Lcg(7);
    let mut checked = 0;
    for (a, b) in pair_shapes() {
        let eps = if curved(&a, &b) {
            tol(1e-5, 5e-3)
        } else {
            tol(1e-9, 1e-4)
        };
        for k in 0..20 {
            let depth = 0.002 * (k as Real - 10.0);
            let (pa, pb) = near_contact(&mut rng, &a, &b, depth);
            let m = manifold(&a, &pa, &b, &pb, 0.05);
            let motion = rng.pose(5.0);
            let moved = manifold(&a, &motion.mul(&pa), &b, &motion.mul(&pb), 0.05);
            assert!(vclose(motion.transform_vector(m.normal), moved.normal, eps));
            assert!(close(m.min_separation(), moved.min_separation(), eps));
            assert!(close(m.min_separation(), -depth, tol(1e-6, 1e-3)), "{m:?}");
            for p in m.points() {
                // Same features wherever the rounding allows a choice; the same point.
                let q = moved
                    .points()
                    .iter()
                    .find(|q| q.feature == p.feature)
                    .unwrap_or_else(|| {
                        panic!("{} {}: {m:?}\n{moved:?}", a.kind_name(), b.kind_name())
                    });
                assert!(vclose(motion.transform_point(p.point_a), q.point_a, eps));
                assert!(vclose(motion.transform_point(p.point_b), q.point_b, eps));
                assert!(close(p.separation, q.separation, eps));
            }
            checked += 1;
        }
    }
    assert_eq!(checked, 140);
}

#[test]
fn swapping_the_pair_flips_the_normal() {
    let mut rng = Lcg(11);
    for (a, b) in pair_shapes() {
        let eps = if curved(&a, &b) {
            tol(1e-5, 5e-3)
        } else {
            tol(1e-9, 1e-4)
        };
        for k in 0..20 {
            let depth = 0.002 * (k as Real - 10.0);
            let (pa, pb) = near_contact(&mut rng, &a, &b, depth);
            let ab = manifold(&a, &pa, &b, &pb, 0.05);
            let ba = manifold(&b, &pb, &a, &pa, 0.05);
            assert_finite(&ab);
            assert!(vclose(ab.normal, -ba.normal, eps), "{ab:?}\n{ba:?}");
            assert!(close(ab.min_separation(), ba.min_separation(), eps));
            assert_eq!(ab.len(), ba.len());
        }
    }
}

#[test]
fn feature_ids_survive_small_perturbations() {
    let ids = |a: &Shape, pa: &Pose, b: &Shape, pb: &Pose| {
        let mut v: Vec<u32> = manifold(a, pa, b, pb, 0.01)
            .points()
            .iter()
            .map(|p| p.feature)
            .collect();
        v.sort_unstable();
        v
    };
    let nudge = |p: &Pose, k: Real| {
        Pose::new(
            p.position + Vec3::new(1e-5, -2e-5, 1.5e-5) * k,
            (Quat::from_rotation_x(1e-5 * k) * p.rotation).normalize(),
        )
    };
    let hull = cube_hull(Vec3::new(1.0, 0.5, 1.0));
    let small = cube_hull(Vec3::new(0.3, 0.2, 0.4));
    let pb = Pose::new(Vec3::new(0.2, 0.699, -0.1), Quat::from_rotation_y(0.3));
    let base = ids(&hull, &Pose::IDENTITY, &small, &pb);
    assert_eq!(base.len(), 4);
    for k in [-1.0, 1.0, 3.0] {
        assert_eq!(ids(&hull, &Pose::IDENTITY, &small, &nudge(&pb, k)), base);
    }
    let floor = Shape::cuboid(Vec3::new(2.0, 0.5, 2.0));
    let cyl = Shape::cylinder(0.3, 0.5);
    let pc = Pose::new(Vec3::new(0.4, 0.999, -0.3), Quat::from_rotation_y(0.25));
    let base = ids(&floor, &Pose::IDENTITY, &cyl, &pc);
    for k in [-1.0, 1.0, 3.0] {
        assert_eq!(ids(&floor, &Pose::IDENTITY, &cyl, &nudge(&pc, k)), base);
    }
}

#[test]
fn coincident_shapes_give_finite_contacts() {
    let shapes = [
        Shape::cuboid(Vec3::new(0.5, 0.4, 0.3)),
        cube_hull(Vec3::new(0.5, 0.4, 0.3)),
        Shape::sphere(0.4),
        Shape::capsule(0.2, 0.4),
        Shape::cylinder(0.3, 0.4),
    ];
    let poses = [
        Pose::IDENTITY,
        Pose::new(Vec3::new(1.0, 2.0, 3.0), Quat::from_rotation_y(0.7)),
    ];
    for a in &shapes {
        for b in &shapes {
            for p in &poses {
                let m = contacts(a, p, b, p, 0.0);
                assert_eq!(m.len(), 1, "{} {}", a.kind_name(), b.kind_name());
                assert_finite(&m[0]);
                assert!(m[0].min_separation() < 0.0);
                let (ca, cb) = (
                    Convex::from_shape(a).unwrap(),
                    Convex::from_shape(b).unwrap(),
                );
                let cp = closest_points(&ca, p, &cb, p);
                assert!(cp.distance < 0.0 && cp.normal.is_finite() && cp.point_a.is_finite());
            }
        }
    }
}

/// The penetration depth by brute force: min over unit d of h_A(d) + h_B(−d) (the overlap
/// of the projections). That function has sharp local minima at the flat faces of A − B,
/// where pattern search stalls, so the starts include the directions of those faces as well
/// as a Fibonacci sphere, and the best 200 are refined.
fn brute_force_depth(a: &Convex, pa: &Pose, b: &Convex, pb: &Pose) -> Real {
    let h = |c: &Convex, p: &Pose, d: Vec3| {
        p.transform_point(c.support(p.inverse_transform_vector(d)))
            .dot(d)
    };
    let overlap = |d: Vec3| {
        let d = d.normalize();
        h(a, pa, d) + h(b, pb, -d)
    };
    let n = 4000;
    let golden = std::f64::consts::PI as Real * (3.0 - (5.0 as Real).sqrt());
    let mut starts: Vec<Vec3> = (0..n)
        .map(|i| {
            let y = 1.0 - 2.0 * (i as Real + 0.5) / n as Real;
            let r = (1.0 - y * y).sqrt();
            let phi = golden * i as Real;
            Vec3::new(r * phi.cos(), y, r * phi.sin())
        })
        .collect();
    // Flat faces of A − B lie along the shapes' axes (faces, caps) and their cross products
    // (a cylinder's side line against an edge or another side line).
    let axes = |p: &Pose| [Vec3::X, Vec3::Y, Vec3::Z].map(|e| p.transform_vector(e));
    for (u, v) in axes(pa).into_iter().zip(axes(pb)) {
        starts.extend([u, -u, v, -v]);
    }
    for u in axes(pa) {
        for v in axes(pb) {
            let c = u.cross(v).normalize_or_zero();
            if c != Vec3::ZERO {
                starts.extend([c, -c]);
            }
        }
    }
    let mut scored: Vec<(Real, Vec3)> = starts.iter().map(|&d| (overlap(d), d)).collect();
    scored.sort_by(|x, y| x.0.partial_cmp(&y.0).unwrap());
    let mut best = Real::INFINITY;
    for &(mut o, mut d) in scored.iter().take(200) {
        let mut step = 0.05;
        let mut budget = 400;
        while step > 1e-8 && budget > 0 {
            budget -= 1;
            let (u, v) = d.any_orthonormal_pair();
            let mut moved = false;
            for t in [u, -u, v, -v] {
                let e = (d + t * step).normalize();
                let oe = overlap(e);
                if oe < o {
                    (o, d, moved) = (oe, e, true);
                }
            }
            if !moved {
                step *= 0.5;
            }
        }
        best = best.min(o);
    }
    best
}

#[test]
fn penetration_depth_matches_brute_force() {
    let mut rng = Lcg(23);
    let h = Vec3::new(0.5, 0.4, 0.3);
    let hull_shape = cube_hull(h);
    let shapes = [
        Shape::cylinder(0.3, 0.5),
        Shape::cuboid(h),
        hull_shape,
        Shape::capsule(0.2, 0.4),
        Shape::sphere(0.35),
    ];
    for (i, a) in shapes.iter().enumerate() {
        for b in &shapes[..=i] {
            let (ca, cb) = (
                Convex::from_shape(a).unwrap(),
                Convex::from_shape(b).unwrap(),
            );
            for _ in 0..6 {
                let (pa, pb) = (rng.pose(0.25), rng.pose(0.25));
                let cp = closest_points(&ca, &pa, &cb, &pb);
                let depth = brute_force_depth(&ca, &pa, &cb, &pb);
                if depth <= 0.0 {
                    continue;
                }
                let what = format!("{} {}", a.kind_name(), b.kind_name());
                assert!(
                    close(-cp.distance, depth, tol(1e-5, 1e-3)),
                    "{what}: {cp:?} vs {depth}"
                );
                // The manifold of the general routine (the dedicated box, sphere and capsule
                // pairs choose their own axis biases) reports the same depth.
                let general = [a, b]
                    .iter()
                    .any(|s| matches!(s, Shape::ConvexHull(_) | Shape::Cylinder { .. }));
                if !general {
                    continue;
                }
                let m = manifold(a, &pa, b, &pb, 0.0);
                assert!(
                    close(m.min_separation(), cp.distance, tol(1e-5, 1e-3)),
                    "{what}: {m:?}\n{cp:?}"
                );
            }
        }
    }
}

#[test]
fn random_pairs_are_finite_and_within_the_margin() {
    let mut rng = Lcg(5);
    // Ordinary and degenerate proportions: a plate, a disc, a needle, a zero-length capsule.
    let shapes = [
        Shape::cylinder(0.3, 0.5),
        Shape::cylinder(2.0, 0.01),
        Shape::cylinder(0.01, 2.0),
        Shape::cuboid(Vec3::new(0.5, 0.1, 0.3)),
        Shape::cuboid(Vec3::new(0.5, 0.001, 0.3)),
        Shape::convex_hull(&[
            Vec3::new(0.0, 0.6, 0.0),
            Vec3::new(0.5, -0.2, 0.1),
            Vec3::new(-0.4, -0.2, 0.3),
            Vec3::new(-0.1, -0.3, -0.5),
            Vec3::new(0.2, 0.1, 0.4),
            Vec3::new(0.3, 0.3, -0.3),
        ])
        .unwrap(),
        Shape::capsule(0.1, 0.6),
        Shape::capsule(0.1, 0.0),
        Shape::sphere(0.2),
    ];
    let mut touching = 0;
    for a in &shapes {
        for b in &shapes {
            for k in 0..40 {
                // Near the origin and 10 km away; apart, touching, deep and coincident.
                let far = if k % 5 == 0 { 1e4 } else { 0.0 };
                let base = Vec3::new(far, -far, 0.5 * far);
                let spread = [0.0, 0.05, 0.3, 1.0][k % 4];
                let pa = rng.pose(spread);
                let pa = Pose::new(pa.position + base, pa.rotation);
                let pb = if k % 7 == 0 {
                    pa
                } else {
                    let p = rng.pose(spread);
                    Pose::new(p.position + base, p.rotation)
                };
                let margin = 0.02;
                for m in contacts(a, &pa, b, &pb, margin) {
                    assert_finite(&m);
                    assert!(!m.is_empty() && m.len() <= 4);
                    for p in m.points() {
                        assert!(p.separation <= margin + tol(1e-9, 1e-4));
                    }
                    touching += 1;
                }
                let (ca, cb) = (
                    Convex::from_shape(a).unwrap(),
                    Convex::from_shape(b).unwrap(),
                );
                let cp = closest_points(&ca, &pa, &cb, &pb);
                assert!(cp.distance.is_finite() && cp.normal.is_finite());
                assert!(cp.point_a.is_finite() && cp.point_b.is_finite());
                assert!(close(cp.normal.length(), 1.0, tol(1e-9, 1e-4)));
            }
        }
    }
    assert!(touching > 1000, "{touching}");
}

// ---------------------------------------------------------------------------------------
// Time of impact and shape casts.

fn still(pose: Pose) -> Sweep {
    Sweep {
        start: pose,
        translation: Vec3::ZERO,
        rotation: Vec3::ZERO,
        local_center: Vec3::ZERO,
    }
}

#[test]
fn spheres_head_on_hit_at_the_analytic_time() {
    let a = Convex::Sphere { radius: 0.5 };
    let b = Convex::Sphere { radius: 0.25 };
    let sa = Sweep {
        translation: Vec3::new(6.0, 0.0, 0.0),
        ..still(at(-3.0, 0.0, 0.0))
    };
    let sb = Sweep {
        translation: Vec3::new(-2.0, 0.0, 0.0),
        ..still(at(3.0, 0.0, 0.0))
    };
    // Gap 6 − 0.75 closing at 8 per unit t.
    for target in [0.0, 0.05] {
        let hit = time_of_impact(&a, &sa, &b, &sb, target).unwrap();
        let exact = (6.0 - 0.75 - target) / 8.0;
        assert!(hit.t <= exact + tol(1e-9, 1e-5), "{hit:?} vs {exact}");
        assert!(
            close(hit.t, exact, tol(1e-6, 1e-5) + 0.05 * target / 8.0),
            "{hit:?}"
        );
        assert!(vclose(hit.normal, Vec3::X, tol(1e-9, 1e-5)));
    }
    // Moving apart, or too short a sweep: no impact.
    let away = Sweep {
        translation: -sa.translation,
        ..sa
    };
    assert!(time_of_impact(&a, &away, &b, &still(sb.start), 0.0).is_none());
    let short = Sweep {
        translation: Vec3::new(1.0, 0.0, 0.0),
        ..sa
    };
    assert!(time_of_impact(&a, &short, &b, &still(sb.start), 0.0).is_none());
    // Already touching: t = 0.
    let hit = time_of_impact(
        &a,
        &still(at(0.0, 0.0, 0.0)),
        &b,
        &still(at(0.7, 0.0, 0.0)),
        0.0,
    );
    assert_eq!(hit.unwrap().t, 0.0);
}

#[test]
fn spinning_box_hits_a_wall_no_later_than_first_contact() {
    let h = Vec3::new(0.5, 0.1, 0.3);
    let bx = Convex::Box { half_extents: h };
    let wall = Convex::Box {
        half_extents: Vec3::new(10.0, 0.5, 10.0),
    };
    let wall_pose = at(0.0, -0.5, 0.0);
    let sweep = Sweep {
        start: Pose::new(Vec3::new(0.0, 2.0, 0.0), Quat::from_rotation_x(0.3)),
        translation: Vec3::new(0.4, -1.9, 0.0),
        rotation: Vec3::new(0.0, 0.0, 4.0),
        local_center: Vec3::ZERO,
    };
    // The true first contact: the lowest corner reaches y = 0 (sampled, then bisected).
    let lowest = |t: Real| {
        let p = sweep.at(t);
        cube_points(h)
            .into_iter()
            .map(|c| p.transform_point(c).y)
            .fold(Real::INFINITY, Real::min)
    };
    let mut lo = 0.0;
    let steps = 4000;
    while lowest(lo + 1.0 / steps as Real) > 0.0 {
        lo += 1.0 / steps as Real;
    }
    let mut hi = lo + 1.0 / steps as Real;
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if lowest(mid) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let first_contact = lo;
    for target in [0.0, 0.01] {
        let hit = time_of_impact(&bx, &sweep, &wall, &still(wall_pose), target).unwrap();
        assert!(
            hit.t <= first_contact + tol(1e-9, 1e-5),
            "{hit:?} vs {first_contact}"
        );
        let gap = closest_points(&bx, &sweep.at(hit.t), &wall, &wall_pose).distance;
        // f32: the 20 m wall's coordinates round at about 1e-6, and the distance tolerance
        // is 1e-5 of the pair's size.
        assert!(gap >= target - tol(1e-9, 5e-4), "gap {gap} at {hit:?}");
        assert!(
            gap <= 1.05 * target + tol(1e-9, 5e-4),
            "gap {gap} at {hit:?}"
        );
        assert!(hit.normal.y < -0.99);
    }
}

#[test]
fn sphere_cast_against_box_matches_the_analytic_hit() {
    let eps = tol(1e-9, 5e-5);
    let sphere = Convex::Sphere { radius: 0.25 };
    let bx = Convex::Box {
        half_extents: Vec3::ONE,
    };
    let frame = Pose::new(Vec3::new(1.0, -2.0, 0.5), Quat::from_rotation_y(0.4));
    let world = |x: Real, y: Real, z: Real| frame.transform_point(Vec3::new(x, y, z));
    let dir = frame.transform_vector(Vec3::new(6.0, 0.0, 0.0));
    // Face hit: the centre stops at x = −1.25.
    let start = Pose::from_translation(world(-3.0, 0.2, 0.1));
    let hit = cast_shape(&sphere, &start, dir, &bx, &frame).unwrap();
    assert!(close(hit.t, 1.75 / 6.0, eps), "{hit:?}");
    assert!(vclose(hit.normal, frame.transform_vector(-Vec3::X), eps));
    assert!(vclose(hit.point, world(-1.0, 0.2, 0.1), eps));
    // Edge hit: passing 0.1 above the top face, it meets the edge x = −1, y = 1 when the
    // centre is 0.25 from it: x = −1 − √(0.25² − 0.1²).
    let start = Pose::from_translation(world(-3.0, 1.1, 0.0));
    let hit = cast_shape(&sphere, &start, dir, &bx, &frame).unwrap();
    let x = -1.0 - (0.0625 - 0.01 as Real).sqrt();
    assert!(close(hit.t, (x + 3.0) / 6.0, eps), "{hit:?}");
    assert!(vclose(hit.point, world(-1.0, 1.0, 0.0), eps));
    // Passing above, or stopping short: misses.
    let start = Pose::from_translation(world(-3.0, 1.3, 0.0));
    assert!(cast_shape(&sphere, &start, dir, &bx, &frame).is_none());
    let start = Pose::from_translation(world(-3.0, 0.0, 0.0));
    assert!(cast_shape(&sphere, &start, dir * 0.2, &bx, &frame).is_none());
}
