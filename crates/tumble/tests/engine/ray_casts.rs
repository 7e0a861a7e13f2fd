//! Ray casts and point queries against independent closed forms: the quadratic for
//! spheres, the slab test for boxes, hand-worked capsule and cylinder cases, and shapes
//! that must agree with each other (a hull of a box's corners, a 12-triangle cube mesh and
//! a box; a flat height field and a plane).

// Casts between Real and f64 are no-ops in the default build but needed in the f32 one.
#![allow(clippy::unnecessary_cast)]

use crate::common::tol;
use proptest::prelude::*;
use tumble::geometry::{Pose, Ray, RayHit};
use tumble::prelude::*;
use tumble::query::{cast_ray, contains_point, project_point};
use tumble::{HeightField, TriMesh};

fn v(x: f64, y: f64, z: f64) -> Vec3 {
    Vec3::new(x as Real, y as Real, z as Real)
}

fn pose(p: [f64; 3], axis: [f64; 3], angle: f64) -> Pose {
    let axis = v(axis[0], axis[1], axis[2]).normalize_or(Vec3::Y);
    Pose::new(
        v(p[0], p[1], p[2]),
        Quat::from_axis_angle(axis, angle as Real),
    )
}

fn close(a: Vec3, b: Vec3, eps: Real) -> bool {
    (a - b).length() <= eps
}

fn cube_mesh(h: Vec3) -> TriMesh {
    let c = |i: u32| {
        Vec3::new(
            if i & 1 == 0 { -h.x } else { h.x },
            if i & 2 == 0 { -h.y } else { h.y },
            if i & 4 == 0 { -h.z } else { h.z },
        )
    };
    let vertices = (0..8).map(c).collect();
    // Two counter-clockwise (seen from outside) triangles per face.
    let faces: [[u32; 4]; 6] = [
        [0, 4, 6, 2], // −x
        [1, 3, 7, 5], // +x
        [0, 1, 5, 4], // −y
        [2, 6, 7, 3], // +y
        [0, 2, 3, 1], // −z
        [4, 5, 7, 6], // +z
    ];
    let mut indices = Vec::new();
    for [a, b, c, d] in faces {
        indices.push([a, b, c]);
        indices.push([a, c, d]);
    }
    TriMesh::new(vertices, indices).unwrap()
}

/// Reference ray–sphere hit in f64 from the textbook quadratic |o + t d − c|² = r².
fn sphere_reference(o: [f64; 3], d: [f64; 3], c: [f64; 3], r: f64) -> Option<(f64, [f64; 3])> {
    let oc = [o[0] - c[0], o[1] - c[1], o[2] - c[2]];
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let (a, b, cc) = (dot(d, d), 2.0 * dot(oc, d), dot(oc, oc) - r * r);
    let disc = b * b - 4.0 * a * cc;
    if disc < 0.0 {
        return None;
    }
    let t = (-b - disc.sqrt()) / (2.0 * a);
    if t < 0.0 {
        return None;
    }
    let p = [oc[0] + t * d[0], oc[1] + t * d[1], oc[2] + t * d[2]];
    Some((t, [p[0] / r, p[1] / r, p[2] / r]))
}

/// Reference slab test in the box's frame (f64): entry t, the local entry normal, and the
/// gap to the runner-up slab entry (how far the hit is from an edge).
fn slab_reference(o: [f64; 3], d: [f64; 3], h: [f64; 3]) -> Option<(f64, [f64; 3], f64)> {
    let mut entries = Vec::new();
    let mut t1 = f64::INFINITY;
    for i in 0..3 {
        if d[i] == 0.0 {
            if o[i].abs() > h[i] {
                return None;
            }
            continue;
        }
        let (a, b) = ((-h[i] - o[i]) / d[i], (h[i] - o[i]) / d[i]);
        entries.push((a.min(b), i));
        t1 = t1.min(a.max(b));
    }
    entries.sort_by(|a, b| b.0.total_cmp(&a.0));
    let (t0, axis) = entries[0];
    if t0 > t1 || t0 < 0.0 {
        return None;
    }
    let mut n = [0.0; 3];
    n[axis] = -d[axis].signum();
    let gap = entries.get(1).map_or(f64::INFINITY, |e| t0 - e.0);
    Some((t0, n, gap))
}

