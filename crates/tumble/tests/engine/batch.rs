//! Batches: W copies of a world stepped together equal W worlds stepped alone, bit for
//! bit, on any thread count; per-world forces, joint targets, states and resets go to the
//! world named and no other; bad input is refused with the field named, changing nothing.

// Casts between Real and f64 are no-ops in the default build but needed in the f32 one.
#![allow(clippy::unnecessary_cast)]

use tumble::prelude::*;
use tumble::{Batch, BodyStates, JointTarget};

/// Boxes and balls dropped, spinning, onto a ground plane and onto each other: contacts,
/// friction, sleep.
fn contact_scene() -> World {
    let mut w = World::new(&WorldDef::default());
    w.create_body(
        &BodyDef {
            kind: BodyKind::Static,
            ..Default::default()
        },
        Shape::plane(Vec3::Y, 0.0),
    )
    .unwrap();
    for k in 0..5 {
        let shape = if k % 2 == 0 {
            Shape::cuboid(Vec3::new(0.2, 0.1, 0.15))
        } else {
            Shape::sphere(0.12)
        };
        let def = BodyDef {
            position: Vec3::new(0.05 * k as Real, 0.3 + 0.25 * k as Real, 0.0),
            angular_velocity: Vec3::new(0.5, 1.0 * k as Real, 0.2),
            ..Default::default()
        };
        w.create_body(&def, shape).unwrap();
    }
    w
}

/// A chain of three boxes hanging from hinges, the top one with a motor, the second with
/// a servo (joints named "motor" and "servo").
fn jointed_scene() -> World {
    let mut w = World::new(&WorldDef {
        sleep: false,
        ..Default::default()
    });
    let mut above: Option<BodyId> = None;
    for k in 0..3 {
        let y = -0.5 * k as Real;
        let body = w
            .create_body(
                &BodyDef {
                    position: Vec3::new(0.2, y - 0.25, 0.0),
                    mass: MassSpec::Mass(1.0 + k as Real),
                    ..Default::default()
                },
                Shape::cuboid(Vec3::new(0.05, 0.25, 0.05)),
            )
            .unwrap();
        let kind = JointKind::Hinge {
            limits: None,
            motor: (k == 0).then_some(Motor {
                speed: 1.0,
                max_force: 5.0,
            }),
            spring: None,
            servo: (k == 1).then_some(Servo {
                target: 0.3,
                stiffness: 20.0,
                damping: 1.0,
                max_force: 50.0,
            }),
        };
        let mut def = JointDef::new(kind, body);
        def.name = ["motor", "servo", "free"].map(String::from).get(k).cloned();
        def.anchor = Vec3::new(0.0, 0.25, 0.0);
        def.axis = Vec3::Z;
        def.other_axis = Vec3::Z;
        match above {
            Some(a) => {
                def.other = Some(a);
                def.other_anchor = Vec3::new(0.0, -0.25, 0.0);
            }
            None => def.other_anchor = Vec3::new(0.2, y, 0.0),
        }
        w.create_joint(&def).unwrap();
        above = Some(body);
    }
    w
}

/// A different start for each world: every dynamic body pushed by a velocity that
/// depends on the world's index, so that the copies are not W times the same run.
fn start_velocities(w: &World, i: usize) -> Vec<Vec3> {
    w.bodies()
        .map(|(_, b)| match b.kind() {
            BodyKind::Dynamic => Vec3::new(0.1 * i as Real, 0.05, -0.07 * i as Real),
            _ => Vec3::ZERO,
        })
        .collect()
}

/// Every body's state bits: positions, orientations, velocities, angular velocities.
fn state(w: &World) -> Vec<[Real; 13]> {
    w.bodies()
        .map(|(_, b)| {
            let (p, q, v, o) = (
                b.position(),
                b.orientation(),
                b.linear_velocity(),
                b.angular_velocity(),
            );
            [
                p.x, p.y, p.z, q.x, q.y, q.z, q.w, v.x, v.y, v.z, o.x, o.y, o.z,
            ]
        })
        .collect()
}

