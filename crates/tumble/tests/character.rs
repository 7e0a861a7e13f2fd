//! The character controller (`tumble::CharacterController`): a kinematic capsule walked
//! through slopes, steps, walls and corners, against closed forms of where it must end
//! up, for several radii and time steps.
//!
//! The walker of these tests is the one the scene format drives: a horizontal velocity,
//! and while it is in the air the world's gravity accumulated into a fall speed. Where a
//! test compares a position with a closed form, the tolerance is the skin (2 cm by
//! default) or a part of it: the controller promises to keep a skin's gap to surfaces,
//! within the solver's and the sweep's tolerances (it stops at one skin from afar, and
//! never closer than half the gap it starts with).

// Casts between Real and f64 are no-ops in the default build but needed in the f32 one.
#![allow(clippy::unnecessary_cast)]

mod common;
use common::*;
use tumble::prelude::*;
use tumble::{CharacterController, CharacterDef, TriMesh};

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
}

impl Walker {
    fn new() -> Walker {
        Walker { fall: Vec3::ZERO }
    }

    fn step(&mut self, c: &mut CharacterController, w: &mut World, velocity: Vec3, dt: Real) {
        if c.on_ground() {
            self.fall = Vec3::ZERO;
        } else {
            self.fall += Vec3::new(0.0, -G, 0.0) * dt;
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
            gap >= 0.4 * SKIN && gap <= 1.1 * SKIN,
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
                    assert!(gap >= 0.4 * SKIN && gap <= 1.1 * SKIN, "{case}");
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
            touching = (gap - SKIN).abs() < 1e-6;
            if touching && arrived {
                sliding += 1;
                let e = (c.velocity() - tangential).length();
                assert!(e <= tol(1e-9, 1e-4), "r {r} dt {dt}: {}", c.velocity());
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
