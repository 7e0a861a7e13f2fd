//! The character controller (`tumble::CharacterController`): a kinematic capsule walked
//! through slopes, steps, walls and corners, against closed forms of where it must end
//! up, for several radii and time steps.
//!
//! The walker of these tests is the one the scene format drives: a horizontal velocity,
//! and while it is in the air the world's gravity accumulated into a fall speed. Where a
//! test compares a position with a closed form, the tolerance is the skin (2 cm by
//! default) or a part of it: the controller promises to keep a skin's gap to surfaces,
//! within the solver's and the sweep's tolerances (it stops at one skin from afar, and
//! never closer than half the gap it starts with). Tolerances quoted in the comments
//! are the f64 build's; the f32 build's looser ones (positions good to ~1e-7 relative,
//! GJK distances to ~1e-5 m) are the second argument of each `tol`.

// Casts between Real and f64 are no-ops in the default build but needed in the f32 one.
#![allow(clippy::unnecessary_cast)]

use crate::common::*;
use tumble::prelude::*;
use tumble::{CharacterController, CharacterDef, HeightField, TriMesh};

const G: Real = 9.8;
const SKIN: Real = 0.02;

/// A world with gravity −9.8 y and the static ground plane y = 0.
fn flat_world() -> World {
    let mut w = World::new(&WorldDef::default());
    let def = BodyDef {
        kind: BodyKind::Static,
        ..Default::default()
    };
    w.create_body(&def, Shape::plane(Vec3::Y, 0.0)).unwrap();
    w
}

/// A static box.
fn fixed_box(w: &mut World, center: Vec3, half: Vec3, q: Quat) -> BodyId {
    let def = BodyDef {
        kind: BodyKind::Static,
        position: center,
        orientation: q,
        ..Default::default()
    };
    w.create_body(&def, Shape::cuboid(half)).unwrap()
}

/// A ramp rising at `angle` along +x from the ground at x = `foot`, `length` m long along
/// its surface, 6 m wide: a slab whose top face is the plane y = tan(angle) (x − foot).
fn ramp(w: &mut World, foot: Real, angle: Real, length: Real) -> BodyId {
    let n = Vec3::new(-angle.sin(), angle.cos(), 0.0);
    let half_thickness = 0.5;
    let mid = Vec3::new(
        foot + 0.5 * length * angle.cos(),
        0.5 * length * angle.sin(),
        0.0,
    );
    let half = Vec3::new(0.5 * length, half_thickness, 3.0);
    fixed_box(
        w,
        mid - n * half_thickness,
        half,
        Quat::from_rotation_z(angle),
    )
}

/// A character of `radius` (and the default half height 0.6) standing on the ground at
/// (x, 0, 0), a skin above it.
fn standing(w: &World, x: Real, def: CharacterDef) -> CharacterController {
    let y = def.radius + def.half_height + SKIN;
    let def = CharacterDef {
        position: Vec3::new(x, y, 0.0),
        ..def
    };
    CharacterController::new(w, &def).unwrap()
}

/// The scene format's walker: `velocity` across, gravity while in the air.
struct Walker {
    fall: Vec3,
    gravity: Vec3,
}

impl Walker {
    fn new() -> Walker {
        Walker {
            fall: Vec3::ZERO,
            gravity: Vec3::new(0.0, -G, 0.0),
        }
    }

    fn step(&mut self, c: &mut CharacterController, w: &mut World, velocity: Vec3, dt: Real) {
        if c.on_ground() {
            self.fall = Vec3::ZERO;
        } else {
            self.fall += self.gravity * dt;
        }
        c.move_by(w, (velocity + self.fall) * dt, dt).unwrap();
    }
}

fn radii_and_steps() -> Vec<(Real, Real)> {
    let mut out = Vec::new();
    for r in [0.2, 0.3, 0.45] {
        for dt in [1.0 / 30.0, 1.0 / 60.0, 1.0 / 240.0] {
            out.push((r as Real, dt as Real));
        }
    }
    out
}

/// On a 20° ramp (max_slope 45°) the character climbs: every frame on it is on the
/// ground with the ramp's normal, its centre stays on the line a skin above the ramp
/// (y = tan θ (x − foot) + (r + skin)/cos θ + h, to half a skin: the slide keeps the
/// gap to the ramp's plane exactly, and it arrives at the ramp from the sweep's stop
/// between half and one skin), and the height it gains between two frames on the ramp is
/// the distance it moved times sin θ (to 1e-9 m: it moves in the ramp's plane).
#[test]
fn slopes_under_the_limit_are_climbed() {
    let angle = (20.0 as Real).to_radians();
    for (r, dt) in radii_and_steps() {
        let mut w = flat_world();
        ramp(&mut w, 1.0, angle, 8.0);
        let def = CharacterDef {
            radius: r,
            ..Default::default()
        };
        let mut c = standing(&w, 0.0, def);
        let mut walker = Walker::new();
        let normal = Vec3::new(-angle.sin(), angle.cos(), 0.0);
        let mut last: Option<Vec3> = None;
        let mut frames_on_ramp = 0;
        for _ in 0..(3.0 / dt) as usize {
            walker.step(&mut c, &mut w, Vec3::new(2.0, 0.0, 0.0), dt);
            assert!(
                c.on_ground(),
                "r {r} dt {dt}: off the ground at {}",
                c.position()
            );
            let p = c.position();
            if (c.ground_normal().unwrap() - normal).length() > 1e-6 {
                last = None;
                continue;
            }
            frames_on_ramp += 1;
            let line = angle.tan() * (p.x - 1.0) + (r + SKIN) / angle.cos() + 0.6;
            assert!(
                (p.y - line).abs() <= 0.5 * SKIN,
                "r {r} dt {dt}: {p} vs {line}"
            );
            if let Some(q) = last {
                let gained = p.y - q.y;
                let along = (p - q).length() * angle.sin();
                assert!(
                    (gained - along).abs() <= tol(1e-9, 1e-5),
                    "{gained} vs {along}"
                );
            }
            last = Some(p);
        }
        assert!(
            frames_on_ramp as Real * dt > 1.0,
            "r {r} dt {dt}: {frames_on_ramp} frames"
        );
        assert!(
            c.position().y > 1.5,
            "r {r} dt {dt}: climbed only to {}",
            c.position()
        );
    }
}

