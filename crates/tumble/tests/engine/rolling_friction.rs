//! Rolling resistance and torsional friction against their closed forms (the derivations
//! are in `src/dynamics/solver/angular.rs` and docs/integrators.md).
//!
//! Conventions: `rolling_resistance` μ_r is dimensionless, the resisting torque at most
//! μ_r r N with r the contact's rolling radius (a ball's radius); `torsional_friction` μ_t
//! is a length, the torque about the normal at most μ_t N; a pair uses the larger of each.
//!
//! A solid ball rolling on a level plane slows at a = μ_r g / (1 + I/(m r²)) = (5/7) μ_r g
//! and stops after v₀² / 2a; spinning about the normal it slows at ω̇ = μ_t m g / I.

// Casts between Real and f64 are no-ops in the default build but needed in the f32 one.
#![allow(clippy::unnecessary_cast)]

use crate::common::*;
use tumble::prelude::*;

const G: Real = 9.8;

fn world(dt_sleep: bool) -> World {
    World::new(&WorldDef {
        gravity: Vec3::new(0.0, -G, 0.0),
        sleep: dt_sleep,
        ..Default::default()
    })
}

/// A static plane through the origin with `normal`, of rolling resistance `rolling` and
/// torsional friction `twist`.
fn ground(w: &mut World, normal: Vec3, (rolling, twist): (Real, Real)) -> BodyId {
    let def = BodyDef {
        kind: BodyKind::Static,
        friction: 0.8,
        rolling_resistance: rolling,
        torsional_friction: twist,
        ..Default::default()
    };
    w.create_body(&def, Shape::plane(normal, 0.0)).unwrap()
}

/// A solid ball: radius, mass, its (rolling, twist) coefficients.
#[derive(Clone, Copy)]
struct Ball {
    r: Real,
    m: Real,
    coefficients: (Real, Real),
}

impl Ball {
    /// Placed on the level ground at x = 0, rolling along +x at `v0` without slipping.
    fn rolling(self, w: &mut World, v0: Real) -> BodyId {
        let def = BodyDef {
            position: Vec3::new(0.0, self.r, 0.0),
            linear_velocity: Vec3::new(v0, 0.0, 0.0),
            angular_velocity: Vec3::new(0.0, 0.0, -v0 / self.r),
            ..self.def()
        };
        w.create_body(&def, Shape::sphere(self.r)).unwrap()
    }

    fn def(self) -> BodyDef {
        BodyDef {
            mass: MassSpec::Mass(self.m),
            friction: 0.8,
            rolling_resistance: self.coefficients.0,
            torsional_friction: self.coefficients.1,
            ..Default::default()
        }
    }
}

/// One rolling run: (t, x, v) after each step until `duration`.
fn roll(w: &mut World, body: BodyId, dt: Real, duration: Real) -> Vec<(Real, Real, Real)> {
    let mut out = Vec::new();
    for k in 0..(duration / dt).round() as usize {
        w.step(dt).unwrap();
        let b = w.body(body).unwrap();
        out.push(((k + 1) as Real * dt, b.position().x, b.linear_velocity().x));
    }
    out
}

/// Least-squares slope of v(t) over the samples with v between 0.25 and 0.75 of `v0`:
/// clear of the first steps (the ball settles into its contact) and of the stop.
fn deceleration(samples: &[(Real, Real, Real)], v0: Real) -> Real {
    let mid: Vec<_> = samples
        .iter()
        .filter(|s| s.2 > 0.25 * v0 && s.2 < 0.75 * v0)
        .collect();
    assert!(mid.len() >= 10, "too few samples: {}", mid.len());
    let n = mid.len() as Real;
    let (mt, mv) = mid
        .iter()
        .fold((0.0, 0.0), |(a, b), s| (a + s.0 / n, b + s.2 / n));
    let (num, den) = mid.iter().fold((0.0, 0.0), |(a, b), s| {
        (a + (s.0 - mt) * (s.2 - mv), b + (s.0 - mt) * (s.0 - mt))
    });
    -num / den
}

