//! Threads (issue 16): a world steps to the same bits on any thread count, and the thread
//! count is a checked setting.
//!
//! The stages split their work only past sizes that pay on a real machine; these tests
//! switch that off (`split_everything`) so that scenes small enough to run quickly take
//! every split path: the narrow phase's pieces and the colours' groups on several threads.
//! Results never depend on the switch, so the other tests of this binary may run beside
//! it.

use tumble::prelude::*;
use tumble::threads::{split_everything, MAX_THREADS};

/// A heap of boxes, balls and capsules of mixed sizes and masses dropped into a box of
/// walls, some spinning, on `threads` threads.
fn build_heap(threads: usize, sleep: bool) -> World {
    split_everything(true);
    let mut w = World::try_new(&WorldDef {
        sleep,
        threads: Some(threads),
        ..Default::default()
    })
    .unwrap();
    let fixed = BodyDef {
        kind: BodyKind::Static,
        ..Default::default()
    };
    w.create_body(&fixed, Shape::plane(Vec3::Y, 0.0)).unwrap();
    for (x, z) in [(-2.2, 0.0), (2.2, 0.0), (0.0, -2.2), (0.0, 2.2)] {
        let wall = BodyDef {
            position: Vec3::new(x, 1.0, z),
            ..fixed.clone()
        };
        let half = Vec3::new(
            if x == 0.0 { 2.4 } else { 0.2 },
            1.0,
            if z == 0.0 { 2.4 } else { 0.2 },
        );
        w.create_body(&wall, Shape::cuboid(half)).unwrap();
    }
    for i in 0..180 {
        let (layer, k) = (i / 36, i % 36);
        let position = Vec3::new(
            -1.5 + 0.6 * (k % 6) as Real + 0.05 * layer as Real,
            0.3 + 0.55 * layer as Real,
            -1.5 + 0.6 * (k / 6) as Real,
        );
        let size = 0.12 + 0.03 * (i % 5) as Real;
        let shape = match i % 3 {
            0 => Shape::cuboid(Vec3::splat(size)),
            1 => Shape::sphere(size),
            _ => Shape::capsule(size, 0.7 * size),
        };
        let def = BodyDef {
            position,
            orientation: Quat::from_rotation_z(0.3 * (i % 7) as Real),
            angular_velocity: Vec3::new(0.0, (i % 4) as Real, 0.0),
            mass: MassSpec::Density(500.0 + 400.0 * (i % 4) as Real),
            restitution: if i % 6 == 0 { 0.5 } else { 0.0 },
            ..Default::default()
        };
        w.create_body(&def, shape).unwrap();
    }
    w
}

/// The heap after `steps` steps of `dt` on `threads` threads: each step's state hash and,
/// at the end, every contact impulse, printed exactly.
fn heap(threads: usize, sleep: bool, dt: Real, steps: usize) -> (Vec<u64>, Vec<String>) {
    let mut w = build_heap(threads, sleep);
    let mut hashes = Vec::new();
    for _ in 0..steps {
        w.step(dt).unwrap();
        hashes.push(w.state_hash());
    }
    let impulses = w
        .contacts()
        .iter()
        .flat_map(|c| {
            c.manifold
                .points()
                .iter()
                .map(|p| format!("{:?}", p.normal_impulse))
        })
        .collect();
    (hashes, impulses)
}

#[test]
fn every_thread_count_gives_the_bits_of_one() {
    for (sleep, dt) in [(false, 1.0 / 60.0), (true, 1.0 / 120.0)] {
        let one = heap(1, sleep, dt, 150);
        // The heap lands and piles up: contacts enough that colours hold several groups.
        assert!(one.1.len() > 300, "{} contact points", one.1.len());
        for threads in [2, 3, 4, 7] {
            let many = heap(threads, sleep, dt, 150);
            let first = one.0.iter().zip(&many.0).position(|(a, b)| a != b);
            assert_eq!(first, None, "{threads} threads differ from step {first:?}");
            assert_eq!(one.1, many.1, "{threads} threads: contact impulses differ");
        }
    }
}

