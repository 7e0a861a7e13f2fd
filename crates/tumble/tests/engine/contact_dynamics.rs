//! Contact dynamics measured against physics: bounces, friction on slopes, resting,
//! stacking, mass ratios, isotropy, momentum transfer, tunnelling, determinism, scale.

// Casts between Real and f64 are no-ops in the default build but needed in the f32 one.
#![allow(clippy::unnecessary_cast)]

use crate::common::*;
use tumble::prelude::*;

const G: Real = 9.8;

fn scene(sleep: bool, dt_substeps: u32) -> World {
    World::new(&WorldDef {
        sleep,
        solver: SolverSettings {
            substeps: dt_substeps,
            ..Default::default()
        },
        ..Default::default()
    })
}

fn ground_plane(w: &mut World, normal: Vec3, friction: Real, restitution: Real) -> BodyId {
    w.create_body(
        &BodyDef {
            kind: BodyKind::Static,
            friction,
            restitution,
            ..Default::default()
        },
        Shape::plane(normal, 0.0),
    )
    .unwrap()
}

fn dynamic(w: &mut World, def: BodyDef, shape: Shape) -> BodyId {
    w.create_body(&def, shape).unwrap()
}

#[test]
fn a_dropped_ball_rebounds_to_e_squared_of_its_height() {
    // Dropped from 1 m (bottom of the ball above the plane). The rebound height is read
    // from the energy in free flight just after the bounce, y + v²/2g: the highest
    // sampled y would undershoot the continuous apex by about v·dt/2 of sampling alone.
    for e in [0.0, 0.5, 0.9] {
        let mut w = scene(false, 4);
        ground_plane(&mut w, Vec3::Y, 0.5, e);
        let r = 0.1;
        let ball = dynamic(
            &mut w,
            BodyDef {
                position: Vec3::new(0.0, 1.0 + r, 0.0),
                restitution: e,
                ..Default::default()
            },
            Shape::sphere(r),
        );
        let dt = 1.0 / 240.0;
        let mut rebound: Option<Real> = None;
        let mut highest: Real = 0.0;
        let mut bounced = false;
        for _ in 0..(3.0 / dt) as usize {
            w.step(dt).unwrap();
            let b = w.body(ball).unwrap();
            let (y, v) = (b.position().y - r, b.linear_velocity().y);
            bounced |= v > 0.0;
            if bounced {
                highest = highest.max(y);
                if rebound.is_none() && v > 0.0 && y > 0.05 {
                    rebound = Some(y + v * v / (2.0 * G));
                }
            }
        }
        if e == 0.0 {
            // No bounce, and resting without jitter: it settles and stays.
            assert!(highest < 1e-3, "e = 0 bounced to {highest}");
            for _ in 0..240 {
                w.step(dt).unwrap();
                let b = w.body(ball).unwrap();
                assert!(
                    b.linear_velocity().length() < 1e-3,
                    "jitter: {:?}",
                    b.linear_velocity()
                );
                assert!((b.position().y - r).abs() < 2e-3);
            }
        } else {
            let h = rebound.expect("never left the ground");
            assert!(
                (h - e * e).abs() < 0.02 * e * e,
                "e = {e}: rebound {h} vs {}",
                e * e
            );
        }
    }
}

fn incline(angle: Real, mu: Real) -> (World, BodyId, Vec3) {
    let mut w = scene(false, 4);
    let n = Vec3::new(-angle.sin(), angle.cos(), 0.0);
    ground_plane(&mut w, n, mu, 0.0);
    let q = Quat::from_rotation_z(angle);
    let b = dynamic(
        &mut w,
        BodyDef {
            position: n * 0.25,
            orientation: q,
            friction: mu,
            ..Default::default()
        },
        Shape::cuboid(Vec3::new(0.5, 0.25, 0.5)),
    );
    // Down the slope: the plane's x axis rotated by the angle, pointing downhill.
    let down = Vec3::new(-angle.cos(), -angle.sin(), 0.0);
    (w, b, down)
}

