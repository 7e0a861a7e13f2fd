//! The harmonic oscillator m ẍ = −k x − b ẋ: the seed's "convergence, order, stability".

// Casts between Real and f64 are no-ops in the default build but needed in the f32 one.
#![allow(clippy::unnecessary_cast)]

use crate::common::*;
use tumble::analysis::{
    convergence, default_steps, energy_behaviour, largest_stable_step, oscillator, oscillator_exact,
};
use tumble::prelude::*;

#[test]
fn observed_orders_match_the_theory() {
    // Expected orders in the order Integrator::ALL lists them.
    let expected = [1.0, 1.0, 1.0, 2.0, 4.0, 2.0, 2.0];
    for (integrator, want) in Integrator::ALL.into_iter().zip(expected) {
        let (dt0, levels) = default_steps(integrator);
        let c = convergence(integrator, dt0, levels);
        assert!(
            (c.order - want).abs() <= 0.2,
            "{}: observed order {} (errors {:?})",
            integrator.name(),
            c.order,
            c.errors
        );
    }
}

#[test]
fn energy_grows_decays_or_stays_bounded_as_theory_says() {
    // 20 steps per period, 10 periods: explicit Euler's energy grows 1.5e8-fold, its
    // speed to 12 km/s (100 periods would take it past every speed the engine accepts,
    // and the run would stop there).
    let periods = 10;
    let e = |i| energy_behaviour(i, 0.05, periods);
    let explicit = e(Integrator::ExplicitEuler);
    // Explicit Euler multiplies the energy by 1 + (hω)² every step.
    let growth: Real =
        (1.0 + (0.05 * 2.0 * tumble::math::PI).powi(2)).powi(20 * periods as i32) - 1.0;
    assert!(explicit.final_change > 1e7, "{explicit:?}");
    assert!(
        ((explicit.final_change - growth) / growth).abs() < tol(1e-6, 1e-2),
        "{} vs {growth}",
        explicit.final_change
    );
    // Energy grows monotonically period after period.
    assert!(explicit.per_period.windows(2).all(|w| w[1] > w[0]));

    let implicit = e(Integrator::ImplicitEuler);
    // Each period takes the same share of what is left (until rounding is all there is).
    assert!(
        implicit.per_period[..periods.min(20)]
            .windows(2)
            .all(|w| w[1] < 0.2 * w[0]),
        "{implicit:?}"
    );
    assert!(implicit.final_change < -0.99);

    // Symplectic methods: the energy oscillates but its envelope does not drift. The
    // bound is the first-order energy error of each method at hω = 0.31.
    for (integrator, bound) in [
        (Integrator::SymplecticEuler, 0.2),
        (Integrator::Verlet, 0.1),
        (Integrator::VelocityVerlet, 0.03),
    ] {
        let b = e(integrator);
        assert!(b.max_deviation < bound, "{}: {b:?}", integrator.name());
        // No secular drift: the last ten periods look like the first ten.
        let envelope = |range: std::ops::Range<usize>| {
            b.deviation_per_period[range]
                .iter()
                .copied()
                .fold(0.0, Real::max)
        };
        let (first, last) = (envelope(0..5), envelope(periods - 5..periods));
        assert!(
            last < 1.05 * first + tol(1e-12, 1e-5),
            "{}: {first} then {last}",
            integrator.name()
        );
    }
}

#[test]
fn damped_spring_follows_the_analytic_solution() {
    // ζ = 0.1, ω₀ = 2π: the envelope e^{−ζω₀t} shrinks by 4.6x in 4 s. Each method's worst
    // error over 4 s must be small and shrink with its order when the step is halved:
    // damping is a velocity-dependent force, which is where Verlet-type methods often
    // lose an order.
    let k = 4.0 * tumble::math::PI * tumble::math::PI;
    let b = 0.2 * k.sqrt();
    let worst_error = |integrator, dt: Real| {
        let mut w = oscillator(integrator, k, b);
        let id = w.body_ids()[0];
        let mut worst: Real = 0.0;
        let steps = (4.0 / dt).round() as usize;
        for n in 1..=steps {
            w.step(dt).unwrap();
            let x = w.body(id).unwrap().position().x;
            worst = worst.max((x - oscillator_exact(k, b, n as Real * dt)).abs());
        }
        worst
    };
    let dt = if single_precision() { 8e-3 } else { 2e-3 };
    for integrator in Integrator::ALL {
        let (coarse, fine) = (
            worst_error(integrator, dt),
            worst_error(integrator, dt / 2.0),
        );
        let order = (coarse / fine).log2();
        let want = integrator.order() as Real;
        // In f32, RK4's error is already at the rounding floor; only its bound is checked.
        let at_rounding_floor = fine < tol(0.0, 1e-5);
        assert!(
            at_rounding_floor || (order - want).abs() < 0.25,
            "{}: errors {coarse} then {fine}",
            integrator.name()
        );
        // Bounds at dt = 1e-3 (f64), scaled by the order for f32's coarser steps.
        let bound: Real = [0.03, 1e-4, 1e-8][(integrator.order() as usize).min(3) / 2];
        let bound = (bound * (dt / 2e-3).powi(integrator.order() as i32)).max(tol(0.0, 1e-3));
        assert!(fine < bound, "{}: error {fine}", integrator.name());
    }
}

#[test]
fn implicit_euler_stays_stable_where_explicit_euler_explodes() {
    // A stiff spring (ω = 100 rad/s) at h = 0.05 s: hω = 5.
    let k = 1.0e4;
    let run_to = |integrator| -> std::result::Result<Real, Error> {
        let mut w = oscillator(integrator, k, 0.0);
        for _ in 0..200 {
            w.step(0.05)?;
        }
        Ok(w.body(w.body_ids()[0]).unwrap().position().x)
    };
    // Explicit Euler grows by √(1 + (hω)²) = 5.1 per step: the engine stops it when it
    // leaves the largest coordinate it accepts (1e9 m), at step ln(1e9)/ln(5.1) ≈ 13.
    match run_to(Integrator::ExplicitEuler) {
        Err(Error::Unstable(u)) => assert!(u.step > 10 && u.step < 18, "{}", u.step),
        other => panic!("explicit Euler ran on: {other:?}"),
    }
    let implicit = run_to(Integrator::ImplicitEuler).unwrap();
    assert!(implicit.abs() < 1e-3, "implicit ended at {implicit}");
    // The measured stability limits agree with the linear theory of each method.
    let limit = |i| largest_stable_step(i).unwrap_or(0.0);
    assert_eq!(limit(Integrator::ImplicitEuler), 10.0);
    assert!((limit(Integrator::Rk4) - 2.0 * (2.0 as Real).sqrt()).abs() < 0.01);
    assert!((limit(Integrator::VelocityVerlet) - 2.0).abs() < 0.01);
    assert!(limit(Integrator::ExplicitEuler) < 0.01);
}
