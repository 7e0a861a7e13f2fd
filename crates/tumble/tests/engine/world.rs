//! World bookkeeping that physics depends on: body kinds, ids, removal, edits.

// Casts between Real and f64 are no-ops in the default build but needed in the f32 one.
#![allow(clippy::unnecessary_cast)]

use crate::common::*;
use tumble::prelude::*;

#[test]
fn static_bodies_stay_and_kinematic_bodies_follow_their_velocity_exactly() {
    for integrator in Integrator::ALL {
        let mut w = world(Vec3::new(0.0, -9.8, 0.0), integrator);
        let fixed = w
            .create_body(
                &BodyDef {
                    kind: BodyKind::Static,
                    position: Vec3::new(0.0, 1.0, 0.0),
                    ..Default::default()
                },
                Shape::cuboid(Vec3::ONE),
            )
            .unwrap();
        let spin = Vec3::new(0.0, 0.0, 2.0);
        let mover = w
            .create_body(
                &BodyDef {
                    kind: BodyKind::Kinematic,
                    linear_velocity: Vec3::new(1.0, 0.0, 0.0),
                    angular_velocity: spin,
                    ..Default::default()
                },
                Shape::sphere(0.5),
            )
            .unwrap();
        // A dynamic body hanging from the kinematic one is dragged along; the kinematic
        // body does not feel the spring's reaction.
        let bob = ball(&mut w, Vec3::new(0.0, -1.0, 0.0));
        w.add_force(Force::Spring(Spring {
            body: bob,
            anchor: Vec3::ZERO,
            other: SpringEnd::Body {
                body: mover,
                anchor: Vec3::ZERO,
            },
            stiffness: 200.0,
            rest_length: 1.0,
            damping: 5.0,
        }))
        .unwrap();
        run(&mut w, 0.01, 200);
        let k = w.body(mover).unwrap();
        assert!(
            (k.position() - Vec3::new(2.0, 0.0, 0.0)).length() < tol(1e-12, 1e-5),
            "{}",
            integrator.name()
        );
        let expect = Quat::from_rotation_z(4.0);
        assert!(
            k.orientation().dot(expect).abs() > 1.0 - tol(1e-12, 1e-6),
            "{}",
            integrator.name()
        );
        assert_eq!(w.body(fixed).unwrap().position(), Vec3::new(0.0, 1.0, 0.0));
        assert!(
            w.body(bob).unwrap().position().x > 1.0,
            "{}: bob not dragged",
            integrator.name()
        );
        // Only the dynamic body counts in the diagnostics.
        let d = w.diagnostics();
        let b = w.body(bob).unwrap();
        assert!((d.linear_momentum - b.linear_velocity()).length() < tol(1e-12, 1e-5));
    }
}

#[test]
fn removed_bodies_leave_stale_ids_and_take_their_forces_along() {
    let mut w = world(Vec3::ZERO, Integrator::default());
    let a = ball(&mut w, Vec3::ZERO);
    let b = ball(&mut w, Vec3::X);
    let c = ball(&mut w, Vec3::Y);
    w.add_force(Force::Spring(Spring {
        body: a,
        anchor: Vec3::ZERO,
        other: SpringEnd::Body {
            body: b,
            anchor: Vec3::ZERO,
        },
        stiffness: 1.0,
        rest_length: 0.0,
        damping: 0.0,
    }))
    .unwrap();
    w.add_force(Force::Drag(Drag {
        body: c,
        linear: 1.0,
        quadratic: 0.0,
    }))
    .unwrap();
    w.remove_body(b).unwrap();
    assert_eq!(w.forces().count(), 1);
    assert!(w.body(b).is_err());
    assert!(w.remove_body(b).is_err());
    // The slot is reused, but the old id stays dead.
    let d = ball(&mut w, Vec3::Z);
    assert_eq!(d.index, b.index);
    assert!(w.body(b).is_err());
    assert_eq!(w.body_ids(), &[a, c, d]);
    assert_eq!(w.body(c).unwrap().position(), Vec3::Y);
    // Forces naming a dead body are refused.
    let err = w
        .add_force(Force::Drag(Drag {
            body: b,
            linear: 1.0,
            quadratic: 0.0,
        }))
        .unwrap_err();
    assert_eq!(err.field(), "body");
    run(&mut w, 0.01, 10);
}