#[test]
fn a_box_on_an_incline_sticks_or_slides_as_coulomb_says() {
    let mu = 0.5;
    // tan 20° = 0.36 < μ: it stays put.
    let (mut w, b, _) = incline((20.0 as Real).to_radians(), mu);
    run(&mut w, 1.0 / 60.0, 30);
    let start = w.body(b).unwrap().position();
    run(&mut w, 1.0 / 60.0, 120);
    let moved = (w.body(b).unwrap().position() - start).length();
    // Soft contacts let a sticking box creep a little; f32 rounding of the friction
    // impulses about doubles it (measured 1.3 mm in f32).
    assert!(moved < tol(1e-3, 2e-3), "stuck box crept {moved} m");
    // tan 35° = 0.70 > μ: it slides with a = g (sin θ − μ cos θ).
    let theta = (35.0 as Real).to_radians();
    let (mut w, b, down) = incline(theta, mu);
    run(&mut w, 1.0 / 60.0, 30);
    let v0 = w.body(b).unwrap().linear_velocity().dot(down);
    run(&mut w, 1.0 / 60.0, 60);
    let v1 = w.body(b).unwrap().linear_velocity().dot(down);
    let a = (v1 - v0) / 1.0;
    let expect = G * (theta.sin() - mu * theta.cos());
    assert!(
        (a - expect).abs() < 0.02 * expect,
        "a = {a}, expected {expect}"
    );
}

#[test]
fn a_resting_box_is_still_and_falls_asleep() {
    let mut w = scene(true, 4);
    ground_plane(&mut w, Vec3::Y, 0.6, 0.0);
    let b = dynamic(
        &mut w,
        BodyDef {
            position: Vec3::new(0.0, 0.5, 0.0),
            ..Default::default()
        },
        Shape::cuboid(Vec3::splat(0.5)),
    );
    let mut asleep_at = None;
    for k in 0..240 {
        w.step(1.0 / 60.0).unwrap();
        let body = w.body(b).unwrap();
        assert!(
            body.linear_velocity().length() < 1e-3,
            "step {k}: {:?}",
            body.linear_velocity()
        );
        if !body.is_awake() && asleep_at.is_none() {
            asleep_at = Some(k);
        }
    }
    let k = asleep_at.expect("never fell asleep");
    assert!(k as Real / 60.0 <= 2.0, "asleep only after {k} steps");
    // A push wakes it.
    w.apply_impulse(
        b,
        Vec3::new(500.0, 0.0, 0.0),
        w.body(b).unwrap().center_of_mass(),
    )
    .unwrap();
    assert!(w.body(b).unwrap().is_awake());
}

fn box_stack(w: &mut World, n: usize) -> Vec<BodyId> {
    (0..n)
        .map(|i| {
            dynamic(
                w,
                BodyDef {
                    position: Vec3::new(0.0, 0.5 + i as Real, 0.0),
                    friction: 0.5,
                    ..Default::default()
                },
                Shape::cuboid(Vec3::splat(0.5)),
            )
        })
        .collect()
}

fn pyramid(w: &mut World, base: usize) -> Vec<BodyId> {
    let mut ids = Vec::new();
    for layer in 0..base {
        let m = base - layer;
        let offset = (base - m) as Real * 0.5 - base as Real * 0.5;
        for i in 0..m {
            for k in 0..m {
                let p = Vec3::new(i as Real + offset, 0.5 + layer as Real, k as Real + offset);
                ids.push(dynamic(
                    w,
                    BodyDef {
                        position: p,
                        friction: 0.5,
                        ..Default::default()
                    },
                    Shape::cuboid(Vec3::splat(0.5)),
                ));
            }
        }
    }
    ids
}

/// Largest displacement of any body over `seconds` after one second of settling.
fn drift(w: &mut World, ids: &[BodyId], seconds: Real) -> Real {
    run(w, 1.0 / 60.0, 60);
    let settled: Vec<Vec3> = ids.iter().map(|i| w.body(*i).unwrap().position()).collect();
    run(w, 1.0 / 60.0, (seconds * 60.0) as usize);
    ids.iter()
        .zip(&settled)
        .map(|(i, s)| (w.body(*i).unwrap().position() - *s).length())
        .fold(0.0, Real::max)
}

#[test]
fn a_stack_of_twenty_boxes_stands_with_and_without_sleeping() {
    // A 20-box tower on soft contacts is near its buckling load (see docs/integrators.md).
    // In f32 the rounding noise keeps it swaying: measured drift 3.0 / 2.2 / 1.2 / 0.7 cm
    // with 1 / 2 / 3 / 4 iterations per substep, against 2.2 mm with 1 in f64. The f32
    // build therefore uses 4, and this is a known weakness of single precision here.
    let iterations = if single_precision() { 4 } else { 1 };
    for sleep in [false, true] {
        let mut w = scene(sleep, 4);
        let mut settings = w.solver_settings();
        settings.iterations = iterations;
        w.set_solver_settings(settings).unwrap();
        ground_plane(&mut w, Vec3::Y, 0.5, 0.0);
        let ids = box_stack(&mut w, 20);
        let d = drift(&mut w, &ids, 10.0);
        assert!(d < 0.01, "sleep {sleep}: drift {d} m");
    }
}

