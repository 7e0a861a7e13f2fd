//! Chains of joints through light bodies (`solver/joint_chain.rs`): how MJCF and URDF
//! import a body with several joints (a planar root of slide, slide and hinge; a hip of
//! three hinges), a light body between each two joints. The chain must act as the one
//! joint it stands for, whatever the light bodies' share of the mass and the step.
//! f64 and f32 alike.

// Casts between Real and f64 are no-ops in the default build but needed in the f32 one.
#![allow(clippy::unnecessary_cast)]

use crate::common::{awake, free_hinge, free_slider, tol};
use tumble::prelude::*;
use tumble::{JointCoordinate, JointId};

const G: Real = 9.81;

/// A body of `mass` kg at `at`, a box of half extents `half`; colliding with nothing when
/// `ghost` (the light bodies, as the importers make them: no geometry).
fn body(w: &mut World, at: Vec3, mass: Real, half: Vec3, ghost: bool) -> BodyId {
    let def = BodyDef {
        position: at,
        mass: MassSpec::Mass(mass),
        collision_mask: if ghost { 0 } else { u32::MAX },
        ..Default::default()
    };
    w.create_body(&def, Shape::cuboid(half)).unwrap()
}

/// Joins `body` to `other` (`None`: the world) by `kind` along `axis`, at `body`'s origin
/// and the same world point on `other`.
fn join(w: &mut World, kind: JointKind, body: BodyId, other: Option<BodyId>, axis: Vec3) {
    let at = w.body(body).unwrap().position();
    let mut def = JointDef::new(kind, body);
    def.axis = axis;
    def.other = other;
    def.other_anchor = match other {
        Some(o) => at - w.body(o).unwrap().position(),
        None => at,
    };
    def.other_axis = axis;
    w.create_joint(&def).unwrap();
}

#[test]
fn a_planar_chain_holds_its_plane_and_its_free_directions_fall_freely() {
    // A torso on slide x, slide y and hinge z (two light bodies between the world and
    // it), a 1 m arm hinged to its end: the pair moves in the plane z = 0. Gravity pulls
    // along −y (free) and along z (locked): the chain must carry the z load without
    // leaving the plane, and nothing but gravity acts along y, so the centre of mass
    // falls as g t²/2 however the arm swings. Before the chain's block, Gauss–Seidel
    // through 1/1000-mass bodies let such a body leave its plane by 0.33 m in a second.
    for light in [1e-2 as Real, 1e-3, 1e-4] {
        for torso_mass in [1.0 as Real, 50.0] {
            for dt in [1.0 as Real / 60.0, 1.0 / 240.0, 0.002] {
                let mut w = awake(Vec3::new(0.0, -G, -G));
                let start = Vec3::new(0.0, 2.0, 0.0);
                let half = Vec3::new(0.3, 0.1, 0.1);
                let l1 = body(&mut w, start, light * torso_mass, Vec3::splat(0.05), true);
                let l2 = body(&mut w, start, light * torso_mass, Vec3::splat(0.05), true);
                let torso = body(&mut w, start, torso_mass, half, false);
                let arm_at = start + Vec3::new(0.3, -0.5, 0.0);
                let arm = body(
                    &mut w,
                    arm_at,
                    0.4 * torso_mass,
                    Vec3::new(0.05, 0.5, 0.05),
                    false,
                );
                join(&mut w, free_slider(), l1, None, Vec3::X);
                join(&mut w, free_slider(), l2, Some(l1), Vec3::Y);
                join(&mut w, free_hinge(), torso, Some(l2), Vec3::Z);
                let mut def = JointDef::new(free_hinge(), arm);
                (def.anchor, def.axis) = (Vec3::new(0.0, 0.5, 0.0), Vec3::Z);
                (def.other, def.other_anchor, def.other_axis) =
                    (Some(torso), Vec3::new(0.3, 0.0, 0.0), Vec3::Z);
                w.create_joint(&def).unwrap();
                // Set swinging: the arm kicked sideways.
                w.set_linear_velocity(arm, Vec3::new(3.0, 0.0, 0.0))
                    .unwrap();
                // L1 slides along x only: the world holds it up. The rest falls freely.
                let bodies = [l2, torso, arm];
                let com = |w: &World| {
                    let (mut sum, mut mass) = (Vec3::ZERO, 0.0);
                    for &b in &bodies {
                        let b = w.body(b).unwrap();
                        sum += b.center_of_mass() * b.mass();
                        mass += b.mass();
                    }
                    sum / mass
                };
                let (y0, vy0) = (com(&w).y, {
                    let (mut p, mut m) = (0.0, 0.0);
                    for &b in &bodies {
                        let b = w.body(b).unwrap();
                        (p, m) = (p + b.linear_velocity().y * b.mass(), m + b.mass());
                    }
                    p / m
                });
                let at = format!("light {light}, torso {torso_mass} kg, dt {dt:.4}");
                let steps = (1.0 / dt).round() as usize;
                let mut off: Real = 0.0;
                for _ in 0..steps {
                    w.step(dt).unwrap_or_else(|e| panic!("{at}: {e}"));
                    for &b in &[torso, arm] {
                        off = off.max(w.body(b).unwrap().center_of_mass().z.abs());
                    }
                }
                let t = steps as Real * dt;
                let expect = y0 + vy0 * t - 0.5 * G * t * t;
                assert!(off < tol(1e-3, 2e-3), "{at}: left the plane by {off} m");
                let fall = com(&w).y - expect;
                assert!(
                    fall.abs() < tol(1e-9, 1e-4) * (0.5 * G * t * t),
                    "{at}: the centre of mass is {fall} m off free fall"
                );
                let turned = w.body(torso).unwrap().orientation() * Vec3::Z;
                assert!(
                    turned.angle_between(Vec3::Z) < tol(1e-3, 2e-3),
                    "{at}: the torso tilted out of the plane"
                );
            }
        }
    }
}

