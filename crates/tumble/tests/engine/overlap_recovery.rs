//! Overlap recovery (issue 15, point 1): bodies created inside each other, by up to half
//! their size, are pushed apart without being launched, and settle.
//!
//! Before `dynamics/solver/overlap.rs`, the soft contacts' push-out velocity (3 m/s per
//! contact) summed up a column and the relax pass could not take it back: five 1 m cubes
//! created half inside each other left at 11 m/s and flew 7 m up, ten at 21 m/s and 24 m.

// Casts between Real and f64 are no-ops in the default build but needed in the f32 one.
#![allow(clippy::unnecessary_cast)]

use crate::common::awake_on_ground;
use tumble::prelude::*;

fn world() -> World {
    awake_on_ground(Vec3::new(0.0, -9.81, 0.0))
}

/// The fastest any of `ids` moved over `seconds` at `dt`, and the highest centre seen;
/// `up` counts only upward and sideways motion (a launch), not falling.
fn watch(w: &mut World, ids: &[BodyId], dt: Real, seconds: Real, up: bool) -> (Real, Real) {
    let (mut fastest, mut highest): (Real, Real) = (0.0, Real::MIN);
    for _ in 0..(seconds / dt).round() as usize {
        w.step(dt).unwrap();
        for &id in ids {
            let b = w.body(id).unwrap();
            let mut v = b.linear_velocity();
            if up {
                v.y = v.y.max(0.0);
            }
            fastest = fastest.max(v.length());
            highest = highest.max(b.position().y);
        }
    }
    (fastest, highest)
}

#[test]
fn a_column_created_inside_itself_is_pushed_apart_and_stands() {
    // n cubes of side `size`, each `overlap` into the one below (the first into the
    // ground). Measured (f64 and f32 alike): fastest 0.14 to 0.60 m/s, the top within 7
    // mm of where a column built touching would stand (its contacts' soft sag) and at
    // most 0.04 of a cube aside (ten 1 m cubes: 1.7 cm).
    for (n, size, overlap) in [
        (5, 1.0, 0.5),
        (5, 1.0, 0.25),
        (10, 1.0, 0.5),
        (5, 0.2, 0.1),
        (8, 0.1, 0.05),
        (3, 0.2, 0.02),
    ] {
        for dt in [1.0 / 60.0, 1.0 / 240.0] {
            let mut w = world();
            let half = 0.5 * size;
            let ids: Vec<BodyId> = (0..n)
                .map(|i| {
                    let y = half - overlap + i as Real * (size - overlap);
                    let def = BodyDef {
                        position: Vec3::new(0.0, y, 0.0),
                        ..Default::default()
                    };
                    w.create_body(&def, Shape::cuboid(Vec3::splat(half)))
                        .unwrap()
                })
                .collect();
            let (fastest, highest) = watch(&mut w, &ids, dt, 5.0, false);
            let rest = half + (n - 1) as Real * size;
            let top = w.body(ids[n - 1]).unwrap().position();
            // A tenth of a cube aside: pushes that turned the boxes left the ten 1 m
            // cubes standing 0.5 m aside.
            let lean = 0.1;
            let at = format!("{n} cubes of {size} m, {overlap} m deep, dt {dt:.4}");
            assert!(fastest < 1.0, "{at}: launched at {fastest} m/s");
            assert!(highest < rest + 0.01 * size, "{at}: rose to {highest}");
            assert!(
                (top.y - rest).abs() < 0.01 * n as Real * size
                    && top.x.abs().max(top.z.abs()) < lean * size,
                "{at}: top at {top:?}, standing it would be at {rest}"
            );
        }
    }
}

