//! Contact hooks: the pair filter (no contact at all for a refused pair) and the contact
//! modifier (friction, restitution, surface velocity, dropped points), against closed
//! forms.

// Casts between Real and f64 are no-ops in the default build but needed in the f32 one.
#![allow(clippy::unnecessary_cast)]

use crate::common::*;
use std::sync::{Arc, Mutex};
use tumble::prelude::*;

const G: Real = 9.8;

fn down() -> Vec3 {
    Vec3::new(0.0, -G, 0.0)
}

/// A static slab whose top face is y = 0, `half` thick.
fn floor(w: &mut World, half: Real) -> BodyId {
    let def = BodyDef {
        kind: BodyKind::Static,
        position: Vec3::new(0.0, -half, 0.0),
        ..Default::default()
    };
    w.create_body(&def, Shape::cuboid(Vec3::new(20.0, half, 20.0)))
        .unwrap()
}

/// A cube of half extent `half` at `at`, friction `mu`.
fn cube(w: &mut World, at: Vec3, half: Real, mu: Real) -> BodyId {
    let def = BodyDef {
        position: at,
        friction: mu,
        ..Default::default()
    };
    w.create_body(&def, Shape::cuboid(Vec3::splat(half)))
        .unwrap()
}

fn awake() -> World {
    World::new(&WorldDef {
        gravity: down(),
        sleep: false,
        ..Default::default()
    })
}

/// The filter refuses (floor, a): `a` falls through as if the floor were not there, `b`
/// lands; the filter is asked once per pair (the pairs persist: a plane-wide floor keeps
/// both boxes' boxes), and a refused pair makes no contact event.
#[test]
fn the_filter_drops_a_pair() {
    for (half, dt) in [(0.25, 1.0 / 60.0), (0.1, 1.0 / 240.0)] {
        let mut w = awake();
        let ground = floor(&mut w, 0.5);
        let a = cube(&mut w, Vec3::new(-2.0, 1.0, 0.0), half, 0.6);
        let b = cube(&mut w, Vec3::new(2.0, 1.0, 0.0), half, 0.6);
        let asked = Arc::new(Mutex::new(Vec::new()));
        let log = asked.clone();
        w.set_contact_filter(move |p: &ContactPair<'_>| {
            log.lock().unwrap().push((p.body_a, p.body_b));
            !(p.body_a == ground && p.body_b == a)
        });
        let mut events = Vec::new();
        let steps = (1.5 / dt) as usize;
        for _ in 0..steps {
            w.step(dt).unwrap();
            events.extend_from_slice(w.contact_events());
        }
        let t = w.time();
        let fell = w.body(a).unwrap().center_of_mass().y;
        // Symplectic Euler's fall, 1 − g dt² n (n + 1) / 2, to rounding.
        let n = steps as Real;
        let free = 1.0 - G * dt * dt * n * (n + 1.0) / 2.0;
        assert!(
            (fell - free).abs() < tol(1e-9, 1e-3),
            "t {t}: {fell} vs {free}"
        );
        let rest = w.body(b).unwrap().center_of_mass().y;
        assert!((rest - half).abs() < 0.01, "b rests at {rest}");
        let asked = asked.lock().unwrap().clone();
        assert_eq!(asked, [(ground, a), (ground, b)]);
        assert!(events.iter().all(|e| e.body_b != a), "{events:?}");
    }
}