#[test]
fn three_hinges_through_light_bodies_swing_as_one_ball_joint() {
    // A hip: hinges about x, y and z through two light bodies at one pivot, a rod of
    // 10 kg hanging 1 m below it, started 0.4 rad out in two directions. Beside it the
    // same rod on a ball joint: the two must swing together (the light bodies' own
    // turning is their share of the inertia, 1/1000 of it) and the pivot hold.
    for dt in [1.0 as Real / 60.0, 1.0 / 240.0] {
        let mut w = awake(Vec3::new(0.0, -G, 0.0));
        let pivot = Vec3::new(0.0, 3.0, 0.0);
        let tilt = Quat::from_rotation_x(0.4) * Quat::from_rotation_z(0.3);
        let rod = |w: &mut World, x: Real| {
            let def = BodyDef {
                position: pivot + Vec3::X * x + tilt * Vec3::new(0.0, -1.0, 0.0),
                orientation: tilt,
                mass: MassSpec::Mass(10.0),
                collision_mask: 0,
                ..Default::default()
            };
            w.create_body(&def, Shape::cuboid(Vec3::new(0.05, 1.0, 0.05)))
                .unwrap()
        };
        let chained = rod(&mut w, 0.0);
        let balled = rod(&mut w, 5.0);
        let l1 = body(&mut w, pivot, 1e-2, Vec3::splat(0.05), true);
        let l2 = body(&mut w, pivot, 1e-2, Vec3::splat(0.05), true);
        join(&mut w, free_hinge(), l1, None, Vec3::X);
        join(&mut w, free_hinge(), l2, Some(l1), Vec3::Y);
        let mut def = JointDef::new(free_hinge(), chained);
        def.anchor = Vec3::new(0.0, 1.0, 0.0);
        def.axis = tilt.inverse() * Vec3::Z;
        (def.other, def.other_anchor, def.other_axis) = (Some(l2), Vec3::ZERO, Vec3::Z);
        w.create_joint(&def).unwrap();
        let mut def = JointDef::new(
            JointKind::Ball {
                cone: None,
                twist: None,
            },
            balled,
        );
        def.anchor = Vec3::new(0.0, 1.0, 0.0);
        def.other_anchor = pivot + Vec3::X * 5.0;
        w.create_joint(&def).unwrap();
        let (mut apart, mut gap): (Real, Real) = (0.0, 0.0);
        for _ in 0..(3.0 / dt).round() as usize {
            w.step(dt).unwrap();
            let (c, b) = (w.body(chained).unwrap(), w.body(balled).unwrap());
            let top = c.position() + c.orientation() * Vec3::new(0.0, 1.0, 0.0);
            gap = gap.max((top - pivot).length());
            let shift = Vec3::X * 5.0;
            apart = apart.max((c.position() - (b.position() - shift)).length());
        }
        let at = format!("dt {dt:.4}");
        assert!(gap < tol(1e-3, 2e-3), "{at}: the pivot opened by {gap} m");
        assert!(
            apart < 0.01,
            "{at}: the chained rod ran {apart} m from the balled one"
        );
    }
}