#[test]
fn a_rolling_ball_slows_at_five_sevenths_mu_g_and_stops_where_predicted() {
    // Radii over a decade, masses over forty times, three coefficients, both time steps.
    // Measured (f64): the deceleration within 0.17 % of (5/7) μ_r g at dt 1/60 and 0.11 % at
    // 1/240 (the ball sinks up to 2 mm into its soft contact, which shortens the lever of
    // friction a little); the stop within 0.6 % (17 mm of 2.8 m) and 0.06 % of v²/2a; and
    // then it stays put.
    let cases = [
        (0.1, 1.0, 0.05),
        (0.05, 0.5, 0.1),
        (0.3, 20.0, 0.02),
        (0.5, 2.0, 0.05),
    ];
    for dt in [1.0 / 60.0, 1.0 / 240.0] {
        for (r, m, mu) in cases {
            let mut w = world(false);
            ground(&mut w, Vec3::Y, (0.0, 0.0));
            let ball = Ball {
                r,
                m,
                coefficients: (mu, 0.0),
            };
            let v0 = 2.0;
            let id = ball.rolling(&mut w, v0);
            let a = 5.0 / 7.0 * mu * G;
            let samples = roll(&mut w, id, dt, 1.3 * v0 / a);
            let measured = deceleration(&samples, v0);
            let err = (measured - a).abs() / a;
            assert!(
                err < 0.005,
                "r {r} m {m} μ_r {mu} dt {dt}: a = {measured}, closed form {a} ({err:.2e})"
            );
            // Stop: from the state a tenth of a second in (settled), x + v²/2a.
            let start = samples[(0.1 / dt) as usize];
            let predicted = start.1 + start.2 * start.2 / (2.0 * a);
            let (_, x_end, v_end) = *samples.last().unwrap();
            assert!(v_end.abs() < 1e-3, "still rolling at {v_end} m/s");
            let stopped = samples[(1.15 * v0 / a / dt) as usize].1;
            assert!(
                (x_end - stopped).abs() < 1e-4,
                "crept {} m",
                x_end - stopped
            );
            let miss = (x_end - predicted).abs() / predicted;
            assert!(
                miss < 0.01,
                "r {r} dt {dt}: stopped at {x_end} m, predicted {predicted} ({miss:.2e})"
            );
        }
    }
}

#[test]
fn without_rolling_resistance_a_rolling_ball_keeps_its_speed() {
    // The default coefficients are zero: after the first steps (the ball settles into its
    // contact, 0.35 % of the speed at 1/60) the speed stays, for any friction.
    for dt in [1.0 / 60.0, 1.0 / 240.0] {
        let mut w = world(false);
        ground(&mut w, Vec3::Y, (0.0, 0.0));
        let ball = Ball {
            r: 0.2,
            m: 3.0,
            coefficients: (0.0, 0.0),
        };
        let id = ball.rolling(&mut w, 1.5);
        let samples = roll(&mut w, id, dt, 4.0);
        let settled = samples[(0.2 / dt) as usize].2;
        let end = samples.last().unwrap().2;
        assert!(settled > 1.49, "lost {} m/s settling", 1.5 - settled);
        assert!(
            (end - settled).abs() < tol(1e-6, 1e-4),
            "dt {dt}: {settled} -> {end} m/s"
        );
    }
}

#[test]
fn a_planar_ball_rolls_resisted_too() {
    // A planar body turns about z alone: the rolling block is singular (rank one) and is
    // solved by its pseudo-inverse, which must give the same closed form.
    let mut w = world(false);
    ground(&mut w, Vec3::Y, (0.0, 0.0));
    let (r, mu, v0) = (0.1, 0.08, 2.0);
    let def = BodyDef {
        planar: true,
        position: Vec3::new(0.0, r, 0.0),
        linear_velocity: Vec3::new(v0, 0.0, 0.0),
        angular_velocity: Vec3::new(0.0, 0.0, -v0 / r),
        friction: 0.8,
        rolling_resistance: mu,
        mass: MassSpec::Mass(1.0),
        ..Default::default()
    };
    let id = w.create_body(&def, Shape::sphere(r)).unwrap();
    let a = 5.0 / 7.0 * mu * G;
    let dt = 1.0 / 120.0;
    let samples = roll(&mut w, id, dt, 1.3 * v0 / a);
    let measured = deceleration(&samples, v0);
    assert!(
        (measured - a).abs() < 0.01 * a,
        "a = {measured}, closed form {a}"
    );
    assert!(samples.last().unwrap().2.abs() < 1e-3);
}