fn arr(x: Vec3) -> [f64; 3] {
    [x.x as f64, x.y as f64, x.z as f64]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn sphere_matches_the_quadratic(
        p in prop::array::uniform3(-5.0f64..5.0), axis in prop::array::uniform3(-1.0f64..1.0),
        angle in 0.0f64..6.3, r in 0.1f64..3.0,
        o in prop::array::uniform3(-10.0f64..10.0), d in prop::array::uniform3(-1.0f64..1.0),
        len in 0.1f64..5.0,
    ) {
        let dv = v(d[0], d[1], d[2]);
        prop_assume!(dv.length() > 0.1);
        let dv = dv.normalize() * len as Real;
        let pose = pose(p, axis, angle);
        let ray = Ray::new(v(o[0], o[1], o[2]), dv);
        let (ow, dw) = (arr(ray.origin), arr(ray.direction));
        let c = arr(pose.position);
        let inside = (0..3).map(|i| (ow[i] - c[i]).powi(2)).sum::<f64>() < r * r;
        if inside {
            // Solid: a hit at once. Hollow: the far root of the quadratic, normal outward.
            let shape = Shape::sphere(r as Real);
            let h = cast_ray(&shape, &pose, &ray, 1e3, true).unwrap();
            prop_assert_eq!((h.t, h.normal), (0.0, Vec3::ZERO));
            let h = cast_ray(&shape, &pose, &ray, 1e3, false).unwrap();
            let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
            let oc = [ow[0] - c[0], ow[1] - c[1], ow[2] - c[2]];
            let (a, b, cc) = (dot(dw, dw), 2.0 * dot(oc, dw), dot(oc, oc) - r * r);
            let t = (-b + (b * b - 4.0 * a * cc).sqrt()) / (2.0 * a);
            let n = [(oc[0] + t * dw[0]) / r, (oc[1] + t * dw[1]) / r, (oc[2] + t * dw[2]) / r];
            prop_assert!((h.t - t as Real).abs() <= tol(1e-9, 1e-3) * (1.0 + t as Real));
            prop_assert!(close(h.normal, v(n[0], n[1], n[2]), tol(1e-8, 1e-2)));
            return Ok(());
        }
        let reference = sphere_reference(ow, dw, c, r);
        let hit = cast_ray(&Shape::sphere(r as Real), &pose, &ray, 1e3, true);
        match (reference, hit) {
            (None, None) => {}
            (Some((t, n)), Some(h)) => {
                let eps = tol(1e-9, 1e-3) * (1.0 + t as Real);
                prop_assert!((h.t - t as Real).abs() <= eps, "t {} vs {}", h.t, t);
                prop_assert!(close(h.normal, v(n[0], n[1], n[2]), tol(1e-9, 1e-3) * 10.0));
                prop_assert!((h.normal.length() - 1.0).abs() < tol(1e-12, 1e-5));
            }
            (a, b) => {
                // Only grazing rays may disagree, and only by rounding.
                let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
                let oc = [ow[0] - c[0], ow[1] - c[1], ow[2] - c[2]];
                let s = dot(oc, dw) / dot(dw, dw);
                let perp2 = dot(oc, oc) - s * s * dot(dw, dw);
                prop_assert!((perp2.sqrt() - r).abs() < 1e-3, "{a:?} vs {b:?}");
            }
        }
    }

    #[test]
    fn box_matches_the_slab_test(
        p in prop::array::uniform3(-5.0f64..5.0), axis in prop::array::uniform3(-1.0f64..1.0),
        angle in 0.0f64..6.3, h in prop::array::uniform3(0.1f64..3.0),
        o in prop::array::uniform3(-10.0f64..10.0), d in prop::array::uniform3(-1.0f64..1.0),
    ) {
        let dv = v(d[0], d[1], d[2]);
        prop_assume!(dv.length() > 0.1);
        let pose = pose(p, axis, angle);
        let ray = Ray::new(v(o[0], o[1], o[2]), dv);
        let he = v(h[0], h[1], h[2]);
        let local_o = arr(pose.inverse_transform_point(ray.origin));
        let local_d = arr(pose.inverse_transform_vector(ray.direction));
        let inside = (0..3).all(|i| local_o[i].abs() <= h[i]);
        prop_assume!(!inside);
        let hit = cast_ray(&Shape::cuboid(he), &pose, &ray, 1e3, true);
        match (slab_reference(local_o, local_d, h), hit) {
            (None, None) => {}
            (Some((t, n, gap)), Some(hit)) => {
                let eps = tol(1e-9, 1e-3) * (1.0 + t as Real);
                prop_assert!((hit.t - t as Real).abs() <= eps, "t {} vs {}", hit.t, t);
                if gap > 1e-6 {
                    let n = pose.transform_vector(v(n[0], n[1], n[2]));
                    let eps = tol(1e-9, 1e-4);
                    prop_assert!(close(hit.normal, n, eps), "{:?} vs {:?}", hit.normal, n);
                }
            }
            (a, b) => {
                // Disagreement only for rays that graze an edge, by rounding.
                let near = |q: [f64; 3]| {
                    (0..3).filter(|&i| (q[i].abs() - h[i]).abs() < 1e-4).count()
                };
                let t = a.map(|r| r.0).or(b.map(|h| h.t as f64)).unwrap();
                let q = [
                    local_o[0] + t * local_d[0],
                    local_o[1] + t * local_d[1],
                    local_o[2] + t * local_d[2],
                ];
                prop_assert!(near(q) >= 2, "{a:?} vs {b:?}");
            }
        }
    }

    #[test]
    fn hull_and_cube_mesh_equal_the_box(
        p in prop::array::uniform3(-3.0f64..3.0), axis in prop::array::uniform3(-1.0f64..1.0),
        angle in 0.0f64..6.3, o in prop::array::uniform3(-6.0f64..6.0),
        target in prop::array::uniform3(-1.5f64..1.5),
    ) {
        let pose = pose(p, axis, angle);
        let h = v(0.5, 1.0, 1.5);
        let corners: Vec<Vec3> = (0..8)
            .map(|i| Vec3::new(
                if i & 1 == 0 { -h.x } else { h.x },
                if i & 2 == 0 { -h.y } else { h.y },
                if i & 4 == 0 { -h.z } else { h.z },
            ))
            .collect();
        let hull = Shape::convex_hull(&corners).unwrap();
        let mesh = Shape::TriMesh(cube_mesh(h));
        // Aim at a point near the box so most rays hit.
        let origin = v(o[0], o[1], o[2]) + pose.position;
        let aim = pose.transform_point(v(target[0], target[1], target[2]));
        prop_assume!((aim - origin).length() > 0.1);
        let ray = Ray::new(origin, aim - origin);
        let boxed = Shape::cuboid(h);
        prop_assume!(!contains_point(&boxed, &pose, origin));
        let reference = cast_ray(&boxed, &pose, &ray, 10.0, true);
        for other in [&hull, &mesh] {
            let hit = cast_ray(other, &pose, &ray, 10.0, true);
            match (reference, hit) {
                (None, None) => {}
                (Some(a), Some(b)) => {
                    prop_assert!((a.t - b.t).abs() <= tol(1e-9, 1e-4), "{a:?} vs {b:?}");
                    let q = pose.inverse_transform_point(ray.at(a.t));
                    let on_edge = (0..3).filter(|&i| (q[i].abs() - h[i]).abs() < 1e-6).count() > 1;
                    if !on_edge {
                        prop_assert!(close(a.normal, b.normal, tol(1e-9, 1e-4)), "{a:?} vs {b:?}");
                    }
                }
                (a, b) => {
                    let t = a.or(b).unwrap().t;
                    let q = pose.inverse_transform_point(ray.at(t));
                    let grazing = (0..3).filter(|&i| (q[i].abs() - h[i]).abs() < 1e-4).count() > 1;
                    prop_assert!(grazing, "{a:?} vs {b:?}");
                }
            }
        }
    }

    #[test]
    fn flat_heightfield_equals_a_plane(
        p in prop::array::uniform3(-3.0f64..3.0), axis in prop::array::uniform3(-1.0f64..1.0),
        angle in 0.0f64..6.3, o in prop::array::uniform3(-4.0f64..4.0),
        target in prop::array::uniform2(-3.5f64..3.5),
    ) {
        prop_assume!((o[1] * 2.0 - 0.7).abs() > 0.05 * (o[0] - target[0]).hypot(o[2] - target[1]));
        let pose = pose(p, axis, angle);
        // 9 × 8 samples at spacings 1 × 1, 2: 8 m by 7·2 m; all at height 0.35·2 = 0.7.
        let field = HeightField::new(vec![0.35; 72], 8, 9, v(1.0, 2.0, 2.0)).unwrap();
        let plane = Shape::plane(Vec3::Y, 0.7);
        let field = Shape::HeightField(field);
        let origin = pose.transform_point(v(o[0], o[1] * 2.0, o[2]));
        let aim = pose.transform_point(v(target[0], 0.7, target[1] * 1.9));
        prop_assume!((aim - origin).length() > 0.1);
        let ray = Ray::new(origin, aim - origin);
        let a = cast_ray(&plane, &pose, &ray, 10.0, true);
        let b = cast_ray(&field, &pose, &ray, 10.0, true);
        match (a, b) {
            (Some(a), Some(b)) => {
                prop_assert!((a.t - b.t).abs() <= tol(1e-9, 1e-4), "{a:?} vs {b:?}");
                prop_assert!(close(a.normal, b.normal, tol(1e-12, 1e-5)));
                prop_assert!(close(a.normal, pose.transform_vector(Vec3::Y), tol(1e-12, 1e-5)));
            }
            (None, None) => {}
            (a, b) => prop_assert!(false, "plane {a:?}, field {b:?}"),
        }
    }
}