#[test]
fn copies_equal_separate_worlds_bit_for_bit_on_any_thread_count() {
    // `==` on every number: the batch must be the worlds' own steps, not an approximation.
    for (scene, dt, steps) in [
        (contact_scene as fn() -> World, 1.0 / 60.0, 40u64),
        (jointed_scene, 1.0 / 120.0, 50),
    ] {
        for threads in [1, 2] {
            let copies = 3;
            let mut batch = Batch::new(&scene(), copies, Some(threads)).unwrap();
            let mut alone: Vec<World> = (0..copies).map(|_| scene()).collect();
            let starts: Vec<Vec<Vec3>> = alone
                .iter()
                .enumerate()
                .map(|(i, w)| start_velocities(w, i))
                .collect();
            let states: Vec<BodyStates> = starts
                .iter()
                .map(|v| BodyStates {
                    velocities: Some(v),
                    ..Default::default()
                })
                .collect();
            batch.set_states(None, &states).unwrap();
            for (w, s) in alone.iter_mut().zip(&states) {
                w.set_states(s).unwrap();
            }
            batch.step(dt, steps / 2).unwrap();
            batch.step(dt, steps - steps / 2).unwrap();
            for (i, w) in alone.iter_mut().enumerate() {
                for _ in 0..steps {
                    w.step(dt).unwrap();
                }
                let copy = batch.world(i).unwrap();
                assert_eq!(state(copy), state(w), "world {i}, {threads} threads");
                assert_eq!(copy.step_count(), steps);
            }
            // The starts differ, so the worlds do: the comparison above is not of W
            // copies of one run.
            assert_ne!(
                state(batch.world(0).unwrap()),
                state(batch.world(1).unwrap())
            );
        }
    }
}

/// A free ball of `mass` in a world without gravity, in each of four copies.
fn floating_batch(mass: Real, radius: Real) -> Batch {
    let mut w = World::new(&WorldDef {
        gravity: Vec3::ZERO,
        ..Default::default()
    });
    let def = BodyDef {
        mass: MassSpec::Mass(mass),
        ..Default::default()
    };
    w.create_body(&def, Shape::sphere(radius)).unwrap();
    Batch::new(&w, 4, Some(2)).unwrap()
}

#[test]
fn a_force_on_world_two_moves_world_two_only_by_f_t_over_m() {
    // Constant F on a free body: Δv = F t / m and Δω = τ t / I (a ball: I = 2/5 m r²).
    // Each step adds F dt / m to v (and τ dt to L), so n steps give the closed form up to
    // n roundings: 1e-12 relative in f64, 1e-5 in f32.
    let tol: Real = if std::mem::size_of::<Real>() == 8 {
        1e-12
    } else {
        1e-5
    };
    for (mass, radius, dt, steps) in [
        (2.0 as Real, 0.1, 0.01, 50u64),
        (0.3, 0.5, 1.0 / 240.0, 120),
    ] {
        let mut batch = floating_batch(mass, radius);
        let (f, tau) = (Vec3::new(3.0, -1.0, 0.5), Vec3::new(0.0, 0.02, -0.01));
        let mut forces = vec![Vec3::ZERO; 4];
        let mut torques = vec![Vec3::ZERO; 4];
        forces[2] = f;
        torques[2] = tau;
        batch.set_forces(&forces, Some(&torques)).unwrap();
        batch.step(dt, steps).unwrap();
        let t = dt * steps as Real;
        let inertia = 0.4 * mass * radius * radius;
        for (i, w) in batch.worlds().iter().enumerate() {
            let b = w.body(w.body_ids()[0]).unwrap();
            if i == 2 {
                let (v, om) = (f * t / mass, tau * t / inertia);
                assert!(
                    (b.linear_velocity() - v).length() <= tol * v.length(),
                    "{i}"
                );
                assert!(
                    (b.angular_velocity() - om).length() <= tol * om.length(),
                    "{i}"
                );
            } else {
                assert_eq!(b.linear_velocity(), Vec3::ZERO, "world {i} was pushed");
                assert_eq!(b.angular_velocity(), Vec3::ZERO, "world {i} was turned");
            }
        }
        // The forces persist until cleared: after clear_forces the velocity holds.
        batch.clear_forces();
        let v = batch
            .world(2)
            .unwrap()
            .bodies()
            .next()
            .unwrap()
            .1
            .linear_velocity();
        batch.step(dt, 10).unwrap();
        let after = batch
            .world(2)
            .unwrap()
            .bodies()
            .next()
            .unwrap()
            .1
            .linear_velocity();
        assert_eq!(after, v);
    }
}

