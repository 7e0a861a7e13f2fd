//! Force callbacks: how often a step calls them, what they see, and that adding one wakes
//! the world. (A callback that stops the step: `finite_state.rs`.)

// Casts between Real and f64 are no-ops in the default build but needed in the f32 one.
#![allow(clippy::unnecessary_cast)]

use crate::common;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use tumble::prelude::*;

/// Adds a callback that counts its calls.
fn counted(w: &mut World) -> Arc<AtomicUsize> {
    let calls = Arc::new(AtomicUsize::new(0));
    let c = calls.clone();
    w.add_force_callback(Box::new(move |_: &mut ForceContext<'_>| {
        c.fetch_add(1, Ordering::Relaxed);
    }));
    calls
}

#[test]
fn a_free_body_calls_back_as_often_as_its_integrator_evaluates_forces() {
    // The counts `ForceCallback`'s documentation gives, per integrator.
    for integrator in Integrator::ALL {
        let expected = match integrator {
            Integrator::Midpoint | Integrator::VelocityVerlet => 2,
            Integrator::Rk4 => 4,
            _ => 1,
        };
        let mut w = common::world(Vec3::new(0.0, -9.8, 0.0), integrator);
        common::ball(&mut w, Vec3::new(0.0, 5.0, 0.0));
        let calls = counted(&mut w);
        common::run(&mut w, 0.01, 10);
        let per_step = calls.load(Ordering::Relaxed) as f64 / 10.0;
        assert_eq!(per_step, expected as f64, "{}", integrator.name());
    }
}

#[test]
fn a_body_in_contact_calls_back_once_per_substep_and_a_joined_one_once_more() {
    for substeps in [1, 4, 7] {
        let mut w = common::awake_on_ground(Vec3::new(0.0, -9.8, 0.0));
        let mut settings = w.solver_settings();
        settings.substeps = substeps;
        w.set_solver_settings(settings).unwrap();
        common::ball(&mut w, Vec3::new(0.0, 0.1, 0.0));
        let calls = counted(&mut w);
        common::run(&mut w, 0.01, 10);
        assert_eq!(calls.load(Ordering::Relaxed), 10 * substeps as usize);
        let mut w = common::world(Vec3::new(0.0, -9.8, 0.0), Integrator::Rk4);
        w.set_solver_settings(settings).unwrap();
        let bob = common::ball(&mut w, Vec3::new(1.0, 0.0, 0.0));
        let mut def = JointDef::new(
            JointKind::Ball {
                cone: None,
                twist: None,
            },
            bob,
        );
        def.anchor = Vec3::new(-1.0, 0.0, 0.0);
        w.create_joint(&def).unwrap();
        let calls = counted(&mut w);
        common::run(&mut w, 0.01, 10);
        assert_eq!(calls.load(Ordering::Relaxed), 10 * (substeps as usize + 1));
    }
}

#[test]
fn a_callback_sees_each_body_as_it_is_at_the_first_evaluation_of_a_step() {
    // Under symplectic Euler the one evaluation is at the step's start: the state the
    // callback reads is the world's before the step, bit for bit, in creation order (the
    // box's centre of mass off its frame's origin, so that the two differ).
    let mut w = common::world(Vec3::ZERO, Integrator::SymplecticEuler);
    let a = w
        .create_body(
            &BodyDef {
                position: Vec3::new(1.0, 2.0, 3.0),
                orientation: Quat::from_rotation_z(0.7),
                linear_velocity: Vec3::new(0.5, -0.25, 2.0),
                angular_velocity: Vec3::new(0.0, 3.0, 1.0),
                mass: MassSpec::Mass(2.5),
                center_of_mass: Some(Vec3::new(0.1, 0.0, 0.0)),
                name: Some("box".into()),
                ..Default::default()
            },
            Shape::cuboid(Vec3::new(0.3, 0.2, 0.1)),
        )
        .unwrap();
    let b = common::ball(&mut w, Vec3::new(-4.0, 0.0, 0.0));
    let seen = Arc::new(Mutex::new(Vec::new()));
    let s = seen.clone();
    w.add_force_callback(Box::new(move |ctx: &mut ForceContext<'_>| {
        let all = (0..ctx.body_count()).map(|i| ctx.state_at(i).unwrap());
        *s.lock().unwrap() = all.collect::<Vec<_>>();
        assert!(ctx.state_at(ctx.body_count()).is_none());
        assert_eq!(ctx.body_ids(), [a, b]);
        assert_eq!(
            (ctx.name_at(0), ctx.name_at(1), ctx.name_at(2)),
            (Some("box"), None, None)
        );
    }));
    for _ in 0..3 {
        let expected: Vec<_> = [a, b]
            .iter()
            .map(|&id| {
                let body = w.body(id).unwrap();
                (
                    body.position(),
                    body.center_of_mass(),
                    body.orientation(),
                    body.linear_velocity(),
                    body.angular_velocity(),
                    body.mass(),
                )
            })
            .collect();
        w.step(0.01).unwrap();
        let got: Vec<_> = seen
            .lock()
            .unwrap()
            .iter()
            .map(|s| {
                let q = s.orientation;
                let p = s.position;
                (
                    p,
                    s.center_of_mass,
                    q,
                    s.velocity,
                    s.angular_velocity,
                    s.mass,
                )
            })
            .collect();
        assert_eq!(got, expected);
    }
}