#[test]
fn capsule_hand_cases() {
    let cap = Shape::capsule(0.5, 1.0);
    let at = Pose::IDENTITY;
    let cast = |o: Vec3, d: Vec3| cast_ray(&cap, &at, &Ray::new(o, d), 100.0, true);
    let eps = tol(1e-12, 1e-5);
    // The shaft, side on.
    let h = cast(v(5.0, 0.0, 0.0), -Vec3::X).unwrap();
    assert!((h.t - 4.5).abs() < eps && close(h.normal, Vec3::X, eps));
    // The top of the cap, straight down.
    let h = cast(v(0.0, 5.0, 0.0), -Vec3::Y).unwrap();
    assert!((h.t - 3.5).abs() < eps && close(h.normal, Vec3::Y, eps));
    // Off-centre onto the cap: y = 1 + √(0.25 − 0.09) = 1.4, normal (0.3, 0.4)/0.5.
    let h = cast(v(0.3, 5.0, 0.0), -Vec3::Y).unwrap();
    assert!((h.t - 3.6).abs() < eps && close(h.normal, v(0.6, 0.8, 0.0), eps));
    // Sideways through the cap's sphere above the shaft: x = √(0.25 − 0.04).
    let h = cast(v(5.0, 1.2, 0.0), -Vec3::X * 2.0).unwrap();
    let x = (0.21 as Real).sqrt();
    assert!((h.t - (5.0 - x) / 2.0).abs() < eps);
    assert!(close(h.normal, v(x as f64 / 0.5, 0.4, 0.0), eps));
    // Over the top: a miss.
    assert!(cast(v(5.0, 1.6, 0.0), -Vec3::X).is_none());
    // Laid along x by a quarter turn about z.
    let turned = Pose::new(
        Vec3::ZERO,
        Quat::from_rotation_z(std::f64::consts::FRAC_PI_2 as Real),
    );
    let h = cast_ray(
        &cap,
        &turned,
        &Ray::new(v(5.0, 0.0, 0.0), -Vec3::X),
        100.0,
        true,
    )
    .unwrap();
    assert!((h.t - 3.5).abs() < eps && close(h.normal, Vec3::X, eps));
    // From the inside: solid hits at once, hollow reports the exit.
    let h = cast(Vec3::ZERO, Vec3::X).unwrap();
    assert_eq!((h.t, h.normal), (0.0, Vec3::ZERO));
    let h = cast_ray(&cap, &at, &Ray::new(Vec3::ZERO, Vec3::X), 100.0, false).unwrap();
    assert!((h.t - 0.5).abs() < eps && close(h.normal, Vec3::X, eps));
    let h = cast_ray(
        &cap,
        &at,
        &Ray::new(v(0.0, 0.9, 0.0), Vec3::Y),
        100.0,
        false,
    )
    .unwrap();
    assert!((h.t - 0.6).abs() < eps && close(h.normal, Vec3::Y, eps));
}

