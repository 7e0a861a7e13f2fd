//! Hull construction and mass properties: closed-form solids, degenerate and rotated
//! clouds, determinism, and the fields named by invalid inputs.

use super::*;
use crate::collision::shape::MassProperties;
use crate::math::{real, Mat3, Quat, PI};
use proptest::prelude::*;
use std::collections::BTreeMap;

/// Slack for "on or inside the hull": ten times the construction tolerance.
fn inside_tol(points: &[Vec3]) -> Real {
    let m = points
        .iter()
        .fold(0.0 as Real, |m, p| m.max(p.abs().max_element()));
    10.0 * OUTSIDE_ULPS as Real * EPSILON * m
}

fn close(a: Real, b: Real, rel: Real) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()).max(1.0)
}

fn assert_mat_close(a: Mat3, b: Mat3, tol: Real) {
    let d = (a - b)
        .to_cols_array()
        .iter()
        .fold(0.0 as Real, |m, x| m.max(x.abs()));
    assert!(d <= tol, "{a} vs {b}");
}

/// A valid hull of `points`: closed, convex, outward and holding every point.
fn check_hull(hull: &ConvexHull, points: &[Vec3]) {
    check_topology(hull);
    check_geometry(hull, points);
}

/// Every edge used once in each direction, V − E + F = 2, every vertex used.
fn check_topology(hull: &ConvexHull) {
    let mut directed = BTreeMap::new();
    for t in hull.triangles() {
        for i in 0..3 {
            *directed.entry((t[i], t[(i + 1) % 3])).or_insert(0) += 1;
        }
    }
    for (&(a, b), &n) in &directed {
        assert_eq!(n, 1, "edge {a}->{b} used {n} times");
        assert_eq!(directed.get(&(b, a)), Some(&1), "edge {a}->{b} has no twin");
    }
    let (v, e, f) = (
        hull.vertices().len(),
        directed.len() / 2,
        hull.triangles().len(),
    );
    assert_eq!(v as i64 - e as i64 + f as i64, 2, "Euler characteristic");
    let mut used = vec![false; v];
    hull.triangles()
        .iter()
        .flatten()
        .for_each(|&i| used[i as usize] = true);
    assert!(used.iter().all(|&u| u), "unused vertex");
}

/// Positive volume (outward), unit face normals, faces through their vertices, every
/// input point on the inner side of every face, vertices drawn from the input.
fn check_geometry(hull: &ConvexHull, points: &[Vec3]) {
    assert!(hull.mass_properties(1.0).mass > 0.0, "not outward");
    let tol = inside_tol(points);
    for (k, &(n, d)) in hull.face_planes().iter().enumerate() {
        assert!((n.length() - 1.0).abs() < 1e3 * EPSILON, "normal {n}");
        for &p in points {
            assert!(
                n.dot(p) <= d + tol,
                "point {p} above face {k} by {}",
                n.dot(p) - d
            );
        }
        for &i in hull.face_vertices(k) {
            let h = n.dot(hull.vertices()[i as usize]) - d;
            assert!(h.abs() <= tol, "face {k} vertex off its plane by {h}");
        }
    }
    for v in hull.vertices() {
        assert!(points.contains(v), "vertex {v} not an input point");
    }
}

/// The corners, face centres, edge midpoints and some interior points of a box.
fn box_cloud(h: Vec3) -> Vec<Vec3> {
    let mut pts = Vec::new();
    for x in [-1.0, 0.0, 1.0] {
        for y in [-1.0, 0.0, 1.0] {
            for z in [-1.0, 0.0, 1.0] {
                pts.push(Vec3::new(x, y, z) * h);
            }
        }
    }
    pts.push(h * 0.5);
    pts.push(h * -0.25);
    pts
}

struct Rng(u64);
impl Rng {
    fn next(&mut self) -> Real {
        // splitmix64
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        real((z >> 11) as f64 / (1u64 << 53) as f64)
    }
    fn on_sphere(&mut self) -> Vec3 {
        loop {
            let v = Vec3::new(self.next(), self.next(), self.next()) * 2.0 - Vec3::ONE;
            if v.length_squared() > 0.01 && v.length_squared() <= 1.0 {
                return v.normalize();
            }
        }
    }
}

