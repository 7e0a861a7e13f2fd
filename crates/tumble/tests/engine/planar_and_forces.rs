//! The seed's 2D angular dynamics on planar bodies, and the force elements: springs
//! between bodies, forces at points, drag, callbacks.

// Casts between Real and f64 are no-ops in the default build but needed in the f32 one.
#![allow(clippy::unnecessary_cast)]

use crate::common::*;
use tumble::prelude::*;

fn planar_box(w: &mut World, torque: Vec3, force: Vec3) -> BodyId {
    let id = w
        .create_body(
            &BodyDef {
                planar: true,
                mass: MassSpec::Mass(3.0),
                ..Default::default()
            },
            Shape::cuboid(Vec3::new(0.5, 0.2, 0.3)),
        )
        .unwrap();
    w.add_force(Force::Applied(AppliedForce {
        body: id,
        force,
        point: None,
        torque,
    }))
    .unwrap();
    id
}

#[test]
fn planar_body_under_constant_torque_follows_half_alpha_t_squared() {
    // N_z = I α with the scalar I = I_zz = m/3 (a² + b²) = 0.29 kg·m².
    let torque = Vec3::new(0.7, -0.4, 0.58);
    let alpha = 0.58 / (3.0 / 3.0 * (0.25 + 0.04));
    // Velocity Verlet turns by h·ω½ per step, exact for linear ω(t); RK4 integrates
    // q̇ = ½ωq with a fifth-order local error; midpoint's is third order.
    for (integrator, accuracy) in [
        (Integrator::VelocityVerlet, tol(1e-12, 1e-5)),
        (Integrator::Rk4, tol(1e-9, 1e-5)),
        (Integrator::Midpoint, tol(1e-5, 1e-4)),
    ] {
        let mut w = world(Vec3::new(0.0, -9.8, 0.0), integrator);
        let id = planar_box(&mut w, torque, Vec3::new(0.0, 0.0, 50.0));
        let dt = 0.01;
        for n in 1..=100 {
            w.step(dt).unwrap();
            let t = n as Real * dt;
            let b = w.body(id).unwrap();
            let (axis, angle) = b.orientation().to_axis_angle();
            let theta = angle * axis.z.signum();
            let expect = 0.5 * alpha * t * t;
            // θ < π over the run, so the axis–angle form is unambiguous.
            assert!(
                (theta - expect).abs() < accuracy,
                "{}: t {t}: θ {theta} vs {expect}",
                integrator.name()
            );
            assert!((b.angular_velocity().z - alpha * t).abs() < tol(1e-12, 1e-4));
            // Out-of-plane force and torque components are ignored.
            assert_eq!(b.position().z, 0.0);
            assert!(axis.x.abs() < tol(1e-12, 1e-5) && axis.y.abs() < tol(1e-12, 1e-5));
            assert_eq!(b.angular_velocity().x, 0.0);
        }
    }
    // Symplectic Euler follows its discrete sum θ_n = α h² n(n+1)/2.
    let mut w = world(Vec3::ZERO, Integrator::SymplecticEuler);
    let id = planar_box(&mut w, torque, Vec3::ZERO);
    run(&mut w, 0.01, 100);
    let theta = w.body(id).unwrap().orientation().to_axis_angle().1;
    assert!((theta - alpha * 1e-4 * 5050.0).abs() < tol(1e-9, 1e-4));
}

#[test]
fn spring_between_two_bodies_conserves_momentum_and_energy() {
    // Energy bounds: first-order oscillation ~hω/2 for symplectic Euler (hω = 0.007), second
    // order for the others.
    for (integrator, bound) in [
        (Integrator::VelocityVerlet, 1e-4 as Real),
        (Integrator::Rk4, 1e-6),
        (Integrator::SymplecticEuler, 1e-2),
    ] {
        let mut w = world(Vec3::ZERO, integrator);
        let a = ball(&mut w, Vec3::new(-1.0, 0.0, 0.0));
        let b = w
            .create_body(
                &BodyDef {
                    position: Vec3::new(1.0, 0.3, 0.0),
                    linear_velocity: Vec3::new(0.0, 0.5, 0.2),
                    mass: MassSpec::Mass(2.0),
                    ..Default::default()
                },
                Shape::cuboid(Vec3::new(0.2, 0.1, 0.1)),
            )
            .unwrap();
        // Off-centre anchors: the spring also turns both bodies.
        w.add_force(Force::Spring(Spring {
            body: a,
            anchor: Vec3::new(0.05, 0.05, 0.0),
            other: SpringEnd::Body {
                body: b,
                anchor: Vec3::new(-0.2, 0.1, 0.0),
            },
            stiffness: 50.0,
            rest_length: 1.5,
            damping: 0.0,
        }))
        .unwrap();
        let d0 = w.diagnostics();
        let mut worst: Real = 0.0;
        for _ in 0..5000 {
            w.step(1e-3).unwrap();
            let d = w.diagnostics();
            // Equal and opposite forces: Σp exactly conserved up to rounding.
            assert!((d.linear_momentum - d0.linear_momentum).length() < tol(1e-12, 1e-4));
            // Central forces at the anchors: angular momentum about the origin too.
            assert!((d.angular_momentum - d0.angular_momentum).length() < tol(1e-10, 1e-3));
            worst = worst.max(((d.total - d0.total) / d0.total).abs());
        }
        assert!(
            worst < bound.max(tol(0.0, 1e-4)),
            "{}: energy error {worst}",
            integrator.name()
        );
    }
}

