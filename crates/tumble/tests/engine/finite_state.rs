//! The finite-state invariant: a step whose result is not finite, or faster than the
//! world's speed limits, is undone and reported; values that can only overflow are refused
//! where they enter.

// Casts between Real and f64 are no-ops in the default build but needed in the f32 one.
#![allow(clippy::unnecessary_cast)]

use crate::common;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;
use tumble::error::Unstable;
use tumble::prelude::*;
use tumble::SpeedLimits;

/// A 1 kg ball hanging from a spring of stiffness `k` (N/m) to the point 1 m above it,
/// released 0.1 m from rest length.
fn stiff_spring(k: Real, integrator: Integrator) -> (World, BodyId) {
    let mut w = common::world(Vec3::new(0.0, -9.8, 0.0), integrator);
    let def = BodyDef {
        name: Some("ball".into()),
        mass: MassSpec::Mass(1.0),
        ..Default::default()
    };
    let ball = w.create_body(&def, Shape::sphere(0.1)).unwrap();
    w.add_force(Force::Spring(Spring {
        body: ball,
        anchor: Vec3::ZERO,
        other: SpringEnd::World(Vec3::new(0.0, 1.0, 0.0)),
        stiffness: k,
        rest_length: 0.9,
        damping: 0.0,
    }))
    .unwrap();
    (w, ball)
}

fn unstable(e: Error) -> Unstable {
    match e {
        Error::Unstable(u) => *u,
        other => panic!("expected an unstable step, got {other}"),
    }
}

/// Steps until a step fails; the failure, and the hash and clock before the failing step.
fn run_until_failure(w: &mut World, dt: Real, steps: usize) -> Option<(Unstable, u64, Real)> {
    for _ in 0..steps {
        let (hash, time) = (w.state_hash(), w.time());
        if let Err(e) = w.step(dt) {
            return Some((unstable(e), hash, time));
        }
    }
    None
}

#[test]
fn a_stiff_spring_under_explicit_integrators_stops_with_the_step_undone() {
    // ω = √(k/m) = 31,623 rad/s; ω dt = 31.6 at dt = 1 ms: every explicit method's
    // growth factor per step exceeds 1, by a factor near (ω dt)² for Euler.
    let explicit = [
        Integrator::ExplicitEuler,
        Integrator::Midpoint,
        Integrator::Rk4,
        Integrator::SymplecticEuler,
        Integrator::VelocityVerlet,
    ];
    for integrator in explicit {
        let (mut w, ball) = stiff_spring(1e9, integrator);
        let (u, hash, time) = run_until_failure(&mut w, 1e-3, 2_000)
            .unwrap_or_else(|| panic!("{integrator:?} survived a spring with ω dt = 31.6"));
        assert_eq!(
            w.state_hash(),
            hash,
            "{integrator:?}: the failed step was not undone"
        );
        assert_eq!(w.time(), time);
        assert_eq!(u.step, w.step_count() + 1);
        assert_eq!(u.body, ball);
        assert_eq!(u.index, 0);
        assert!((u.time - (time + 1e-3)).abs() < 1e-9, "{}", u.time);
        // Caught by the speed bound long before the first infinity.
        assert_eq!(
            u.quantity,
            "velocity",
            "{integrator:?}: {}",
            Error::Unstable(Box::new(u.clone()))
        );
        let text = Error::Unstable(Box::new(u)).to_string();
        assert!(
            text.starts_with(&format!("step {} (t = ", w.step_count() + 1)),
            "{text}"
        );
        assert!(
            text.contains("bodies[0] \"ball\": velocity reached the speed"),
            "{text}"
        );
        assert_eq!(text.lines().count(), 1);
        // The world stays usable: it refuses the same step again, the same way.
        assert!(w.step(1e-3).is_err());
        assert_eq!(w.state_hash(), hash);
    }
}

#[test]
fn the_stiff_spring_under_implicit_euler_runs_and_stays_below_the_limit() {
    // Implicit Euler damps every mode: the same spring runs, decaying.
    let (mut w, ball) = stiff_spring(1e9, Integrator::ImplicitEuler);
    for _ in 0..2_000 {
        w.step(1e-3).unwrap();
    }
    let v = w.body(ball).unwrap().linear_velocity().length();
    assert!(v.is_finite() && v < 10.0, "{v}");
}

