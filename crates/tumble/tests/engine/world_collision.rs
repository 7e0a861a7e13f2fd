//! Collision detection through the world: broad phase + narrow phase + persistence, layer
//! filtering, and the world queries.

// Casts between Real and f64 are no-ops in the default build but needed in the f32 one.
#![allow(clippy::unnecessary_cast)]

use crate::common::*;
use tumble::prelude::*;
use tumble::{Pose, QueryFilter, Ray};

fn ground(w: &mut World) -> BodyId {
    w.create_body(
        &BodyDef {
            kind: BodyKind::Static,
            ..Default::default()
        },
        Shape::plane(Vec3::Y, 0.0),
    )
    .unwrap()
}

fn cube_at(w: &mut World, p: Vec3) -> BodyId {
    w.create_body(
        &BodyDef {
            position: p,
            ..Default::default()
        },
        Shape::cuboid(Vec3::splat(0.5)),
    )
    .unwrap()
}

#[test]
fn a_box_resting_on_the_ground_has_four_persistent_contacts() {
    let mut w = world(Vec3::ZERO, Integrator::default());
    let g = ground(&mut w);
    let b = cube_at(&mut w, Vec3::new(0.3, 0.5 - 0.001, -0.2));
    let contacts = w.update_contacts().to_vec();
    assert_eq!(contacts.len(), 1, "{contacts:?}");
    let c = &contacts[0];
    // Body order follows creation: the ground is A, the normal points from it up... into B.
    assert_eq!((c.body_a, c.body_b), (g, b));
    assert!(
        (c.manifold.normal - Vec3::Y).length() < tol(1e-12, 1e-6),
        "{:?}",
        c.manifold.normal
    );
    assert_eq!(c.manifold.len(), 4);
    for p in c.manifold.points() {
        assert!((p.separation + 0.001).abs() < tol(1e-9, 1e-5), "{p:?}");
        assert!((p.point_b.x - 0.3).abs() > 0.49 && (p.point_b.z + 0.2).abs() > 0.49);
    }
    // Impulses written by a solver survive the next update where the features match.
    let features: Vec<u32> = c.manifold.points().iter().map(|p| p.feature).collect();
    w.set_position(b, Vec3::new(0.3001, 0.5 - 0.0011, -0.2))
        .unwrap();
    let again = w.update_contacts();
    let now: Vec<u32> = again[0]
        .manifold
        .points()
        .iter()
        .map(|p| p.feature)
        .collect();
    assert_eq!(features, now);
}

#[test]
fn speculative_contacts_appear_within_the_margin_only() {
    let mut w = world(Vec3::ZERO, Integrator::default());
    ground(&mut w);
    let b = cube_at(&mut w, Vec3::new(0.0, 0.5 + 0.01, 0.0));
    let seps: Vec<Real> = w.update_contacts()[0]
        .manifold
        .points()
        .iter()
        .map(|p| p.separation)
        .collect();
    assert!(
        seps.iter().all(|s| (s - 0.01).abs() < tol(1e-9, 1e-5)),
        "{seps:?}"
    );
    w.set_position(b, Vec3::new(0.0, 0.5 + 2.0 * w.contact_margin(), 0.0))
        .unwrap();
    assert!(w.update_contacts().is_empty());
}

#[test]
fn collision_layers_filter_pairs() {
    let mut w = world(Vec3::ZERO, Integrator::default());
    let def = |x: Real, group: u32, mask: u32| BodyDef {
        position: Vec3::new(x, 0.0, 0.0),
        collision_group: group,
        collision_mask: mask,
        ..Default::default()
    };
    let a = w
        .create_body(&def(0.0, 0b01, 0b01), Shape::sphere(0.5))
        .unwrap();
    let b = w
        .create_body(&def(0.9, 0b10, 0b11), Shape::sphere(0.5))
        .unwrap();
    let c = w
        .create_body(&def(-0.9, 0b01, 0b11), Shape::sphere(0.5))
        .unwrap();
    let pairs: Vec<(BodyId, BodyId)> = w
        .update_contacts()
        .iter()
        .map(|c| (c.body_a, c.body_b))
        .collect();
    // a ignores b (a's mask lacks b's group); a and c share layer 1.
    assert_eq!(pairs, vec![(a, c)]);
    let _ = b;
}

