//! Restitution at every speed: slow impacts bounce as e says, and resting contacts do not.
//!
//! A fixed bounce threshold (Box2D's 1 m/s) makes every slower impact perfectly
//! inelastic. These tests drop balls from 2 cm to 2 m, exchange momentum between balls at
//! 0.1 m/s and strike Newton's cradles at 0.5 and 1 m/s, at two time steps, and check that
//! stacks with restitution still rest without jitter.

// Casts between Real and f64 are no-ops in the default build but needed in the f32 one.
#![allow(clippy::unnecessary_cast)]

use crate::common::*;
use tumble::prelude::*;

const G: Real = 9.81;

fn world_with(gravity: Vec3, substeps: u32) -> World {
    World::new(&WorldDef {
        gravity,
        sleep: false,
        solver: SolverSettings {
            substeps,
            ..Default::default()
        },
        ..Default::default()
    })
}

fn ground(w: &mut World, restitution: Real) {
    w.create_body(
        &BodyDef {
            kind: BodyKind::Static,
            restitution,
            ..Default::default()
        },
        Shape::plane(Vec3::Y, 0.0),
    )
    .unwrap();
}

/// A ball of radius `r` dropped from `drop` (its bottom above the ground): its energy
/// per unit weight, y + v²/2g, at the last step before the bounce and at the first step
/// after it (the launch), each read from the state the world reports.
fn bounce_energies(e: Real, drop: Real, r: Real, dt: Real, integrator: Integrator) -> (Real, Real) {
    let mut w = World::new(&WorldDef {
        gravity: Vec3::new(0.0, -G, 0.0),
        integrator,
        sleep: false,
        ..Default::default()
    });
    ground(&mut w, e);
    let ball = w
        .create_body(
            &BodyDef {
                position: Vec3::new(0.0, drop + r, 0.0),
                restitution: e,
                ..Default::default()
            },
            Shape::sphere(r),
        )
        .unwrap();
    let fall = (2.0 * drop / G).sqrt();
    let mut before = drop;
    for _ in 0..((3.0 * fall + 0.5) / dt) as usize {
        w.step(dt).unwrap();
        let b = w.body(ball).unwrap();
        let (y, v) = (b.position().y - r, b.linear_velocity().y);
        let energy = y + v * v / (2.0 * G);
        if v > 0.0 {
            return (before, energy);
        }
        before = energy;
    }
    (before, 0.0)
}

/// The drops: 2 cm to 2 m, e from 0.3 to 0.9, two radii and two time steps. Returns the
/// worst relative error of the rebound energy against e² times `reference` (the energy
/// before the bounce, or the drop height) and a table of every case.
fn worst_rebound(integrator: Integrator, against_drop: bool) -> (Real, String) {
    let mut worst: Real = 0.0;
    let mut report = String::new();
    for dt in [1.0 / 60.0, 1.0 / 240.0] {
        for drop in [0.02, 0.05, 0.2, 0.5, 2.0] {
            for e in [0.3, 0.5, 0.8, 0.9] {
                for r in [0.05, 0.25] {
                    let (before, after) = bounce_energies(e, drop, r, dt, integrator);
                    let reference = if against_drop { drop } else { before };
                    let ratio = after / (e * e * reference);
                    worst = worst.max((ratio - 1.0).abs());
                    report += &format!("dt {dt:.4} drop {drop} e {e} r {r}: {ratio:.4}\n");
                }
            }
        }
    }
    (worst, report)
}

#[test]
fn drops_from_two_centimetres_to_two_metres_rebound_with_e_squared_of_their_energy() {
    // The default integrator (symplectic Euler) loses g·dt²/2 of y + v²/2g per step of
    // free flight (a 2 cm drop at dt 1/60 reaches the ground with 73 % of it), so the
    // bounce is checked against the energy it met; the drift is the integrator's.
    let (worst, report) = worst_rebound(Integrator::SymplecticEuler, false);
    assert!(worst < 0.02, "worst relative error {worst}\n{report}");
}

#[test]
fn other_integrators_bounce_with_e_squared_of_the_energy_too() {
    for integrator in [
        Integrator::Rk4,
        Integrator::ImplicitEuler,
        Integrator::Midpoint,
        Integrator::VelocityVerlet,
    ] {
        let (worst, report) = worst_rebound(integrator, false);
        assert!(
            worst < 0.02,
            "{integrator:?}: worst relative error {worst}\n{report}"
        );
    }
}

/// Two equal balls in free space, e = 1, one moving at `speed` into the other at rest.
fn exchange(speed: Real, r: Real, substeps: u32, dt: Real) -> (Vec3, Vec3) {
    let mut w = world_with(Vec3::ZERO, substeps);
    let make = |w: &mut World, x: Real, v: Real| {
        w.create_body(
            &BodyDef {
                position: Vec3::new(x, 0.0, 0.0),
                linear_velocity: Vec3::X * v,
                restitution: 1.0,
                friction: 0.0,
                ..Default::default()
            },
            Shape::sphere(r),
        )
        .unwrap()
    };
    let a = make(&mut w, -3.0 * r, speed);
    let b = make(&mut w, 0.0, 0.0);
    let time = 2.0 * r / speed + 0.5;
    run(&mut w, dt, (time / dt) as usize);
    let va = w.body(a).unwrap().linear_velocity();
    let vb = w.body(b).unwrap().linear_velocity();
    (va, vb)
}