/// A plane through the origin tilted by `angle` about z (downhill towards +x), and a ball
/// of radius `r` resting on it at the origin, released at rest.
fn on_slope(w: &mut World, angle: Real, ball: Ball) -> (BodyId, Vec3) {
    let normal = Vec3::new(angle.sin(), angle.cos(), 0.0);
    ground(w, normal, (0.0, 0.0));
    let def = BodyDef {
        position: normal * ball.r,
        ..ball.def()
    };
    let down = Vec3::new(angle.cos(), -angle.sin(), 0.0);
    (w.create_body(&def, Shape::sphere(ball.r)).unwrap(), down)
}

#[test]
fn on_a_slope_rolling_resistance_holds_a_ball_below_tan_theta_and_reports_the_torque() {
    // Held if the weight's torque about the contact, m g sinθ r, is within μ_r r m g cosθ:
    // tan θ ≤ μ_r. Held, the contact's angular impulse per substep is that torque times h.
    let (mu, r, m): (Real, Real, Real) = (0.2, 0.15, 2.0);
    for dt in [1.0 / 60.0, 1.0 / 240.0] {
        let angle = (0.8 * mu).atan();
        let mut w = world(false);
        let ball = Ball {
            r,
            m,
            coefficients: (mu, 0.0),
        };
        let (id, down) = on_slope(&mut w, angle, ball);
        run(&mut w, dt, (2.0 / dt) as usize);
        let b = w.body(id).unwrap();
        let moved = b.position().dot(down);
        assert!(
            moved.abs() < 1e-3,
            "dt {dt}: crept {moved} m down the slope"
        );
        assert!(b.linear_velocity().length() < 1e-3);
        let h = dt / 4.0;
        let torque = w.contacts()[0].manifold.angular_impulse.length() / h;
        let weight = m * G * angle.sin() * r;
        assert!(
            (torque - weight).abs() < 0.01 * weight,
            "held with {torque} N·m, the weight turns with {weight}"
        );
    }
}

#[test]
fn on_a_steeper_slope_the_ball_rolls_down_at_the_closed_form_rate() {
    // a = (5/7) g (sinθ − μ_r cosθ) for tan θ > μ_r (rolling without slipping).
    let mu = 0.1;
    for (dt, angle) in [(1.0 / 60.0, 0.3), (1.0 / 240.0, 0.2)] {
        let mut w = world(false);
        let ball = Ball {
            r: 0.1,
            m: 1.0,
            coefficients: (mu, 0.0),
        };
        let (id, down) = on_slope(&mut w, angle as Real, ball);
        let mut samples = Vec::new();
        for k in 0..(1.5 / dt) as usize {
            w.step(dt).unwrap();
            let v = w.body(id).unwrap().linear_velocity().dot(down);
            samples.push(((k + 1) as Real * dt, v));
        }
        let (t0, v0) = samples[(0.5 / dt) as usize];
        let (t1, v1) = *samples.last().unwrap();
        let measured = (v1 - v0) / (t1 - t0);
        let (s, c) = (angle as Real).sin_cos();
        let a = 5.0 / 7.0 * G * (s - mu * c);
        assert!(
            (measured - a).abs() < 0.01 * a,
            "θ {angle}: a = {measured}, closed form {a}"
        );
    }
}

