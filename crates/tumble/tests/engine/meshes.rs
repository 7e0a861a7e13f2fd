//! Triangle meshes and height fields: validation messages, the hierarchy against brute
//! force, adjacency, and contacts without ghost normals at internal edges.

// Casts between Real and f64 are no-ops in the default build but needed in the f32 one.
#![allow(clippy::unnecessary_cast)]

use crate::common::tol;
use proptest::prelude::*;
use tumble::geometry::{Aabb, Pose, Ray};
use tumble::narrow_phase::{collide, Manifold};
use tumble::prelude::*;
use tumble::query::cast_ray;
use tumble::{HeightField, TriMesh};

fn v(x: f64, y: f64, z: f64) -> Vec3 {
    Vec3::new(x as Real, y as Real, z as Real)
}

fn message<T: std::fmt::Debug>(r: Result<T, Error>) -> String {
    r.unwrap_err().to_string()
}

/// An n × n grid of unit cells in the xz plane at height 0, centred on the origin, two
/// triangles per cell (normals up).
fn floor_mesh(n: usize) -> TriMesh {
    let half = n as f64 / 2.0;
    let mut vertices = Vec::new();
    for z in 0..=n {
        for x in 0..=n {
            vertices.push(v(x as f64 - half, 0.0, z as f64 - half));
        }
    }
    let w = (n + 1) as u32;
    let mut indices = Vec::new();
    for z in 0..n as u32 {
        for x in 0..n as u32 {
            let a = z * w + x;
            indices.push([a, a + w, a + w + 1]);
            indices.push([a, a + w + 1, a + 1]);
        }
    }
    TriMesh::new(vertices, indices).unwrap()
}

/// An (n+1) × (n+1)-sample flat height field of unit cells at height 0.
fn floor_field(n: usize) -> HeightField {
    HeightField::new(vec![0.0; (n + 1) * (n + 1)], n + 1, n + 1, Vec3::ONE).unwrap()
}

const MARGIN: Real = 0.02;

/// Manifolds of `ground` (A) against `body` (B): normals point from the ground up.
fn contacts(ground: &Shape, at: &Pose, body: &Shape, pose: &Pose) -> Vec<Manifold> {
    let mut out = Vec::new();
    collide(ground, at, body, pose, MARGIN, &mut out);
    out
}

#[test]
fn mesh_validation_names_the_entry() {
    let tri = vec![v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.0, 0.0, 1.0)];
    assert_eq!(
        message(TriMesh::new(tri.clone(), vec![])),
        "indices: must hold at least one triangle"
    );
    let mut bad = tri.clone();
    bad[1].y = Real::NAN;
    assert_eq!(
        message(TriMesh::new(bad, vec![[0, 1, 2]])),
        "vertices[1]: must be finite numbers"
    );
    let five = vec![Vec3::ZERO, Vec3::X, Vec3::Z, Vec3::Y, Vec3::ONE];
    assert_eq!(
        message(TriMesh::new(five.clone(), vec![[0, 1, 2], [0, 7, 1]])),
        "indices[1]: vertex index 7 out of range (5 vertices)"
    );
    assert_eq!(
        message(TriMesh::new(five.clone(), vec![[0, 2, 1], [0, 0, 1]])),
        "indices[1]: degenerate triangle (zero area)"
    );
    let collinear = vec![Vec3::ZERO, Vec3::ONE, Vec3::ONE * 2.0];
    assert_eq!(
        message(TriMesh::new(collinear, vec![[0, 1, 2]])),
        "indices[0]: degenerate triangle (zero area)"
    );
    assert!(TriMesh::new(tri, vec![[0, 2, 1]]).is_ok());
}

#[test]
fn heightfield_validation_names_the_field() {
    assert_eq!(
        message(HeightField::new(vec![0.0; 3], 1, 3, Vec3::ONE)),
        "heights: needs at least 2 rows and 2 columns (got 1 × 3)"
    );
    assert_eq!(
        message(HeightField::new(vec![0.0; 5], 2, 3, Vec3::ONE)),
        "heights: must hold rows × cols = 2 × 3 values (got 5)"
    );
    let mut h = vec![0.0; 6];
    h[4] = Real::INFINITY;
    assert_eq!(
        message(HeightField::new(h, 2, 3, Vec3::ONE)),
        "heights[4]: must be a finite number"
    );
    assert_eq!(
        message(HeightField::new(vec![0.0; 6], 2, 3, v(1.0, 0.0, 1.0))),
        "scale: every component must be > 0"
    );
    assert_eq!(
        message(HeightField::new(
            vec![0.0; 6],
            2,
            3,
            v(1.0, Real::NAN as f64, 1.0)
        )),
        "scale: must be finite numbers"
    );
    assert!(HeightField::new(vec![0.0; 6], 2, 3, Vec3::ONE).is_ok());
}

