//! Linear and angular damping against their closed forms: dv/dt = −c v and dL/dt = −c L
//! besides the forces, so a free body's v(t) = v₀ exp(−c t), its position
//! x(t) = x₀ + v₀ (1 − exp(−c t)) / c, and a body falling from rest under gravity
//! v(t) = −(g/c)(1 − exp(−c t)), tending to the terminal speed g/c.
//!
//! The engine solves the damping exactly, v × exp(−c dt/2) on each side of each step (free
//! bodies, every integrator) or substep kick (bodies in contact): see
//! `dynamics/integrate/mod.rs`, `damp_half`.

// Casts between Real and f64 are no-ops in the default build but needed in the f32 one.
#![allow(clippy::unnecessary_cast)]

use crate::common::*;
use tumble::prelude::*;

const G: Real = 9.8;
const RATES: [Real; 3] = [0.1, 1.0, 5.0];
const STEPS: [Real; 2] = [1.0 / 60.0, 1.0 / 240.0];

/// A free body with damping `c` (both), in a world with gravity `g` and `integrator`.
fn damped(integrator: Integrator, g: Real, c: Real, def: BodyDef, shape: Shape) -> (World, BodyId) {
    let mut w = World::new(&WorldDef {
        gravity: Vec3::new(0.0, -g, 0.0),
        integrator,
        sleep: false,
        ..Default::default()
    });
    let def = BodyDef {
        linear_damping: c,
        angular_damping: c,
        ..def
    };
    let id = w.create_body(&def, shape).unwrap();
    (w, id)
}

/// The relative error allowed after `n` steps: the decay is exact per step, so only
/// rounding accumulates, about one ulp per step (64 ulps a step leaves room); never looser
/// than the 0.5 %, which the f32 build's 7,200 steps would otherwise pass.
fn rounding(n: usize) -> Real {
    (n as Real * 64.0 * Real::EPSILON).min(0.005)
}

/// v, ω (a ball: ω = L / I, whatever the orientation) and the position of a free damped
/// body, every integrator, c ∈ {0.1, 1, 5} /s, dt ∈ {1/60, 1/240} s, over three time
/// constants; its spin about a tilted axis, so that the orientation moves too.
#[test]
fn free_body_decays_as_exp_minus_ct_with_every_integrator() {
    let (v0, w0) = (Vec3::new(3.0, -2.0, 1.0), Vec3::new(1.0, 2.0, -0.5));
    for integrator in Integrator::ALL {
        for c in RATES {
            for dt in STEPS {
                let def = BodyDef {
                    mass: MassSpec::Mass(2.0),
                    linear_velocity: v0,
                    angular_velocity: w0,
                    ..Default::default()
                };
                let (mut w, id) = damped(integrator, 0.0, c, def, Shape::sphere(0.3));
                let n = (3.0 / (c * dt)).round() as usize;
                run(&mut w, dt, n);
                let t = n as Real * dt;
                let decay = (-c * t).exp();
                let b = w.body(id).unwrap();
                let what = format!("{} c = {c} dt = {dt}", integrator.name());
                let v_err = (b.linear_velocity() - v0 * decay).length() / (v0.length() * decay);
                let w_err = (b.angular_velocity() - w0 * decay).length() / (w0.length() * decay);
                assert!(v_err < rounding(n), "{what}: v off by {v_err}");
                assert!(w_err < rounding(n), "{what}: ω off by {w_err}");
                // The position integrates the damped velocity; the split puts each step's
                // drift at the mid-step velocity, the midpoint rule for ∫ v₀ e^(−ct) dt,
                // off by (c dt)²/24 relative: 3e-4 at c dt = 1/12. Allowed 0.1 %.
                let travel = v0 * (1.0 - decay) / c;
                let x_err = (b.position() - travel).length() / travel.length();
                assert!(x_err < 1e-3, "{what}: position off by {x_err}");
            }
        }
    }
}

/// A box's angular momentum decays as exp(−c t) however it tumbles (torque-free, L only
/// decays; ω = I_world⁻¹ L turns with the orientation, so |L| is what has a closed form).
#[test]
fn tumbling_box_angular_momentum_decays_as_exp_minus_ct() {
    for integrator in Integrator::ALL {
        for (c, dt) in [(1.0, 1.0 / 60.0), (5.0, 1.0 / 240.0)] {
            let def = BodyDef {
                mass: MassSpec::Mass(1.5),
                angular_velocity: Vec3::new(0.2, 4.0, 0.3),
                ..Default::default()
            };
            let shape = Shape::cuboid(Vec3::new(0.5, 0.3, 0.1));
            let (mut w, id) = damped(integrator, 0.0, c, def, shape);
            let l0 = w.body(id).unwrap().angular_momentum();
            let n = (3.0 / (c * dt)).round() as usize;
            run(&mut w, dt, n);
            let expected = l0 * (-c * n as Real * dt).exp();
            let l = w.body(id).unwrap().angular_momentum();
            let err = (l - expected).length() / expected.length();
            assert!(
                err < rounding(n),
                "{} c = {c}: L off by {err}",
                integrator.name()
            );
        }
    }
}

