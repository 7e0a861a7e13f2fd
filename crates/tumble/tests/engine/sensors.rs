//! Sensors: bodies that report overlaps (begin and end events, current overlaps) and
//! never push or are pushed. Times are checked against free fall, and "never pushed"
//! against a world without the sensor, bit for bit.

// Casts between Real and f64 are no-ops in the default build but needed in the f32 one.
#![allow(clippy::unnecessary_cast)]

use crate::common::*;
use tumble::prelude::*;

const G: Real = 9.8;

fn down() -> Vec3 {
    Vec3::new(0.0, -G, 0.0)
}

/// A sensor slab, `kind`, filling y in [`low`, `high`] and 4 m × 4 m across.
fn slab(w: &mut World, kind: BodyKind, low: Real, high: Real) -> BodyId {
    let def = BodyDef {
        kind,
        position: Vec3::new(0.0, 0.5 * (low + high), 0.0),
        sensor: true,
        ..Default::default()
    };
    let half = Vec3::new(2.0, 0.5 * (high - low), 2.0);
    w.create_body(&def, Shape::cuboid(half)).unwrap()
}

/// A ball of radius `r` dropped from rest at height `h` (its centre) through a sensor slab
/// [low, high]: the overlap begins when its bottom reaches `high`, at t₁ = √(2 (h − high −
/// r) / g), and ends when its top leaves `low`, at t₂ = √(2 (h − low + r) / g). Events are
/// stamped at the end of the step that sees the change, so each lies within one step of
/// the exact time: after it by less than dt, or before it by what symplectic Euler's fall
/// runs ahead (g dt t / 2, at most half a step by t = 1 s), both bounded by dt. The ball
/// must fall exactly as it does in a world without the sensor (bit for bit), for a static,
/// a kinematic (moving sideways at 1 m/s) and a dynamic sensor (weightless, at rest).
#[test]
fn falling_ball_begins_and_ends_at_the_free_fall_times() {
    let kinds = [BodyKind::Static, BodyKind::Kinematic, BodyKind::Dynamic];
    for (r, h, (low, high), dt) in [
        (0.1, 5.0, (1.0, 2.0), 1.0 / 60.0),
        (0.3, 3.0, (-1.0, 0.5), 1.0 / 240.0),
        (0.05, 8.0, (2.0, 2.2), 1.0 / 120.0),
    ] {
        for kind in kinds {
            let mut w = world(down(), Integrator::SymplecticEuler);
            let mut alone = world(down(), Integrator::SymplecticEuler);
            let sensor = slab(&mut w, kind, low, high);
            match kind {
                BodyKind::Kinematic => w.set_linear_velocity(sensor, Vec3::X).unwrap(),
                BodyKind::Dynamic => w.set_gravity_scale(sensor, 0.0).unwrap(),
                BodyKind::Static => {}
            }
            let def = BodyDef {
                position: Vec3::new(0.0, h, 0.0),
                ..Default::default()
            };
            let ball = w.create_body(&def, Shape::sphere(r)).unwrap();
            let twin = alone.create_body(&def, Shape::sphere(r)).unwrap();
            let mut events = Vec::new();
            let end = (2.0 * (h - low + r) / G).sqrt() + 0.2;
            while w.time() < end {
                w.step(dt).unwrap();
                alone.step(dt).unwrap();
                events.extend_from_slice(w.sensor_events());
                let (a, b) = (w.body(ball).unwrap(), alone.body(twin).unwrap());
                assert_eq!(a.center_of_mass(), b.center_of_mass(), "{kind:?}: pushed");
                assert_eq!(a.linear_velocity(), b.linear_velocity(), "{kind:?}: pushed");
            }
            let t1 = (2.0 * (h - high - r) / G).sqrt();
            let t2 = (2.0 * (h - low + r) / G).sqrt();
            assert_eq!(events.len(), 2, "{kind:?}: {events:?}");
            for (e, (t, began)) in events.iter().zip([(t1, true), (t2, false)]) {
                assert_eq!((e.sensor, e.body, e.began), (sensor, ball, began));
                assert!(
                    (e.time - t).abs() <= dt,
                    "{kind:?} r {r} dt {dt}: event at {} vs free fall {t}",
                    e.time
                );
            }
        }
    }
}