#[test]
fn cylinder_hand_cases() {
    let cyl = Shape::cylinder(1.0, 2.0);
    let at = Pose::from_translation(v(1.0, 2.0, 3.0));
    let shift = at.position;
    let cast = |o: Vec3, d: Vec3, solid| cast_ray(&cyl, &at, &Ray::new(o + shift, d), 100.0, solid);
    let eps = tol(1e-12, 1e-5);
    let check = |h: Option<RayHit>, t: f64, n: Vec3| {
        let h = h.unwrap();
        assert!((h.t - t as Real).abs() < eps, "{h:?} vs t {t}");
        assert!(close(h.normal, n, eps), "{h:?} vs n {n}");
    };
    check(cast(v(5.0, 0.0, 0.0), -Vec3::X, true), 4.0, Vec3::X);
    check(cast(v(0.0, 5.0, 0.0), -Vec3::Y, true), 3.0, Vec3::Y);
    check(cast(v(0.9, 5.0, 0.0), -Vec3::Y, true), 3.0, Vec3::Y);
    check(cast(v(0.0, -5.0, 0.6), Vec3::Y, true), 3.0, -Vec3::Y);
    assert!(cast(v(5.0, 2.5, 0.0), -Vec3::X, true).is_none());
    assert!(cast(v(1.1, 5.0, 0.0), -Vec3::Y, true).is_none());
    // Diagonal: the cap first (x = 0 at y = 2), then one that meets the side (y = 0).
    check(
        cast(v(3.0, 5.0, 0.0), v(-1.0, -1.0, 0.0), true),
        3.0,
        Vec3::Y,
    );
    check(
        cast(v(4.0, 3.0, 0.0), v(-1.0, -1.0, 0.0), true),
        3.0,
        Vec3::X,
    );
    // Side at 45° in the xz plane: x = z = √½.
    let s = std::f64::consts::FRAC_1_SQRT_2;
    check(cast(v(5.0, 0.0, s), -Vec3::X, true), 5.0 - s, v(s, 0.0, s));
    // Inside.
    check(cast(Vec3::ZERO, Vec3::Z, true), 0.0, Vec3::ZERO);
    check(cast(Vec3::ZERO, Vec3::Z, false), 1.0, Vec3::Z);
    check(cast(v(0.0, 1.0, 0.0), Vec3::Y, false), 1.0, Vec3::Y);
}

