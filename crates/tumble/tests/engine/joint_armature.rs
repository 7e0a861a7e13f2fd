//! Joint armature (a hinge's or slider's rotor inertia, MuJoCo's `armature`) against the
//! closed forms of a pendulum and a slider, and its checks.

// Casts between Real and f64 are no-ops in the default build but needed in the f32 one.
#![allow(clippy::unnecessary_cast)]

use crate::common::*;
use tumble::prelude::*;

const G: Real = 9.81;

/// A ball of `mass` (radius 5 cm) hanging `length` below a hinge to the world about z,
/// with `armature`, let go `angle` (rad) from the vertical.
fn pendulum(length: Real, mass: Real, armature: Real, angle: Real) -> (World, BodyId, JointId) {
    let mut w = awake(Vec3::new(0.0, -G, 0.0));
    let at = Vec3::new(length * angle.sin(), -length * angle.cos(), 0.0);
    let def = BodyDef {
        position: at,
        mass: MassSpec::Mass(mass),
        ..Default::default()
    };
    let bob = w.create_body(&def, Shape::sphere(0.05)).unwrap();
    let mut joint = JointDef::new(free_hinge(), bob);
    joint.anchor = -at;
    joint.axis = Vec3::Z;
    joint.other_axis = Vec3::Z;
    joint.armature = armature;
    let j = w.create_joint(&joint).unwrap();
    (w, bob, j)
}

/// The time between the first and the last of `swings` upward zero crossings of the
/// bob's x, over that many periods.
fn period(w: &mut World, bob: BodyId, dt: Real, swings: usize) -> Real {
    let (mut t, mut last_x, mut crossings) = (0.0, w.body(bob).unwrap().position().x, vec![]);
    while crossings.len() <= swings && t < 200.0 {
        w.step(dt).unwrap();
        t += dt;
        let x = w.body(bob).unwrap().position().x;
        if last_x < 0.0 && x >= 0.0 {
            crossings.push(t - dt * x / (x - last_x));
        }
        last_x = x;
    }
    (crossings[swings] - crossings[0]) / swings as Real
}

#[test]
fn armature_lengthens_a_pendulum_s_period_as_the_added_inertia_says() {
    // Small swings: T = 2π √((I + a) / (m g l)), I = m l² + (2/5) m r² about the pivot.
    for (length, mass) in [(0.5, 1.0), (1.0, 3.0), (2.0, 0.2)] {
        let inertia = mass * length * length + 0.4 * mass * 0.05 * 0.05;
        for share in [0.0, 0.5, 2.0, 10.0] {
            let armature = share * inertia;
            for dt in [1.0 / 60.0, 1.0 / 240.0] {
                let (mut w, bob, _) = pendulum(length, mass, armature, 0.02);
                let expected = 2.0
                    * std::f64::consts::PI as Real
                    * ((inertia + armature) / (mass * G * length)).sqrt();
                let measured = period(&mut w, bob, dt, 4);
                assert!(
                    (measured / expected - 1.0).abs() < 0.01,
                    "l {length} m {mass} a {armature} dt {dt}: period {measured} s, expected {expected} s"
                );
            }
        }
    }
}

#[test]
fn a_slider_with_armature_falls_at_m_g_over_m_plus_a() {
    for (mass, armature) in [(1.0, 0.0), (1.0, 1.0), (2.0, 6.0), (0.5, 0.05)] {
        let mut w = awake(Vec3::new(0.0, -G, 0.0));
        let def = BodyDef {
            mass: MassSpec::Mass(mass),
            ..Default::default()
        };
        let body = w
            .create_body(&def, Shape::cuboid(Vec3::splat(0.1)))
            .unwrap();
        let mut joint = JointDef::new(free_slider(), body);
        joint.axis = Vec3::Y;
        joint.other_axis = Vec3::Y;
        joint.armature = armature;
        w.create_joint(&joint).unwrap();
        run(&mut w, 1.0 / 60.0, 60);
        let v = w.body(body).unwrap().linear_velocity().y;
        let expected = -mass * G / (mass + armature);
        assert!(
            (v / expected - 1.0).abs() < 1e-3,
            "m {mass} a {armature}: v {v}, expected {expected}"
        );
    }
}

#[test]
fn armature_is_checked_and_set_at_run_time() {
    let (mut w, bob, j) = pendulum(1.0, 1.0, 0.0, 0.3);
    let hash = w.state_hash();
    let err = |r: tumble::Result<()>| r.unwrap_err().to_string();
    assert_eq!(err(w.set_joint_armature(j, -1.0)), "armature: must be >= 0");
    assert!(err(w.set_joint_armature(j, Real::NAN)).starts_with("armature:"));
    assert_eq!(w.state_hash(), hash);
    assert_eq!(w.joint(j).unwrap().def().armature, 0.0);
    w.set_joint_armature(j, 2.0).unwrap();
    assert_eq!(w.joint(j).unwrap().def().armature, 2.0);
    let mut ball = JointDef::new(
        JointKind::Ball {
            cone: None,
            twist: None,
        },
        bob,
    );
    ball.armature = 1.0;
    assert_eq!(
        err(w.create_joint(&ball).map(|_| ())),
        "armature: only hinge and slider joints take one"
    );
}