/// A 60° ramp (max_slope 45°) is a wall: walking into it for 2 s, the character never
/// rises more than a skin (the steep plane's vertical stand-in keeps the walk from
/// turning into a climb), and stops where its lower sphere touches the ramp, a skin
/// off: the sphere's centre (x, r + skin) is r + skin from the ramp's plane.
#[test]
fn slopes_over_the_limit_are_refused() {
    let angle = (60.0 as Real).to_radians();
    for (r, dt) in radii_and_steps() {
        let mut w = flat_world();
        ramp(&mut w, 1.0, angle, 4.0);
        let def = CharacterDef {
            radius: r,
            ..Default::default()
        };
        let mut c = standing(&w, 0.0, def);
        let start = c.position();
        let mut walker = Walker::new();
        for _ in 0..(2.0 / dt) as usize {
            walker.step(&mut c, &mut w, Vec3::new(2.0, 0.0, 0.0), dt);
            assert!(
                c.position().y - start.y <= SKIN,
                "r {r} dt {dt}: {}",
                c.position()
            );
        }
        // The sphere centre's distance to the ramp's plane through (1, 0, 0).
        let n = Vec3::new(-angle.sin(), angle.cos(), 0.0);
        let sphere = Vec3::new(c.position().x, r + SKIN, 0.0);
        let gap = n.dot(sphere - Vec3::new(1.0, 0.0, 0.0)) - r;
        assert!(
            (0.4 * SKIN..=1.1 * SKIN).contains(&gap),
            "r {r} dt {dt}: gap {gap}"
        );
        assert!(c.on_ground(), "r {r} dt {dt}: stands on the flat ground");
    }
}

/// A step of 0.8 × step_height is climbed, one of 1.5 × refused, for step heights 0.2 to
/// 0.4 m, radii 0.2 to 0.45 m and three time steps. Climbed: 2 s later it stands on the
/// step's top, a skin above it (centre at h + r + half_height + skin, to half a skin),
/// on the ground, past the edge. Refused: it never rises more than a skin and stays in
/// front of the step, its lower sphere between 0.4 and 1.1 skins from the step's face or
/// edge.
#[test]
fn steps_under_the_step_height_are_climbed_and_higher_ones_refused() {
    for step_height in [0.2, 0.3, 0.4] {
        for (r, dt) in radii_and_steps() {
            for (ratio, climbed) in [(0.8, true), (1.5, false)] {
                let h = ratio * step_height as Real;
                let mut w = flat_world();
                let face = 1.0;
                fixed_box(
                    &mut w,
                    Vec3::new(face + 2.0, 0.5 * h, 0.0),
                    Vec3::new(2.0, 0.5 * h, 3.0),
                    Quat::IDENTITY,
                );
                let def = CharacterDef {
                    radius: r,
                    step_height: step_height as Real,
                    ..Default::default()
                };
                let mut c = standing(&w, 0.0, def);
                let mut walker = Walker::new();
                let ground_y = c.position().y;
                for _ in 0..(2.0 / dt) as usize {
                    walker.step(&mut c, &mut w, Vec3::new(1.5, 0.0, 0.0), dt);
                    if !climbed {
                        let p = c.position();
                        assert!(p.y - ground_y <= SKIN, "step {h} r {r} dt {dt}: {p}");
                    }
                }
                let p = c.position();
                let case = format!("step {h} r {r} dt {dt}: {p}");
                if climbed {
                    let top = h + r + 0.6 + SKIN;
                    assert!((p.y - top).abs() <= 0.5 * SKIN, "{case}");
                    assert!(p.x > face + 1.0 && c.on_ground(), "{case}");
                    let n = c.ground_normal().unwrap();
                    assert!((n - Vec3::Y).length() < 1e-6, "{case}");
                } else {
                    // The step's nearest point to the lower sphere's centre c: on its
                    // face, or its top edge when c is above it (a step lower than r).
                    let c = p - Vec3::new(0.0, 0.6, 0.0);
                    let gap = (c - Vec3::new(face, c.y.min(h), 0.0)).length() - r;
                    assert!((0.4 * SKIN..=1.1 * SKIN).contains(&gap), "{case}");
                }
            }
        }
    }
}