#[test]
fn edits_take_effect_and_bad_edits_change_nothing() {
    let mut w = world(Vec3::ZERO, Integrator::Verlet);
    let id = w
        .create_body(
            &BodyDef {
                name: Some("box".into()),
                ..Default::default()
            },
            Shape::cuboid(Vec3::new(0.3, 0.2, 0.1)),
        )
        .unwrap();
    assert_eq!(w.find_body("box"), Some(id));
    assert!(w
        .create_body(
            &BodyDef {
                name: Some("box".into()),
                ..Default::default()
            },
            Shape::sphere(1.0)
        )
        .is_err());
    run(&mut w, 0.01, 5);
    w.set_linear_velocity(id, Vec3::new(0.0, 2.0, 0.0)).unwrap();
    w.set_angular_velocity(id, Vec3::new(1.0, 0.0, 0.0))
        .unwrap();
    run(&mut w, 0.01, 100);
    let b = w.body(id).unwrap();
    // Verlet restarts from the edited state instead of its stale memory.
    assert!((b.position().y - 2.0).abs() < tol(1e-12, 1e-5));
    assert!(
        (b.angular_momentum() - Vec3::new(b.inertia_local().x_axis.x, 0.0, 0.0)).length() < 1e-3
    );
    let before = w.state_hash();
    assert!(w.set_position(id, Vec3::new(Real::NAN, 0.0, 0.0)).is_err());
    assert!(w
        .set_orientation(id, Quat::from_xyzw(0.0, 0.0, 0.0, 0.0))
        .is_err());
    assert!(w.step(-1.0).is_err());
    assert!(w.set_gravity(Vec3::splat(Real::INFINITY)).is_err());
    assert_eq!(w.state_hash(), before);
    // An impulse at an offset point adds (p − x) × J to L.
    w.set_angular_velocity(id, Vec3::ZERO).unwrap();
    let x = w.body(id).unwrap().center_of_mass();
    w.apply_impulse(id, Vec3::new(0.0, 0.0, 1.0), x + Vec3::new(0.5, 0.0, 0.0))
        .unwrap();
    let l = w.body(id).unwrap().angular_momentum();
    assert!((l - Vec3::new(0.0, -0.5, 0.0)).length() < tol(1e-12, 1e-6));
}

/// Two balls on springs, one to the world and one between them, moving in 3D with no
/// spin (so that a world built from their state reproduces it bit for bit).
fn springs_world(integrator: Integrator, state: &[(Vec3, Vec3)]) -> (World, Vec<BodyId>) {
    let mut w = world(Vec3::new(0.0, -9.8, 0.0), integrator);
    let ids: Vec<BodyId> = state
        .iter()
        .map(|&(position, linear_velocity)| {
            let def = BodyDef {
                position,
                linear_velocity,
                mass: MassSpec::Mass(0.7),
                ..Default::default()
            };
            w.create_body(&def, Shape::sphere(0.1)).unwrap()
        })
        .collect();
    let spring = |body, other, stiffness| {
        Force::Spring(Spring {
            body,
            anchor: Vec3::ZERO,
            other,
            stiffness,
            rest_length: 0.5,
            damping: 0.3,
        })
    };
    w.add_force(spring(
        ids[0],
        SpringEnd::World(Vec3::new(0.0, 2.0, 0.0)),
        80.0,
    ))
    .unwrap();
    let other = SpringEnd::Body {
        body: ids[0],
        anchor: Vec3::ZERO,
    };
    w.add_force(spring(ids[1], other, 45.0)).unwrap();
    (w, ids)
}

#[test]
fn switching_back_to_verlet_starts_it_afresh_as_a_new_world_would() {
    let dt = 0.004;
    let start = [
        (Vec3::new(0.1, 1.2, 0.0), Vec3::new(0.5, 0.0, -0.2)),
        (Vec3::new(-0.3, 0.8, 0.2), Vec3::new(0.0, 0.3, 0.4)),
    ];
    let (mut w, ids) = springs_world(Integrator::Verlet, &start);
    run(&mut w, dt, 50);
    w.set_integrator(Integrator::Rk4);
    run(&mut w, dt, 20);
    w.set_integrator(Integrator::Verlet);
    // A fresh Verlet world from the state reached: it has no memory of earlier steps.
    let state: Vec<(Vec3, Vec3)> = ids
        .iter()
        .map(|&id| {
            let b = w.body(id).unwrap();
            (b.position(), b.linear_velocity())
        })
        .collect();
    let (mut fresh, _) = springs_world(Integrator::Verlet, &state);
    assert_eq!(fresh.state_hash(), w.state_hash());
    for _ in 0..60 {
        w.step(dt).unwrap();
        fresh.step(dt).unwrap();
        assert_eq!(fresh.state_hash(), w.state_hash());
    }
}