/// A double pendulum in the plane z = 0: an upper rod of `m1` hinged to the world at
/// (0, 2, 0), a lower rod of `m2` hinged to its end, both 0.5 m (capsules), each hinge
/// with its armature, let go at angles (from hanging) `q1` and `q1 + q2`.
fn double_pendulum(
    (m1, m2): (Real, Real),
    (a1, a2): (Real, Real),
    (q1, q2): (Real, Real),
) -> (World, [BodyId; 2], [JointId; 2]) {
    let mut w = awake(Vec3::new(0.0, -G, 0.0));
    let (l, pivot) = (0.5, Vec3::new(0.0, 2.0, 0.0));
    let down = |q: Real| Vec3::new(q.sin(), -q.cos(), 0.0);
    let elbow = pivot + down(q1) * l;
    let rod = |w: &mut World, centre: Vec3, q: Real, mass: Real| {
        let def = BodyDef {
            position: centre,
            orientation: Quat::from_rotation_z(q),
            mass: MassSpec::Mass(mass),
            ..Default::default()
        };
        w.create_body(&def, Shape::capsule(0.2, 0.05)).unwrap()
    };
    let upper = rod(&mut w, pivot + down(q1) * (0.5 * l), q1, m1);
    let lower = rod(&mut w, elbow + down(q1 + q2) * (0.5 * l), q1 + q2, m2);
    let hinge = |w: &mut World, body: BodyId, other: Option<BodyId>, armature: Real| {
        let mut def = JointDef::new(free_hinge(), body);
        def.anchor = Vec3::new(0.0, 0.5 * l, 0.0);
        def.other = other;
        def.other_anchor = match other {
            Some(_) => Vec3::new(0.0, -0.5 * l, 0.0),
            None => pivot,
        };
        (def.axis, def.other_axis) = (Vec3::Z, Vec3::Z);
        def.armature = armature;
        w.create_joint(&def).unwrap()
    };
    let j1 = hinge(&mut w, upper, None, a1);
    let j2 = hinge(&mut w, lower, Some(upper), a2);
    (w, [upper, lower], [j1, j2])
}

/// Kinetic and potential energy of the bodies plus the armatures' ½ a q̇².
fn energy(w: &World, bodies: &[BodyId], joints: &[(JointId, Real)]) -> Real {
    let bodies: Real = bodies
        .iter()
        .map(|&b| {
            let b = w.body(b).unwrap();
            b.kinetic_energy() + b.mass() * G * b.position().y
        })
        .sum();
    let armatures: Real = joints
        .iter()
        .map(|&(j, a)| 0.5 * a * w.joint_velocity(j).unwrap().scalar().unwrap().powi(2))
        .sum();
    bodies + armatures
}

#[test]
fn a_double_pendulum_with_armature_keeps_its_energy_flywheels_included() {
    // Armature on the world-held hinge, on the hinge between two moving rods, and on
    // both, from a quarter to four times a rod's inertia about its end: the energy with
    // ½ a q̇² counted stays within 0.3 % of m g l of its start over 3 s (measured 3e-5
    // to 1.6e-3). The flywheels hold 0.75 % to 9.5 % of it at their fastest, so leaving
    // them out of the sum fails, and so did restarting each flywheel at its coordinate's
    // rate every substep (the coupling's unsolved rest lost each time: 4.8e-3 in the first).
    for (masses, armatures, dt) in [
        ((1.0, 0.5), (0.02, 0.0), 1.0 / 240.0),
        ((1.0, 0.5), (0.0, 0.02), 1.0 / 240.0),
        ((2.0, 1.0), (0.3, 0.1), 1.0 / 240.0),
        ((0.5, 2.0), (0.05, 0.3), 1.0 / 480.0),
    ] {
        let (mut w, bodies, [j1, j2]) = double_pendulum(masses, armatures, (0.6, 0.4));
        let joints = [(j1, armatures.0), (j2, armatures.1)];
        let e0 = energy(&w, &bodies, &joints);
        let (mut worst, mut flywheels): (Real, Real) = (0.0, 0.0);
        let scale = (masses.0 + masses.1) * G * 0.5;
        for _ in 0..(3.0 / dt) as usize {
            w.step(dt).unwrap();
            worst = worst.max((energy(&w, &bodies, &joints) - e0).abs() / scale);
            flywheels = flywheels.max(energy(&w, &[], &joints) / scale);
        }
        assert!(
            worst < 0.003,
            "{masses:?} {armatures:?}: energy off by {worst} of m g l"
        );
        assert!(flywheels > 0.005, "{masses:?} {armatures:?}: {flywheels}");
    }
}