#[test]
fn a_pyramid_of_385_boxes_stands_with_and_without_sleeping() {
    for sleep in [false, true] {
        let mut w = scene(sleep, 4);
        ground_plane(&mut w, Vec3::Y, 0.5, 0.0);
        let ids = pyramid(&mut w, 10);
        assert_eq!(ids.len(), 385);
        let d = drift(&mut w, &ids, 10.0);
        assert!(d < 0.01, "sleep {sleep}: drift {d} m");
    }
}

#[test]
fn friction_is_isotropic() {
    // A box given 3 m/s along headings all round the circle slides v²/(2μg) each time.
    let mut distances = Vec::new();
    for k in 0..12 {
        let heading = k as Real * 30.0_f64.to_radians() as Real + 0.1;
        let mut w = scene(false, 4);
        ground_plane(&mut w, Vec3::Y, 0.5, 0.0);
        let dir = Vec3::new(heading.cos(), 0.0, heading.sin());
        let b = dynamic(
            &mut w,
            BodyDef {
                position: Vec3::new(0.0, 0.25, 0.0),
                linear_velocity: dir * 3.0,
                friction: 0.5,
                ..Default::default()
            },
            Shape::cuboid(Vec3::new(0.25, 0.25, 0.25)),
        );
        run(&mut w, 1.0 / 60.0, 120);
        distances.push(w.body(b).unwrap().position().length());
    }
    let mean = distances.iter().sum::<Real>() / distances.len() as Real;
    for d in &distances {
        assert!((d - mean).abs() < 0.005 * mean, "distances {distances:?}");
    }
    let expect = 9.0 / (2.0 * 0.5 * G);
    assert!(
        (mean - expect).abs() < 0.05 * expect,
        "slid {mean} m, Coulomb says {expect}"
    );
}

/// Plates of `half` × `thick` × `half` (half extents): a box, the same as a hull, a coin.
fn plates(half: Real, thick: Real) -> [Shape; 3] {
    let corners: Vec<Vec3> = (0..8)
        .map(|k| {
            let s = |bit: usize| if k & bit != 0 { 1.0 } else { -1.0 };
            Vec3::new(s(1) * half, s(2) * thick, s(4) * half)
        })
        .collect();
    [
        Shape::cuboid(Vec3::new(half, thick, half)),
        Shape::convex_hull(&corners).unwrap(),
        Shape::cylinder(half, thick),
    ]
}

#[test]
fn a_thin_plate_pushed_along_the_floor_stays_flat_and_slides_as_coulomb_says() {
    // Plates thinner than the speculative margin have their top corners within it. The
    // manifold's four points must still be the bottom ones: with a top corner in a bottom
    // corner's place, a 1.8 cm plate pushed at 0.5 m/s rocked onto the missing corner, sank
    // 16 mm into the floor and spun at 10 rad/s. Held flat, it slides with deceleration μg
    // (v = v₀ − μ g t until it stops, exact per step but for the soft contact's give),
    // sinks no more than the soft contact's fraction of a millimetre, and barely turns.
    let mu = 0.3;
    let mut worst = (0.0 as Real, 0.0 as Real, 0.0 as Real);
    for (thick, half) in [(0.001, 0.01), (0.004, 0.05), (0.009, 0.0189), (0.009, 0.3)] {
        for on_box in [false, true] {
            for (dt, v0) in [(1.0 / 60.0, 2.0), (1.0 / 120.0, 0.5)] {
                for (k, plate) in plates(half, thick).into_iter().enumerate() {
                    let mut w = scene(false, 4);
                    if on_box {
                        let def = BodyDef {
                            kind: BodyKind::Static,
                            position: Vec3::new(0.0, -0.5, 0.0),
                            friction: mu,
                            ..Default::default()
                        };
                        dynamic(&mut w, def, Shape::cuboid(Vec3::new(5.0, 0.5, 5.0)));
                    } else {
                        ground_plane(&mut w, Vec3::Y, mu, 0.0);
                    }
                    let def = BodyDef {
                        position: Vec3::new(0.0, thick, 0.0),
                        linear_velocity: Vec3::new(v0, 0.0, 0.0),
                        friction: mu,
                        ..Default::default()
                    };
                    let b = dynamic(&mut w, def, plate);
                    let (mut spin, mut sink) = (0.0 as Real, 0.0 as Real);
                    let steps = (0.8 / dt) as usize;
                    for _ in 0..steps {
                        w.step(dt).unwrap();
                        let body = w.body(b).unwrap();
                        spin = spin.max(body.angular_velocity().length());
                        sink = sink.max(thick - body.position().y);
                    }
                    let v = w.body(b).unwrap().linear_velocity().x;
                    let expect = (v0 - mu * G * steps as Real * dt).max(0.0);
                    let case = format!("shape {k}, {thick} × {half}, box floor {on_box}, dt {dt}");
                    assert!(
                        (v - expect).abs() < 0.02,
                        "{case}: v {v}, Coulomb says {expect}"
                    );
                    assert!(spin < 0.5, "{case}: turned at up to {spin} rad/s");
                    assert!(sink < 5e-4, "{case}: sank {sink} m");
                    worst = (
                        worst.0.max((v - expect).abs()),
                        worst.1.max(spin),
                        worst.2.max(sink),
                    );
                }
            }
        }
    }
    eprintln!("worst |v − v_Coulomb|, spin, sink: {worst:?}");
}