#[test]
fn box_with_face_edge_and_interior_points_has_only_its_corners() {
    let h = Vec3::new(1.0, 2.0, 3.0);
    let pts = box_cloud(h);
    let hull = ConvexHull::from_points(&pts).unwrap();
    check_hull(&hull, &pts);
    assert_eq!(hull.vertices().len(), 8);
    assert_eq!(hull.triangles().len(), 12);
    assert_eq!(hull.face_planes().len(), 6);
    assert_eq!(hull.edges().len(), 12);
    assert!((0..6).all(|f| hull.face_vertices(f).len() == 4));
    let density = 2.5;
    let mp = hull.mass_properties(density);
    let expect = MassProperties::cuboid(density, h);
    let rel = 100.0 * EPSILON;
    assert!(close(mp.mass, density * 8.0 * h.x * h.y * h.z, rel));
    assert!(mp.center.length() <= rel * h.length());
    assert_mat_close(
        mp.inertia,
        expect.inertia,
        rel * expect.inertia.x_axis.x.abs(),
    );
    assert!(close(
        mp.inertia.x_axis.x,
        mp.mass / 3.0 * (h.y * h.y + h.z * h.z),
        rel
    ));
}

#[test]
fn rotated_translated_box_keeps_mass_moves_centre_and_turns_inertia() {
    let h = Vec3::new(0.5, 1.5, 2.0);
    let q = Quat::from_euler(glam::EulerRot::XYZ, 0.3, -1.1, 2.0);
    let t = Vec3::new(3.0, -7.0, 11.0);
    let pts: Vec<Vec3> = box_cloud(h).iter().map(|&p| t + q * p).collect();
    let hull = ConvexHull::from_points(&pts).unwrap();
    check_hull(&hull, &pts);
    assert_eq!(
        hull.vertices().len(),
        8,
        "rounded face/edge points must not be vertices"
    );
    assert_eq!(hull.face_planes().len(), 6);
    let mp = hull.mass_properties(1.0);
    let expect = MassProperties::cuboid(1.0, h).transformed(t, q);
    let rel = 1e3 * EPSILON;
    assert!(close(mp.mass, expect.mass, rel));
    assert!((mp.center - t).length() <= rel * t.length());
    assert_mat_close(
        mp.inertia,
        expect.inertia,
        rel * expect.inertia.z_axis.z.abs(),
    );
}

#[test]
fn regular_tetrahedron_matches_closed_form() {
    let pts = [
        Vec3::new(1.0, 1.0, 1.0),
        Vec3::new(1.0, -1.0, -1.0),
        Vec3::new(-1.0, 1.0, -1.0),
        Vec3::new(-1.0, -1.0, 1.0),
    ];
    let hull = ConvexHull::from_points(&pts).unwrap();
    check_hull(&hull, &pts);
    assert_eq!((hull.vertices().len(), hull.triangles().len()), (4, 4));
    let a: Real = (8.0 as Real).sqrt();
    let volume = a.powi(3) / (6.0 * (2.0 as Real).sqrt());
    let mp = hull.mass_properties(3.0);
    let rel = 100.0 * EPSILON;
    assert!(
        close(mp.mass, 3.0 * volume, rel),
        "{} vs {}",
        mp.mass,
        3.0 * volume
    );
    assert!(mp.center.length() <= rel);
    // A regular tetrahedron's inertia is isotropic: m a²/20 about any axis.
    let i = mp.mass * a * a / 20.0;
    assert_mat_close(mp.inertia, Mat3::from_diagonal(Vec3::splat(i)), rel * i);
}

#[test]
fn sphere_points_give_growing_inscribed_volume_and_contain_every_point() {
    let mut rng = Rng(7);
    let ball = 4.0 / 3.0 * PI;
    let mut last = 0.0;
    for n in [50, 400, 3000] {
        let pts: Vec<Vec3> = (0..n).map(|_| rng.on_sphere()).collect();
        let hull = ConvexHull::from_points(&pts).unwrap();
        check_hull(&hull, &pts);
        let v = hull.mass_properties(1.0).mass;
        assert!(v > last && v < ball, "n = {n}: volume {v}, ball {ball}");
        last = v;
    }
    assert!(last > 0.99 * ball, "{last} vs {ball}");
}