/// A hip as the MJCF importer makes one: hinges about x (world to `l1`), y (`l1` to `l2`)
/// and z (`l2` to the rod) at one pivot, the two light bodies of `light` times the rod's
/// 10 kg, each hinge with `servo` (target per hinge) and limits ±`limit` (rad). The rod,
/// 2 m long, hangs from its top end at the pivot. Beside it, 5 m along x, the same rod on
/// one hinge about the axis of `reference` (0, 1, 2: x, y, z) with that hinge's servo and
/// limits. Returns the world, the rod, the pivot and the three joints, and the reference
/// hinge.
fn sprung_hip(
    light: Real,
    (servo, targets): (Servo, [Real; 3]),
    limit: Real,
    reference: usize,
) -> (World, BodyId, Vec3, [JointId; 4]) {
    let mut w = awake(Vec3::new(0.0, -G, 0.0));
    let pivot = Vec3::new(0.0, 3.0, 0.0);
    let rod_at = |w: &mut World, at: Vec3| {
        let def = BodyDef {
            position: at - Vec3::Y,
            mass: MassSpec::Mass(10.0),
            collision_mask: 0,
            ..Default::default()
        };
        w.create_body(&def, Shape::cuboid(Vec3::new(0.05, 1.0, 0.05)))
            .unwrap()
    };
    let rod = rod_at(&mut w, pivot);
    let single = rod_at(&mut w, pivot + 5.0 * Vec3::X);
    let l1 = body(&mut w, pivot, light * 10.0, Vec3::splat(0.05), true);
    let l2 = body(&mut w, pivot, light * 10.0, Vec3::splat(0.05), true);
    let kind = |k: usize| JointKind::Hinge {
        limits: Some([-limit, limit]),
        motor: None,
        spring: None,
        servo: Some(Servo {
            target: targets[k],
            ..servo
        }),
    };
    let hinge = |w: &mut World, k: usize, (b, other): (BodyId, Option<BodyId>), at: Vec3| {
        let axis = [Vec3::X, Vec3::Y, Vec3::Z][k];
        let mut def = JointDef::new(kind(k), b);
        (def.anchor, def.axis) = (at, axis);
        (def.other, def.other_axis) = (other, axis);
        def.other_anchor = match other {
            Some(_) => Vec3::ZERO,
            None => w.body(b).unwrap().position() + w.body(b).unwrap().orientation() * at,
        };
        w.create_joint(&def).unwrap()
    };
    let joints = [
        hinge(&mut w, 0, (l1, None), Vec3::ZERO),
        hinge(&mut w, 1, (l2, Some(l1)), Vec3::ZERO),
        hinge(&mut w, 2, (rod, Some(l2)), Vec3::Y),
        hinge(&mut w, reference, (single, None), Vec3::Y),
    ];
    (w, rod, pivot, joints)
}

/// Runs the hip for 3 s at `dt`: the largest gap between the rod's top and the pivot, and
/// the hinges' angles at the end (the reference hinge's last).
fn settle(
    w: &mut World,
    (rod, pivot, joints): (BodyId, Vec3, [JointId; 4]),
    dt: Real,
) -> (Real, [Real; 4]) {
    let mut gap: Real = 0.0;
    for _ in 0..(3.0 / dt).round() as usize {
        w.step(dt).unwrap();
        let r = w.body(rod).unwrap();
        gap = gap.max((r.position() + r.orientation() * Vec3::Y - pivot).length());
    }
    let angle = |j: JointId| match w.joint_position(j).unwrap() {
        JointCoordinate::Scalar(a) => a,
        JointCoordinate::Vector(_) => panic!("a hinge's coordinate is a scalar"),
    };
    (gap, joints.map(angle))
}