#[test]
fn a_fast_small_ball_does_not_tunnel_through_a_thin_wall() {
    let mut w = World::new(&WorldDef {
        gravity: Vec3::ZERO,
        ..Default::default()
    });
    let wall = w
        .create_body(
            &BodyDef {
                kind: BodyKind::Static,
                position: Vec3::new(5.0, 0.0, 0.0),
                ..Default::default()
            },
            Shape::cuboid(Vec3::new(0.05, 2.0, 2.0)),
        )
        .unwrap();
    let ball = dynamic(
        &mut w,
        BodyDef {
            linear_velocity: Vec3::new(200.0, 0.0, 0.0),
            ..Default::default()
        },
        Shape::sphere(0.05),
    );
    for _ in 0..60 {
        w.step(1.0 / 60.0).unwrap();
        assert!(
            w.body(ball).unwrap().position().x < 5.0,
            "tunnelled to {:?}",
            w.body(ball).unwrap().position()
        );
    }
    let _ = wall;
}

#[test]
fn identical_piles_give_identical_bits() {
    let run_pile = || {
        let mut w = scene(true, 4);
        ground_plane(&mut w, Vec3::Y, 0.5, 0.0);
        for i in 0..1000 {
            let p = Vec3::new(
                (i % 10) as Real * 0.6 - 3.0,
                0.5 + (i / 100) as Real * 0.6,
                ((i / 10) % 10) as Real * 0.6 - 3.0,
            );
            let shape = if i % 2 == 0 {
                Shape::sphere(0.25)
            } else {
                Shape::cuboid(Vec3::splat(0.25))
            };
            dynamic(
                &mut w,
                BodyDef {
                    position: p,
                    orientation: Quat::from_rotation_y(i as Real * 0.1),
                    ..Default::default()
                },
                shape,
            );
        }
        run(&mut w, 1.0 / 60.0, 60);
        w.state_hash()
    };
    assert_eq!(run_pile(), run_pile());
}

#[test]
fn a_scene_in_centimetres_behaves_like_the_same_scene_in_metres() {
    let drop = |unit: Real| {
        let mut w = World::new(&WorldDef {
            gravity: Vec3::new(0.0, -G * unit, 0.0),
            length_unit: unit,
            sleep: false,
            ..Default::default()
        });
        w.create_body(
            &BodyDef {
                kind: BodyKind::Static,
                ..Default::default()
            },
            Shape::plane(Vec3::Y, 0.0),
        )
        .unwrap();
        let b = dynamic(
            &mut w,
            BodyDef {
                position: Vec3::new(0.0, 2.0 * unit, 0.0),
                angular_velocity: Vec3::new(0.0, 0.0, 3.0),
                mass: MassSpec::Mass(1.0),
                ..Default::default()
            },
            Shape::cuboid(Vec3::splat(0.5 * unit)),
        );
        run(&mut w, 1.0 / 60.0, 120);
        w.body(b).unwrap().position() / unit
    };
    let (m, cm) = (drop(1.0), drop(100.0));
    assert!((m - cm).length() < tol(1e-6, 1e-3), "{m} vs {cm}");
}