#[test]
fn a_world_can_change_its_thread_count_between_steps() {
    let (reference, _) = heap(1, false, 1.0 / 60.0, 60);
    // The same heap, its count changed every ten steps.
    let mut w = build_heap(2, false);
    let mut switched = Vec::new();
    for k in 0..60 {
        if k % 10 == 0 {
            w.set_threads([2, 1, 4, 3][k / 10 % 4]).unwrap();
        }
        w.step(1.0 / 60.0).unwrap();
        switched.push(w.state_hash());
    }
    assert_eq!(switched, reference);
    let mut w = World::try_new(&WorldDef {
        threads: Some(3),
        ..Default::default()
    })
    .unwrap();
    assert_eq!(w.threads(), 3);
    w.set_threads(1).unwrap();
    assert_eq!(w.threads(), 1);
    w.set_threads(MAX_THREADS).unwrap();
    assert_eq!(w.threads(), MAX_THREADS);
}

#[test]
fn thread_counts_outside_the_range_are_refused_and_change_nothing() {
    let mut w = World::try_new(&WorldDef {
        threads: Some(2),
        ..Default::default()
    })
    .unwrap();
    for bad in [0, MAX_THREADS + 1] {
        let e = w.set_threads(bad).unwrap_err().to_string();
        assert!(e.starts_with("threads: must be between 1 and"), "{e}");
        assert_eq!(w.threads(), 2);
        let e = World::try_new(&WorldDef {
            threads: Some(bad),
            ..Default::default()
        })
        .err()
        .unwrap()
        .to_string();
        assert!(e.starts_with("threads: "), "{e}");
    }
}

/// A hanging net of 40 × 40 balls, each joined to its +x and +z neighbours by a ball joint,
/// a hinge or a fixed joint in turn, with masses from 1 to 4 kg, held by every fourth ball
/// of its first row, on `threads` threads. Its 3,120 joints are enough for the joint
/// colours to be cut into several stripes each, which the passes split over threads.
fn build_net(threads: usize) -> World {
    let n = 40;
    let mut w = World::try_new(&WorldDef {
        threads: Some(threads),
        ..Default::default()
    })
    .unwrap();
    let mut balls = Vec::new();
    for row in 0..n {
        for column in 0..n {
            let fixed = row == 0 && column % 4 == 0;
            let def = BodyDef {
                kind: if fixed {
                    BodyKind::Static
                } else {
                    BodyKind::Dynamic
                },
                position: Vec3::new(column as Real, 0.0, row as Real),
                mass: MassSpec::Mass(1.0 + ((row + column) % 4) as Real),
                ..Default::default()
            };
            balls.push(w.create_body(&def, Shape::sphere(0.3)).unwrap());
        }
    }
    let mut k = 0;
    for row in 0..n {
        for column in 0..n {
            let a = balls[row * n + column];
            for (dx, dz) in [(1, 0), (0, 1)] {
                if column + dx >= n || row + dz >= n {
                    continue;
                }
                let b = balls[(row + dz) * n + column + dx];
                let kind = match k % 3 {
                    0 => JointKind::Ball {
                        cone: None,
                        twist: None,
                    },
                    1 => JointKind::Hinge {
                        limits: None,
                        motor: None,
                        spring: None,
                        servo: None,
                    },
                    _ => JointKind::Fixed,
                };
                k += 1;
                let half = 0.5 * Vec3::new(dx as Real, 0.0, dz as Real);
                let mut def = JointDef::new(kind, a);
                def.anchor = half;
                def.other = Some(b);
                def.other_anchor = -half;
                (def.axis, def.other_axis) = (Vec3::Y, Vec3::Y);
                w.create_joint(&def).unwrap();
            }
        }
    }
    w
}

#[test]
fn a_joint_net_steps_to_the_same_bits_on_any_thread_count() {
    let run = |threads: usize| {
        let mut w = build_net(threads);
        (0..20)
            .map(|_| {
                w.step(1.0 / 60.0).unwrap();
                w.state_hash()
            })
            .collect::<Vec<u64>>()
    };
    let one = run(1);
    for threads in [2, 3, 8] {
        let many = run(threads);
        let first = one.iter().zip(&many).position(|(a, b)| a != b);
        assert_eq!(first, None, "{threads} threads differ from step {first:?}");
    }
}