/// CCD honours the filter: a 2 cm plate shot down at 40 m/s through a 5 cm floor it may
/// not touch passes it (without the filter, the same shot stops on it).
#[test]
fn the_filter_lets_fast_bodies_through() {
    for refuse in [true, false] {
        let mut w = awake();
        floor(&mut w, 0.025);
        let def = BodyDef {
            position: Vec3::new(0.0, 0.5, 0.0),
            linear_velocity: Vec3::new(0.0, -40.0, 0.0),
            ..Default::default()
        };
        let plate = w
            .create_body(&def, Shape::cuboid(Vec3::new(0.2, 0.01, 0.2)))
            .unwrap();
        if refuse {
            w.set_contact_filter(|_: &ContactPair<'_>| false);
        }
        run(&mut w, 1.0 / 60.0, 6);
        let y = w.body(plate).unwrap().center_of_mass().y;
        assert_eq!(y < -1.0, refuse, "refuse {refuse}: y = {y}");
    }
}

/// A conveyor: the floor's contacts carry what rests on them at `belt` along x. A box set
/// down at rest is dragged at μ g until it moves at the belt's speed, at t = belt / (μ g),
/// and then rides at that speed. Checked: the speed at half that time is μ g t within 2 %
/// (the box settles onto the floor in its first steps), and after it the belt's speed to
/// 0.5 %; the box does not creep back (no friction anchors on a belt).
#[test]
fn a_surface_velocity_moves_a_resting_box_at_the_belt_speed() {
    for (half, mu, belt, dt) in [
        (0.25, 0.5, 1.0, 1.0 / 60.0),
        (0.1, 0.8, 2.5, 1.0 / 120.0),
        (0.4, 0.3, 0.6, 1.0 / 240.0),
    ] {
        let mut w = awake();
        let ground = floor(&mut w, 0.5);
        w.set_friction(ground, mu).unwrap();
        let b = cube(&mut w, Vec3::new(0.0, half, 0.0), half, mu);
        w.set_contact_modifier(move |m: &mut ContactModification<'_>| {
            if m.body_a == ground {
                m.set_surface_velocity(Vec3::new(belt, 0.0, 0.0)).unwrap();
            }
        });
        let reach = belt / (mu * G);
        let speed = |w: &World| w.body(b).unwrap().linear_velocity().x;
        run(&mut w, dt, (0.5 * reach / dt).round() as usize);
        let early = speed(&w) / (mu * G * w.time());
        assert!((early - 1.0).abs() < 0.02, "μ {mu}: {early} of μ g t");
        run(&mut w, dt, (reach / dt) as usize + 30);
        let x0 = w.body(b).unwrap().center_of_mass().x;
        let t0 = w.time();
        run(&mut w, dt, 60);
        let ride = (w.body(b).unwrap().center_of_mass().x - x0) / (w.time() - t0);
        assert!(((speed(&w) - belt) / belt).abs() < 0.005, "v {}", speed(&w));
        assert!(((ride - belt) / belt).abs() < 0.005, "moved at {ride}");
    }
}

/// On a slope of θ (tan θ < μ = 1, so the box would stick), a modifier taking friction
/// away makes the box slide with a = g sin θ, within 1 % (measured between 0.2 s and 0.7 s,
/// after it settled onto the slope); without it the box stays within 1 mm.
#[test]
fn zero_friction_slides_at_g_sin_theta() {
    for (theta, half, dt) in [(0.35, 0.2, 1.0 / 60.0), (0.6, 0.1, 1.0 / 120.0)] {
        for slide in [true, false] {
            let theta: Real = theta;
            let n = Vec3::new(-theta.sin(), theta.cos(), 0.0);
            let mut w = awake();
            let slope = BodyDef {
                kind: BodyKind::Static,
                friction: 1.0,
                ..Default::default()
            };
            w.create_body(&slope, Shape::plane(n, 0.0)).unwrap();
            let def = BodyDef {
                position: n * half,
                orientation: Quat::from_rotation_z(theta),
                friction: 1.0,
                ..Default::default()
            };
            let b = w
                .create_body(&def, Shape::cuboid(Vec3::splat(half)))
                .unwrap();
            if slide {
                w.set_contact_modifier(|m: &mut ContactModification<'_>| {
                    m.set_friction(0.0).unwrap();
                });
            }
            let down_slope = -Vec3::new(theta.cos(), theta.sin(), 0.0);
            let along = |w: &World| w.body(b).unwrap().linear_velocity().dot(down_slope);
            run(&mut w, dt, (0.2 / dt).round() as usize);
            let (v0, t0) = (along(&w), w.time());
            run(&mut w, dt, (0.5 / dt).round() as usize);
            let a = (along(&w) - v0) / (w.time() - t0);
            if slide {
                let exact = G * theta.sin();
                assert!(
                    ((a - exact) / exact).abs() < 0.01,
                    "θ {theta}: a {a} vs {exact}"
                );
            } else {
                let moved = w.body(b).unwrap().center_of_mass() - n * half;
                assert!(moved.length() < 1e-3, "θ {theta}: crept {moved}");
            }
        }
    }
}

