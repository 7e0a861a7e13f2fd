//! One-way platforms (`BodyDef::one_way`): bodies from the normal's side land on them,
//! bodies from below or from the side pass through untouched.

// Casts between Real and f64 are no-ops in the default build but needed in the f32 one.
#![allow(clippy::unnecessary_cast)]

use crate::common::*;
use tumble::prelude::*;

const G: Real = 9.8;

/// The platform's top face, y (m), and its half thickness.
const TOP: Real = 1.0;
const THICK: Real = 0.05;

fn down() -> Vec3 {
    Vec3::new(0.0, -G, 0.0)
}

/// A static one-way platform (normal +y) whose top face is y = `TOP`, 4 m across, in a
/// world without sleeping.
fn platform_world(gravity: Vec3) -> (World, BodyId) {
    let mut w = World::new(&WorldDef {
        gravity,
        sleep: false,
        ..Default::default()
    });
    let def = BodyDef {
        kind: BodyKind::Static,
        position: Vec3::new(0.0, TOP - THICK, 0.0),
        one_way: Some(Vec3::new(0.0, 3.0, 0.0)),
        ..Default::default()
    };
    let p = w
        .create_body(&def, Shape::cuboid(Vec3::new(2.0, THICK, 2.0)))
        .unwrap();
    (w, p)
}

/// A cube of half extent `half` at `at`, moving at `v`.
fn cube(w: &mut World, at: Vec3, v: Vec3, half: Real) -> BodyId {
    let def = BodyDef {
        position: at,
        linear_velocity: v,
        ..Default::default()
    };
    w.create_body(&def, Shape::cuboid(Vec3::splat(half)))
        .unwrap()
}

/// A box launched up from below passes through the platform untouched (until its bottom
/// face clears the top face it moves exactly as in a world without the platform, bit for
/// bit; above, a kept speculative contact puts it through the solver's substeps, a
/// different integration of the same flight), then lands on it and
/// rests on top: after 2 s more its centre is `half` above the top face, within 1 cm (the
/// contact's give), and it moves slower than 1 cm/s. The apexes of its bottom face range
/// from 3 mm above the top face (inside the contact margin: the pass is decided again as
/// the box clears the platform) to 1.5 m above, over sizes and steps.
#[test]
fn a_box_jumps_up_through_and_lands_on_top() {
    for (half, clear, dt) in [
        (0.2, 0.5, 1.0 / 60.0),
        (0.1, 0.003, 1.0 / 60.0),
        (0.3, 1.5, 1.0 / 120.0),
        (0.05, 0.02, 1.0 / 240.0),
        (0.15, 0.1, 1.0 / 30.0),
    ] {
        let (mut w, _) = platform_world(down());
        let mut free = World::new(&WorldDef {
            gravity: down(),
            sleep: false,
            ..Default::default()
        });
        let start = Vec3::new(0.3, TOP - 2.0 * THICK - 0.6, 0.0);
        // The bottom face rises to TOP + clear. Symplectic Euler's flight is the parabola
        // of v₀ − g dt / 2 sampled at the steps, whose apex is (v₀ − g dt/2)² / 2g up, so
        // v₀ = √(2 g rise) + g dt / 2; the sampled apex is lower by at most g dt² / 8
        // (0.34 mm at dt 1/60 s).
        let rise = TOP + clear + half - start.y;
        let v = Vec3::new(0.0, (2.0 * G * rise).sqrt() + 0.5 * G * dt, 0.0);
        let b = cube(&mut w, start, v, half);
        let twin = cube(&mut free, start, v, half);
        loop {
            w.step(dt).unwrap();
            free.step(dt).unwrap();
            let (x, y) = (w.body(b).unwrap(), free.body(twin).unwrap());
            if y.center_of_mass().y - half >= TOP {
                break;
            }
            assert_eq!(x.center_of_mass(), y.center_of_mass(), "half {half}: held");
            assert_eq!(
                x.linear_velocity(),
                y.linear_velocity(),
                "half {half}: held"
            );
        }
        run(&mut w, dt, (2.0 / dt) as usize);
        let body = w.body(b).unwrap();
        let y = body.center_of_mass().y;
        assert!(
            (y - (TOP + half)).abs() < 0.01,
            "half {half} clear {clear}: y {y}"
        );
        assert!(
            body.linear_velocity().length() < 0.01,
            "{}",
            body.linear_velocity()
        );
    }
}

/// A box dropped from above lands and rests on the top face, from heights that bring it
/// in slowly, and fast enough (12 m/s at dt 1/60 s, 0.2 m a step) that CCD stops it.
#[test]
fn a_falling_box_lands() {
    for (half, height, dt) in [
        (0.2, 0.5, 1.0 / 60.0),
        (0.1, 7.0, 1.0 / 60.0),
        (0.02, 3.0, 1.0 / 120.0),
    ] {
        let (mut w, _) = platform_world(down());
        let b = cube(
            &mut w,
            Vec3::new(0.0, TOP + half + height, 0.0),
            Vec3::ZERO,
            half,
        );
        run(&mut w, dt, (3.0 / dt) as usize);
        let y = w.body(b).unwrap().center_of_mass().y;
        assert!(
            (y - (TOP + half)).abs() < 0.01,
            "half {half} h {height}: y {y}"
        );
    }
}