#[test]
fn compound_reports_the_nearest_child() {
    let ball = |x: f64| CompoundChild {
        shape: Shape::sphere(1.0),
        position: v(x, 0.0, 0.0),
        orientation: Quat::IDENTITY,
    };
    let boxed = CompoundChild {
        shape: Shape::cuboid(v(0.5, 0.5, 0.5)),
        position: v(0.0, 3.0, 0.0),
        orientation: Quat::from_rotation_y(0.3),
    };
    let shape = Shape::Compound(vec![ball(-2.0), ball(2.0), boxed]);
    let at = Pose::from_translation(v(0.0, 1.0, 0.0));
    let eps = tol(1e-12, 1e-5);
    let cast = |o: Vec3, d: Vec3| cast_ray(&shape, &at, &Ray::new(o, d), 100.0, true);
    let h = cast(v(10.0, 1.0, 0.0), -Vec3::X).unwrap();
    assert!((h.t - 7.0).abs() < eps && h.subshape == 1 && close(h.normal, Vec3::X, eps));
    let h = cast(v(-10.0, 1.0, 0.0), Vec3::X).unwrap();
    assert!((h.t - 7.0).abs() < eps && h.subshape == 0 && close(h.normal, -Vec3::X, eps));
    let h = cast(v(0.0, 10.0, 0.0), -Vec3::Y).unwrap();
    assert!((h.t - 5.5).abs() < eps && h.subshape == 2 && close(h.normal, Vec3::Y, eps));
    // Through the gap between the balls and under the box: nothing.
    assert!(cast(v(0.0, 1.0, 10.0), -Vec3::Z).is_none());
    // Inside a child.
    let h = cast(v(2.0, 1.0, 0.0), Vec3::Z).unwrap();
    assert_eq!((h.t, h.subshape), (0.0, 1));
    assert!(contains_point(&shape, &at, v(-2.5, 1.0, 0.0)));
    assert!(!contains_point(&shape, &at, v(0.0, 1.0, 0.0)));
}