#[test]
fn contact_events_and_impulses_are_reported() {
    let mut w = scene(false, 4);
    let g = ground_plane(&mut w, Vec3::Y, 0.5, 0.0);
    let b = dynamic(
        &mut w,
        BodyDef {
            position: Vec3::new(0.0, 0.6, 0.0),
            ..Default::default()
        },
        Shape::cuboid(Vec3::splat(0.5)),
    );
    let mut began = None;
    for k in 0..60 {
        w.step(1.0 / 60.0).unwrap();
        if w.contact_events()
            .iter()
            .any(|e| e.kind == tumble::ContactEventKind::Begin && (e.body_a, e.body_b) == (g, b))
        {
            began.get_or_insert(k);
        }
    }
    assert!(began.is_some(), "no begin event");
    // At rest the normal impulses over a step carry the weight: Σ λ = m g dt.
    let weight = w.body(b).unwrap().mass() * G / 60.0;
    let total: Real = w
        .contacts()
        .iter()
        .flat_map(|c| c.manifold.points())
        .map(|p| p.total_normal_impulse)
        .sum();
    assert!(
        (total - weight).abs() < 1e-3 * weight,
        "{total} vs {weight}"
    );
    w.remove_body(g).unwrap();
    assert!(w
        .contact_events()
        .iter()
        .any(|e| e.kind == tumble::ContactEventKind::End && e.body_b == b));
}

#[test]
fn a_sleeping_island_wakes_when_its_support_goes_or_something_hits_it() {
    let mut w = scene(true, 4);
    let g = ground_plane(&mut w, Vec3::Y, 0.5, 0.0);
    let ids = box_stack(&mut w, 3);
    run(&mut w, 1.0 / 60.0, 180);
    assert!(
        ids.iter().all(|i| !w.body(*i).unwrap().is_awake()),
        "stack did not sleep"
    );
    // A ball dropped on it wakes the whole island.
    let ball = dynamic(
        &mut w,
        BodyDef {
            position: Vec3::new(0.0, 3.6, 0.0),
            ..Default::default()
        },
        Shape::sphere(0.1),
    );
    run(&mut w, 1.0 / 60.0, 20);
    assert!(
        ids.iter().all(|i| w.body(*i).unwrap().is_awake()),
        "touch did not wake the island"
    );
    run(&mut w, 1.0 / 60.0, 240);
    assert!(!w.body(ball).unwrap().is_awake());
    // Removing the ground wakes everything on it, and it falls.
    w.remove_body(g).unwrap();
    assert!(ids.iter().all(|i| w.body(*i).unwrap().is_awake()));
    run(&mut w, 1.0 / 60.0, 30);
    assert!(w.body(ids[0]).unwrap().position().y < 0.0);
}

#[test]
fn a_box_slides_over_a_floor_of_adjoining_boxes_without_catching_on_the_seams() {
    // Twelve unit boxes side by side make the floor; a 0.5 m box slides across six seams.
    // Either creation order (the floor's boxes as body A or as body B of the pairs).
    for floor_first in [true, false] {
        for mu in [0.0, 0.3] {
            let mut w = scene(false, 4);
            let floor = |w: &mut World| {
                for i in 0..12 {
                    let def = BodyDef {
                        kind: BodyKind::Static,
                        position: Vec3::new(i as Real - 5.5, -0.5, 0.0),
                        friction: mu,
                        ..Default::default()
                    };
                    w.create_body(&def, Shape::cuboid(Vec3::splat(0.5)))
                        .unwrap();
                }
            };
            if floor_first {
                floor(&mut w);
            }
            let def = BodyDef {
                position: Vec3::new(-5.0, 0.25, 0.0),
                linear_velocity: Vec3::new(4.0, 0.0, 0.0),
                friction: mu,
                ..Default::default()
            };
            let b = dynamic(&mut w, def, Shape::cuboid(Vec3::splat(0.25)));
            if !floor_first {
                floor(&mut w);
            }
            let mut worst_vy: Real = 0.0;
            for _ in 0..120 {
                w.step(1.0 / 60.0).unwrap();
                worst_vy = worst_vy.max(w.body(b).unwrap().linear_velocity().y.abs());
            }
            assert!(
                worst_vy < 1e-2,
                "floor first {floor_first}, μ {mu}: hopped at {worst_vy} m/s"
            );
            let x = w.body(b).unwrap().position().x;
            // Frictionless: 4 m/s for 2 s; with friction: v²/(2μg) of sliding, as on one box.
            let expect = if mu == 0.0 {
                3.0
            } else {
                -5.0 + 16.0 / (2.0 * mu * G)
            };
            assert!(
                (x - expect).abs() < 0.02 * (expect + 5.0),
                "floor first {floor_first}, μ {mu}: ended at {x}, expected {expect}"
            );
        }
    }
}