#[test]
fn force_at_a_point_turns_the_body_by_r_cross_f() {
    let mut w = world(Vec3::ZERO, Integrator::Rk4);
    let id = ball(&mut w, Vec3::ZERO);
    // 1 N along y at the local point (0.1, 0, 0): τ = r × F = 0.1 N·m about z.
    w.add_force(Force::Applied(AppliedForce {
        body: id,
        force: Vec3::Y,
        point: Some(Vec3::new(0.1, 0.0, 0.0)),
        torque: Vec3::ZERO,
    }))
    .unwrap();
    w.step(1e-3).unwrap();
    let b = w.body(id).unwrap();
    assert!((b.angular_momentum() - Vec3::new(0.0, 0.0, 1e-4)).length() < tol(1e-12, 1e-8));
    assert!((b.linear_velocity() - Vec3::new(0.0, 1e-3, 0.0)).length() < tol(1e-12, 1e-8));
}

#[test]
fn drag_reaches_its_terminal_velocity() {
    // m g = c₁ v + c₂ v²: with m = 1, g = 9.8, c₁ = 0.5, c₂ = 0.2 → v = 5.8437… m/s.
    let (c1, c2): (Real, Real) = (0.5, 0.2);
    let terminal = (-c1 + (c1 * c1 + 4.0 * c2 * 9.8).sqrt()) / (2.0 * c2);
    for integrator in Integrator::ALL {
        let mut w = world(Vec3::new(0.0, -9.8, 0.0), integrator);
        let id = ball(&mut w, Vec3::ZERO);
        w.add_force(Force::Drag(Drag {
            body: id,
            linear: c1,
            quadratic: c2,
        }))
        .unwrap();
        // The time constant m / (c₁ + 2c₂v) is 0.36 s: 15 s is 40 of them.
        run(&mut w, 0.01, 1500);
        let v = -w.body(id).unwrap().linear_velocity().y;
        // In f32, Verlet's velocity is a difference of ~80 m positions over h.
        assert!(
            (v - terminal).abs() < tol(1e-6, 3e-3),
            "{}: {v} vs {terminal}",
            integrator.name()
        );
    }
}

#[test]
fn a_user_callback_is_a_force_like_any_other() {
    // A callback implementing the same spring must reproduce the built-in spring exactly.
    let run_with = |callback: bool| {
        let mut w = world(Vec3::new(0.0, -9.8, 0.0), Integrator::Rk4);
        let id = ball(&mut w, Vec3::new(1.0, 0.0, 0.0));
        if callback {
            w.add_force_callback(Box::new(move |ctx: &mut ForceContext<'_>| {
                let x = ctx.position(id).unwrap();
                ctx.add_force(id, -x * 30.0);
            }));
        } else {
            w.add_force(Force::Spring(Spring {
                body: id,
                anchor: Vec3::ZERO,
                other: SpringEnd::World(Vec3::ZERO),
                stiffness: 30.0,
                rest_length: 0.0,
                damping: 0.0,
            }))
            .unwrap();
        }
        run(&mut w, 0.01, 500);
        w.body(id).unwrap().position()
    };
    let (a, b) = (run_with(true), run_with(false));
    assert!((a - b).length() < tol(1e-12, 1e-4), "{a} vs {b}");
}

#[test]
fn identical_runs_give_identical_bits() {
    let build = || {
        let mut w = world(Vec3::new(0.0, -9.8, 0.0), Integrator::ImplicitEuler);
        let mut prev = None;
        for i in 0..20 {
            let id = w
                .create_body(
                    &BodyDef {
                        position: Vec3::new(i as Real * 0.3, 0.0, 0.0),
                        angular_velocity: Vec3::new(0.1 * i as Real, 1.0, 0.0),
                        ..Default::default()
                    },
                    Shape::cuboid(Vec3::new(0.1, 0.05, 0.02)),
                )
                .unwrap();
            if let Some(p) = prev {
                w.add_force(Force::Spring(Spring {
                    body: p,
                    anchor: Vec3::new(0.1, 0.0, 0.0),
                    other: SpringEnd::Body {
                        body: id,
                        anchor: Vec3::new(-0.1, 0.0, 0.0),
                    },
                    stiffness: 100.0,
                    rest_length: 0.1,
                    damping: 0.5,
                }))
                .unwrap();
            }
            prev = Some(id);
        }
        run(&mut w, 1.0 / 60.0, 300);
        w.state_hash()
    };
    assert_eq!(build(), build());
}