/// A scene with what a step changes besides bodies: a stack in contact (warm starts), a
/// jointed pendulum (joint warm starts), a free ball under Störmer–Verlet (memory) and a
/// box that falls asleep on the ground.
fn busy_scene() -> World {
    let mut w = World::new(&WorldDef {
        integrator: Integrator::Verlet,
        ..Default::default()
    });
    let ground = BodyDef {
        kind: BodyKind::Static,
        ..Default::default()
    };
    w.create_body(&ground, Shape::plane(Vec3::Y, 0.0)).unwrap();
    for i in 0..4 {
        let def = BodyDef {
            position: Vec3::new(0.0, 0.25 + 0.5 * i as Real, 0.0),
            ..Default::default()
        };
        w.create_body(&def, Shape::cuboid(Vec3::splat(0.25)))
            .unwrap();
    }
    let bob = BodyDef {
        position: Vec3::new(3.0, 2.0, 0.0),
        linear_velocity: Vec3::new(0.0, 0.0, 1.0),
        ..Default::default()
    };
    let bob = w.create_body(&bob, Shape::sphere(0.1)).unwrap();
    let mut def = JointDef::new(
        JointKind::Ball {
            cone: None,
            twist: None,
        },
        bob,
    );
    def.anchor = Vec3::new(-1.0, 0.0, 0.0);
    def.other_anchor = Vec3::new(2.0, 2.0, 0.0);
    w.create_joint(&def).unwrap();
    common::ball(&mut w, Vec3::new(-3.0, 5.0, 0.0));
    w
}

/// `busy_scene` with a force callback that pushes body `poison` (a dense index, when set)
/// with a NaN force: the step it poisons must fail.
fn poisonable_scene(poison: Arc<AtomicUsize>) -> World {
    let mut w = busy_scene();
    let ids: Vec<BodyId> = w.body_ids().to_vec();
    w.add_force_callback(Box::new(move |ctx: &mut ForceContext<'_>| {
        if let Some(&id) = ids.get(poison.load(Ordering::Relaxed)) {
            ctx.add_force(id, Vec3::new(0.0, Real::NAN, 0.0));
        }
    }));
    w
}

#[test]
fn an_undone_step_leaves_the_world_exactly_as_before() {
    // Two equal worlds; in one, now and then a step is poisoned (a body in the stack, the
    // pendulum's bob or the free ball is pushed with a NaN force), fails and is undone.
    // From then on both must agree bit for bit: bodies, contacts' impulses and events,
    // joints, sleep and the integrator's memory all came back.
    let (none, stack, bob, free) = (usize::MAX, 2, 5, 6);
    let poison = Arc::new(AtomicUsize::new(none));
    let mut a = poisonable_scene(poison.clone());
    let mut b = poisonable_scene(Arc::new(AtomicUsize::new(none)));
    let dt = 1.0 / 60.0;
    let impulses = |w: &World| -> Vec<Real> {
        w.contacts()
            .iter()
            .flat_map(|c| c.manifold.points().iter().map(|p| p.normal_impulse))
            .collect()
    };
    // The joints' reactions and broken flags (warm starts show in the states after).
    let joints = |w: &World| -> Vec<(Vec3, Vec3, bool)> {
        w.joints()
            .map(|(_, j)| (j.reaction_force(), j.reaction_torque(), j.is_broken()))
            .collect()
    };
    let mut poisoned = 0;
    for n in 0..240 {
        let target = [stack, bob, free][n % 3];
        // Forces on a sleeping body are not evaluated: only awake ones can be poisoned.
        let awake = a.body(a.body_ids()[target]).unwrap().is_awake();
        if n % 17 == 5 && awake {
            poison.store(target, Ordering::Relaxed);
            let (before, time, reactions) = (a.state_hash(), a.time(), joints(&a));
            let u = unstable(a.step(dt).unwrap_err());
            assert_eq!(u.index, target, "step {n}");
            assert!(
                ["position", "velocity"].contains(&u.quantity),
                "step {n}: {}",
                u.quantity
            );
            assert_eq!(u.problem, "is not finite");
            assert_eq!((a.state_hash(), a.time()), (before, time));
            assert_eq!(joints(&a), reactions, "step {n}");
            poison.store(none, Ordering::Relaxed);
            poisoned += 1;
        }
        a.step(dt).unwrap();
        b.step(dt).unwrap();
        assert_eq!(a.state_hash(), b.state_hash(), "step {n}");
        assert_eq!(impulses(&a), impulses(&b), "step {n}");
        assert_eq!(joints(&a), joints(&b), "step {n}");
        assert_eq!(a.contact_events(), b.contact_events(), "step {n}");
    }
    assert!(joints(&a).iter().any(|r| r.0 != Vec3::ZERO));
    let asleep = |w: &World| w.bodies().filter(|(_, b)| !b.is_awake()).count();
    assert_eq!(asleep(&a), asleep(&b));
    assert!(asleep(&a) > 0, "the stack was meant to fall asleep");
    assert!(poisoned >= 6, "{poisoned}");
}