#[test]
fn a_motor_spins_up_a_wheel_at_torque_over_inertia_plus_armature() {
    // A ball of radius r on a hinge at its centre, a motor far from its speed at its
    // torque cap: ω(t) = τ t / (I + a), I = (2/5) m r².
    for (mass, radius, armature, torque) in [
        (1.0, 0.2, 0.0, 1.0),
        (1.0, 0.2, 0.016, 1.0),
        (3.0, 0.5, 1.5, 10.0),
    ] {
        let mut w = awake(Vec3::ZERO);
        let def = BodyDef {
            mass: MassSpec::Mass(mass),
            ..Default::default()
        };
        let wheel = w.create_body(&def, Shape::sphere(radius)).unwrap();
        let mut joint = JointDef::new(
            JointKind::Hinge {
                limits: None,
                motor: Some(Motor {
                    speed: 1e4,
                    max_force: torque,
                }),
                spring: None,
                servo: None,
            },
            wheel,
        );
        (joint.axis, joint.other_axis) = (Vec3::Z, Vec3::Z);
        joint.armature = armature;
        w.create_joint(&joint).unwrap();
        run(&mut w, 1.0 / 60.0, 60);
        let inertia = 0.4 * mass * radius * radius;
        let expected = torque * 1.0 / (inertia + armature);
        let spin = w.body(wheel).unwrap().angular_velocity().z.abs();
        assert!(
            (spin / expected - 1.0).abs() < 1e-3,
            "m {mass} r {radius} a {armature}: ω {spin}, expected {expected}"
        );
    }
}

#[test]
fn a_pendulum_let_go_beyond_its_limit_comes_back_to_it_and_stays() {
    // The ant's ankles start outside their ranges: the limit pushes back with the
    // armature's inertia as well as the bob's, and neither row may ring up.
    for (armature, dt) in [(0.05, 1.0 / 60.0), (1.0, 1.0 / 60.0), (5.0, 1.0 / 240.0)] {
        let (mut w, _, j) = pendulum(1.0, 1.0, armature, 0.8);
        w.set_joint_limits(j, Some([-0.5, 0.5])).unwrap();
        let mut fastest: Real = 0.0;
        for _ in 0..(3.0 / dt) as usize {
            w.step(dt).unwrap();
            let rate = w.joint_velocity(j).unwrap().scalar().unwrap();
            fastest = fastest.max(rate.abs());
        }
        let q = w.joint_position(j).unwrap().scalar().unwrap();
        let rate = w.joint_velocity(j).unwrap().scalar().unwrap();
        assert!((q.abs() - 0.5).abs() < 0.01, "a {armature}: at {q} rad");
        assert!(
            rate.abs() < 0.05,
            "a {armature}: still turning at {rate} rad/s"
        );
        assert!(fastest < 3.0, "a {armature}: reached {fastest} rad/s");
    }
}

#[test]
fn a_snapshot_mid_swing_continues_bit_identically_with_armatures() {
    let (mut w, _, _) = double_pendulum((1.0, 0.5), (0.1, 0.05), (0.9, 0.5));
    run(&mut w, 1.0 / 60.0, 20);
    let bytes = w.snapshot();
    let mut resumed = World::from_snapshot(&bytes).unwrap();
    for _ in 0..60 {
        w.step(1.0 / 60.0).unwrap();
        resumed.step(1.0 / 60.0).unwrap();
        assert_eq!(w.state_hash(), resumed.state_hash());
    }
}

#[test]
fn an_armature_set_to_zero_mid_fall_leaves_nothing_behind() {
    // A slider falling with armature falls at m g / (m + a); set to 0 mid-fall, it falls
    // at g from then on: the flywheel's warm-started push goes with it.
    let mut w = awake(Vec3::new(0.0, -G, 0.0));
    let body = w
        .create_body(&BodyDef::default(), Shape::cuboid(Vec3::splat(0.1)))
        .unwrap();
    let mut joint = JointDef::new(free_slider(), body);
    (joint.axis, joint.other_axis) = (Vec3::Y, Vec3::Y);
    joint.armature = 3.0;
    let j = w.create_joint(&joint).unwrap();
    let dt = 1.0 / 60.0;
    run(&mut w, dt, 30);
    w.set_joint_armature(j, 0.0).unwrap();
    let v0 = w.body(body).unwrap().linear_velocity().y;
    run(&mut w, dt, 30);
    let g = (v0 - w.body(body).unwrap().linear_velocity().y) / (30.0 * dt);
    assert!(
        (g / G - 1.0).abs() < tol(1e-6, 1e-4),
        "falls at {g} m/s² after"
    );
}