#[test]
fn adding_a_callback_wakes_every_body() {
    // A ball asleep on the ground, then a callback pushing it up at twice its weight:
    // it must leave the ground at a = g (closed form: y = r + ½ g t² after the push).
    let g = 9.8;
    let mut w = World::new(&WorldDef {
        gravity: Vec3::new(0.0, -g, 0.0),
        ..Default::default()
    });
    let ground = BodyDef {
        kind: BodyKind::Static,
        ..Default::default()
    };
    w.create_body(&ground, Shape::plane(Vec3::Y, 0.0)).unwrap();
    let ball = common::ball(&mut w, Vec3::new(0.0, 0.1, 0.0));
    common::run(&mut w, 0.01, 300);
    assert!(!w.body(ball).unwrap().is_awake(), "meant to fall asleep");
    w.add_force_callback(Box::new(move |ctx: &mut ForceContext<'_>| {
        ctx.add_force(ball, Vec3::new(0.0, 2.0 * g, 0.0));
    }));
    assert!(w.body(ball).unwrap().is_awake());
    common::run(&mut w, 0.01, 50);
    let y = w.body(ball).unwrap().position().y;
    // Symplectic Euler off the ground after the first step: ½ g t² + ½ g t dt at most;
    // the contact's first steps take a little, so 5 % of the rise.
    let rise = 0.5 * g * 0.5 * 0.5;
    assert!((y - 0.1 - rise).abs() < 0.05 * rise, "{y}");
}

#[test]
fn a_force_at_a_local_point_is_an_applied_force_bit_for_bit() {
    // Both add r × F with r = q (p − c) to a wrench summed from zero: the same bits, on a
    // box spinning about an axis off its centre of mass under RK4 (four evaluations).
    let (force, point, torque) = (
        Vec3::new(0.0, 2.0, 1.0),
        Vec3::new(0.4, 0.1, -0.2),
        Vec3::new(0.3, 0.0, 0.0),
    );
    let run = |callback: bool| {
        let mut w = common::world(Vec3::ZERO, Integrator::Rk4);
        let def = BodyDef {
            mass: MassSpec::Mass(3.0),
            center_of_mass: Some(Vec3::new(0.05, 0.0, 0.0)),
            ..Default::default()
        };
        let id = w
            .create_body(&def, Shape::cuboid(Vec3::new(0.4, 0.1, 0.2)))
            .unwrap();
        if callback {
            w.add_force_callback(Box::new(move |ctx: &mut ForceContext<'_>| {
                assert!(ctx.add_force_at_local_point(id, force, point));
                ctx.add_torque(id, torque);
            }));
        } else {
            let applied = AppliedForce {
                body: id,
                force,
                point: Some(point),
                torque,
            };
            w.add_force(Force::Applied(applied)).unwrap();
        }
        common::run(&mut w, 0.01, 100);
        let b = w.body(id).unwrap();
        (b.position(), b.orientation(), b.angular_velocity())
    };
    let (a, b) = (run(true), run(false));
    assert!(b.2.length() > 1.0, "it was meant to spin");
    assert_eq!(a, b);
}