#[test]
fn adjacency_and_edge_kinds() {
    // The kinds by name: `EdgeKind` has no public path yet (shape/mod.rs does not
    // re-export it).
    let kinds = |m: &TriMesh, i: usize| m.edge_kinds(i).map(|k| k.map(|k| format!("{k:?}")));
    let floor = floor_mesh(2);
    for i in 0..floor.len() {
        for (k, kind) in kinds(&floor, i).unwrap().into_iter().enumerate() {
            let n = floor.neighbors(i).unwrap()[k];
            assert_eq!(kind == "Boundary", n.is_none());
            assert!(kind == "Boundary" || kind == "Flat");
        }
    }
    // A closed box: every edge convex.
    let h = 0.5;
    let c = |i: u32| {
        v(
            if i & 1 == 0 { -h } else { h },
            if i & 2 == 0 { -h } else { h },
            if i & 4 == 0 { -h } else { h },
        )
    };
    let faces: [[u32; 4]; 6] = [
        [0, 4, 6, 2],
        [1, 3, 7, 5],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 2, 3, 1],
        [4, 5, 7, 6],
    ];
    let mut idx = Vec::new();
    for [a, b, c, d] in faces {
        idx.extend([[a, b, c], [a, c, d]]);
    }
    let cube = TriMesh::new((0..8).map(c).collect(), idx).unwrap();
    for i in 0..12 {
        let k = kinds(&cube, i).unwrap();
        // Each triangle has one diagonal (flat) and two cube edges (convex).
        let convex = k.iter().filter(|k| *k == "Convex").count();
        let flat = k.iter().filter(|k| *k == "Flat").count();
        assert_eq!((convex, flat), (2, 1), "triangle {i}: {k:?}");
    }
    // A valley with per-triangle (duplicated) vertices: still joined, concave.
    let valley = TriMesh::new(
        vec![
            v(0.0, 0.0, 0.0),
            v(0.0, 0.0, 1.0),
            v(-1.0, 1.0, 0.0),
            v(0.0, 0.0, 1.0),
            v(0.0, 0.0, 0.0),
            v(1.0, 1.0, 0.0),
        ],
        vec![[0, 2, 1], [3, 5, 4]],
    )
    .unwrap();
    assert!(valley.normal(0).unwrap().y > 0.0 && valley.normal(1).unwrap().y > 0.0);
    assert_eq!(valley.neighbors(0).unwrap()[2], Some(1));
    assert_eq!(kinds(&valley, 0).unwrap()[2], "Concave");
    assert_eq!(kinds(&valley, 1).unwrap()[2], "Concave");
    assert_eq!(valley.edge_kinds(5), None);
}

fn random_mesh(points: &[[f64; 9]]) -> Option<TriMesh> {
    let mut vertices = Vec::new();
    let mut indices = Vec::new();
    for (i, p) in points.iter().enumerate() {
        for k in 0..3 {
            vertices.push(v(p[3 * k], p[3 * k + 1], p[3 * k + 2]));
        }
        let i = 3 * i as u32;
        indices.push([i, i + 1, i + 2]);
    }
    TriMesh::new(vertices, indices).ok()
}