/// `busy_scene` with a force callback that counts its calls and, when `fail_at` holds a
/// call number, stops the step at that call (as a Python exception does).
fn failing_scene(calls: Arc<AtomicUsize>, fail_at: Arc<AtomicUsize>) -> World {
    let mut w = busy_scene();
    w.add_force_callback(Box::new(move |ctx: &mut ForceContext<'_>| {
        let n = calls.fetch_add(1, Ordering::Relaxed) + 1;
        if n == fail_at.load(Ordering::Relaxed) {
            ctx.fail(format!("call {n}"));
        }
    }));
    w
}

#[test]
fn a_step_a_callback_fails_is_undone_and_calls_nothing_more() {
    // The callback fails at its k-th call, in the integrator's stage (the free ball,
    // Störmer–Verlet: one call) or in the solver's substeps (stack and pendulum):
    // the step is undone bit for bit, no call follows the failing one, and from then on
    // the world agrees with one that never failed, contacts, joints and memory included.
    let dt = 1.0 / 60.0;
    let (calls, fail_at) = (Arc::new(AtomicUsize::new(0)), Arc::new(AtomicUsize::new(0)));
    let mut a = failing_scene(calls.clone(), fail_at.clone());
    let unused = Arc::new(AtomicUsize::new(0));
    let mut b = failing_scene(Arc::new(AtomicUsize::new(0)), unused);
    for n in 0..120 {
        if n % 13 == 4 {
            let start = calls.load(Ordering::Relaxed);
            // The step's 1st to 4th call: while the free ball falls, the 1st is the
            // integrator's; the swinging pendulum keeps the solver's 4 substeps going.
            let k = start + 1 + n % 4;
            fail_at.store(k, Ordering::Relaxed);
            let (before, time, steps) = (a.state_hash(), a.time(), a.step_count());
            let e = a.step(dt).unwrap_err();
            assert!(e.is_step_failure());
            assert_eq!(
                e.to_string(),
                format!(
                    "step {} (t = {} s): force callback: call {k}",
                    steps + 1,
                    tumble::limits::short(time + dt)
                )
            );
            assert_eq!(
                calls.load(Ordering::Relaxed),
                k,
                "step {n}: a call after the failure"
            );
            assert_eq!(
                (a.state_hash(), a.time(), a.step_count()),
                (before, time, steps)
            );
        }
        a.step(dt).unwrap();
        b.step(dt).unwrap();
        assert_eq!(a.state_hash(), b.state_hash(), "step {n}");
        assert_eq!(a.contact_events(), b.contact_events(), "step {n}");
    }
}

