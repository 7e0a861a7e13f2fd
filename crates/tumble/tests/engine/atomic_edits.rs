//! Edits are all or nothing: a refused edit leaves the world bit-identical (by its state
//! hash), and a bulk edit of every body is checked whole before any body changes.

// Casts between Real and f64 are no-ops in the default build but needed in the f32 one.
#![allow(clippy::unnecessary_cast)]

use crate::common;
use tumble::prelude::*;
use tumble::BodyStates;

/// Four bodies of different kinds and shapes, two of them touching, one planar, so that a
/// bulk edit meets every rule the single setters apply.
fn busy_world() -> World {
    let mut w = World::new(&WorldDef::default());
    let defs = [
        BodyDef {
            position: Vec3::new(0.0, 0.5, 0.0),
            ..Default::default()
        },
        BodyDef {
            position: Vec3::new(0.0, 1.45, 0.0),
            orientation: Quat::from_rotation_z(0.3),
            ..Default::default()
        },
        BodyDef {
            position: Vec3::new(3.0, 0.0, 0.0),
            planar: true,
            ..Default::default()
        },
        BodyDef {
            position: Vec3::new(-3.0, 0.0, 0.0),
            kind: BodyKind::Static,
            ..Default::default()
        },
    ];
    let shapes = [
        Shape::cuboid(Vec3::splat(0.5)),
        Shape::cuboid(Vec3::new(0.5, 0.25, 0.5)),
        Shape::sphere(0.2),
        Shape::sphere(1.0),
    ];
    for (def, shape) in defs.iter().zip(shapes) {
        w.create_body(def, shape).unwrap();
    }
    common::run(&mut w, 0.01, 3);
    w
}

fn vecs(f: impl Fn(Real) -> Vec3) -> Vec<Vec3> {
    (0..4).map(|i| f(i as Real)).collect()
}

fn good_quats() -> Vec<Quat> {
    (0..4)
        .map(|i| Quat::from_xyzw(0.1 * i as Real, 0.2, 0.0, 1.0))
        .collect()
}

/// Refuses `states` with `message`, leaving the world's state hash as it was.
fn refused(w: &mut World, states: &BodyStates<'_>, message: &str) {
    let before = w.state_hash();
    let e = w.set_states(states).unwrap_err();
    assert_eq!(e.to_string(), message);
    assert_eq!(
        w.state_hash(),
        before,
        "a refused bulk edit changed the world"
    );
}

#[test]
fn good_positions_with_a_bad_velocity_row_move_nothing() {
    let mut w = busy_world();
    let positions = vecs(|i| Vec3::new(i, 7.0, 0.0));
    let mut velocities = vecs(|i| Vec3::new(i, 0.0, 0.0));
    velocities[3] = Vec3::new(0.0, Real::NAN, 0.0);
    let states = BodyStates {
        positions: Some(&positions),
        velocities: Some(&velocities),
        ..Default::default()
    };
    refused(&mut w, &states, "velocities[3]: must be finite numbers");
}

#[test]
fn one_bad_orientation_row_rewrites_no_other_row() {
    let mut w = busy_world();
    let mut q = good_quats();
    q[2] = Quat::from_xyzw(0.0, 0.0, 0.0, 0.0);
    let states = BodyStates {
        orientations: Some(&q),
        ..Default::default()
    };
    refused(
        &mut w,
        &states,
        "orientations[2]: must be a non-zero quaternion [x, y, z, w]",
    );
    q[2] = Quat::from_xyzw(0.0, Real::INFINITY, 0.0, 1.0);
    refused(
        &mut w,
        &states_of(&q),
        "orientations[2]: must be finite numbers",
    );
}

fn states_of(q: &[Quat]) -> BodyStates<'_> {
    BodyStates {
        orientations: Some(q),
        ..Default::default()
    }
}

#[test]
fn rows_beyond_the_limits_are_refused_with_the_limit() {
    let mut w = busy_world();
    let mut p = vecs(Vec3::splat);
    p[1].x = 1e12;
    let states = BodyStates {
        positions: Some(&p),
        ..Default::default()
    };
    refused(
        &mut w,
        &states,
        "positions[1]: must be at most 1e9 m in magnitude",
    );
    let mut v = vecs(|_| Vec3::ZERO);
    v[0] = Vec3::new(0.0, 0.0, 2e4);
    let states = BodyStates {
        velocities: Some(&v),
        ..Default::default()
    };
    refused(
        &mut w,
        &states,
        "velocities[0]: must be no longer than 10000 m/s (max_speed)",
    );
    let mut omega = vecs(|_| Vec3::ZERO);
    omega[3] = Vec3::new(2e5, 0.0, 0.0);
    let states = BodyStates {
        angular_velocities: Some(&omega),
        ..Default::default()
    };
    refused(
        &mut w,
        &states,
        "angular_velocities[3]: must be no longer than 100000 rad/s (max_angular_speed)",
    );
}

#[test]
fn an_array_without_one_row_per_body_is_refused() {
    let mut w = busy_world();
    let p = vec![Vec3::ZERO; 3];
    let states = BodyStates {
        positions: Some(&p),
        ..Default::default()
    };
    refused(
        &mut w,
        &states,
        "positions: expected 4 rows (one per body), got 3",
    );
}

#[test]
fn a_bulk_edit_is_the_single_edits_bit_for_bit() {
    let (mut bulk, mut single) = (busy_world(), busy_world());
    let positions = vecs(|i| Vec3::new(i, 2.0 + i, -i));
    let orientations = good_quats();
    let velocities = vecs(|i| Vec3::new(1.0, i, 0.5));
    let omegas = vecs(|i| Vec3::new(0.0, i, 1.0));
    bulk.set_states(&BodyStates {
        positions: Some(&positions),
        orientations: Some(&orientations),
        velocities: Some(&velocities),
        angular_velocities: Some(&omegas),
    })
    .unwrap();
    let ids = single.body_ids().to_vec();
    for (&id, &p) in ids.iter().zip(&positions) {
        single.set_position(id, p).unwrap();
    }
    for (&id, &q) in ids.iter().zip(&orientations) {
        single.set_orientation(id, q).unwrap();
    }
    for (&id, &v) in ids.iter().zip(&velocities) {
        single.set_linear_velocity(id, v).unwrap();
    }
    for (&id, &w) in ids.iter().zip(&omegas) {
        single.set_angular_velocity(id, w).unwrap();
    }
    assert_eq!(bulk.state_hash(), single.state_hash());
    // The edit is what was asked, less what a body's kind and plane forbid.
    let b = bulk.body(ids[1]).unwrap();
    let tol = common::tol(1e-12, 1e-5);
    assert!((b.position() - positions[1]).length() < tol);
    assert!((b.linear_velocity() - velocities[1]).length() < tol);
    let planar = bulk.body(ids[2]).unwrap();
    assert_eq!(planar.linear_velocity().z, 0.0);
    assert_eq!(bulk.body(ids[3]).unwrap().linear_velocity(), Vec3::ZERO);
    // And the two worlds go on the same.
    common::run(&mut bulk, 0.01, 20);
    common::run(&mut single, 0.01, 20);
    assert_eq!(bulk.state_hash(), single.state_hash());
}

#[test]
fn nothing_given_changes_nothing() {
    let mut w = busy_world();
    let before = w.state_hash();
    w.set_states(&BodyStates::default()).unwrap();
    assert_eq!(w.state_hash(), before);
}