#[test]
fn a_pile_created_interpenetrating_settles() {
    // 27 boxes and balls of 0.3 m on a grid 0.2 m apart, each a third inside its
    // neighbours, turned every which way: pushed apart slowly, they fall into a pile.
    for dt in [1.0 / 60.0, 1.0 / 240.0] {
        let mut w = world();
        let mut ids = Vec::new();
        for i in 0..27 {
            let (x, y, z) = ((i % 3) as Real, ((i / 3) % 3) as Real, (i / 9) as Real);
            let axis = Vec3::new(1.0 + x, 2.0 - y, 0.5 + z).normalize();
            let def = BodyDef {
                position: Vec3::new(0.2 * x, 0.1 + 0.2 * y, 0.2 * z),
                orientation: Quat::from_axis_angle(axis, 0.4 * i as Real),
                friction: 0.6,
                ..Default::default()
            };
            let shape = if i % 2 == 0 {
                Shape::cuboid(Vec3::splat(0.15))
            } else {
                Shape::sphere(0.15)
            };
            ids.push(w.create_body(&def, shape).unwrap());
        }
        // Falling 0.5 m they reach 3.1 m/s; pushed out, not above 3 m/s upwards or aside.
        // Pushed up level by level, the three layers stack before they spread: the
        // highest centre rises from 0.5 to 0.83 m (dt 1/60) and 1.0 m (dt 1/240); launched
        // at 3 m/s one would rise 0.46 m more.
        let (fastest, highest) = watch(&mut w, &ids, dt, 8.0, true);
        assert!(fastest < 3.0, "dt {dt}: launched at {fastest} m/s");
        assert!(highest < 1.1, "dt {dt}: thrown up to {highest} m");
        for &id in &ids {
            let b = w.body(id).unwrap();
            let low = b.shape().aabb(&b.pose()).min.y;
            assert!(low > -0.01, "dt {dt}: a body {low} m into the ground");
            // Balls may roll away on the ground (no rolling resistance); nothing jitters.
            let v = b.linear_velocity();
            let still = if b.shape().round_radius(0) > 0.0 {
                v.y.abs()
            } else {
                v.length()
            };
            assert!(still < 0.05, "dt {dt}: still moving at {v:?} after 8 s");
        }
    }
}

/// How far apart (m) the centres of two cubes created half inside each other, with no
/// gravity, are after each of `steps` steps at `dt`, pushed apart at most at `speed`.
fn separations(speed: Option<Real>, dt: Real, steps: usize) -> (Vec<Real>, World) {
    let mut w = World::try_new(&WorldDef {
        gravity: Vec3::ZERO,
        sleep: false,
        max_push_speed: speed,
        ..Default::default()
    })
    .unwrap();
    let ids: Vec<BodyId> = [-0.25, 0.25]
        .iter()
        .map(|&y| {
            let def = BodyDef {
                position: Vec3::new(0.0, y, 0.0),
                ..Default::default()
            };
            w.create_body(&def, Shape::cuboid(Vec3::splat(0.5)))
                .unwrap()
        })
        .collect();
    let gap = |w: &World| {
        let p = |i: usize| w.body(ids[i]).unwrap().position();
        (p(1) - p(0)).length()
    };
    let mut out = vec![gap(&w)];
    for _ in 0..steps {
        w.step(dt).unwrap();
        out.push(gap(&w));
    }
    (out, w)
}

#[test]
fn the_push_out_speed_is_a_setting_and_bounds_the_recovery() {
    // Two 1 m cubes half inside each other: whatever the cap, they part no faster than
    // it (relative travel per step at most cap × dt, plus float noise), come within the
    // slop (5 mm, which the soft contact closes) of touching in about 0.5 m / cap, and
    // are not launched: what they keep is what the
    // soft contact's correction of the last few millimetres leaves, 0.008 to 0.011 m/s
    // each (measured), whatever the cap; a launch would keep the cap's speed.
    assert_eq!(World::new(&WorldDef::default()).max_push_speed(), 3.0);
    for cap in [0.25 as Real, 1.0, 3.0, 10.0] {
        for dt in [1.0 / 60.0, 1.0 / 240.0] {
            let at = format!("cap {cap} m/s, dt {dt:.4}");
            let need = (0.5 / (cap * dt)).ceil() as usize;
            let (gaps, w) = separations(Some(cap), dt, 2 * need + 60);
            for (i, pair) in gaps.windows(2).enumerate() {
                let opened = pair[1] - pair[0];
                assert!(
                    opened <= cap * dt * 1.001 + 1e-9,
                    "{at}: step {i} opened {opened}"
                );
            }
            let first = gaps.iter().position(|&g| g >= 0.994).unwrap_or(usize::MAX);
            assert!(
                first <= need + need / 5 + 10,
                "{at}: touching only at step {first} of {need}"
            );
            for (_, b) in w.bodies() {
                let v = b.linear_velocity().length();
                assert!(v < 0.02, "{at}: left moving at {v} m/s");
            }
        }
    }
}

#[test]
fn a_bad_push_out_speed_is_refused_and_changes_nothing() {
    for bad in [0.0, -1.0, Real::NAN, Real::INFINITY] {
        let def = WorldDef {
            max_push_speed: Some(bad),
            ..Default::default()
        };
        let e = World::try_new(&def)
            .err()
            .expect("a bad max_push_speed is refused");
        assert!(e.to_string().starts_with("max_push_speed: must be"), "{e}");
        let mut w = World::new(&WorldDef::default());
        assert!(w.set_max_push_speed(bad).is_err());
        assert_eq!(w.max_push_speed(), 3.0);
    }
    let unit = WorldDef {
        length_unit: 0.01,
        ..Default::default()
    };
    assert_eq!(World::new(&unit).max_push_speed(), 3.0 * 0.01);
}