/// The overlaps as the ball passes: none above, the ball while inside, none below; and a
/// sensor never detects another sensor, nor a static sensor a static body.
#[test]
fn overlaps_follow_the_ball_and_skip_sensors_and_statics() {
    let mut w = world(down(), Integrator::SymplecticEuler);
    let sensor = slab(&mut w, BodyKind::Static, 1.0, 2.0);
    let other = slab(&mut w, BodyKind::Static, 1.5, 3.0);
    let ground = BodyDef {
        kind: BodyKind::Static,
        position: Vec3::new(0.0, 1.5, 0.0),
        ..Default::default()
    };
    w.create_body(&ground, Shape::cuboid(Vec3::splat(0.2)))
        .unwrap();
    let ball = ball(&mut w, Vec3::new(1.0, 3.0, 0.0));
    let dt = 1.0 / 60.0;
    let mut seen = Vec::new();
    for _ in 0..60 {
        w.step(dt).unwrap();
        let y = w.body(ball).unwrap().center_of_mass().y;
        let inside = y - 0.1 <= 2.0 && y + 0.1 >= 1.0;
        let now = w.sensor_overlaps(sensor).unwrap();
        // A step either side of the boundary: the test is of the shapes at the step's end.
        if (y - 0.1 - 2.0).abs() > 1e-9 && (y + 0.1 - 1.0).abs() > 1e-9 {
            assert_eq!(now == [ball], inside, "y = {y}: {now:?}");
        }
        seen.push(now.len());
        // The ball is inside the second slab from y < 3.1, and it is a sensor too.
        let second = w.sensor_overlaps(other).unwrap();
        assert!(second.iter().all(|&b| b == ball), "{second:?}");
    }
    assert!(seen.contains(&1) && seen.last() == Some(&0), "{seen:?}");
}

/// A dynamic sensor falls under gravity through the ground (neither pushes nor is pushed)
/// at the free-fall rate: after 1 s at dt 1/100 it is where symplectic Euler puts a free
/// body, h − g dt² n (n + 1) / 2, to rounding; and it reports the ground it passed.
#[test]
fn a_dynamic_sensor_falls_through_the_ground() {
    let mut w = awake_on_ground(down());
    let ground = w.body_ids()[0];
    let def = BodyDef {
        position: Vec3::new(0.0, 1.0, 0.0),
        sensor: true,
        ..Default::default()
    };
    let s = w
        .create_body(&def, Shape::cuboid(Vec3::splat(0.3)))
        .unwrap();
    let (dt, n) = (0.01, 100);
    let mut began = None;
    for _ in 0..n {
        w.step(dt).unwrap();
        if let Some(e) = w.sensor_events().iter().find(|e| e.began) {
            began = Some((e.body, e.time));
        }
    }
    let y = w.body(s).unwrap().center_of_mass().y;
    let exact = 1.0 - G * dt * dt * (n * (n + 1)) as Real / 2.0;
    assert!((y - exact).abs() < tol(1e-9, 1e-4), "y {y} vs {exact}");
    assert!(w.contacts().iter().all(|c| c.manifold.is_empty()));
    // The plane y = 0 meets the box's bottom when its centre is 0.3 up: t = √(2·0.7/g).
    let (body, t) = began.expect("the ground was detected");
    assert_eq!(body, ground);
    assert!((t - (1.4 / G).sqrt()).abs() <= dt, "began at {t}");
}

/// A box resting on the ground inside a sensor falls asleep and stays reported: no end
/// event when it sleeps, and its overlap is still listed.
#[test]
fn sleeping_bodies_stay_reported() {
    let mut w = World::new(&WorldDef {
        gravity: down(),
        ..Default::default()
    });
    let ground = BodyDef {
        kind: BodyKind::Static,
        ..Default::default()
    };
    w.create_body(&ground, Shape::plane(Vec3::Y, 0.0)).unwrap();
    let sensor = slab(&mut w, BodyKind::Static, 0.0, 1.0);
    let def = BodyDef {
        position: Vec3::new(0.0, 0.2, 0.0),
        ..Default::default()
    };
    let b = w
        .create_body(&def, Shape::cuboid(Vec3::splat(0.2)))
        .unwrap();
    let mut events = Vec::new();
    for _ in 0..600 {
        w.step(1.0 / 60.0).unwrap();
        events.extend_from_slice(w.sensor_events());
    }
    assert!(!w.body(b).unwrap().is_awake(), "the box should sleep");
    assert_eq!(w.sensor_overlaps(sensor).unwrap(), [b]);
    assert_eq!(events.len(), 1, "{events:?}");
    assert!(events[0].began);
}