/// Falling from rest under gravity: v(t) = −(g/c)(1 − e^(−ct)) at every step's end,
/// reaching g/c. The splitting's steady state is (g/c)(c dt/2)/sinh(c dt/2), within
/// (c dt)²/24 = 0.03 % of g/c at c dt = 1/12; checked within 0.5 % of g/c all the way.
#[test]
fn falling_body_reaches_the_terminal_speed_g_over_c() {
    for integrator in Integrator::ALL {
        for c in [1.0, 5.0] {
            for dt in STEPS {
                let def = BodyDef {
                    mass: MassSpec::Mass(0.7),
                    position: Vec3::new(0.0, 1000.0, 0.0),
                    ..Default::default()
                };
                let (mut w, id) = damped(integrator, G, c, def, Shape::sphere(0.1));
                let terminal = G / c;
                let n = (8.0 / (c * dt)).round() as usize;
                for k in 1..=n {
                    w.step(dt).unwrap();
                    let t = k as Real * dt;
                    let v = w.body(id).unwrap().linear_velocity().y;
                    let expected = -terminal * (1.0 - (-c * t).exp());
                    let err = (v - expected).abs() / terminal;
                    assert!(
                        err < 0.005,
                        "{} c = {c} dt = {dt} t = {t}: v = {v}, expected {expected}",
                        integrator.name()
                    );
                }
                let v = w.body(id).unwrap().linear_velocity().y;
                assert!(
                    ((v + terminal) / terminal).abs() < 1e-3,
                    "{}: terminal {v}, expected {}",
                    integrator.name(),
                    -terminal
                );
            }
        }
    }
}

/// In contact, through the solver's substeps: a box sliding on frictionless ground slows
/// as exp(−c t) (the ground pushes only along the normal), and a ball spinning about the
/// normal (no torsional friction) spins down as exp(−c t).
#[test]
fn damping_in_contact_is_exp_minus_ct() {
    for (c, dt) in [(0.5, 1.0 / 60.0), (2.0, 1.0 / 240.0)] {
        let mut w = awake_on_ground(Vec3::new(0.0, -G, 0.0));
        let floor = w.body_ids()[0];
        w.set_friction(floor, 0.0).unwrap();
        let sliding = BodyDef {
            position: Vec3::new(0.0, 0.25, 0.0),
            linear_velocity: Vec3::new(2.0, 0.0, 0.0),
            linear_damping: c,
            friction: 0.0,
            ..Default::default()
        };
        let slider = w
            .create_body(&sliding, Shape::cuboid(Vec3::splat(0.25)))
            .unwrap();
        let spinning = BodyDef {
            position: Vec3::new(0.0, 0.2, 5.0),
            angular_velocity: Vec3::new(0.0, 6.0, 0.0),
            angular_damping: c,
            ..Default::default()
        };
        let spinner = w.create_body(&spinning, Shape::sphere(0.2)).unwrap();
        let n = (2.0 / (c * dt)).round() as usize;
        run(&mut w, dt, n);
        let decay = (-c * n as Real * dt).exp();
        // Exact per substep kick; the contacts add only rounding and the settling of a
        // body created touching the ground (its first steps' push is vertical). 0.5 %.
        let v = w.body(slider).unwrap().linear_velocity().x;
        assert!(
            ((v - 2.0 * decay) / (2.0 * decay)).abs() < 0.005,
            "c = {c}: slide {v} vs {}",
            2.0 * decay
        );
        let spin = w.body(spinner).unwrap().angular_velocity().y;
        assert!(
            ((spin - 6.0 * decay) / (6.0 * decay)).abs() < 0.005,
            "c = {c}: spin {spin} vs {}",
            6.0 * decay
        );
        assert!(
            w.contacts().len() >= 2,
            "both bodies should be on the ground"
        );
    }
}

/// Damping refused as the scene loader refuses it, and a set that fails changes nothing.
#[test]
fn bad_damping_is_refused_with_the_field_named() {
    let (mut w, id) = damped(
        Integrator::Rk4,
        G,
        0.0,
        BodyDef::default(),
        Shape::sphere(0.1),
    );
    let bad = BodyDef {
        linear_damping: -1.0,
        ..Default::default()
    };
    let e = w.create_body(&bad, Shape::sphere(0.1)).unwrap_err();
    assert_eq!(e.to_string(), "linear_damping: must be >= 0");
    let e = w.set_linear_damping(id, Real::NAN).unwrap_err();
    assert_eq!(e.to_string(), "linear_damping: must be a finite number");
    let e = w.set_angular_damping(id, -0.5).unwrap_err();
    assert_eq!(e.to_string(), "angular_damping: must be >= 0");
    let b = w.body(id).unwrap();
    assert_eq!((b.linear_damping(), b.angular_damping()), (0.0, 0.0));
    w.set_linear_damping(id, 2.0).unwrap();
    w.set_angular_damping(id, 3.0).unwrap();
    let b = w.body(id).unwrap();
    assert_eq!((b.linear_damping(), b.angular_damping()), (2.0, 3.0));
}

/// Set at run time, damping acts from the next step on: a ball in flight without gravity
/// keeps its speed exactly, then decays as exp(−c t) from the edit.
#[test]
fn damping_set_at_run_time_acts_from_the_next_step() {
    let dt = 1.0 / 120.0;
    let def = BodyDef {
        linear_velocity: Vec3::new(4.0, 0.0, 0.0),
        ..Default::default()
    };
    let (mut w, id) = damped(
        Integrator::VelocityVerlet,
        0.0,
        0.0,
        def,
        Shape::sphere(0.1),
    );
    run(&mut w, dt, 60);
    assert_eq!(w.body(id).unwrap().linear_velocity().x, 4.0);
    w.set_linear_damping(id, 1.5).unwrap();
    run(&mut w, dt, 120);
    let v = w.body(id).unwrap().linear_velocity().x;
    let expected = 4.0 * (-1.5 as Real).exp();
    assert!(
        ((v - expected) / expected).abs() < rounding(120),
        "{v} vs {expected}"
    );
}