/// The hip's servo: k = 200 N·m/rad against the rod's gravity stiffness m g L = 98.1
/// N·m/rad, c = 130 N·m·s/rad near critical for the rod's 13.3 kg·m² about the pivot
/// (2√(298 · 13.3) = 126): settled to well within a thousandth in 3 s (time constant
/// 0.2 s).
const HIP_SERVO: Servo = Servo {
    target: 0.0,
    stiffness: 200.0,
    damping: 130.0,
    max_force: 1e6,
};

#[test]
fn a_sprung_hip_through_light_bodies_holds_its_pivot_and_its_spring_balances_gravity() {
    // The servo about x pulls towards 0.3 rad; the rod settles near where k (0.3 − θ) =
    // m g L sin θ (L = 1 m to its centre), and where the same rod on one hinge with that
    // servo settles (a servo's static stiffness is only near k, `joint_1d.rs`: the
    // single hinge came within 0.1 % of the balance, the chain within 0.7 % at dt = 1/60
    // s, its servo meeting the rod through the block's softness). The
    // light bodies carry the rod's weight and the servo's torque: solved joint by joint
    // through them (the limits and servos kept such hips out of the chain's block), the
    // pivot opened and the servo met a light body's mass.
    let (k, mgl) = (HIP_SERVO.stiffness, 10.0 * G);
    let mut theta: Real = 0.0;
    for _ in 0..50 {
        let f = k * (0.3 - theta) - mgl * theta.sin();
        theta -= f / (-k - mgl * theta.cos());
    }
    for light in [1e-2 as Real, 1e-3] {
        for dt in [1.0 as Real / 60.0, 1.0 / 240.0] {
            let (mut w, rod, pivot, joints) =
                sprung_hip(light, (HIP_SERVO, [0.3, 0.0, 0.0]), 0.6, 0);
            let (gap, angles) = settle(&mut w, (rod, pivot, joints), dt);
            let at = format!("light {light}, dt {dt:.4}");
            assert!(gap < tol(1e-3, 2e-3), "{at}: the pivot opened by {gap} m");
            assert!(
                (angles[0] - angles[3]).abs() < 1e-2 * theta,
                "{at}: settled at {} rad, the single hinge at {} rad",
                angles[0],
                angles[3]
            );
            assert!(
                (angles[0] - theta).abs() < 0.02 * theta,
                "{at}: settled at {} rad, not near {theta} rad",
                angles[0]
            );
            assert!(
                angles[1].abs() < 1e-3 && angles[2].abs() < 1e-3,
                "{at}: the other hinges turned: {angles:?}"
            );
        }
    }
}

#[test]
fn a_hip_through_light_bodies_pressed_against_its_limit_stays_at_it() {
    // The servo about z pulls towards 0.8 rad, past the 0.4 rad limit: at the limit it
    // presses with k·0.4 = 80 N·m against gravity's m g L sin 0.4 = 38 N·m, so the rod
    // must rest at the limit, the pivot closed.
    for light in [1e-2 as Real, 1e-3] {
        for dt in [1.0 as Real / 60.0, 1.0 / 240.0] {
            let (mut w, rod, pivot, joints) =
                sprung_hip(light, (HIP_SERVO, [0.0, 0.0, 0.8]), 0.4, 2);
            let (gap, angles) = settle(&mut w, (rod, pivot, joints), dt);
            let at = format!("light {light}, dt {dt:.4}");
            assert!(gap < tol(1e-3, 2e-3), "{at}: the pivot opened by {gap} m");
            assert!(
                (angles[2] - 0.4).abs() < 2e-3,
                "{at}: rests at {} rad, not at the 0.4 rad limit",
                angles[2]
            );
            assert!(
                angles[0].abs() < 1e-3 && angles[1].abs() < 1e-3,
                "{at}: the other hinges turned: {angles:?}"
            );
        }
    }
}