/// Walking at v into a wall at 45° to the way, the character slides along it with the
/// tangential part of the velocity, v − (v·n) n, exactly (to 1e-9 m/s: the plane solver
/// projects the move onto the wall's plane and the sweep along it meets nothing), and
/// keeps a skin's gap (to 1e-6 m).
#[test]
fn walls_are_slid_along_with_the_tangential_velocity() {
    for (r, dt) in radii_and_steps() {
        let mut w = flat_world();
        // A wall whose face has normal n = (−1, 0, 1)/√2, through (2, 0, 0).
        let n = Vec3::new(-1.0, 0.0, 1.0).normalize();
        let q = Quat::from_rotation_y(std::f64::consts::FRAC_PI_4 as Real);
        let half = Vec3::new(0.1, 2.0, 20.0);
        fixed_box(&mut w, Vec3::new(2.0, 0.0, 0.0) - n * 0.1, half, q);
        let def = CharacterDef {
            radius: r,
            ..Default::default()
        };
        let mut c = standing(&w, 0.0, def);
        let mut walker = Walker::new();
        let v = Vec3::new(3.0, 0.0, 0.0);
        let tangential = v - n * v.dot(n);
        let mut sliding = 0;
        let mut touching = false;
        for _ in 0..(2.0 / dt) as usize {
            walker.step(&mut c, &mut w, v, dt);
            let gap = n.dot(c.position() - Vec3::new(2.0, 0.0, 0.0)) - r;
            assert!(gap >= 0.4 * SKIN, "r {r} dt {dt}: gap {gap}");
            // The frame it arrives it moves partly straight, partly along the wall.
            let arrived = touching;
            touching = (gap - SKIN).abs() < tol(1e-6, 1e-4);
            if touching && arrived {
                sliding += 1;
                let e = (c.velocity() - tangential).length();
                assert!(e <= tol(1e-9, 1e-3), "r {r} dt {dt}: {}", c.velocity());
            }
        }
        assert!(
            sliding as Real * dt > 1.0,
            "r {r} dt {dt}: slid {sliding} frames"
        );
    }
}

/// At 20 m/s (a third of a metre to 1.3 m a move) towards a 5 cm wall, a box, or a
/// single triangle pair of no thickness at all, the character never passes it: its
/// centre stays a radius and at least half a skin in front of the face, every frame for
/// 1 s, for radii down to 0.1 m (less than one move).
#[test]
fn no_tunnelling_at_20_m_s_through_thin_walls() {
    for mesh in [false, true] {
        for r in [0.1, 0.3] {
            for dt in [1.0 / 15.0, 1.0 / 30.0, 1.0 / 60.0] {
                let mut w = flat_world();
                let face = 3.0;
                if mesh {
                    let v = [
                        Vec3::new(face, 0.0, -5.0),
                        Vec3::new(face, 0.0, 5.0),
                        Vec3::new(face, 4.0, 5.0),
                        Vec3::new(face, 4.0, -5.0),
                    ];
                    let tm = TriMesh::new(v.to_vec(), vec![[0, 1, 2], [0, 2, 3]]).unwrap();
                    let def = BodyDef {
                        kind: BodyKind::Static,
                        ..Default::default()
                    };
                    w.create_body(&def, Shape::TriMesh(tm)).unwrap();
                } else {
                    let half = Vec3::new(0.025, 2.0, 5.0);
                    fixed_box(
                        &mut w,
                        Vec3::new(face + 0.025, 2.0, 0.0),
                        half,
                        Quat::IDENTITY,
                    );
                }
                let def = CharacterDef {
                    radius: r as Real,
                    ..Default::default()
                };
                let mut c = standing(&w, 0.0, def);
                let mut walker = Walker::new();
                for _ in 0..(1.0 / dt) as usize {
                    walker.step(&mut c, &mut w, Vec3::new(20.0, 0.0, 0.0), dt as Real);
                    let x = c.position().x;
                    let case = format!("mesh {mesh} r {r} dt {dt}: x {x}");
                    assert!(x <= face - r as Real - 0.4 * SKIN, "{case}");
                }
                assert!(c.position().x >= face - r as Real - 1.1 * SKIN);
            }
        }
    }
}