/// A body standing still on the ground spinning about the vertical at `w0`; its ω_y each
/// step until `duration`.
fn spin_down(
    w: &mut World,
    def: BodyDef,
    shape: Shape,
    w0: Real,
    dt: Real,
    duration: Real,
) -> Vec<Real> {
    let def = BodyDef {
        angular_velocity: Vec3::new(0.0, w0, 0.0),
        ..def
    };
    let id = w.create_body(&def, shape).unwrap();
    (0..(duration / dt).round() as usize)
        .map(|_| {
            w.step(dt).unwrap();
            w.body(id).unwrap().angular_velocity().y
        })
        .collect()
}

/// The mean slope of ω over the samples between 0.25 and 0.75 of `w0`.
fn spin_rate(omega: &[Real], w0: Real, dt: Real) -> Real {
    let i0 = omega.iter().position(|&w| w < 0.75 * w0).unwrap();
    let i1 = omega.iter().position(|&w| w < 0.25 * w0).unwrap();
    (omega[i0] - omega[i1]) / ((i1 - i0) as Real * dt)
}

#[test]
fn a_spinning_ball_slows_at_mu_t_m_g_over_i_and_stops() {
    // A ball touches at one point on its axis: friction there cannot slow a spin about the
    // normal, only torsional friction can. ω̇ = μ_t m g / (⅖ m r²): measured to 1e-13 in
    // f64 (the limit is reached every substep, and a ball pressing steadily has its weight
    // as normal impulse).
    for dt in [1.0 / 60.0, 1.0 / 240.0] {
        for (r, m, mu_t) in [(0.1, 1.0, 0.002), (0.25, 8.0, 0.01)] {
            let mut w = world(false);
            ground(&mut w, Vec3::Y, (0.0, 0.0));
            let ball = Ball {
                r,
                m,
                coefficients: (0.0, mu_t),
            };
            let def = BodyDef {
                position: Vec3::new(0.0, r, 0.0),
                ..ball.def()
            };
            let rate = mu_t * m * G / (0.4 * m * r * r);
            let w0 = 20.0;
            let omega = spin_down(&mut w, def, Shape::sphere(r), w0, dt, 1.3 * w0 / rate);
            let measured = spin_rate(&omega, w0, dt);
            assert!(
                (measured - rate).abs() < tol(1e-6, 1e-2) * rate,
                "r {r} μ_t {mu_t} dt {dt}: ω̇ = {measured}, closed form {rate}"
            );
            let end = *omega.last().unwrap();
            assert!(end.abs() < 1e-3, "still spinning at {end} rad/s");
        }
    }
}

#[test]
fn a_cylinder_spinning_on_its_base_slows_at_the_torsional_rate() {
    // Standing on its flat base with no Coulomb friction (its points would otherwise add
    // their own torque), only torsional friction acts: ω̇ = μ_t m g / (½ m R²), whatever
    // the number of points the base touches with (the limit is the manifold's whole
    // normal impulse).
    for dt in [1.0 / 60.0, 1.0 / 240.0] {
        let (radius, half, m, mu_t) = (0.3, 0.2, 5.0, 0.01);
        let mut w = world(false);
        ground(&mut w, Vec3::Y, (0.0, 0.0));
        let def = BodyDef {
            position: Vec3::new(0.0, half, 0.0),
            mass: MassSpec::Mass(m),
            friction: 0.0,
            torsional_friction: mu_t,
            ..Default::default()
        };
        let rate = mu_t * m * G / (0.5 * m * radius * radius);
        let w0 = 10.0;
        let shape = Shape::cylinder(radius, half);
        let omega = spin_down(&mut w, def, shape, w0, dt, 1.3 * w0 / rate);
        let measured = spin_rate(&omega, w0, dt);
        assert!(
            (measured - rate).abs() < tol(1e-6, 1e-2) * rate,
            "dt {dt}: ω̇ = {measured}, closed form {rate}"
        );
        assert!(omega.last().unwrap().abs() < 1e-3);
    }
}

