//! Chains of joints through light bodies (`solver/joint_chain.rs`): how MJCF and URDF
//! import a body with several joints (a planar root of slide, slide and hinge; a hip of
//! three hinges), a light body between each two joints. The chain must act as the one
//! joint it stands for, whatever the light bodies' share of the mass and the step.
//! f64 and f32 alike.

// Casts between Real and f64 are no-ops in the default build but needed in the f32 one.
#![allow(clippy::unnecessary_cast)]

use crate::common::{awake, tol};
use tumble::prelude::*;

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

fn hinge() -> JointKind {
    JointKind::Hinge {
        limits: None,
        motor: None,
        spring: None,
        servo: None,
    }
}

fn slider() -> JointKind {
    JointKind::Slider {
        limits: None,
        motor: None,
        spring: None,
        servo: None,
    }
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
                join(&mut w, slider(), l1, None, Vec3::X);
                join(&mut w, slider(), l2, Some(l1), Vec3::Y);
                join(&mut w, hinge(), torso, Some(l2), Vec3::Z);
                let mut def = JointDef::new(hinge(), arm);
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
        join(&mut w, hinge(), l1, None, Vec3::X);
        join(&mut w, hinge(), l2, Some(l1), Vec3::Y);
        let mut def = JointDef::new(hinge(), chained);
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