/// Walking down a 30° ramp (from its top, at 2 m/s, horizontal: the ramp falls away
/// 3.8 cm a move at dt = 1/30 s, more than the two skins the ground is looked for within)
/// onto a plateau 0.6 m up, then down its three 0.2 m stairs, the character is on the
/// ground after every move: snapping takes it down to the slope or the next tread. On the
/// ramp its centre is on the line a skin above it (to half a skin), and at the bottom it
/// stands on the floor a skin up (to half a skin).
#[test]
fn going_down_slopes_and_stairs_stays_on_the_ground() {
    let angle = (30.0 as Real).to_radians();
    for (r, dt) in radii_and_steps() {
        let mut w = flat_world();
        // The plateau, x in [−5, 3], and its stairs: treads 0.3 m deep at 0.4 and 0.2 m.
        fixed_box(
            &mut w,
            Vec3::new(-1.0, 0.3, 0.0),
            Vec3::new(4.0, 0.3, 3.0),
            Quat::IDENTITY,
        );
        for (x, y) in [(3.15, 0.4), (3.45, 0.2)] {
            let half = Vec3::new(0.15, 0.5 * y, 3.0);
            fixed_box(&mut w, Vec3::new(x, 0.5 * y, 0.0), half, Quat::IDENTITY);
        }
        // The ramp rises towards −x from its foot at (0, 0.6): a +x ramp mirrored.
        let n = Vec3::new(angle.sin(), angle.cos(), 0.0);
        let length = 4.0;
        let mid = Vec3::new(
            -0.5 * length * angle.cos(),
            0.6 + 0.5 * length * angle.sin(),
            0.0,
        );
        let half = Vec3::new(0.5 * length, 0.5, 3.0);
        fixed_box(&mut w, mid - n * 0.5, half, Quat::from_rotation_z(-angle));
        let line = |x: Real| 0.6 - angle.tan() * x + (r + SKIN) / angle.cos() + 0.6;
        let def = CharacterDef {
            radius: r,
            position: Vec3::new(-3.0, line(-3.0), 0.0),
            ..Default::default()
        };
        let mut c = CharacterController::new(&w, &def).unwrap();
        assert!(c.on_ground());
        let mut walker = Walker::new();
        let mut on_ramp = 0;
        for _ in 0..(5.0 / dt) as usize {
            walker.step(&mut c, &mut w, Vec3::new(2.0, 0.0, 0.0), dt);
            let p = c.position();
            assert!(c.on_ground(), "r {r} dt {dt}: in the air at {p}");
            if p.x < -0.5 {
                on_ramp += 1;
                assert!((p.y - line(p.x)).abs() <= 0.5 * SKIN, "r {r} dt {dt}: {p}");
            }
        }
        let p = c.position();
        assert!(on_ramp > 10 && p.x > 5.0, "r {r} dt {dt}: {p}");
        assert!(
            (p.y - (r + 0.6 + SKIN)).abs() <= 0.5 * SKIN,
            "r {r} dt {dt}: {p}"
        );
    }
}

/// Two walls meeting at an apex (3, 0, 0) in a wedge of full angle 2α opening towards −x.
fn wedge(w: &mut World, alpha: Real) {
    let apex = Vec3::new(3.0, 0.0, 0.0);
    for side in [1.0, -1.0] {
        // Along the wall, away from the apex, and its normal into the wedge.
        let along = Vec3::new(-alpha.cos(), 0.0, side * alpha.sin());
        let normal = Vec3::new(-alpha.sin(), 0.0, -side * alpha.cos());
        let (half_length, half_thickness) = (4.0, 0.1);
        // Past the apex by a thickness, hidden behind the other wall.
        let center = apex + along * (half_length - half_thickness) - normal * half_thickness;
        let q = Quat::from_rotation_arc(Vec3::X, normal);
        let half = Vec3::new(half_thickness, 2.0, half_length);
        let z = q * Vec3::Z;
        assert!(
            z.cross(along).length() < tol(1e-9, 1e-5),
            "the box's long axis runs along the wall"
        );
        fixed_box(w, center + Vec3::Y * 2.0, half, q);
    }
}

/// Walking into the corner of two walls at 60° and at 20°, straight along the bisector or
/// at an angle (sliding along one wall into the corner), the character stops where it
/// is a skin from both: on the bisector, (r + skin)/sin α from the apex (to a skin over
/// sin α, the distance a skin's error along a wall's normal moves it along the bisector;
/// to 1e-9 m across). There it does not jitter (it moves less than 1e-9 m a frame over
/// the last second) and it is not stuck: walking out, it moves at exactly the velocity
/// asked for.
#[test]
fn a_corner_neither_sticks_nor_jitters() {
    for alpha_deg in [30.0, 10.0] {
        let alpha = (alpha_deg as Real).to_radians();
        for (r, dt) in radii_and_steps() {
            for v in [Vec3::new(2.0, 0.0, 0.0), Vec3::new(2.0, 0.0, 1.0)] {
                let mut w = flat_world();
                wedge(&mut w, alpha);
                let def = CharacterDef {
                    radius: r,
                    ..Default::default()
                };
                let mut c = standing(&w, -1.0, def);
                let mut walker = Walker::new();
                let frames = (4.0 / dt) as usize;
                let mut last = c.position();
                for k in 0..frames {
                    walker.step(&mut c, &mut w, v, dt);
                    let p = c.position();
                    if k > frames - (1.0 / dt) as usize {
                        assert!(
                            (p - last).length() <= tol(1e-9, 1e-5),
                            "a {alpha_deg} r {r} dt {dt}: {p}"
                        );
                    }
                    last = p;
                }
                let p = c.position();
                let x = 3.0 - (r + SKIN) / alpha.sin();
                let case = format!("a {alpha_deg} r {r} dt {dt} v {v}: {p} vs {x}");
                assert!((p.x - x).abs() <= SKIN / alpha.sin(), "{case}");
                assert!(p.z.abs() <= tol(1e-9, 1e-5), "{case}");
                let out = Vec3::new(-1.5, 0.0, 0.1);
                walker.step(&mut c, &mut w, out, dt);
                assert!(
                    (c.velocity() - out).length() <= tol(1e-9, 1e-3),
                    "{case}: {}",
                    c.velocity()
                );
            }
        }
    }
}