#[test]
fn misses_and_limits() {
    let shapes = [
        Shape::sphere(1.0),
        Shape::cuboid(Vec3::ONE),
        Shape::capsule(1.0, 1.0),
        Shape::cylinder(1.0, 1.0),
        Shape::convex_hull(&[
            v(1.0, 0.0, 0.0),
            v(0.0, 1.0, 0.0),
            v(0.0, 0.0, 1.0),
            v(-1.0, -1.0, -1.0),
        ])
        .unwrap(),
        Shape::TriMesh(cube_mesh(Vec3::ONE)),
        Shape::HeightField(HeightField::new(vec![0.0; 9], 3, 3, Vec3::ONE).unwrap()),
        Shape::plane(Vec3::Y, 0.0),
    ];
    let at = Pose::from_translation(v(0.0, 0.0, 0.0));
    for s in &shapes {
        let kind = s.kind_name();
        let toward = Ray::new(v(0.3, 10.0, 0.2), -Vec3::Y);
        assert!(cast_ray(s, &at, &toward, 100.0, true).is_some(), "{kind}");
        // Pointing away, too short, or passing by.
        let away = Ray::new(v(0.3, 10.0, 0.2), Vec3::Y);
        assert!(cast_ray(s, &at, &away, 100.0, true).is_none(), "{kind}");
        assert!(cast_ray(s, &at, &toward, 5.0, true).is_none(), "{kind}");
        if !matches!(s, Shape::Plane { .. }) {
            let by = Ray::new(v(30.0, 10.0, 0.2), -Vec3::Y);
            assert!(cast_ray(s, &at, &by, 100.0, true).is_none(), "{kind}");
        }
        // Garbage in, nothing out.
        let nan = Ray::new(v(f64::NAN, 0.0, 0.0), Vec3::Y);
        assert!(cast_ray(s, &at, &nan, 100.0, true).is_none(), "{kind}");
        assert!(cast_ray(s, &at, &toward, -1.0, true).is_none(), "{kind}");
        assert!(cast_ray(s, &at, &Ray::new(v(0.3, 10.0, 0.2), Vec3::ZERO), 1.0, true).is_none());
    }
}

#[test]
fn rays_from_inside() {
    let hull = Shape::convex_hull(&[
        v(-1.0, -1.0, -1.0),
        v(1.0, -1.0, -1.0),
        v(-1.0, 1.0, -1.0),
        v(1.0, 1.0, -1.0),
        v(-1.0, -1.0, 1.0),
        v(1.0, -1.0, 1.0),
        v(-1.0, 1.0, 1.0),
        v(1.0, 1.0, 1.0),
    ])
    .unwrap();
    let at = Pose::new(v(1.0, 2.0, 3.0), Quat::from_rotation_x(0.4));
    let eps = tol(1e-12, 1e-5);
    for s in [Shape::sphere(1.0), Shape::cuboid(Vec3::ONE), hull] {
        let ray = Ray::new(
            at.transform_point(v(0.0, 0.0, 0.5)),
            at.transform_vector(Vec3::Z * 2.0),
        );
        let solid = cast_ray(&s, &at, &ray, 10.0, true).unwrap();
        assert_eq!((solid.t, solid.normal), (0.0, Vec3::ZERO));
        let hollow = cast_ray(&s, &at, &ray, 10.0, false).unwrap();
        assert!((hollow.t - 0.25).abs() < eps, "{hollow:?}");
        assert!(close(hollow.normal, at.transform_vector(Vec3::Z), eps));
        // The exit beyond max_t is no hit.
        assert!(cast_ray(&s, &at, &ray, 0.2, false).is_none());
        // A zero-length ray inside a solid still starts in it.
        let still = Ray::new(ray.origin, Vec3::ZERO);
        assert!(cast_ray(&s, &at, &still, 1.0, true).is_some());
        assert!(cast_ray(&s, &at, &still, 1.0, false).is_none());
    }
}

#[test]
fn surfaces_are_hit_from_both_sides_with_their_own_normal() {
    let at = Pose::IDENTITY;
    let eps = tol(1e-12, 1e-5);
    let field =
        Shape::HeightField(HeightField::new(vec![0.0, 0.0, 1.0, 1.0], 2, 2, Vec3::ONE).unwrap());
    let mesh = Shape::TriMesh(cube_mesh(Vec3::ONE));
    let plane = Shape::plane(Vec3::Y, 0.0);
    for (s, up) in [(&field, v(0.0, 1.0, -1.0).normalize()), (&plane, Vec3::Y)] {
        let below = cast_ray(s, &at, &Ray::new(v(0.1, -5.0, 0.1), Vec3::Y), 10.0, true).unwrap();
        let above = cast_ray(s, &at, &Ray::new(v(0.1, 5.0, 0.1), -Vec3::Y), 10.0, true).unwrap();
        assert!(close(below.normal, up, eps) && close(above.normal, up, eps));
        assert!((below.t + above.t - 10.0).abs() < eps);
    }
    // A mesh has no inside: from the centre of the cube the ray meets the +x face.
    let h = cast_ray(&mesh, &at, &Ray::new(Vec3::ZERO, Vec3::X), 10.0, true).unwrap();
    assert!((h.t - 1.0).abs() < eps && close(h.normal, Vec3::X, eps));
    assert!(
        matches!(mesh, Shape::TriMesh(ref m) if m.normal(h.subshape as usize) == Some(Vec3::X))
    );
}

