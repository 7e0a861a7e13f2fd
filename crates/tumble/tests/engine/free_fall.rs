//! The seed's free-fall ball (5 m, v₀ = 0, dt = 0.01 s, g = −9.8 m/s²) through every
//! integrator, against the closed form ½gt² or the method's own exact discrete sum.

// Casts between Real and f64 are no-ops in the default build but needed in the f32 one.
#![allow(clippy::unnecessary_cast)]

use crate::common::*;
use tumble::prelude::*;

const G: Real = -9.8;
const H: Real = 0.01;
const STEPS: usize = 100;

fn fall(integrator: Integrator) -> (Vec<Real>, Vec<Real>) {
    let mut w = world(Vec3::new(0.0, G, 0.0), integrator);
    let b = ball(&mut w, Vec3::new(0.0, 5.0, 0.0));
    let mut ys = vec![5.0];
    let mut vs = vec![0.0];
    for _ in 0..STEPS {
        w.step(H).unwrap();
        let body = w.body(b).unwrap();
        ys.push(body.position().y);
        vs.push(body.linear_velocity().y);
    }
    (ys, vs)
}

/// Rounding grows with the number of additions; 64 ulps of the 5 m height is plenty.
fn rounding() -> Real {
    tol(
        64.0 * f64::EPSILON * 5.0 * STEPS as f64,
        4.0 * f32::EPSILON as f64 * 5.0 * STEPS as f64,
    )
}

#[test]
fn second_order_methods_match_the_parabola_to_rounding() {
    for integrator in [
        Integrator::VelocityVerlet,
        Integrator::Rk4,
        Integrator::Midpoint,
        Integrator::Verlet,
    ] {
        let (ys, vs) = fall(integrator);
        // Verlet's velocity is a difference of positions over h, so position rounding
        // reaches it divided by h.
        // Störmer's x₊ = 2x − x₋ + a h² sums its rounding twice, so it grows as n², not n.
        let stormer = integrator == Integrator::Verlet;
        for (n, (y, v)) in ys.iter().zip(&vs).enumerate() {
            let y_tol = if stormer {
                rounding() * (1 + n) as Real
            } else {
                rounding()
            };
            let v_tol = if stormer { y_tol * 2.0 / H } else { rounding() };
            let t = n as Real * H;
            let exact = 5.0 + 0.5 * G * t * t;
            assert!(
                (y - exact).abs() < y_tol,
                "{}: step {n}: y {y} vs {exact}",
                integrator.name()
            );
            assert!(
                (v - G * t).abs() < v_tol,
                "{}: step {n}: v {v}",
                integrator.name()
            );
        }
    }
}

#[test]
fn explicit_euler_follows_its_discrete_sum() {
    // v_n = g n h; y_n = y₀ + Σ_{k<n} v_k h = y₀ + g h² n(n−1)/2: a step behind the parabola.
    let (ys, _) = fall(Integrator::ExplicitEuler);
    for (n, y) in ys.iter().enumerate() {
        let n = n as Real;
        let sum = 5.0 + G * H * H * n * (n - 1.0) / 2.0;
        assert!((y - sum).abs() < rounding(), "step {n}: {y} vs {sum}");
    }
}

#[test]
fn symplectic_and_implicit_euler_follow_their_discrete_sum() {
    // Velocity first: y_n = y₀ + Σ_{k=1..n} v_k h = y₀ + g h² n(n+1)/2, a step ahead.
    // Backward Euler under a constant force is the same recurrence.
    for integrator in [Integrator::SymplecticEuler, Integrator::ImplicitEuler] {
        let (ys, _) = fall(integrator);
        for (n, y) in ys.iter().enumerate() {
            let n = n as Real;
            let sum = 5.0 + G * H * H * n * (n + 1.0) / 2.0;
            assert!(
                (y - sum).abs() < rounding(),
                "{}: step {n}: {y} vs {sum}",
                integrator.name()
            );
        }
    }
    // After 1 s the parabola is at 5 − 4.9 = 0.1 m; the symplectic ball has fallen
    // 9.8 · 10⁻⁴ · 5050 = 4.949 m, to 0.051 m.
    let (ys, _) = fall(Integrator::SymplecticEuler);
    assert!((ys[STEPS] - 0.051).abs() < tol(1e-12, 1e-5));
}