fn tri_box(t: [Vec3; 3]) -> Aabb {
    Aabb::new(t[0].min(t[1]).min(t[2]), t[0].max(t[1]).max(t[2]))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn hierarchy_queries_equal_brute_force(
        // Small triangles scattered in a 20 m cube: corners near a random centre.
        tris in prop::collection::vec(
            (prop::array::uniform3(-10.0f64..10.0), prop::array::uniform9(-1.0f64..1.0)),
            1..300,
        ),
        boxes in prop::collection::vec(
            (prop::array::uniform3(-11.0f64..11.0), prop::array::uniform3(0.0f64..4.0)),
            8,
        ),
        rays in prop::collection::vec(
            (prop::array::uniform3(-12.0f64..12.0), prop::array::uniform3(-1.0f64..1.0)),
            8,
        ),
    ) {
        let points: Vec<[f64; 9]> = tris
            .iter()
            .map(|(c, d)| std::array::from_fn(|j| c[j % 3] + d[j]))
            .collect();
        let Some(mesh) = random_mesh(&points) else {
            return Ok(()); // a (vanishingly rare) degenerate triangle
        };
        for (c, h) in &boxes {
            let q = Aabb::from_center(v(c[0], c[1], c[2]), v(h[0], h[1], h[2]));
            let mut found = Vec::new();
            mesh.for_each_triangle_in(&q, |i| found.push(i));
            found.sort_unstable();
            let brute: Vec<usize> =
                (0..mesh.len()).filter(|&i| tri_box(mesh.triangle(i)).overlaps(&q)).collect();
            prop_assert_eq!(found, brute);
        }
        let shape = Shape::TriMesh(mesh.clone());
        for (o, d) in &rays {
            let ray = Ray::new(v(o[0], o[1], o[2]), v(d[0], d[1], d[2]));
            let hit = cast_ray(&shape, &Pose::IDENTITY, &ray, 30.0, true);
            // Brute force: every triangle, Möller–Trumbore in f64.
            let mut best: Option<f64> = None;
            for i in 0..mesh.len() {
                if let Some(t) = ray_triangle(&ray, mesh.triangle(i)) {
                    if t <= 30.0 && best.is_none_or(|b| t < b) {
                        best = Some(t);
                    }
                }
            }
            match (hit, best) {
                (None, None) => {}
                (Some(h), Some(b)) => {
                    prop_assert!((h.t as f64 - b).abs() <= tol(1e-9, 1e-3) as f64 * (1.0 + b));
                    let tri = mesh.triangle(h.subshape as usize);
                    prop_assert!(ray_triangle(&ray, tri).is_some());
                }
                (h, b) => {
                    // Only edge-grazing rays can disagree, by rounding.
                    let t = h.map(|h| h.t as f64).or(b).unwrap();
                    let p = ray.at(t as Real);
                    let near_edge = (0..mesh.len()).any(|i| {
                        let [a, b, c] = mesh.triangle(i);
                        [(a, b), (b, c), (c, a)].iter().any(|&(x, y)| {
                            let s = ((p - x).dot(y - x) / (y - x).length_squared()).clamp(0.0, 1.0);
                            (x + (y - x) * s - p).length() < 1e-4
                        })
                    });
                    prop_assert!(near_edge, "{:?} vs {:?}", h, b);
                }
            }
        }
        // Closest point against every triangle.
        for (c, _) in &boxes {
            let p = v(c[0], c[1], c[2]);
            let (q, _) = mesh.closest_point(p).unwrap();
            let brute = (0..mesh.len())
                .map(|i| (closest_on(p, mesh.triangle(i)) - p).length())
                .fold(Real::INFINITY, Real::min);
            prop_assert!(((q - p).length() - brute).abs() <= tol(1e-9, 1e-4));
        }
    }

    #[test]
    fn heightfield_box_query_equals_brute_force(
        heights in prop::collection::vec(-2.0f64..2.0, 35),
        c in prop::array::uniform3(-4.0f64..4.0), h in prop::array::uniform3(0.0f64..2.0),
    ) {
        let field = HeightField::new(
            heights.iter().map(|&x| x as Real).collect(), 5, 7, v(1.0, 0.5, 1.5),
        ).unwrap();
        let q = Aabb::from_center(v(c[0], c[1], c[2]), v(h[0], h[1], h[2]));
        let mut found = Vec::new();
        field.for_each_triangle_in(&q, |i, t| {
            assert_eq!(field.triangle(i), Some(t));
            found.push(i);
        });
        found.sort_unstable();
        let brute: Vec<usize> = (0..field.triangle_count())
            .filter(|&i| tri_box(field.triangle(i).unwrap()).overlaps(&q))
            .collect();
        prop_assert_eq!(found, brute);
        for i in 0..field.triangle_count() {
            prop_assert!(field.normal(i).unwrap().y > 0.0);
        }
    }

    #[test]
    fn heightfield_rays_and_projections_equal_brute_force(
        heights in prop::collection::vec(-2.0f64..2.0, 35),
        rays in prop::collection::vec(
            (prop::array::uniform3(-6.0f64..6.0), prop::array::uniform3(-1.0f64..1.0)),
            16,
        ),
    ) {
        let field = HeightField::new(
            heights.iter().map(|&x| x as Real).collect(), 5, 7, v(1.0, 0.5, 1.5),
        ).unwrap();
        let shape = Shape::HeightField(field.clone());
        for (o, d) in &rays {
            let ray = Ray::new(v(o[0], o[1] * 0.3, o[2]), v(d[0], d[1], d[2]));
            let hit = cast_ray(&shape, &Pose::IDENTITY, &ray, 20.0, true);
            let mut best: Option<f64> = None;
            for i in 0..field.triangle_count() {
                if let Some(t) = ray_triangle(&ray, field.triangle(i).unwrap()) {
                    if t <= 20.0 && best.is_none_or(|b| t < b) {
                        best = Some(t);
                    }
                }
            }
            match (hit, best) {
                (None, None) => {}
                (Some(h), Some(b)) => {
                    let eps = tol(1e-9, 1e-3) as f64 * (1.0 + b);
                    prop_assert!((h.t as f64 - b).abs() <= eps, "{h:?} vs {b}");
                }
                (h, b) => {
                    // Only rays grazing an edge may disagree, by rounding.
                    let t = h.map(|h| h.t as f64).or(b).unwrap();
                    let p = ray.at(t as Real);
                    let near_edge = (0..field.triangle_count()).any(|i| {
                        let [a, b, c] = field.triangle(i).unwrap();
                        [(a, b), (b, c), (c, a)].iter().any(|&(x, y)| {
                            let s = ((p - x).dot(y - x) / (y - x).length_squared()).clamp(0.0, 1.0);
                            (x + (y - x) * s - p).length() < 1e-4
                        })
                    });
                    prop_assert!(near_edge, "{:?} vs {:?}", h, b);
                }
            }
            // The nearest surface point to the ray's origin.
            let p = ray.origin;
            let (q, _) = field.closest_point(p).unwrap();
            let brute = (0..field.triangle_count())
                .map(|i| (closest_on(p, field.triangle(i).unwrap()) - p).length())
                .fold(Real::INFINITY, Real::min);
            prop_assert!(((q - p).length() - brute).abs() <= tol(1e-9, 1e-4));
        }
    }

    #[test]
    fn random_meshes_give_finite_contacts(
        tris in prop::collection::vec(
            (prop::array::uniform3(-2.0f64..2.0), prop::array::uniform9(-1.0f64..1.0)),
            1..40,
        ),
        bodies in prop::collection::vec(
            (prop::array::uniform3(-2.0f64..2.0), prop::array::uniform3(-1.0f64..1.0), 0usize..4),
            6,
        ),
    ) {
        let points: Vec<[f64; 9]> = tris
            .iter()
            .map(|(c, d)| std::array::from_fn(|j| c[j % 3] + d[j]))
            .collect();
        let Some(mesh) = random_mesh(&points) else {
            return Ok(());
        };
        let count = mesh.len();
        let ground = Shape::TriMesh(mesh);
        let shapes = [
            Shape::sphere(0.4),
            Shape::cuboid(v(0.3, 0.2, 0.5)),
            Shape::capsule(0.2, 0.4),
            Shape::cylinder(0.3, 0.3),
        ];
        for (p, r, k) in &bodies {
            let rot = v(r[0], r[1], r[2]);
            let pose = Pose::new(
                v(p[0], p[1], p[2]),
                Quat::from_axis_angle(rot.normalize_or(Vec3::Y), rot.length() * 3.0),
            );
            for m in contacts(&ground, &Pose::IDENTITY, &shapes[*k], &pose) {
                prop_assert!((m.normal.length() - 1.0).abs() < tol(1e-9, 1e-4), "{m:?}");
                prop_assert!((m.subshape_a as usize) < count);
                prop_assert!(!m.is_empty());
                for c in m.points() {
                    prop_assert!(c.point_a.is_finite() && c.point_b.is_finite());
                    prop_assert!(c.separation <= MARGIN + tol(1e-9, 1e-4), "{m:?}");
                }
            }
        }
    }
}