/// A modifier's restitution bounces a ball that has none: dropped from h onto the floor it
/// rises to e² h, within 3 % (the bounce pass replays the impact; the rest is the contact's
/// give and the step's discretisation of the apex).
#[test]
fn a_modified_restitution_bounces() {
    for (e, h, dt) in [(0.5, 1.0, 1.0 / 240.0), (0.8, 2.0, 1.0 / 120.0)] {
        let mut w = awake();
        floor(&mut w, 0.5);
        let b = ball(&mut w, Vec3::new(0.0, h + 0.1, 0.0));
        w.set_contact_modifier(move |m: &mut ContactModification<'_>| {
            m.set_restitution(e).unwrap();
        });
        let fall = (2.0 * h / G).sqrt();
        run(&mut w, dt, (fall / dt) as usize + 5);
        let mut top: Real = 0.0;
        for _ in 0..(2.0 * e * fall / dt) as usize + 20 {
            w.step(dt).unwrap();
            top = top.max(w.body(b).unwrap().center_of_mass().y - 0.1);
        }
        let want = e * e * h;
        assert!(
            ((top - want) / want).abs() < 0.03,
            "e {e}: apex {top} vs {want}"
        );
    }
}

/// Dropping every point is no contact: the box falls through, with no contact event; the
/// modifier sees each manifold as new once, then as persisting.
#[test]
fn dropped_points_do_not_touch() {
    let mut w = awake();
    floor(&mut w, 0.5);
    let b = cube(&mut w, Vec3::new(0.0, 0.3, 0.0), 0.25, 0.6);
    let news = Arc::new(Mutex::new(Vec::new()));
    let log = news.clone();
    w.set_contact_modifier(move |m: &mut ContactModification<'_>| {
        log.lock().unwrap().push(m.is_new());
        m.disable();
        assert!(m.points().is_empty());
    });
    let mut events = Vec::new();
    for _ in 0..30 {
        w.step(1.0 / 60.0).unwrap();
        events.extend_from_slice(w.contact_events());
    }
    assert!(events.is_empty(), "{events:?}");
    assert!(w.body(b).unwrap().center_of_mass().y < -0.3);
    let news = news.lock().unwrap().clone();
    assert!(
        news.len() > 3 && news[0] && news[1..].iter().all(|n| !n),
        "{news:?}"
    );
}

/// Keeping some points keeps that much support: a box held only at the points of its
/// bottom face with x > 0 (the edge x = +half) tips over that edge towards −x, a positive
/// turn about z. After 0.2 s it turns about z at > 1 rad/s, and about the other axes at
/// under 3 % of that (the two kept corners are symmetric in z; Gauss–Seidel, solving one
/// after the other, yaws the box a little: 1.4 % measured).
#[test]
fn retained_points_are_the_only_support() {
    let mut w = awake();
    floor(&mut w, 0.5);
    let b = cube(&mut w, Vec3::new(0.0, 0.25, 0.0), 0.25, 0.6);
    w.set_contact_modifier(|m: &mut ContactModification<'_>| {
        m.retain_points(|p| p.point_b.x > 0.0);
    });
    run(&mut w, 1.0 / 60.0, 12);
    let spin = w.body(b).unwrap().angular_velocity();
    assert!(spin.z > 1.0, "spins at {spin}");
    let off = spin.x.hypot(spin.y);
    assert!(off < 0.03 * spin.z, "spins at {spin}");
}

/// The setters refuse bad values with the scene loader's messages, changing nothing.
#[test]
fn setters_validate_their_values() {
    let mut w = awake();
    floor(&mut w, 0.5);
    cube(&mut w, Vec3::new(0.0, 0.25, 0.0), 0.25, 0.6);
    let seen = Arc::new(Mutex::new(Vec::new()));
    let log = seen.clone();
    w.set_contact_modifier(move |m: &mut ContactModification<'_>| {
        let before = m.material();
        let mut out = log.lock().unwrap();
        out.push(m.set_friction(-1.0).unwrap_err().to_string());
        out.push(m.set_restitution(2.0).unwrap_err().to_string());
        out.push(m.set_restitution(Real::NAN).unwrap_err().to_string());
        out.push(
            m.set_surface_velocity(Vec3::new(Real::NAN, 0.0, 0.0))
                .unwrap_err()
                .to_string(),
        );
        out.push(
            m.set_surface_velocity(Vec3::new(1e9, 0.0, 0.0))
                .unwrap_err()
                .to_string(),
        );
        assert_eq!(m.material(), before);
    });
    w.step(1.0 / 60.0).unwrap();
    let seen = seen.lock().unwrap().clone();
    assert_eq!(
        seen,
        [
            "friction: must be >= 0",
            "restitution: must be <= 1",
            "restitution: must be a finite number",
            "surface_velocity: must be finite numbers",
            "surface_velocity: must be no longer than 10000 m/s (max_speed)",
        ]
    );
}