/// Removing a body ends its overlap at once; the end event, stamped with the time of the
/// removal, comes first among the next step's events. Clearing the sensor flag ends the
/// sensor's overlaps the same way; setting it on a resting box lets it fall through the
/// ground it rested on.
#[test]
fn removal_and_flag_changes_end_overlaps() {
    let mut w = world(Vec3::ZERO, Integrator::SymplecticEuler);
    let sensor = slab(&mut w, BodyKind::Static, 0.0, 1.0);
    let a = ball(&mut w, Vec3::new(0.0, 0.5, 0.0));
    let b = ball(&mut w, Vec3::new(1.0, 0.5, 0.0));
    w.step(0.1).unwrap();
    assert_eq!(w.sensor_overlaps(sensor).unwrap(), [a, b]);
    let removed_at = w.time();
    w.remove_body(a).unwrap();
    assert_eq!(w.sensor_overlaps(sensor).unwrap(), [b]);
    w.step(0.1).unwrap();
    let end = SensorEvent {
        sensor,
        body: a,
        began: false,
        time: removed_at,
    };
    assert_eq!(w.sensor_events(), [end]);
    w.step(0.1).unwrap();
    assert!(w.sensor_events().is_empty());
    w.set_sensor(sensor, false).unwrap();
    assert!(w.sensor_overlaps(sensor).unwrap().is_empty());
    w.step(0.1).unwrap();
    assert_eq!(w.sensor_events().len(), 1);
    assert_eq!(
        (w.sensor_events()[0].body, w.sensor_events()[0].began),
        (b, false)
    );
    assert!(matches!(
        w.set_sensor(a, true),
        Err(Error::UnknownBody { .. })
    ));

    let mut w = awake_on_ground(down());
    let def = BodyDef {
        position: Vec3::new(0.0, 0.2, 0.0),
        ..Default::default()
    };
    let b = w
        .create_body(&def, Shape::cuboid(Vec3::splat(0.2)))
        .unwrap();
    run(&mut w, 1.0 / 60.0, 60);
    let rest = w.body(b).unwrap().center_of_mass().y;
    assert!((rest - 0.2).abs() < 0.01, "rests at {rest}");
    w.set_sensor(b, true).unwrap();
    assert!(w.body(b).unwrap().is_sensor());
    run(&mut w, 1.0 / 60.0, 30);
    assert!(
        w.body(b).unwrap().center_of_mass().y < -0.5,
        "should fall through"
    );
}

/// Sensors respect collision filters and never count toward the contact limits: a sensor
/// holding 60 balls in a world allowed 8 manifolds a step steps, and lists all 60; one
/// whose mask leaves out the balls' layer lists none.
#[test]
fn filters_apply_and_limits_do_not() {
    let mut w = World::new(&WorldDef {
        gravity: Vec3::ZERO,
        contact_limits: tumble::limits::ContactLimits {
            per_body: 2,
            per_step: 8,
        },
        ..Default::default()
    });
    let sensor = slab(&mut w, BodyKind::Static, 0.0, 1.0);
    let blind = slab(&mut w, BodyKind::Kinematic, 0.0, 1.0);
    w.set_collision_filter(blind, 1, 2).unwrap();
    let balls: Vec<BodyId> = (0..60)
        .map(|i| {
            let at = Vec3::new(
                (i % 8) as Real * 0.3 - 1.0,
                0.5,
                (i / 8) as Real * 0.3 - 1.0,
            );
            ball(&mut w, at)
        })
        .collect();
    w.step(1.0 / 60.0).unwrap();
    assert_eq!(w.sensor_overlaps(sensor).unwrap(), balls);
    assert!(w.sensor_overlaps(blind).unwrap().is_empty());
    assert_eq!(w.sensor_events().len(), 60);
    assert!(w.sensor_events().windows(2).all(|e| e[0].body < e[1].body));
}

/// The same scene run twice gives the same events, in the same order.
#[test]
fn events_are_deterministic() {
    let run_once = || {
        let mut w = awake_on_ground(down());
        slab(&mut w, BodyKind::Static, 0.0, 0.5);
        slab(&mut w, BodyKind::Static, 0.3, 2.0);
        for i in 0..20 {
            let at = Vec3::new((i % 5) as Real * 0.25, 1.0 + 0.3 * i as Real, 0.0);
            ball(&mut w, at);
        }
        let mut events = Vec::new();
        for _ in 0..240 {
            w.step(1.0 / 120.0).unwrap();
            events.extend_from_slice(w.sensor_events());
        }
        events
    };
    let first = run_once();
    // Every ball enters the upper slab and then the lower; those low in their column of
    // four leave the upper one too.
    assert!(first.len() >= 40, "{}", first.len());
    assert_eq!(first, run_once());
}

/// The scene loader's rules and messages apply to the flag's neighbours; `sensor_overlaps`
/// of an unknown body is refused, of a body that is not a sensor empty.
#[test]
fn queries_on_unknown_and_plain_bodies() {
    let mut w = world(down(), Integrator::SymplecticEuler);
    let b = ball(&mut w, Vec3::ZERO);
    assert!(w.sensor_overlaps(b).unwrap().is_empty());
    w.remove_body(b).unwrap();
    let err = w.sensor_overlaps(b).unwrap_err();
    assert!(matches!(err, Error::UnknownBody { .. }), "{err}");
}