#[test]
fn a_pair_uses_the_larger_of_each_coefficient() {
    // Rolling: the ball's or the ground's, whichever is larger; zero on both is none.
    let dt = 1.0 / 120.0;
    let v0 = 2.0;
    for (on_ball, on_ground) in [(0.1, 0.0), (0.0, 0.1), (0.04, 0.1), (0.1, 0.04)] {
        let mut w = world(false);
        ground(&mut w, Vec3::Y, (on_ground, 0.0));
        let ball = Ball {
            r: 0.1,
            m: 1.0,
            coefficients: (on_ball, 0.0),
        };
        let id = ball.rolling(&mut w, v0);
        let a = 5.0 / 7.0 * 0.1 * G;
        let measured = deceleration(&roll(&mut w, id, dt, 1.3 * v0 / a), v0);
        assert!(
            (measured - a).abs() < 0.01 * a,
            "ball {on_ball}, ground {on_ground}: a = {measured}, max rule {a}"
        );
    }
    // Twist likewise: the ground's torsional friction slows a ball that has none.
    let mut w = world(false);
    ground(&mut w, Vec3::Y, (0.0, 0.005));
    let ball = Ball {
        r: 0.1,
        m: 1.0,
        coefficients: (0.0, 0.001),
    };
    let def = BodyDef {
        position: Vec3::new(0.0, 0.1, 0.0),
        ..ball.def()
    };
    let rate = 0.005 * G / (0.4 * 0.01);
    let omega = spin_down(&mut w, def, Shape::sphere(0.1), 20.0, dt, 1.3 * 20.0 / rate);
    let measured = spin_rate(&omega, 20.0, dt);
    assert!(
        (measured - rate).abs() < 0.01 * rate,
        "ω̇ = {measured}, max rule {rate}"
    );
}

#[test]
fn the_coefficients_are_checked_where_they_enter() {
    let mut w = world(false);
    for (def, field) in [
        (
            BodyDef {
                rolling_resistance: -0.1,
                ..Default::default()
            },
            "rolling_resistance: must be >= 0",
        ),
        (
            BodyDef {
                torsional_friction: Real::NAN,
                ..Default::default()
            },
            "torsional_friction: must be a finite number",
        ),
        (
            BodyDef {
                rolling_resistance: 1e20,
                ..Default::default()
            },
            "rolling_resistance: must be at most 1e15 in magnitude",
        ),
    ] {
        let err = w.create_body(&def, Shape::sphere(0.1)).unwrap_err();
        assert_eq!(err.to_string(), field);
    }
    let def = BodyDef {
        rolling_resistance: 0.3,
        torsional_friction: 0.01,
        ..Default::default()
    };
    let id = w.create_body(&def, Shape::sphere(0.1)).unwrap();
    let b = w.body(id).unwrap();
    assert_eq!(
        (b.rolling_resistance(), b.torsional_friction()),
        (0.3, 0.01)
    );
}

#[test]
fn a_ball_with_rolling_resistance_moves_as_its_velocity_says() {
    // Friction anchors of a pair with angular rows are renewed as the contact rolls on
    // (`solver::contact::rolled_away`; for round bodies without either coefficient too,
    // `tests/rolling_contact.rs`): stale anchors pulled a slowly rolling ball back in the
    // biased pass, and its position lagged its velocity by 6 % at dt 1/60. Measured: 1e-4.
    for dt in [1.0 / 60.0, 1.0 / 240.0] {
        let mut w = world(false);
        ground(&mut w, Vec3::Y, (0.0, 0.0));
        let ball = Ball {
            r: 0.3,
            m: 20.0,
            coefficients: (1e-3, 0.0),
        };
        let id = ball.rolling(&mut w, 0.5);
        let mut travel = 0.0;
        for _ in 0..(3.0 / dt) as usize {
            w.step(dt).unwrap();
            travel += w.body(id).unwrap().linear_velocity().x * dt;
        }
        let x = w.body(id).unwrap().position().x;
        assert!(
            (x - travel).abs() < 1e-3 * travel,
            "dt {dt}: moved {x} m, its velocity says {travel} m"
        );
    }
}