/// Sleeping pairs are not offered to the modifier; the pile keeps its modified contacts
/// and nothing it decided is undone by falling asleep.
#[test]
fn sleeping_pairs_are_left_alone() {
    let mut w = World::new(&WorldDef {
        gravity: down(),
        ..Default::default()
    });
    floor(&mut w, 0.5);
    let b = cube(&mut w, Vec3::new(0.0, 0.25, 0.0), 0.25, 0.6);
    let calls = Arc::new(Mutex::new(0usize));
    let count = calls.clone();
    w.set_contact_modifier(move |m: &mut ContactModification<'_>| {
        *count.lock().unwrap() += 1;
        m.set_friction(0.9).unwrap();
    });
    run(&mut w, 1.0 / 60.0, 300);
    assert!(!w.body(b).unwrap().is_awake());
    let before = *calls.lock().unwrap();
    run(&mut w, 1.0 / 60.0, 60);
    assert_eq!(*calls.lock().unwrap(), before);
    assert!(before > 10);
}

/// A 0.2 m cube (half extent) resting on the floor and a 0.1 m one above it at 1 m,
/// excluded from each other or not.
fn stacked(exclude: bool) -> (World, BodyId, BodyId) {
    let mut w = awake();
    floor(&mut w, 0.5);
    let big = cube(&mut w, Vec3::new(0.0, 0.2, 0.0), 0.2, 0.5);
    let small = cube(&mut w, Vec3::new(0.0, 1.0, 0.0), 0.1, 0.5);
    if exclude {
        w.exclude_contacts(small, big).unwrap();
    }
    (w, big, small)
}

/// Excluded from the big cube, the small one falls through it onto the floor (its centre
/// 0.1 m up, to 5 mm: resting depths are a fraction of that); not excluded, it lands on
/// the big one (0.5 m). The exclusion is data: a snapshot and a batch copy taken mid-fall
/// go on as the original does, bit for bit.
#[test]
fn excluded_pairs_never_touch_and_are_kept_by_copies_and_snapshots() {
    let dt = 1.0 / 60.0;
    for exclude in [false, true] {
        let (mut w, big, small) = stacked(exclude);
        run(&mut w, dt, 120);
        let y = w.body(small).unwrap().position().y;
        let rest = if exclude { 0.1 } else { 0.5 };
        assert!(
            (y - rest).abs() < 5e-3,
            "exclude {exclude}: the small cube at {y}"
        );
        let big_y = w.body(big).unwrap().position().y;
        assert!((big_y - 0.2).abs() < 5e-3, "the big cube at {big_y}");
        let expected: Vec<(BodyId, BodyId)> = if exclude { vec![(big, small)] } else { vec![] };
        assert_eq!(w.excluded_contacts(), expected.as_slice());
    }
    let (mut w, _, _) = stacked(true);
    run(&mut w, dt, 20);
    let mut restored = World::from_snapshot(&w.snapshot()).unwrap();
    let mut batch = tumble::Batch::new(&w, 2, Some(1)).unwrap();
    run(&mut w, dt, 100);
    run(&mut restored, dt, 100);
    batch.step(dt, 100).unwrap();
    assert_eq!(restored.state_hash(), w.state_hash());
    assert_eq!(batch.world(1).unwrap().state_hash(), w.state_hash());
}

#[test]
fn allowing_an_excluded_pair_and_removing_a_body_end_the_exclusion() {
    let dt = 1.0 / 60.0;
    let (mut w, big, small) = stacked(true);
    assert!(w.allow_contacts(big, small).unwrap());
    assert!(!w.allow_contacts(big, small).unwrap());
    run(&mut w, dt, 120);
    let y = w.body(small).unwrap().position().y;
    assert!(
        (y - 0.5).abs() < 5e-3,
        "allowed again, the small cube at {y}"
    );
    let (mut w, big, small) = stacked(true);
    w.remove_body(big).unwrap();
    assert!(w.excluded_contacts().is_empty());
    // Bad pairs are refused by name and change nothing.
    let before = w.state_hash();
    let removed = w.exclude_contacts(small, big).unwrap_err().to_string();
    assert!(
        removed.starts_with("b: unknown or removed body"),
        "{removed}"
    );
    let same = w.exclude_contacts(small, small).unwrap_err().to_string();
    assert_eq!(same, "exclude: a body cannot be excluded from itself");
    assert!(w.excluded_contacts().is_empty());
    assert_eq!(w.state_hash(), before);
}
