//! Kinematic targets: `World::set_kinematic_target` makes a kinematic body arrive at a
//! pose exactly at the end of the next step, moving at the velocities that take it there
//! (v = Δx / dt, ω = θ / dt with θ the short rotation vector of q_target q⁻¹), which it
//! keeps afterwards; what it carries moves with it.

// Casts between Real and f64 are no-ops in the default build but needed in the f32 one.
#![allow(clippy::unnecessary_cast)]

use crate::common::*;
use tumble::prelude::*;

const G: Real = 9.8;

/// The angle between two orientations (rad), the short way.
fn angle_between(a: Quat, b: Quat) -> Real {
    let d = (a * b.inverse()).normalize();
    2.0 * Vec3::new(d.x, d.y, d.z).length().atan2(d.w.abs())
}

/// A platform driven through a sequence of poses, translating and turning up to 2.5 rad a
/// step about changing axes (some given as −q, the same rotation), with its centre of
/// mass off its frame's origin, for three step sizes: after each step it is at the target
/// to 1e-9 m and rad in f64 (the step's motion x₀ + dt (Δx/dt) and exp(θ/2) q₀ undo the
/// target's arithmetic to a few ulps of the coordinates); 1e-4 in f32 (ulps of 10 m).
#[test]
fn a_platform_hits_every_target_pose() {
    for dt in [1.0 / 60.0, 1.0 / 240.0, 0.013] {
        let mut w = world(Vec3::new(0.0, -G, 0.0), Integrator::Rk4);
        let def = BodyDef {
            kind: BodyKind::Kinematic,
            center_of_mass: Some(Vec3::new(0.3, -0.1, 0.2)),
            ..Default::default()
        };
        let id = w
            .create_body(&def, Shape::cuboid(Vec3::new(1.0, 0.1, 0.5)))
            .unwrap();
        let eps = tol(1e-9, 1e-4);
        for k in 1..=40 {
            let s = k as Real;
            let position = Vec3::new(3.0 * (0.7 * s).sin(), 0.25 * s, -2.0 + (0.3 * s).cos());
            let axis = Vec3::new((0.4 * s).cos(), 1.0, (0.9 * s).sin()).normalize();
            let q = Quat::from_axis_angle(axis, 0.3 * s);
            let given = if k % 3 == 0 { -q } else { q };
            w.set_kinematic_target(id, position, given).unwrap();
            w.step(dt).unwrap();
            let b = w.body(id).unwrap();
            let off = (b.position() - position).length();
            let turn = angle_between(b.orientation(), q);
            assert!(off < eps * 10.0, "dt = {dt}, target {k}: {off} m off");
            assert!(turn < eps, "dt = {dt}, target {k}: {turn} rad off");
            assert!(b.kinematic_target().is_none(), "the step takes the target");
        }
        // No new target: it keeps the last velocities (documented).
        let (x, v) = {
            let b = w.body(id).unwrap();
            (b.center_of_mass(), b.linear_velocity())
        };
        w.step(dt).unwrap();
        let moved = w.body(id).unwrap().center_of_mass() - x;
        assert!(
            (moved - v * dt).length() < eps * 10.0,
            "coasts at its last velocity"
        );
    }
}

/// The smooth move x(t) = d (t/T − sin(2π t/T)/2π): zero velocity and acceleration at both
/// ends, largest acceleration 2π d/T² (1.57 m/s² for 1 m in 2 s, a fifth of μ g at μ = 0.8).
fn smooth(d: Real, t_end: Real, t: Real) -> Real {
    let u = (t / t_end).clamp(0.0, 1.0);
    d * (u - (2.0 * tumble::math::PI * u).sin() / (2.0 * tumble::math::PI))
}