#[test]
fn values_that_can_only_overflow_are_refused_with_the_limit() {
    let mut w = World::new(&WorldDef::default());
    let refuse = |def: BodyDef, shape: Shape, w: &mut World| {
        w.create_body(&def, shape).unwrap_err().to_string()
    };
    let e = refuse(
        BodyDef {
            position: Vec3::new(1e30, 0.0, 0.0),
            ..Default::default()
        },
        Shape::sphere(1.0),
        &mut w,
    );
    assert_eq!(e, "position: must be at most 1e9 m in magnitude");
    let e = refuse(
        BodyDef {
            linear_velocity: Vec3::new(0.0, 2e4, 0.0),
            ..Default::default()
        },
        Shape::sphere(1.0),
        &mut w,
    );
    assert_eq!(e, "velocity: must be no longer than 10000 m/s (max_speed)");
    let e = refuse(
        BodyDef {
            mass: MassSpec::Density(1e-30),
            ..Default::default()
        },
        Shape::sphere(1.0),
        &mut w,
    );
    assert!(
        e.starts_with("density: mass and inertia come out at "),
        "{e}"
    );
    assert!(e.contains("must be in [1e-12, 1e15] kg"), "{e}");
    assert!(e.len() < 200, "{e}");
    let e = w
        .set_gravity(Vec3::new(0.0, -1e30, 0.0))
        .unwrap_err()
        .to_string();
    assert_eq!(e, "gravity: must be at most 1e6 m/s² in magnitude");
    let ball = common::ball(&mut w, Vec3::ZERO);
    let before = w.state_hash();
    let e = w
        .apply_impulse(ball, Vec3::new(1e14, 0.0, 0.0), Vec3::ZERO)
        .unwrap_err();
    assert!(
        e.to_string()
            .starts_with("impulse: would make the body's velocity"),
        "{e}"
    );
    assert_eq!(w.state_hash(), before, "a refused impulse changed the body");
    let e = w
        .set_linear_velocity(ball, Vec3::new(1e30, 0.0, 0.0))
        .unwrap_err();
    assert_eq!(e.to_string(), "velocity: must be at most 1e15 in magnitude");
    assert_eq!(w.state_hash(), before);
    // A huge but valid rotation is one: [1e308, 0, 0, 1e308] is 90° about x.
    // A huge but valid rotation is one: [3e38, 0, 0, 3e38] is 90° about x.
    let def = BodyDef {
        orientation: Quat::from_xyzw(Real::MAX, 0.0, 0.0, Real::MAX),
        position: Vec3::new(10.0, 0.0, 0.0),
        ..Default::default()
    };
    let id = w.create_body(&def, Shape::sphere(1.0)).unwrap();
    let q = w.body(id).unwrap().orientation();
    let half = (0.5 as Real).sqrt();
    assert!(
        (q.x - half).abs() < 1e-6 && (q.w - half).abs() < 1e-6,
        "{q:?}"
    );
    let before = w.state_hash();
    let mut spring = JointSpring {
        hertz: 1e30,
        damping_ratio: 1.0,
        target: 0.0,
    };
    let hinge = |spring| JointKind::Hinge {
        limits: None,
        motor: None,
        spring: Some(spring),
        servo: None,
    };
    let e = w
        .create_joint(&JointDef::new(hinge(spring), ball))
        .unwrap_err();
    assert!(
        e.to_string()
            .ends_with("hertz: must be at most 1e15 in magnitude"),
        "{e}"
    );
    spring.hertz = 2e6;
    let e = w
        .create_joint(&JointDef::new(hinge(spring), ball))
        .unwrap_err();
    assert!(
        e.to_string()
            .ends_with("hertz: must be at most 1e6 Hz in magnitude"),
        "{e}"
    );
    spring.hertz = 5.0;
    spring.damping_ratio = 1e30;
    let e = w
        .create_joint(&JointDef::new(hinge(spring), ball))
        .unwrap_err();
    assert!(
        e.to_string()
            .ends_with("damping_ratio: must be at most 1e15 in magnitude"),
        "{e}"
    );
    assert_eq!(w.state_hash(), before);
}

#[test]
fn speed_limits_are_a_setting_that_a_moving_body_bounds_from_below() {
    let mut w = World::new(&WorldDef {
        limits: Some(SpeedLimits {
            max_speed: 5e4,
            max_angular_speed: 1e5,
        }),
        ..Default::default()
    });
    let def = BodyDef {
        linear_velocity: Vec3::new(3e4, 0.0, 0.0),
        ..Default::default()
    };
    w.create_body(&def, Shape::sphere(0.01)).unwrap();
    let tight = SpeedLimits {
        max_speed: 1e4,
        max_angular_speed: 1e5,
    };
    let e = w.set_speed_limits(tight).unwrap_err().to_string();
    assert_eq!(
        e,
        "max_speed: must be at least 30000 m/s: bodies[0] moves that fast"
    );
    assert_eq!(w.speed_limits().max_speed, 5e4);
    // A rifle bullet's world: 30 km/s, one second, no complaint.
    for _ in 0..60 {
        w.step(1.0 / 60.0).unwrap();
    }
}