#[test]
fn motor_speeds_go_to_their_own_worlds() {
    // Each world's motor gets its own speed and its servo its own target, keeping the
    // rest of their settings; a world given the same targets as a lone world runs as it.
    let mut batch = Batch::new(&jointed_scene(), 3, Some(2)).unwrap();
    let speeds = [0.5 as Real, -2.0, 3.0];
    batch
        .set_joint_targets("motor", JointTarget::Velocity, &speeds)
        .unwrap();
    let servo = [0.0 as Real, 0.4, -0.4];
    batch
        .set_joint_targets("servo", JointTarget::Position, &servo)
        .unwrap();
    for (i, w) in batch.worlds().iter().enumerate() {
        let id = w.find_joint("motor").unwrap();
        let motor = w
            .joint(id)
            .unwrap()
            .kind()
            .options()
            .get(tumble::joint::JointOption::Motor);
        match motor {
            Some(tumble::joint::OptionValue::Motor(m)) => {
                assert_eq!(m.speed, speeds[i]);
                assert_eq!(m.max_force, 5.0, "the motor's force cap is kept");
            }
            other => panic!("world {i}: {other:?}"),
        }
    }
    // Different targets make different runs; equal ones equal runs (worlds 0 and a fresh
    // batch given 0.5 too are checked bit for bit).
    batch.step(1.0 / 120.0, 30).unwrap();
    let mut other = Batch::new(&jointed_scene(), 1, Some(1)).unwrap();
    other
        .set_joint_targets("motor", JointTarget::Velocity, &speeds[..1])
        .unwrap();
    other
        .set_joint_targets("servo", JointTarget::Position, &servo[..1])
        .unwrap();
    other.step(1.0 / 120.0, 30).unwrap();
    assert_eq!(
        state(other.world(0).unwrap()),
        state(batch.world(0).unwrap())
    );
    assert_ne!(
        state(batch.world(1).unwrap()),
        state(batch.world(2).unwrap())
    );
}

#[test]
fn a_world_reset_mid_run_matches_a_fresh_world_stepped_the_same() {
    let dt = 1.0 / 60.0;
    let mut batch = Batch::new(&contact_scene(), 3, Some(2)).unwrap();
    batch.step(dt, 25).unwrap();
    let before = state(batch.world(0).unwrap());
    batch.reset(Some(&[1]), None).unwrap();
    assert_eq!(batch.world(1).unwrap().step_count(), 0);
    assert_eq!(
        state(batch.world(0).unwrap()),
        before,
        "world 0 was not reset"
    );
    batch.step(dt, 15).unwrap();
    let mut fresh = contact_scene();
    for _ in 0..15 {
        fresh.step(dt).unwrap();
    }
    assert_eq!(state(batch.world(1).unwrap()), state(&fresh));
    // From a snapshot: world 2 continues as world 0 does.
    let snap = batch.world(0).unwrap().snapshot();
    batch.reset(Some(&[2]), Some(&snap)).unwrap();
    batch.step(dt, 5).unwrap();
    assert_eq!(
        state(batch.world(2).unwrap()),
        state(batch.world(0).unwrap())
    );
}