#[test]
fn equal_elastic_balls_exchange_velocities_at_ten_centimetres_per_second() {
    for speed in [0.1, 0.3, 1.0] {
        for r in [0.02, 0.1, 0.5] {
            for dt in [1.0 / 60.0, 1.0 / 240.0] {
                let (va, vb) = exchange(speed, r, 4, dt);
                assert!(
                    va.length() < 0.01 * speed && (vb - Vec3::X * speed).length() < 0.01 * speed,
                    "speed {speed} r {r} dt {dt}: {va} {vb}"
                );
            }
        }
    }
}

/// A row of five touching balls of radius `r`, e = 1, the first struck at `speed`; with
/// `hang`, each hangs on a 1 m rod from the world under gravity, else they float in free
/// space. Returns the balls' velocities and heights a little after the blow has passed.
fn cradle(speed: Real, r: Real, hang: bool, dt: Real) -> Vec<(Vec3, Real)> {
    let gravity = if hang {
        Vec3::new(0.0, -G, 0.0)
    } else {
        Vec3::ZERO
    };
    let mut w = world_with(gravity, 4);
    let balls: Vec<BodyId> = (0..5)
        .map(|i| {
            let x = 2.0 * r * i as Real;
            let ball = w
                .create_body(
                    &BodyDef {
                        position: Vec3::new(x, 0.0, 0.0),
                        linear_velocity: Vec3::X * if i == 0 { speed } else { 0.0 },
                        restitution: 1.0,
                        friction: 0.0,
                        ..Default::default()
                    },
                    Shape::sphere(r),
                )
                .unwrap();
            if hang {
                let rod = JointKind::Distance {
                    length: None,
                    min: None,
                    max: None,
                    spring: None,
                };
                w.create_joint(&JointDef {
                    other_anchor: Vec3::new(x, 1.0, 0.0),
                    ..JointDef::new(rod, ball)
                })
                .unwrap();
            }
            ball
        })
        .collect();
    // Long enough for the blow to pass, short against the pendulum's period (2 s).
    run(&mut w, dt, (0.1 / dt) as usize);
    balls
        .iter()
        .map(|b| {
            let b = w.body(*b).unwrap();
            (b.linear_velocity(), b.position().y)
        })
        .collect()
}

#[test]
fn newtons_cradles_struck_at_half_and_one_metre_per_second_pass_the_blow_along() {
    for hang in [false, true] {
        for speed in [0.5, 1.0] {
            for r in [0.02, 0.1] {
                for dt in [1.0 / 60.0, 1.0 / 240.0] {
                    let v = cradle(speed, r, hang, dt);
                    let case = format!("hang {hang} speed {speed} r {r} dt {dt}: {v:?}");
                    for (vi, _) in &v[..4] {
                        assert!(vi.length() < 0.02 * speed, "{case}");
                    }
                    // A hanging ball has climbed a little since: its energy is the blow's.
                    let (last, y) = v[4];
                    let energy = last.length_squared() + 2.0 * G * y * hang as u8 as Real;
                    assert!(last.x > 0.0, "{case}");
                    assert!(
                        (energy.sqrt() - speed).abs() < 0.01 * speed,
                        "{case}: {}",
                        energy.sqrt()
                    );
                }
            }
        }
    }
}

/// The fastest speed of any body over `seconds` after `settle` seconds.
fn fastest_after(w: &mut World, ids: &[BodyId], dt: Real, settle: Real, seconds: Real) -> Real {
    run(w, dt, (settle / dt) as usize);
    let mut fastest: Real = 0.0;
    for _ in 0..(seconds / dt) as usize {
        w.step(dt).unwrap();
        for id in ids {
            let b = w.body(*id).unwrap();
            fastest = fastest.max(b.linear_velocity().length());
        }
    }
    fastest
}

#[test]
fn bouncy_stacks_and_balls_rest_without_jitter() {
    // The threshold is twice gravity's kick of one substep: a resting contact meets one
    // kick as an approach every substep. A tower of six boxes and a resting ball, e up to
    // 0.9, at both time steps and with 1 to 8 substeps; sleeping off. Once settled,
    // nothing may move faster than it does with e = 0 (the tower's own sway: 6 cm/s with
    // one substep at dt 1/60, 7 mm/s with 4, 20 µm/s with 8). A bounce of a resting
    // contact would launch at e·|g|·h: 3.7 cm/s for e = 0.9 at dt 1/60 with 4 substeps.
    for substeps in [1, 4, 8] {
        for dt in [1.0 / 60.0, 1.0 / 240.0] {
            let still = bouncy_tower(0.0, substeps, dt);
            for e in [0.5, 0.9] {
                let fastest = bouncy_tower(e, substeps, dt);
                assert!(
                    fastest <= still * 1.05 + 1e-4,
                    "e {e} substeps {substeps} dt {dt}: {fastest} m/s against {still}"
                );
            }
        }
    }
}

/// The fastest any body of a tower and a ball with restitution `e` moves once settled.
fn bouncy_tower(e: Real, substeps: u32, dt: Real) -> Real {
    let mut w = world_with(Vec3::new(0.0, -G, 0.0), substeps);
    ground(&mut w, e);
    let mut ids: Vec<BodyId> = (0..6)
        .map(|i| {
            let def = BodyDef {
                position: Vec3::new(0.0, 0.25 + 0.5 * i as Real, 0.0),
                restitution: e,
                ..Default::default()
            };
            w.create_body(&def, Shape::cuboid(Vec3::splat(0.25)))
                .unwrap()
        })
        .collect();
    let def = BodyDef {
        position: Vec3::new(2.0, 0.1, 0.0),
        restitution: e,
        ..Default::default()
    };
    ids.push(w.create_body(&def, Shape::sphere(0.1)).unwrap());
    fastest_after(&mut w, &ids, dt, 1.0, 3.0)
}