/// Möller–Trumbore in f64, both sides, as an independent reference.
fn ray_triangle(ray: &Ray, t: [Vec3; 3]) -> Option<f64> {
    let f = |x: Vec3| glam::DVec3::new(x.x as f64, x.y as f64, x.z as f64);
    let (o, d, a, b, c) = (f(ray.origin), f(ray.direction), f(t[0]), f(t[1]), f(t[2]));
    let (e1, e2) = (b - a, c - a);
    let p = d.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-300 {
        return None;
    }
    let s = o - a;
    let u = s.dot(p) / det;
    let q = s.cross(e1);
    let w = d.dot(q) / det;
    let t = e2.dot(q) / det;
    (u >= 0.0 && w >= 0.0 && u + w <= 1.0 && t >= 0.0).then_some(t)
}

/// Closest point on a triangle by brute force over a face projection and the three edges.
fn closest_on(p: Vec3, t: [Vec3; 3]) -> Vec3 {
    let n = (t[1] - t[0]).cross(t[2] - t[0]).normalize();
    let foot = p - n * n.dot(p - t[0]);
    let inside = (0..3).all(|k| {
        let (a, b) = (t[k], t[(k + 1) % 3]);
        (b - a).cross(foot - a).dot(n) >= 0.0
    });
    if inside {
        return foot;
    }
    (0..3)
        .map(|k| {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let s = ((p - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
            a + (b - a) * s
        })
        .min_by(|x, y| (*x - p).length().total_cmp(&(*y - p).length()))
        .unwrap()
}

/// Every normal straight up (from the ground to the body), every separation `depth`, no
/// point reported twice.
fn assert_flat_contacts(ms: &[Manifold], up: Vec3, depth: Real, what: &str) {
    assert!(!ms.is_empty(), "{what}: no contact");
    let eps = tol(1e-9, 1e-5);
    let mut points: Vec<Vec3> = Vec::new();
    for m in ms {
        assert!(
            (m.normal - up).length() <= eps,
            "{what}: ghost normal {:?}",
            m.normal
        );
        for p in m.points() {
            assert!(
                (p.separation - depth).abs() <= tol(1e-7, 1e-4),
                "{what}: separation {p:?}"
            );
            assert!(
                points.iter().all(|q| (*q - p.point_b).length() > eps),
                "{what}: duplicate point {:?}",
                p.point_b
            );
            points.push(p.point_b);
        }
    }
}

#[test]
fn box_slides_across_mesh_and_field_seams_without_ghost_normals() {
    let grounds = [
        Shape::TriMesh(floor_mesh(10)),
        Shape::HeightField(floor_field(10)),
    ];
    let bx = Shape::cuboid(v(0.4, 0.25, 0.3));
    let at = Pose::from_translation(v(0.0, -1.0, 0.0)); // the floor's surface at y = −1
    for ground in &grounds {
        for depth in [-0.001, 0.0, 0.005] {
            // Across a column of seams and the diagonals, from x = −2 to 2; z at a row seam
            // (0), a vertex row, and mid-cell.
            for z in [0.0, 0.5, 0.37] {
                for step in 0..=80 {
                    let x = -2.0 + step as f64 * 0.05;
                    for yaw in [0.0, 0.3] {
                        let pose = Pose::new(
                            v(x, -1.0 + 0.25 + depth, z),
                            Quat::from_rotation_y(yaw as Real),
                        );
                        let ms = contacts(ground, &at, &bx, &pose);
                        let what =
                            format!("{} x {x} z {z} depth {depth} yaw {yaw}", ground.kind_name());
                        assert_flat_contacts(&ms, Vec3::Y, depth as Real, &what);
                        let n: usize = ms.iter().map(|m| m.len()).sum();
                        assert!(n >= 4, "{what}: {n} points");
                    }
                }
            }
        }
    }
}

#[test]
fn tilted_floor_normals_follow_the_floor() {
    let tilt = Quat::from_rotation_z(0.4);
    let at = Pose::new(v(1.0, 2.0, 3.0), tilt);
    let up = tilt * Vec3::Y;
    let bx = Shape::cuboid(v(0.4, 0.25, 0.3));
    for ground in [
        Shape::TriMesh(floor_mesh(6)),
        Shape::HeightField(floor_field(6)),
    ] {
        for x in [0.0, 0.5, 0.73, 1.0] {
            let local = Pose::new(v(x, 0.25 - 0.002, 0.5), Quat::IDENTITY);
            let pose = at.mul(&local);
            let ms = contacts(&ground, &at, &bx, &pose);
            assert_flat_contacts(&ms, up, -0.002, &format!("{} x {x}", ground.kind_name()));
        }
    }
}

#[test]
fn sphere_on_a_flat_mesh_gets_one_contact() {
    let ball = Shape::sphere(0.5);
    for ground in [
        Shape::TriMesh(floor_mesh(4)),
        Shape::HeightField(floor_field(4)),
    ] {
        // Inside a triangle, on a diagonal, on a cell edge, on a vertex shared by six.
        for (x, z) in [(0.3, 0.6), (0.5, 0.5), (0.0, 0.4), (0.0, 0.0), (1.0, -1.0)] {
            let pose = Pose::from_translation(v(x, 0.5 - 0.001, z));
            let ms = contacts(&ground, &Pose::IDENTITY, &ball, &pose);
            let what = format!("{} at ({x}, {z})", ground.kind_name());
            assert_flat_contacts(&ms, Vec3::Y, -0.001, &what);
            let n: usize = ms.iter().map(|m| m.len()).sum();
            assert_eq!(n, 1, "{what}: {ms:?}");
            let p = ms[0].points()[0].point_a; // on the ground (A)
            assert!((p - v(x, 0.0, z)).length() < tol(1e-9, 1e-5), "{what}: {p}");
        }
    }
}

#[test]
fn bodies_behind_the_surface_are_not_pulled_through() {
    let single = TriMesh::new(
        vec![v(-2.0, 0.0, -2.0), v(-2.0, 0.0, 2.0), v(2.0, 0.0, 0.0)],
        vec![[0, 1, 2]],
    )
    .unwrap();
    assert_eq!(single.normal(0), Some(Vec3::Y));
    let bx = Shape::cuboid(v(0.3, 0.3, 0.3));
    for ground in [
        Shape::TriMesh(single),
        Shape::TriMesh(floor_mesh(4)),
        Shape::HeightField(floor_field(4)),
    ] {
        let kind = ground.kind_name();
        // Just under the back face, within the margin: nothing, in particular no push up.
        for top in [-0.005, -0.015, 0.0] {
            let pose = Pose::from_translation(v(0.1, top - 0.3, 0.1));
            let ms = contacts(&ground, &Pose::IDENTITY, &bx, &pose);
            assert!(ms.is_empty(), "{kind} top {top}: {ms:?}");
        }
        // Mostly below, poking through: still not pushed up through the surface.
        let pose = Pose::from_translation(v(0.1, -0.2, 0.1));
        let ms = contacts(&ground, &Pose::IDENTITY, &bx, &pose);
        assert!(
            ms.iter().all(|m| m.normal.y <= 0.0),
            "{kind} poking: {ms:?}"
        );
        // The same box just above the surface does touch.
        let pose = Pose::from_translation(v(0.1, 0.3 - 0.001, 0.1));
        let ms = contacts(&ground, &Pose::IDENTITY, &bx, &pose);
        assert_flat_contacts(&ms, Vec3::Y, -0.001, kind);
    }
}

#[test]
fn free_edges_still_push_sideways() {
    // A single triangle's border is a real edge: a sphere beside it is pushed out sideways.
    let single = Shape::TriMesh(
        TriMesh::new(
            vec![v(0.0, 0.0, -2.0), v(0.0, 0.0, 2.0), v(2.0, 0.0, 0.0)],
            vec![[0, 1, 2]],
        )
        .unwrap(),
    );
    let ball = Shape::sphere(0.5);
    let pose = Pose::from_translation(v(-0.49, 0.1, 0.0));
    let ms = contacts(&single, &Pose::IDENTITY, &ball, &pose);
    assert_eq!(ms.len(), 1, "{ms:?}");
    let expected = v(-0.49, 0.1, 0.0).normalize();
    assert!(
        (ms[0].normal - expected).length() < tol(1e-6, 1e-3),
        "{ms:?}"
    );
}

#[test]
fn every_convex_kind_rests_flat_across_seams() {
    let hull = Shape::convex_hull(&[
        v(-0.3, -0.2, -0.3),
        v(0.4, -0.2, -0.2),
        v(0.0, -0.2, 0.4),
        v(0.0, 0.3, 0.0),
    ])
    .unwrap();
    let lying = Quat::from_rotation_z(std::f64::consts::FRAC_PI_2 as Real);
    let bodies = [
        (Shape::capsule(0.2, 0.6), lying, 0.2),
        (Shape::cylinder(0.3, 0.5), Quat::IDENTITY, 0.5),
        (Shape::cylinder(0.3, 0.5), lying, 0.3),
        (hull, Quat::from_rotation_y(0.4), 0.2),
    ];
    for ground in [
        Shape::TriMesh(floor_mesh(6)),
        Shape::HeightField(floor_field(6)),
    ] {
        for (body, rotation, rest) in &bodies {
            for (x, z) in [(0.0, 0.0), (0.5, 0.5), (0.25, -0.6), (1.0, 0.3)] {
                let pose = Pose::new(v(x, *rest as f64 - 0.001, z), *rotation);
                let ms = contacts(&ground, &Pose::IDENTITY, body, &pose);
                let what = format!(
                    "{} on {} at ({x}, {z})",
                    body.kind_name(),
                    ground.kind_name()
                );
                assert_flat_contacts(&ms, Vec3::Y, -0.001, &what);
            }
        }
    }
}

#[test]
fn a_ball_on_a_ridge_touches_the_ridge() {
    // A roof along z: two faces falling away from the ridge at x = 0 (a convex edge).
    let roof = TriMesh::new(
        vec![
            v(0.0, 0.0, -2.0),
            v(0.0, 0.0, 2.0),
            v(-2.0, -0.5, 0.0),
            v(2.0, -0.5, 0.0),
        ],
        vec![[0, 2, 1], [0, 1, 3]],
    )
    .unwrap();
    assert_eq!(format!("{:?}", roof.edge_kinds(0).unwrap()[2]), "Convex");
    let roof = Shape::TriMesh(roof);
    let ball = Shape::sphere(0.5);
    for x in [0.0, 0.02, -0.05] {
        let pose = Pose::from_translation(v(x, 0.5 - 0.001, 0.3));
        let ms = contacts(&roof, &Pose::IDENTITY, &ball, &pose);
        let n: usize = ms.iter().map(|m| m.len()).sum();
        assert_eq!(n, 1, "x {x}: {ms:?}");
        // The normal runs from the ridge point to the centre.
        let expected = v(x, 0.5 - 0.001, 0.0).normalize();
        assert!(
            (ms[0].normal - expected).length() < tol(1e-9, 1e-5),
            "x {x}: {ms:?}"
        );
    }
}

#[test]
fn a_box_slides_over_a_mesh_floor_as_over_a_plane() {
    // End to end through the world: a frictionless box sliding at 3 m/s for 4 s crosses
    // 12 cells' worth of seams and diagonals. Ghost normals would kick it up or stop it
    // dead; without them it moves exactly as on a plane. A corner reaching the next
    // triangle keeps its warm start (`contact_cache::warm_start_across`): measured |v_y|
    // up to 2.5e-4 m/s (8.7e-5 on the plane), 5.4e-4 when such points restarted from zero.
    let slide = |ground: Shape| {
        let mut w = World::new(&WorldDef::default());
        let fixed = BodyDef {
            kind: BodyKind::Static,
            friction: 0.0,
            ..Default::default()
        };
        w.create_body(&fixed, ground).unwrap();
        let def = BodyDef {
            position: v(-6.0, 0.25, 0.3),
            friction: 0.0,
            ..Default::default()
        };
        let b = w
            .create_body(&def, Shape::cuboid(v(0.4, 0.25, 0.3)))
            .unwrap();
        w.set_linear_velocity(b, v(3.0, 0.0, 0.0)).unwrap();
        let (mut max_vy, mut min_vx): (Real, Real) = (0.0, Real::INFINITY);
        for _ in 0..240 {
            w.step(1.0 / 60.0).unwrap();
            let v = w.body(b).unwrap().linear_velocity();
            max_vy = max_vy.max(v.y.abs());
            min_vx = min_vx.min(v.x);
        }
        (w.body(b).unwrap().position(), max_vy, min_vx)
    };
    let (on_plane, _, _) = slide(Shape::plane(Vec3::Y, 0.0));
    for ground in [
        Shape::TriMesh(floor_mesh(20)),
        Shape::HeightField(floor_field(20)),
    ] {
        let kind = ground.kind_name();
        let (p, max_vy, min_vx) = slide(ground);
        assert!(max_vy < 4e-4, "{kind}: bounced, |vy| up to {max_vy}");
        assert!(min_vx > 2.99, "{kind}: slowed to {min_vx}");
        assert!((p - on_plane).length() < 1e-3, "{kind}: {p} vs {on_plane}");
    }
}