#[test]
fn ray_queries_find_the_nearest_and_all_hits() {
    let mut w = world(Vec3::ZERO, Integrator::default());
    let g = ground(&mut w);
    let near = w
        .create_body(
            &BodyDef {
                position: Vec3::new(0.0, 1.0, 0.0),
                ..Default::default()
            },
            Shape::sphere(0.25),
        )
        .unwrap();
    let far = cube_at(&mut w, Vec3::new(0.0, 3.0, 0.0));
    let down = Ray::new(Vec3::new(0.0, 10.0, 0.0), -Vec3::Y);
    let hit = w.cast_ray(&down, 100.0, &QueryFilter::default()).unwrap();
    assert_eq!(hit.body, far);
    assert!(
        (hit.hit.t - 6.5).abs() < tol(1e-12, 1e-5)
            && (hit.hit.normal - Vec3::Y).length() < tol(1e-12, 1e-6)
    );
    let all: Vec<(BodyId, Real)> = w
        .cast_ray_all(&down, 100.0, &QueryFilter::default())
        .iter()
        .map(|h| (h.body, h.hit.t))
        .collect();
    assert_eq!(
        all.iter().map(|h| h.0).collect::<Vec<_>>(),
        vec![far, near, g]
    );
    assert!(
        (all[1].1 - 8.75).abs() < tol(1e-12, 1e-5) && (all[2].1 - 10.0).abs() < tol(1e-12, 1e-5)
    );
    let skip_far = QueryFilter {
        exclude: Some(far),
        ..Default::default()
    };
    assert_eq!(w.cast_ray(&down, 100.0, &skip_far).unwrap().body, near);
    assert!(w.cast_ray(&down, 5.0, &QueryFilter::default()).is_none());

    assert_eq!(
        w.query_point(Vec3::new(0.1, 1.1, 0.0), &QueryFilter::default()),
        vec![near]
    );
    assert_eq!(
        w.query_point(Vec3::new(0.0, -1.0, 0.0), &QueryFilter::default()),
        vec![g]
    );
    let box_query = tumble::Aabb::new(Vec3::new(-1.0, 0.5, -1.0), Vec3::new(1.0, 2.6, 1.0));
    assert_eq!(
        w.query_aabb(&box_query, &QueryFilter::default()),
        vec![near, far]
    );
}

#[test]
fn shape_casts_stop_at_the_first_surface() {
    let mut w = world(Vec3::ZERO, Integrator::default());
    let g = ground(&mut w);
    let target = cube_at(&mut w, Vec3::new(3.0, 0.5, 0.0));
    // A sphere of radius 0.25 dropped from y = 2 reaches the ground after 1.75 m of 4.
    let hit = w
        .cast_shape(
            &Shape::sphere(0.25),
            &Pose::from_translation(Vec3::new(0.0, 2.0, 0.0)),
            Vec3::new(0.0, -4.0, 0.0),
            &QueryFilter::default(),
        )
        .unwrap()
        .unwrap();
    assert_eq!(hit.body, g);
    assert!(
        (hit.hit.t - 1.75 / 4.0).abs() < tol(1e-12, 1e-6),
        "{:?}",
        hit.hit
    );
    // Sideways it meets the cube's face at x = 2.5 after 2.25 m of 3.
    let hit = w
        .cast_shape(
            &Shape::sphere(0.25),
            &Pose::from_translation(Vec3::new(0.0, 0.5, 0.0)),
            Vec3::new(3.0, 0.0, 0.0),
            &QueryFilter {
                exclude: Some(g),
                ..Default::default()
            },
        )
        .unwrap()
        .unwrap();
    assert_eq!(hit.body, target);
    assert!(
        (hit.hit.t - 2.25 / 3.0).abs() < tol(1e-6, 1e-4),
        "{:?}",
        hit.hit
    );
    assert!(w
        .cast_shape(
            &Shape::plane(Vec3::Y, 0.0),
            &Pose::IDENTITY,
            Vec3::X,
            &QueryFilter::default()
        )
        .is_err());
}

#[test]
fn removing_a_body_removes_its_contacts_and_proxy() {
    let mut w = world(Vec3::ZERO, Integrator::default());
    ground(&mut w);
    let a = cube_at(&mut w, Vec3::new(0.0, 0.49, 0.0));
    let b = cube_at(&mut w, Vec3::new(5.0, 0.49, 0.0));
    assert_eq!(w.update_contacts().len(), 2);
    w.remove_body(a).unwrap();
    let left: Vec<BodyId> = w.update_contacts().iter().map(|c| c.body_b).collect();
    assert_eq!(left, vec![b]);
    let down = Ray::new(Vec3::new(0.0, 10.0, 0.0), -Vec3::Y);
    assert_ne!(
        w.cast_ray(&down, 100.0, &QueryFilter::default())
            .unwrap()
            .body,
        a
    );
}