/// Deepest penetration between two given bodies in the current contacts (m, ≥ 0).
fn penetration(w: &World, x: BodyId, y: BodyId) -> Real {
    w.contacts()
        .iter()
        .filter(|c| (c.body_a, c.body_b) == (x, y) || (c.body_a, c.body_b) == (y, x))
        .flat_map(|c| c.manifold.points().iter().map(|p| -p.separation))
        .fold(0.0, Real::max)
}

#[test]
fn a_heavy_box_on_a_light_one_neither_sinks_nor_explodes() {
    // A soft contact is a spring of stiffness m_eff·ω² with m_eff about the light body's
    // mass, so a load M·g sinks it by about (M/m)·g/ω²: 7 mm at 1:100 with the default
    // 60 Hz, 7 cm at 1:1000. Gauss–Seidel also carries a heavy body's weight through a light
    // one only in proportion to their mass ratio per pass: with one pass per substep a
    // 1:1000 pair sank 30 cm and slid apart at 11 m/s, so islands with such ratios get
    // stiffened contacts and four or six times the passes (solver/mass_ratio.rs). All at
    // the default settings. Measured: 1:100 3.5 mm deep and still (0.4 mm/s and 7 mm with
    // unstiffened contacts and two passes), 1:1000 3.5 cm deep and at 3.1 mm/s a second
    // after landing (7 cm and 3.5 cm/s with three).
    for (ratio, sink, calm) in [(100.0, 0.005, 0.001), (1000.0, 0.05, 0.01)] {
        let mut w = scene(false, 4);
        let ground = ground_plane(&mut w, Vec3::Y, 0.5, 0.0);
        let boxed = |y: Real, mass: Real| BodyDef {
            position: Vec3::new(0.0, y, 0.0),
            mass: MassSpec::Mass(mass),
            friction: 0.5,
            ..Default::default()
        };
        let light = dynamic(&mut w, boxed(0.5, 1.0), Shape::cuboid(Vec3::splat(0.5)));
        let heavy = dynamic(&mut w, boxed(1.5, ratio), Shape::cuboid(Vec3::splat(0.5)));
        let (mut deepest, mut fastest): (Real, Real) = (0.0, 0.0);
        for i in 0..600 {
            w.step(1.0 / 60.0).unwrap();
            if i < 60 {
                continue;
            }
            deepest = deepest
                .max(penetration(&w, light, heavy))
                .max(penetration(&w, ground, light));
            for id in [light, heavy] {
                fastest = fastest.max(w.body(id).unwrap().linear_velocity().length());
            }
        }
        let top = w.body(heavy).unwrap().position();
        assert!(deepest < sink, "1:{ratio}: penetration {deepest} m");
        assert!(fastest < calm, "1:{ratio}: speed {fastest} m/s");
        assert!(
            top.x.abs() < 0.01 && top.z.abs() < 0.01 && top.y > 1.5 - 2.0 * sink,
            "1:{ratio}: heavy box moved to {top:?}"
        );
    }
}