/// A frictionless floor and a ball of radius 0.5 m and `mass` kg on it at x = 2.
fn floor_and_ball(mass: Real) -> (World, BodyId) {
    let mut w = World::new(&WorldDef::default());
    let ground = BodyDef {
        kind: BodyKind::Static,
        friction: 0.0,
        ..Default::default()
    };
    w.create_body(&ground, Shape::plane(Vec3::Y, 0.0)).unwrap();
    let def = BodyDef {
        position: Vec3::new(2.0, 0.5, 0.0),
        mass: MassSpec::Mass(mass),
        friction: 0.0,
        ..Default::default()
    };
    let id = w.create_body(&def, Shape::sphere(0.5)).unwrap();
    (w, id)
}

/// Walking into a heavy ball (500 kg, max_push_force 100 N) on a frictionless floor, the
/// push is saturated: every push is F·dt (to 1e-9 relative), along +x (to 1e-9: the
/// normal through the ball's centre is horizontal), and the ball's momentum after the
/// run is the sum of the pushes, F times the time it was pushed (to 1e-6 relative:
/// nothing else acts across a frictionless floor). A light one (2 kg, 1000 N: the bound
/// does not bind) is pushed off at the walking speed, to 1e-6 relative (2e-3 in f32,
/// whose GJK distances, which p is measured from, are good to about 1e-5 m): it gets
/// m·p/dt, p the part of the move it held back, and the character then follows it
/// without pushing again. With max_push_force 0 nothing moves the ball at all.
#[test]
fn pushing_a_dynamic_body_is_bounded_by_max_push_force() {
    for dt in [1.0 / 30.0, 1.0 / 60.0, 1.0 / 240.0] {
        for (mass, force) in [(500.0, 100.0), (2.0, 1000.0), (2.0, 0.0)] {
            let (mut w, ball) = floor_and_ball(mass);
            let def = CharacterDef {
                max_push_force: force,
                ..Default::default()
            };
            let mut c = standing(&w, 0.0, def);
            let mut walker = Walker::new();
            let mut total = Vec3::ZERO;
            let mut pushed = 0;
            let v = 1.5;
            for _ in 0..(2.0 / dt) as usize {
                walker.step(&mut c, &mut w, Vec3::new(v, 0.0, 0.0), dt);
                for push in c.pushes() {
                    assert_eq!(push.body, ball);
                    let j = push.impulse;
                    assert!(j.length() <= force * dt * (1.0 + tol(1e-12, 1e-6)));
                    assert!(
                        j.x > 0.0 && j.y.abs() + j.z.abs() < tol(1e-9, 1e-6) * j.x,
                        "{j}"
                    );
                    if mass > 100.0 {
                        let e = (push.impulse.length() - force * dt).abs() / (force * dt);
                        assert!(e < tol(1e-9, 1e-6), "dt {dt}: {}", push.impulse);
                    }
                    total += push.impulse;
                    pushed += 1;
                }
                w.step(dt).unwrap();
            }
            let b = w.body(ball).unwrap();
            let p = b.linear_momentum();
            let case = format!("dt {dt} mass {mass} force {force}: p {p}, pushes {total}");
            if force == 0.0 {
                assert!(pushed == 0 && p.length() < tol(1e-9, 1e-6), "{case}");
                assert!((b.position().x - 2.0).abs() < tol(1e-9, 1e-6), "{case}");
                continue;
            }
            assert!(pushed > 0, "{case}");
            assert!((p.x - total.x).abs() <= tol(1e-6, 1e-4) * total.x, "{case}");
            if mass > 100.0 {
                let expected = force * dt * pushed as Real;
                assert!(
                    (p.x - expected).abs() <= tol(1e-6, 1e-4) * expected,
                    "{case}"
                );
            } else {
                let speed = b.linear_velocity().x;
                assert!(
                    (speed - v).abs() <= tol(1e-6, 2e-3) * v,
                    "{case}: speed {speed}"
                );
            }
        }
    }
}