#[test]
fn point_queries() {
    let at = Pose::new(v(1.0, -2.0, 0.5), Quat::from_rotation_y(0.7));
    let eps = tol(1e-12, 1e-5);
    let w = |p: Vec3| at.transform_point(p);
    let check = |s: &Shape, local: Vec3, point: Vec3, inside: bool, distance: f64| {
        let p = project_point(s, &at, w(local)).unwrap();
        assert!(close(p.point, w(point), eps), "{} {p:?}", s.kind_name());
        assert_eq!(p.inside, inside, "{}", s.kind_name());
        assert!(
            (p.distance - distance as Real).abs() < eps,
            "{} {p:?}",
            s.kind_name()
        );
        assert_eq!(
            contains_point(s, &at, w(local)),
            inside,
            "{}",
            s.kind_name()
        );
    };
    check(
        &Shape::sphere(2.0),
        v(0.0, 3.0, 0.0),
        v(0.0, 2.0, 0.0),
        false,
        1.0,
    );
    check(
        &Shape::sphere(2.0),
        v(0.0, 0.0, -0.5),
        v(0.0, 0.0, -2.0),
        true,
        -1.5,
    );
    let b = Shape::cuboid(v(1.0, 2.0, 3.0));
    check(
        &b,
        v(2.0, 3.0, 0.0),
        v(1.0, 2.0, 0.0),
        false,
        (2.0f64).sqrt(),
    );
    check(&b, v(0.2, 1.5, 0.0), v(0.2, 2.0, 0.0), true, -0.5);
    let c = Shape::capsule(0.5, 1.0);
    check(&c, v(0.0, 3.0, 0.0), v(0.0, 1.5, 0.0), false, 1.5);
    check(&c, v(0.2, 0.3, 0.0), v(0.5, 0.3, 0.0), true, -0.3);
    let y = Shape::cylinder(1.0, 1.0);
    check(
        &y,
        v(3.0, 2.0, 0.0),
        v(1.0, 1.0, 0.0),
        false,
        (5.0f64).sqrt(),
    );
    check(&y, v(0.0, 0.8, 0.5), v(0.0, 1.0, 0.5), true, -0.2);
    check(&y, v(0.0, 0.0, 0.7), v(0.0, 0.0, 1.0), true, -0.3);
    let hull = Shape::convex_hull(&[
        v(0.0, 0.0, 0.0),
        v(1.0, 0.0, 0.0),
        v(0.0, 1.0, 0.0),
        v(0.0, 0.0, 1.0),
    ])
    .unwrap();
    check(
        &hull,
        v(-1.0, -1.0, -1.0),
        v(0.0, 0.0, 0.0),
        false,
        (3.0f64).sqrt(),
    );
    check(&hull, v(2.0, 0.0, 0.0), v(1.0, 0.0, 0.0), false, 1.0);
    check(&hull, v(0.1, 0.2, 0.15), v(0.0, 0.2, 0.15), true, -0.1);
    check(
        &Shape::plane(Vec3::Y, 1.0),
        v(3.0, -1.0, 2.0),
        v(3.0, 1.0, 2.0),
        true,
        -2.0,
    );
    let mesh = Shape::TriMesh(cube_mesh(Vec3::ONE));
    check(&mesh, v(0.0, 0.5, 0.0), v(0.0, 1.0, 0.0), false, 0.5);
    check(&mesh, v(3.0, 0.0, 0.0), v(1.0, 0.0, 0.0), false, 2.0);
    let field = Shape::HeightField(HeightField::new(vec![1.0; 16], 4, 4, Vec3::ONE).unwrap());
    check(&field, v(0.2, 0.5, 0.3), v(0.2, 1.0, 0.3), true, -0.5);
    check(&field, v(0.2, 4.0, 0.3), v(0.2, 1.0, 0.3), false, 3.0);
    check(&field, v(2.5, 1.0, 0.0), v(1.5, 1.0, 0.0), false, 1.0);
}