#[test]
fn a_newtons_cradle_passes_the_momentum_to_the_last_ball() {
    // Five equal balls in a row in free space, e = 1, the first striking the four others,
    // which touch at rest: a chain of binary elastic collisions hands the whole velocity
    // to the last ball. Both when the first ball arrives from a gap and when it starts
    // touching the row. Measured: exact to 1e-4 m/s (it was −0.72, 0.64, 0.64, 0.72,
    // 0.72 m/s before bounces were replayed as a chain of impacts).
    for gap in [0.1, 0.0] {
        let mut w = scene(false, 4);
        w.set_gravity(Vec3::ZERO).unwrap();
        let r = 0.1;
        let speed = 2.0;
        let balls: Vec<BodyId> = (0..5)
            .map(|i| {
                let x = if i == 0 { -gap } else { 2.0 * r * i as Real };
                dynamic(
                    &mut w,
                    BodyDef {
                        position: Vec3::new(x, 0.0, 0.0),
                        linear_velocity: Vec3::X * if i == 0 { speed } else { 0.0 },
                        restitution: 1.0,
                        friction: 0.0,
                        ..Default::default()
                    },
                    Shape::sphere(r),
                )
            })
            .collect();
        run(&mut w, 1.0 / 60.0, 60);
        let v: Vec<Vec3> = balls
            .iter()
            .map(|b| w.body(*b).unwrap().linear_velocity())
            .collect();
        for (i, vi) in v.iter().enumerate().take(4) {
            assert!(vi.length() < 0.01 * speed, "gap {gap}: ball {i} kept {vi}");
        }
        assert!(
            (v[4] - Vec3::X * speed).length() < 0.01 * speed,
            "gap {gap}: last ball {}",
            v[4]
        );
    }
}

#[test]
fn a_ball_passing_close_to_an_edge_or_a_ledge_is_not_deflected() {
    // Speculative contacts take the contact plane as flat: near an edge, a fast body whose
    // path clears the edge by millimetres looks as if it will hit it within the step, and
    // a naive solver stops it there (a ghost collision). Zero gravity, a static unit box,
    // and a 0.1 m ball on straight lines that miss the box by `clearance`, at various
    // speeds and headings: the ball must come out with the velocity it went in with.
    let clearance = 0.005;
    let r = 0.1;
    for speed in [2.0, 10.0, 30.0] {
        for heading in [0.0 as Real, 0.3, 0.7, 1.2] {
            let mut w = World::new(&WorldDef {
                gravity: Vec3::ZERO,
                ..Default::default()
            });
            w.create_body(
                &BodyDef {
                    kind: BodyKind::Static,
                    ..Default::default()
                },
                Shape::cuboid(Vec3::splat(0.5)),
            )
            .unwrap();
            // A line through the point at distance r + clearance from the box's top
            // front edge (the edge along z at x = 0.5, y = 0.5), in the xy plane.
            let dir = Vec3::new(heading.cos(), -heading.sin(), 0.0);
            let outward = Vec3::new(dir.y, -dir.x, 0.0) * -1.0; // left of dir: away from the box
            let closest = Vec3::new(0.5, 0.5, 0.0) + outward * (r + clearance);
            let v0 = dir * speed;
            let ball = dynamic(
                &mut w,
                BodyDef {
                    position: closest - dir * 2.0,
                    linear_velocity: v0,
                    friction: 0.5,
                    ..Default::default()
                },
                Shape::sphere(r),
            );
            let steps = (4.0 / speed * 60.0) as usize + 1;
            run(&mut w, 1.0 / 60.0, steps);
            let v = w.body(ball).unwrap().linear_velocity();
            assert!(
                (v - v0).length() < 1e-6 * speed,
                "speed {speed}, heading {heading}: left with {v} (came with {v0})"
            );
        }
    }
}

#[test]
fn extra_passes_for_a_heavy_pair_leave_other_islands_untouched() {
    // Islands with a large mass ratio get more solver passes (solver/mass_ratio.rs); a
    // tower elsewhere in the world must move exactly as it does alone, to the last bit.
    let tower = |with_heavy_pair: bool| {
        let mut w = scene(false, 4);
        ground_plane(&mut w, Vec3::Y, 0.5, 0.0);
        let ids = box_stack(&mut w, 5);
        if with_heavy_pair {
            for (y, mass) in [(0.5, 1.0), (1.5, 1000.0)] {
                let def = BodyDef {
                    position: Vec3::new(10.0, y, 0.0),
                    mass: MassSpec::Mass(mass),
                    ..Default::default()
                };
                dynamic(&mut w, def, Shape::cuboid(Vec3::splat(0.5)));
            }
        }
        // A push, so that the tower does something worth comparing.
        w.apply_impulse(ids[4], Vec3::new(0.5, 0.0, 0.2), Vec3::new(0.0, 4.6, 0.3))
            .unwrap();
        run(&mut w, 1.0 / 60.0, 120);
        ids.iter()
            .map(|id| {
                let b = w.body(*id).unwrap();
                (b.position(), b.orientation())
            })
            .collect::<Vec<_>>()
    };
    assert_eq!(tower(false), tower(true));
}