/// Bad settings are refused naming the field under `character`, bad move arguments
/// naming the argument, and a refused move changes nothing.
#[test]
fn bad_parameters_are_refused_with_the_field_named() {
    let w = flat_world();
    let d = CharacterDef::default();
    let cases: Vec<(CharacterDef, &str)> = vec![
        (
            CharacterDef { radius: 0.0, ..d },
            "character.radius: must be > 0",
        ),
        (
            CharacterDef {
                radius: Real::NAN,
                ..d
            },
            "character.radius: must be a finite number",
        ),
        (
            CharacterDef {
                half_height: -1.0,
                ..d
            },
            "character.half_height: must be >= 0",
        ),
        (
            CharacterDef {
                up: Vec3::ZERO,
                ..d
            },
            "character.up: must be a non-zero vector",
        ),
        (
            CharacterDef {
                up: Vec3::new(0.0, Real::INFINITY, 0.0),
                ..d
            },
            "character.up: must be finite numbers",
        ),
        (
            CharacterDef {
                max_slope: 2.0,
                ..d
            },
            "character.max_slope: must be >= 0 and below π/2 rad (90°), got 2",
        ),
        (
            CharacterDef {
                max_slope: -0.1,
                ..d
            },
            "character.max_slope: must be >= 0 and below π/2 rad (90°), got -0.1",
        ),
        (
            CharacterDef {
                step_height: -0.1,
                ..d
            },
            "character.step_height: must be >= 0",
        ),
        (
            CharacterDef { skin: 0.0, ..d },
            "character.skin: must be > 0",
        ),
        (
            CharacterDef { skin: 0.3, ..d },
            "character.skin: must be less than radius (0.3 m)",
        ),
        (
            CharacterDef {
                snap_distance: -1.0,
                ..d
            },
            "character.snap_distance: must be >= 0",
        ),
        (
            CharacterDef {
                max_push_force: Real::NAN,
                ..d
            },
            "character.max_push_force: must be a finite number",
        ),
        (
            CharacterDef {
                position: Vec3::new(2e9, 0.0, 0.0),
                ..d
            },
            "character.position: must be at most 1e9 m in magnitude",
        ),
    ];
    for (def, message) in cases {
        let e = CharacterController::new(&w, &def).unwrap_err();
        assert_eq!(e.to_string(), message);
    }
    let mut w = w;
    let mut c = standing(&w, 6e8, d);
    c.move_by(&mut w, Vec3::new(0.1, 0.0, 0.0), 0.1).unwrap();
    let before = c.clone();
    let bad: Vec<(Vec3, Real, &str)> = vec![
        (
            Vec3::new(Real::NAN, 0.0, 0.0),
            0.1,
            "displacement: must be finite numbers",
        ),
        (Vec3::X, 0.0, "dt: must be > 0"),
        (Vec3::X, -1.0, "dt: must be > 0"),
        (Vec3::X, Real::INFINITY, "dt: must be a finite number"),
        (
            Vec3::new(2e9, 0.0, 0.0),
            0.1,
            "displacement: must be at most 1e9 m in magnitude",
        ),
        (
            Vec3::new(6e8, 0.0, 0.0),
            0.1,
            "displacement: would take the character beyond ±1e9 m",
        ),
    ];
    for (displacement, dt, message) in bad {
        let e = c.move_by(&mut w, displacement, dt).unwrap_err();
        assert_eq!(e.to_string(), message);
        assert_eq!(c, before);
    }
    let e = c
        .set_position(&w, Vec3::new(0.0, Real::NAN, 0.0))
        .unwrap_err();
    assert_eq!(e.to_string(), "position: must be finite numbers");
    assert_eq!(c, before);
}

/// Dropped from 2 m (its feet), with the walker's gravity, the character falls freely
/// (its height follows the explicit sum of the walker's steps, y_k = y₀ − g dt² k(k+1)/2,
/// to 1e-9 m, while in the air), lands a skin above the floor (to half a skin) without
/// ever going lower, and is on the ground from then on, with normal +y.
#[test]
fn falling_lands_on_the_ground() {
    for (r, dt) in radii_and_steps() {
        let mut w = flat_world();
        let y0 = 2.0 + r + 0.6;
        let def = CharacterDef {
            radius: r,
            position: Vec3::new(0.0, y0, 0.0),
            ..Default::default()
        };
        let mut c = CharacterController::new(&w, &def).unwrap();
        assert!(!c.on_ground() && c.ground_normal().is_none());
        let mut walker = Walker::new();
        let rest = r + 0.6 + SKIN;
        let mut landed = None;
        for k in 1..=(2.0 / dt) as usize {
            walker.step(&mut c, &mut w, Vec3::ZERO, dt);
            let y = c.position().y;
            assert!(y >= rest - 0.5 * SKIN, "r {r} dt {dt}: {y}");
            if c.on_ground() {
                landed.get_or_insert(k);
                assert!((y - rest).abs() <= 0.5 * SKIN);
                assert!((c.ground_normal().unwrap() - Vec3::Y).length() < tol(1e-12, 1e-6));
            } else {
                assert!(landed.is_none(), "r {r} dt {dt}: left the ground at {k}");
                let free = y0 - G * dt * dt * (k * (k + 1)) as Real / 2.0;
                assert!(
                    (y - free).abs() <= tol(1e-9, 1e-4),
                    "r {r} dt {dt}: {y} vs {free}"
                );
            }
        }
        assert!(landed.is_some());
    }
}

/// A height field terrain (0.5 m cells, x from −10 to 10 m): flat, then rising at 20°
/// from x = 0 to 5 m, then flat again. Walking across it the character is on the ground every move, on the field,
/// and ends on the upper flat a skin above it (to half a skin): the field's triangles
/// are planes of the solver like any other surface (those of one flat merged into one).
#[test]
fn a_height_field_slope_is_walked_up() {
    let angle = (20.0 as Real).to_radians();
    let (rows, cols, cell) = (9, 41, 0.5);
    let height = |x: Real| angle.tan() * x.clamp(0.0, 5.0);
    let mut heights = Vec::new();
    for _ in 0..rows {
        for c in 0..cols {
            heights.push(height((c as Real - (cols - 1) as Real / 2.0) * cell));
        }
    }
    let field = HeightField::new(heights, rows, cols, Vec3::new(cell, 1.0, cell)).unwrap();
    for (r, dt) in radii_and_steps() {
        let mut w = World::new(&WorldDef::default());
        let def = BodyDef {
            kind: BodyKind::Static,
            ..Default::default()
        };
        let terrain = w
            .create_body(&def, Shape::HeightField(field.clone()))
            .unwrap();
        let def = CharacterDef {
            radius: r,
            ..Default::default()
        };
        let mut c = standing(&w, -8.0, def);
        assert_eq!(c.ground_body(), Some(terrain));
        let mut walker = Walker::new();
        while c.position().x < 7.0 {
            walker.step(&mut c, &mut w, Vec3::new(2.0, 0.0, 0.0), dt);
            assert_eq!(
                c.ground_body(),
                Some(terrain),
                "r {r} dt {dt}: {}",
                c.position()
            );
        }
        let top = height(5.0) + r + 0.6 + SKIN;
        let p = c.position();
        assert!(
            (p.y - top).abs() <= 0.5 * SKIN,
            "r {r} dt {dt}: {p} vs {top}"
        );
    }
}