#[test]
fn bad_input_is_refused_naming_the_field_and_changes_nothing() {
    let world = jointed_scene();
    let msg = |e: tumble::Error| e.to_string();
    assert_eq!(
        msg(Batch::new(&world, 0, None).err().unwrap()),
        "copies: must be >= 1, got 0"
    );
    assert!(msg(Batch::new(&world, 2, Some(0)).err().unwrap()).starts_with("threads:"));
    let mut with_callback = jointed_scene();
    with_callback.add_force_callback(Box::new(|_ctx: &mut ForceContext| {}));
    assert!(msg(Batch::new(&with_callback, 2, None).err().unwrap()).contains("force callbacks"));

    let mut batch = Batch::new(&world, 2, Some(1)).unwrap();
    let start = state(batch.world(1).unwrap());
    assert_eq!(
        msg(batch.world(2).err().unwrap()),
        "world: index 2 out of range for a batch of 2 worlds"
    );
    assert_eq!(
        msg(batch.reset(Some(&[0, 7]), None).unwrap_err()),
        "worlds[1]: index 7 out of range for a batch of 2 worlds"
    );
    let e = batch
        .set_joint_targets("nope", JointTarget::Velocity, &[1.0, 2.0])
        .unwrap_err();
    assert_eq!(msg(e), "worlds[0].joint: no joint named 'nope'");
    let e = batch
        .set_joint_targets("free", JointTarget::Position, &[1.0, 2.0])
        .unwrap_err();
    assert!(msg(e).contains("joint 'free' has no servo"));
    let e = batch
        .set_joint_targets("motor", JointTarget::Velocity, &[1.0, Real::NAN])
        .unwrap_err();
    assert_eq!(msg(e), "values[1]: must be a finite number");
    let e = batch
        .set_joint_targets("motor", JointTarget::Velocity, &[1.0])
        .unwrap_err();
    assert!(msg(e).starts_with("values: expected 2 values"));
    // A NaN in world 1's forces: nothing is added to world 0 either.
    let mut forces = vec![Vec3::ONE; 6];
    forces[4] = Vec3::new(Real::NAN, 0.0, 0.0);
    let e = batch.set_forces(&forces, None).unwrap_err();
    assert!(msg(e).starts_with("worlds[1].forces[1]:"));
    assert_eq!(batch.world(0).unwrap().forces().count(), 0);
    assert!(msg(batch.set_forces(&forces[..5], None).unwrap_err())
        .starts_with("forces: expected 6 rows"));
    // A bad velocity in world 1: world 0's good one is not applied.
    let good = vec![Vec3::X; 3];
    let mut bad = good.clone();
    bad[2] = Vec3::new(0.0, Real::INFINITY, 0.0);
    let states = [
        BodyStates {
            velocities: Some(&good),
            ..Default::default()
        },
        BodyStates {
            velocities: Some(&bad),
            ..Default::default()
        },
    ];
    let e = batch.set_states(None, &states).unwrap_err();
    assert!(msg(e).starts_with("worlds[1].velocities[2]:"));
    assert_eq!(state(batch.world(0).unwrap()), start);
    // A snapshot of another scene.
    let e = batch
        .reset(None, Some(&contact_scene().snapshot()))
        .unwrap_err();
    assert!(msg(e).starts_with("snapshot: holds 6 bodies"));
    assert!(batch.step(-1.0, 1).is_err());
    assert_eq!(state(batch.world(1).unwrap()), start);
    assert_eq!(batch.world(1).unwrap().step_count(), 0);
}

#[test]
fn a_failing_world_is_named_and_the_others_finish() {
    // World 1 is sent past the speed limit by a huge force; its step is undone and it
    // stays at its last good step while worlds 0 and 2 finish all of theirs.
    for threads in [1, 2] {
        let mut batch = floating_batch(1.0, 0.1);
        batch.set_threads(threads).unwrap();
        let mut forces = vec![Vec3::ZERO; 4];
        forces[1] = Vec3::new(1e9, 0.0, 0.0);
        forces[2] = Vec3::new(1e9, 0.0, 0.0);
        batch.set_forces(&forces, None).unwrap();
        let e = batch.step(0.01, 20).unwrap_err();
        assert_eq!(e.world, 1, "the lowest failing world reports");
        assert!(e.error.is_step_failure());
        assert!(e.to_string().starts_with("worlds[1]: step "), "{e}");
        for (i, w) in batch.worlds().iter().enumerate() {
            let done = w.step_count() == 20;
            assert_eq!(done, i == 0 || i == 3, "world {i}, {threads} threads");
        }
    }
}

#[test]
fn step_worlds_steps_a_range_of_worlds_each_through_its_numbered_steps() {
    // Worlds 1 and 2 of four take steps 5..9 (step 8 half as long); `after` sees each
    // world after each of its steps, in order, and the world equals one stepped alone.
    for threads in [1, 2] {
        let mut batch = Batch::new(&jointed_scene(), 4, Some(threads)).unwrap();
        let mut seen: Vec<Vec<(u64, u64)>> = vec![Vec::new(); 2];
        let dt = |k: u64| if k == 8 { 0.005 } else { 0.01 };
        batch
            .step_worlds(1, &mut seen, 5..9, dt, |s, k, w| {
                s.push((k, w.step_count()))
            })
            .unwrap();
        for s in &seen {
            assert_eq!(s, &[(5, 1), (6, 2), (7, 3), (8, 4)], "{threads} threads");
        }
        let counts: Vec<u64> = batch.worlds().iter().map(World::step_count).collect();
        assert_eq!(counts, [0, 4, 4, 0]);
        let mut alone = jointed_scene();
        for k in 5..9 {
            alone.step(dt(k)).unwrap();
        }
        assert_eq!(state(batch.world(2).unwrap()), state(&alone));
        // Past the last world: refused before anything steps.
        let e = batch
            .step_worlds(3, &mut [(), ()], 0..1, dt, |_, _, _| ())
            .unwrap_err();
        assert_eq!(
            e.to_string(),
            "worlds[3]: world: index 4 out of range for a batch of 4 worlds"
        );
        assert_eq!(batch.world(3).unwrap().step_count(), 0);
    }
}