/// A box resting on a platform that moves sideways 1 m in 2 s (a target every step) goes
/// with it: static friction 0.8 holds it (the move needs a fifth of that), so it ends
/// 1 m along, within 3 mm, and never slips by more than 3 mm on the way (the soft
/// contact's tangential give); the platform's own pose is exact.
#[test]
fn a_box_rides_a_moving_platform() {
    for (dt, half) in [(1.0 / 60.0, 0.2), (1.0 / 120.0, 0.1)] {
        let mut w = World::new(&WorldDef {
            gravity: Vec3::new(0.0, -G, 0.0),
            ..Default::default()
        });
        let platform = BodyDef {
            kind: BodyKind::Kinematic,
            friction: 0.8,
            ..Default::default()
        };
        let platform = w
            .create_body(&platform, Shape::cuboid(Vec3::new(2.0, 0.1, 1.0)))
            .unwrap();
        let load = BodyDef {
            position: Vec3::new(0.0, 0.1 + half, 0.0),
            friction: 0.8,
            mass: MassSpec::Mass(3.0),
            ..Default::default()
        };
        let load = w
            .create_body(&load, Shape::cuboid(Vec3::splat(half)))
            .unwrap();
        run(&mut w, dt, 30);
        let start = w.body(load).unwrap().position();
        let n = (2.0 / dt).round() as usize;
        let mut worst: Real = 0.0;
        for k in 1..=n {
            let x = smooth(1.0, 2.0, k as Real * dt);
            w.set_kinematic_target(platform, Vec3::new(x, 0.0, 0.0), Quat::IDENTITY)
                .unwrap();
            w.step(dt).unwrap();
            let p = w.body(platform).unwrap().position();
            assert!(
                (p.x - x).abs() < tol(1e-12, 1e-6),
                "platform at {} for {x}",
                p.x
            );
            let slip = w.body(load).unwrap().position().x - start.x - p.x;
            worst = worst.max(slip.abs());
        }
        // It keeps the last step's velocity, Δx/dt of the profile's last step: O(dt²) small.
        let b = w.body(platform).unwrap();
        let last = (smooth(1.0, 2.0, n as Real * dt) - smooth(1.0, 2.0, (n - 1) as Real * dt)) / dt;
        assert!(
            (b.linear_velocity().x - last).abs() < tol(1e-9, 1e-3),
            "{} vs {last}",
            b.linear_velocity().x
        );
        let end = w.body(load).unwrap().position();
        assert!(
            (end.x - start.x - 1.0).abs() < 3e-3,
            "carried {} m",
            end.x - start.x
        );
        assert!(
            (end.y - start.y).abs() < 1e-3,
            "stays on top: {} -> {}",
            start.y,
            end.y
        );
        assert!(worst < 3e-3, "dt = {dt}: slipped {worst} m");
    }
}

/// A platform turned by targets about the vertical turns a box on it about the same axis.
#[test]
fn a_turning_platform_turns_its_load() {
    let dt = 1.0 / 120.0;
    let mut w = World::new(&WorldDef::default());
    let def = BodyDef {
        kind: BodyKind::Kinematic,
        friction: 0.8,
        ..Default::default()
    };
    let platform = w
        .create_body(&def, Shape::cuboid(Vec3::new(2.0, 0.1, 2.0)))
        .unwrap();
    let load = BodyDef {
        position: Vec3::new(1.0, 0.3, 0.0),
        friction: 0.8,
        ..Default::default()
    };
    let load = w
        .create_body(&load, Shape::cuboid(Vec3::splat(0.2)))
        .unwrap();
    run(&mut w, dt, 30);
    let n = 240;
    for k in 1..=n {
        let angle = smooth(0.5 * tumble::math::PI, 2.0, k as Real * dt);
        let q = Quat::from_rotation_y(angle);
        w.set_kinematic_target(platform, Vec3::ZERO, q).unwrap();
        w.step(dt).unwrap();
    }
    // A quarter turn about +y takes (1, y, 0) to (0, y, −1); within 1 cm.
    let p = w.body(load).unwrap().position();
    assert!((p.x.abs() + (p.z + 1.0).abs()) < 0.01, "the load is at {p}");
}

/// Targets are refused on other kinds and for bad values, changing nothing; a target not
/// yet taken survives a failed step (the step is undone with it).
#[test]
fn targets_are_checked() {
    let mut w = World::new(&WorldDef::default());
    let def = BodyDef {
        kind: BodyKind::Kinematic,
        ..Default::default()
    };
    let k = w.create_body(&def, Shape::sphere(0.5)).unwrap();
    let d = ball(&mut w, Vec3::new(0.0, 5.0, 0.0));
    let e = w
        .set_kinematic_target(d, Vec3::ZERO, Quat::IDENTITY)
        .unwrap_err();
    assert_eq!(
        e.to_string(),
        "kind: a kinematic target needs a kinematic body"
    );
    let e = w
        .set_kinematic_target(k, Vec3::new(Real::NAN, 0.0, 0.0), Quat::IDENTITY)
        .unwrap_err();
    assert_eq!(e.to_string(), "position: must be finite numbers");
    let e = w
        .set_kinematic_target(k, Vec3::ZERO, Quat::from_xyzw(0.0, 0.0, 0.0, 0.0))
        .unwrap_err();
    assert!(e.to_string().starts_with("orientation: "), "{e}");
    assert!(w.body(k).unwrap().kinematic_target().is_none());
    // Too far for one step: the speed limit undoes the step, the target stays.
    let far = Vec3::new(1e6, 0.0, 0.0);
    w.set_kinematic_target(k, far, Quat::IDENTITY).unwrap();
    let e = w.step(1.0 / 60.0).unwrap_err();
    assert!(e.is_step_failure(), "{e}");
    let b = w.body(k).unwrap();
    assert_eq!(b.linear_velocity(), Vec3::ZERO);
    assert_eq!(b.kinematic_target(), Some((far, Quat::IDENTITY)));
}