/// With `up` tilted (a world whose gravity is not along −y), slopes and steps are
/// measured against it: the step scene of `steps_under_...` built in a frame turned by
/// R, walked with gravity along −up, ends in the same place seen in that frame (to half
/// a skin) for a step of 0.8 × step_height, and in front of one of 1.5 ×.
#[test]
fn up_sets_what_is_level() {
    let turn = Quat::from_rotation_arc(Vec3::Y, Vec3::new(0.3, 0.9, -0.2).normalize());
    let up = turn * Vec3::Y;
    for (ratio, climbed) in [(0.8, true), (1.5, false)] {
        let h = ratio * 0.3;
        let mut w = World::new(&WorldDef::default());
        let ground = BodyDef {
            kind: BodyKind::Static,
            ..Default::default()
        };
        w.create_body(&ground, Shape::plane(up, 0.0)).unwrap();
        let center = turn * Vec3::new(3.0, 0.5 * h, 0.0);
        fixed_box(&mut w, center, Vec3::new(2.0, 0.5 * h, 3.0), turn);
        let def = CharacterDef {
            position: turn * Vec3::new(0.0, 0.3 + 0.6 + SKIN, 0.0),
            up,
            ..Default::default()
        };
        let mut c = CharacterController::new(&w, &def).unwrap();
        assert!(c.on_ground() && (c.ground_normal().unwrap() - up).length() < tol(1e-9, 1e-6));
        let mut walker = Walker::new();
        walker.gravity = -up * G;
        for _ in 0..120 {
            walker.step(&mut c, &mut w, turn * Vec3::new(1.5, 0.0, 0.0), 1.0 / 60.0);
        }
        let local = turn.inverse() * c.position();
        if climbed {
            assert!(
                (local.y - (h + 0.3 + 0.6 + SKIN)).abs() <= 0.5 * SKIN,
                "{local}"
            );
            assert!(local.x > 2.0 && local.z.abs() < tol(1e-6, 1e-4), "{local}");
        } else {
            assert!(
                (local.y - (0.3 + 0.6 + SKIN)).abs() <= 0.5 * SKIN,
                "{local}"
            );
            assert!(
                (local.x - (1.0 - 0.3 - SKIN)).abs() <= 0.5 * SKIN,
                "{local}"
            );
        }
    }
}

/// The same moves in the same world give bit-identical positions (no order of a hash,
/// no time): a walk through slopes, a step and a wall, twice.
#[test]
fn moves_are_deterministic() {
    let run = || {
        let mut w = flat_world();
        ramp(&mut w, 1.0, 0.3, 3.0);
        fixed_box(
            &mut w,
            Vec3::new(-3.0, 0.1, 0.0),
            Vec3::new(1.0, 0.1, 3.0),
            Quat::IDENTITY,
        );
        let mut c = standing(&w, 0.0, CharacterDef::default());
        let mut walker = Walker::new();
        let mut trace = Vec::new();
        for k in 0..300 {
            let v = Vec3::new(
                (k as Real * 0.05).cos() * 3.0,
                0.0,
                (k as Real * 0.031).sin(),
            );
            walker.step(&mut c, &mut w, v, 1.0 / 60.0);
            trace.push(c.position());
        }
        trace
    };
    assert_eq!(run(), run());
}

/// A character created 10 cm into a wall is put back out by its first move, even one of
/// zero displacement: to a skin from the wall (to 1e-6 m: the plane solver's push of an
/// overlap is exact), still standing on the floor. Squeezed between two walls closer than
/// its width, it stays finite and inside the gap's ends (the planes leave no room; the
/// fallback solver and the sweep keep it from being thrown out through a wall).
#[test]
fn overlaps_are_pushed_out_and_a_squeeze_is_survived() {
    for r in [0.2, 0.3, 0.45] {
        let mut w = flat_world();
        fixed_box(
            &mut w,
            Vec3::new(1.5, 1.0, 0.0),
            Vec3::new(0.5, 1.0, 3.0),
            Quat::IDENTITY,
        );
        let def = CharacterDef {
            radius: r,
            ..Default::default()
        };
        let mut c = standing(&w, 1.0 - r + 0.1, def);
        c.move_by(&mut w, Vec3::ZERO, 1.0 / 60.0).unwrap();
        let gap = 1.0 - (c.position().x + r);
        assert!((gap - SKIN).abs() < tol(1e-6, 1e-4), "r {r}: gap {gap}");
        assert!(c.on_ground() && (c.position().y - (r + 0.6 + SKIN)).abs() < 1e-6);
    }
    let mut w = flat_world();
    for x in [-0.75, 0.75] {
        fixed_box(
            &mut w,
            Vec3::new(x, 1.0, 0.0),
            Vec3::new(0.5, 1.0, 3.0),
            Quat::IDENTITY,
        );
    }
    let mut c = standing(&w, 0.0, CharacterDef::default());
    let mut walker = Walker::new();
    for k in 0..120 {
        let v = Vec3::new(if k % 2 == 0 { 3.0 } else { -3.0 }, 0.0, 1.0);
        walker.step(&mut c, &mut w, v, 1.0 / 60.0);
        let p = c.position();
        assert!(p.is_finite() && p.x.abs() < 0.25, "{p}");
    }
}