/// From the side a body passes through (its contact normal is horizontal, more than 60°
/// off the platform's): without gravity, a box sliding along x through the platform's
/// edge keeps its velocity exactly; so does a box shot up through it at 30 m/s, too fast
/// for the solver (CCD lets it pass as well). Both then end where free motion takes them.
#[test]
fn bodies_from_the_side_and_below_pass_through() {
    let (mut w, _) = platform_world(Vec3::ZERO);
    let v = Vec3::new(3.0, 0.0, 0.0);
    let side = cube(&mut w, Vec3::new(-3.0, TOP - THICK, 0.0), v, 0.1);
    let up = Vec3::new(0.0, 30.0, 0.0);
    let shot = cube(&mut w, Vec3::new(1.0, TOP - 1.0, 1.0), up, 0.02);
    let mut touched = false;
    for _ in 0..120 {
        w.step(1.0 / 60.0).unwrap();
        touched |= w.contacts().iter().any(|c| !c.manifold.is_empty());
        assert_eq!(w.body(side).unwrap().linear_velocity(), v);
        assert_eq!(w.body(shot).unwrap().linear_velocity(), up);
    }
    assert!(!touched, "a contact held");
    let x = w.body(side).unwrap().center_of_mass().x;
    // 120 additions of v dt: rounding only (f32 carries about 7 digits).
    assert!((x - 3.0).abs() < tol(1e-9, 1e-4), "x {x}");
}

/// The platform's normal turns with it: turned −90° about z (its normal now +x), it stops
/// a box coming at it from the +x side at 2 m/s (the box ends in front of its face, moving
/// off at under 0.1 m/s: in zero gravity the soft contact's push-out is all that remains,
/// as at any wall), and lets one from the −x side pass without a change of velocity.
#[test]
fn the_normal_is_in_the_body_frame() {
    let mut w = World::new(&WorldDef {
        gravity: Vec3::ZERO,
        sleep: false,
        ..Default::default()
    });
    let def = BodyDef {
        kind: BodyKind::Static,
        orientation: Quat::from_rotation_z(-std::f64::consts::FRAC_PI_2 as Real),
        one_way: Some(Vec3::Y),
        ..Default::default()
    };
    let wall = w
        .create_body(&def, Shape::cuboid(Vec3::new(2.0, THICK, 2.0)))
        .unwrap();
    // Body frame y turned −90° about z is world +x.
    let n = w.body(wall).unwrap().orientation() * Vec3::Y;
    assert!((n - Vec3::X).length() < 1e-6, "{n}");
    let from_plus = cube(
        &mut w,
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(-2.0, 0.0, 0.0),
        0.1,
    );
    let from_minus = cube(
        &mut w,
        Vec3::new(-1.0, 0.5, 0.0),
        Vec3::new(2.0, 0.0, 0.0),
        0.1,
    );
    run(&mut w, 1.0 / 60.0, 60);
    let stopped = w.body(from_plus).unwrap();
    let (x, vx) = (stopped.center_of_mass().x, stopped.linear_velocity().x);
    assert!(
        x > THICK + 0.1 - 0.01 && (0.0..0.1).contains(&vx),
        "x {x}, v {vx}"
    );
    let passed = w.body(from_minus).unwrap().center_of_mass().x;
    assert!((passed - 1.0).abs() < tol(1e-9, 1e-4), "passed to {passed}");
}

/// `one_way` is checked as the scene loader checks it (finite, non-zero) and normalised;
/// `set_one_way` changes nothing on a bad value, and `None` makes the platform solid from
/// below too.
#[test]
fn one_way_is_validated_and_settable() {
    let (mut w, p) = platform_world(down());
    assert_eq!(w.body(p).unwrap().one_way(), Some(Vec3::Y));
    for (bad, message) in [
        (Vec3::ZERO, "one_way: must be a non-zero vector"),
        (
            Vec3::new(Real::NAN, 1.0, 0.0),
            "one_way: must be finite numbers",
        ),
        (
            Vec3::new(0.0, Real::INFINITY, 0.0),
            "one_way: must be finite numbers",
        ),
    ] {
        let def = BodyDef {
            one_way: Some(bad),
            ..Default::default()
        };
        let err = w.create_body(&def, Shape::sphere(0.1)).unwrap_err();
        assert_eq!(err.to_string(), message);
        let err = w.set_one_way(p, Some(bad)).unwrap_err();
        assert_eq!(err.to_string(), message);
        assert_eq!(w.body(p).unwrap().one_way(), Some(Vec3::Y));
    }
    let tiny = Vec3::new(0.0, 1e-30 as Real, 0.0);
    w.set_one_way(p, Some(tiny)).unwrap();
    assert_eq!(w.body(p).unwrap().one_way(), Some(Vec3::Y));
    w.set_one_way(p, None).unwrap();
    // Solid now: a box from below is stopped under it.
    let b = cube(
        &mut w,
        Vec3::new(0.0, 0.2, 0.0),
        Vec3::new(0.0, 5.0, 0.0),
        0.1,
    );
    run(&mut w, 1.0 / 60.0, 10);
    assert!(w.body(b).unwrap().center_of_mass().y < TOP - 2.0 * THICK);
}