#[test]
fn cylinder_rings_with_cap_centres_keep_every_ring_point() {
    let (r, hh, n) = (0.7, 1.3, 64);
    let mut pts = vec![Vec3::new(0.0, hh, 0.0), Vec3::new(0.0, -hh, 0.0)];
    for y in [hh, -hh] {
        for k in 0..n {
            let a = 2.0 * PI * k as Real / n as Real;
            pts.push(Vec3::new(r * a.cos(), y, r * a.sin()));
        }
    }
    let hull = ConvexHull::from_points(&pts).unwrap();
    check_hull(&hull, &pts);
    assert_eq!(hull.vertices().len(), 2 * n);
    assert_eq!(hull.face_planes().len(), n + 2);
    let polygon = 0.5 * n as Real * r * r * (2.0 * PI / n as Real).sin();
    let v = hull.mass_properties(1.0).mass;
    assert!(close(v, polygon * 2.0 * hh, 100.0 * EPSILON), "{v}");
}

#[test]
fn rotated_lattice_reduces_to_a_cube() {
    let q = Quat::from_euler(glam::EulerRot::ZYX, 0.7, 0.2, -0.4);
    let mut pts = Vec::new();
    for i in 0..5 {
        for j in 0..5 {
            for k in 0..5 {
                pts.push(q * Vec3::new(i as Real, j as Real, k as Real) + Vec3::splat(100.0));
            }
        }
    }
    let hull = ConvexHull::from_points(&pts).unwrap();
    check_hull(&hull, &pts);
    assert_eq!((hull.vertices().len(), hull.triangles().len()), (8, 12));
    assert!(close(hull.mass_properties(1.0).mass, 64.0, 1e4 * EPSILON));
}

#[test]
fn thin_but_real_slab_is_accepted() {
    let mut rng = Rng(3);
    let pts: Vec<Vec3> = (0..200)
        .map(|_| Vec3::new(rng.next(), rng.next(), rng.next() * 0.01))
        .collect();
    let hull = ConvexHull::from_points(&pts).unwrap();
    check_hull(&hull, &pts);
}

#[test]
fn output_is_deterministic_and_independent_of_input_order() {
    let mut rng = Rng(11);
    let pts: Vec<Vec3> = (0..300).map(|_| rng.on_sphere() * rng.next()).collect();
    let a = ConvexHull::from_points(&pts).unwrap();
    assert_eq!(a, ConvexHull::from_points(&pts).unwrap());
    let reversed: Vec<Vec3> = pts.iter().rev().copied().collect();
    let b = ConvexHull::from_points(&reversed).unwrap();
    let key = |h: &ConvexHull| {
        let mut v: Vec<[Real; 3]> = h.vertices().iter().map(|p| p.to_array()).collect();
        v.sort_by(|x, y| x.partial_cmp(y).unwrap());
        v
    };
    assert_eq!(key(&a), key(&b));
    assert!(close(
        a.mass_properties(1.0).mass,
        b.mass_properties(1.0).mass,
        100.0 * EPSILON
    ));
}

#[test]
fn support_picks_the_extreme_vertex() {
    let hull = ConvexHull::from_points(&box_cloud(Vec3::new(1.0, 2.0, 3.0))).unwrap();
    assert_eq!(
        hull.support(Vec3::new(1.0, -1.0, 0.1)),
        Vec3::new(1.0, -2.0, 3.0)
    );
}

fn field_of(points: &[Vec3]) -> String {
    ConvexHull::from_points(points)
        .unwrap_err()
        .field()
        .to_string()
}