/// A static body that is only a trigger volume: a sensor box 2 m tall across the path.
fn trigger(w: &mut World, x: Real) -> BodyId {
    let def = BodyDef {
        kind: BodyKind::Static,
        position: Vec3::new(x, 1.0, 0.0),
        sensor: true,
        ..Default::default()
    };
    w.create_body(&def, Shape::cuboid(Vec3::new(0.5, 1.0, 3.0)))
        .unwrap()
}

/// A sensor stops nothing: walking at 2 m/s for 2 s across a trigger box taller than the
/// character, it ends 4 m on (to rounding), on the ground all the way; before sensors
/// were passed over, the box stopped it a skin short of its face like a wall.
#[test]
fn a_sensor_does_not_stop_the_character() {
    for (r, dt) in radii_and_steps() {
        let mut w = flat_world();
        trigger(&mut w, 2.0);
        let mut c = standing(
            &w,
            0.0,
            CharacterDef {
                radius: r,
                ..Default::default()
            },
        );
        let mut walker = Walker::new();
        let steps = (2.0 / dt).round() as usize;
        for _ in 0..steps {
            walker.step(&mut c, &mut w, Vec3::new(2.0, 0.0, 0.0), dt);
            assert!(c.on_ground(), "r {r} dt {dt}: off the ground");
        }
        let x = c.position().x;
        let end = 2.0 * steps as Real * dt;
        assert!(
            (x - end).abs() < tol(1e-9, 1e-4),
            "r {r} dt {dt}: x {x} vs {end}"
        );
    }
}

/// A one-way platform (a static slab whose top is at y = 2.5 m, 0.2 m thick, one way
/// +y) over a character that jumps at 8 m/s: it rises through the slab as in free flight
/// (its apex that of the discrete flight, about v²/2g = 3.3 m up, to two skins: the frame
/// its feet come out of the top less than a skin deep, the top already holds it and lifts
/// it to a skin above) and lands on the top a skin above it (to half a skin), staying there. The
/// same slab without `one_way` stops the jump under it: the test tells them apart.
#[test]
fn a_character_jumps_up_through_a_one_way_platform_and_lands_on_it() {
    for (r, dt) in radii_and_steps() {
        for one_way in [true, false] {
            let mut w = flat_world();
            let def = BodyDef {
                kind: BodyKind::Static,
                position: Vec3::new(0.0, 2.4, 0.0),
                one_way: one_way.then_some(Vec3::Y),
                ..Default::default()
            };
            w.create_body(&def, Shape::cuboid(Vec3::new(3.0, 0.1, 3.0)))
                .unwrap();
            let mut c = standing(
                &w,
                0.0,
                CharacterDef {
                    radius: r,
                    ..Default::default()
                },
            );
            let y0 = c.position().y;
            let (v0, mut vy, mut apex): (Real, Real, Real) = (8.0, 8.0, y0);
            for _ in 0..(2.0 / dt).round() as usize {
                c.move_by(&mut w, Vec3::new(0.0, vy * dt, 0.0), dt).unwrap();
                apex = apex.max(c.position().y);
                vy = if c.on_ground() && vy <= 0.0 {
                    0.0
                } else {
                    vy - G * dt
                };
            }
            let y = c.position().y;
            if one_way {
                // The discrete flight: after n frames v₀ n dt − g dt² n (n − 1)/2.
                let rise = (0..(2.0 / dt) as usize)
                    .map(|n| n as Real)
                    .map(|n| v0 * dt * n - G * dt * dt * n * (n - 1.0) / 2.0)
                    .fold(0.0, Real::max);
                assert!(
                    (apex - y0 - rise).abs() < 2.0 * SKIN,
                    "r {r} dt {dt}: apex {apex}"
                );
                let on_top = 2.5 + r + 0.6 + SKIN;
                assert!(c.on_ground(), "r {r} dt {dt}: not on the platform");
                assert!((y - on_top).abs() <= 0.5 * SKIN, "r {r} dt {dt}: y {y}");
            } else {
                let under = 2.3 - r - 0.6;
                assert!(
                    apex < under,
                    "r {r} dt {dt}: through a solid slab to {apex}"
                );
                assert!((y - y0).abs() <= 0.5 * SKIN, "r {r} dt {dt}: y {y}");
            }
        }
    }
}