#[test]
fn invalid_inputs_name_the_field() {
    let tri = [Vec3::ZERO, Vec3::X, Vec3::Y];
    assert_eq!(field_of(&tri), "points");
    assert_eq!(field_of(&[]), "points");
    let flat: Vec<Vec3> = (0..20)
        .map(|i| Vec3::new(i as Real % 5.0, i as Real / 5.0, 2.0))
        .collect();
    assert_eq!(field_of(&flat), "points");
    let tilted: Vec<Vec3> = flat
        .iter()
        .map(|&p| Quat::from_rotation_x(0.3) * p + Vec3::splat(9.0))
        .collect();
    assert_eq!(field_of(&tilted), "points");
    let line: Vec<Vec3> = (0..10)
        .map(|i| Vec3::new(1.0, 2.0, 3.0) * i as Real)
        .collect();
    assert_eq!(field_of(&line), "points");
    assert_eq!(field_of(&[Vec3::new(1.0, 2.0, 3.0); 10]), "points");
    let mut with_nan = box_cloud(Vec3::ONE);
    with_nan[3].y = Real::NAN;
    assert_eq!(field_of(&with_nan), "points[3]");
    with_nan[0].x = Real::INFINITY;
    assert_eq!(field_of(&with_nan), "points[0]");
    // Off the plane by a few ulps (rounding noise, well under the 1e3-epsilon tolerance):
    // still flat. A hundred times the tolerance is a real, if thin, solid.
    let lifted = |h: Real| -> Vec<Vec3> {
        let step = |i: usize| Vec3::Z * (i % 2) as Real * h * EPSILON;
        flat.iter().enumerate().map(|(i, &p)| p + step(i)).collect()
    };
    assert_eq!(field_of(&lifted(10.0)), "points");
    let solid = lifted(1e5);
    check_hull(&ConvexHull::from_points(&solid).unwrap(), &solid);
}

fn cloud(raw: &[(Real, Real, Real)], scale: Real, offset: Vec3) -> Vec<Vec3> {
    raw.iter()
        .map(|&(x, y, z)| Vec3::new(x, y, z) * scale + offset)
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn random_clouds_give_closed_outward_hulls_holding_every_point(
        raw in prop::collection::vec((-1.0 as Real..1.0, -1.0 as Real..1.0, -1.0 as Real..1.0), 8..120),
        scale in 1e-2 as Real..1e2,
        offset in (-1e2 as Real..1e2, -1e2 as Real..1e2, -1e2 as Real..1e2),
    ) {
        let pts = cloud(&raw, scale, Vec3::new(offset.0, offset.1, offset.2));
        let hull = ConvexHull::from_points(&pts).unwrap();
        check_hull(&hull, &pts);
    }

    #[test]
    fn grid_clouds_with_duplicates_and_coplanar_runs_are_valid_or_flat(
        raw in prop::collection::vec((-3i32..=3, -3i32..=3, -3i32..=3), 4..60),
        angle in 0.0 as Real..3.0,
    ) {
        let q = Quat::from_euler(glam::EulerRot::XYZ, angle, 0.5 * angle, 0.3);
        let pts: Vec<Vec3> =
            raw.iter().map(|&(x, y, z)| q * Vec3::new(x as Real, y as Real, z as Real)).collect();
        match ConvexHull::from_points(&pts) {
            Ok(hull) => check_hull(&hull, &pts),
            Err(e) => {
                prop_assert_eq!(e.field(), "points");
                prop_assert!(grid_is_flat(&raw), "rejected a solid cloud");
            }
        }
    }
}

/// Whether integer points lie in one plane, in exact integer arithmetic.
fn grid_is_flat(raw: &[(i32, i32, i32)]) -> bool {
    let p: Vec<[i64; 3]> = raw
        .iter()
        .map(|&(x, y, z)| [x.into(), y.into(), z.into()])
        .collect();
    let sub = |a: [i64; 3], b: [i64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let cross = |a: [i64; 3], b: [i64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let dot = |a: [i64; 3], b: [i64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    for &b in &p {
        for &c in &p {
            let n = cross(sub(b, p[0]), sub(c, p[0]));
            if n != [0, 0, 0] {
                return p.iter().all(|&d| dot(n, sub(d, p[0])) == 0);
            }
        }
    }
    true
}
