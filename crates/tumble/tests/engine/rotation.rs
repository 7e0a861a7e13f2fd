//! Torque-free rotation in 3D: L conserved, ω not; stable spin about the largest and
//! smallest principal axes; the intermediate-axis (Dzhanibekov) flip with the period
//! the elliptic-function solution of Euler's equations predicts.

// Casts between Real and f64 are no-ops in the default build but needed in the f32 one.
#![allow(clippy::unnecessary_cast)]

use crate::common::*;
use tumble::prelude::*;

/// Half extents giving I_x < I_y < I_z: x smallest, y intermediate, z largest.
const HALF: [f64; 3] = [0.4, 0.2, 0.1];

fn spinning_box(integrator: Integrator, omega: Vec3, velocity: Vec3) -> (World, BodyId) {
    let mut w = world(Vec3::ZERO, integrator);
    let id = w
        .create_body(
            &BodyDef {
                mass: MassSpec::Mass(2.0),
                angular_velocity: omega,
                linear_velocity: velocity,
                position: Vec3::new(1.0, -2.0, 0.5),
                ..Default::default()
            },
            Shape::cuboid(Vec3::new(HALF[0] as Real, HALF[1] as Real, HALF[2] as Real)),
        )
        .unwrap();
    (w, id)
}

fn body_omega(w: &World, id: BodyId) -> Vec3 {
    let b = w.body(id).unwrap();
    b.orientation().inverse() * b.angular_velocity()
}

/// Complete elliptic integral of the first kind K(k) by the arithmetic–geometric mean.
fn elliptic_k(k: f64) -> f64 {
    let (mut a, mut g) = (1.0, (1.0 - k * k).sqrt());
    while (a - g).abs() > 1e-16 * a {
        (a, g) = (0.5 * (a + g), (a * g).sqrt());
    }
    std::f64::consts::PI / (2.0 * a)
}

/// Period of the body-frame ω of a free asymmetric top (Landau & Lifshitz §37):
/// T = 4K(k)/λ with, for L² > 2EI₂, λ² = (I₃−I₂)(L²−2EI₁)/(I₁I₂I₃) and
/// k² = (I₂−I₁)(2EI₃−L²)/((I₃−I₂)(L²−2EI₁)); for L² < 2EI₂ swap I₁ and I₃.
fn euler_top_period(moments: [f64; 3], omega: [f64; 3]) -> f64 {
    let l2: f64 = (0..3).map(|i| (moments[i] * omega[i]).powi(2)).sum();
    let two_e: f64 = (0..3).map(|i| moments[i] * omega[i] * omega[i]).sum();
    let [mut i1, i2, mut i3] = moments;
    if l2 < two_e * i2 {
        std::mem::swap(&mut i1, &mut i3);
    }
    let lambda = ((i3 - i2) * (l2 - two_e * i1) / (i1 * i2 * i3)).sqrt();
    let k2 = (i2 - i1) * (two_e * i3 - l2) / ((i3 - i2) * (l2 - two_e * i1));
    4.0 * elliptic_k(k2.sqrt()) / lambda
}

/// Times at which body-frame ω_y changes sign, linearly interpolated.
fn flip_times(integrator: Integrator, omega0: Vec3, dt: Real, duration: Real) -> (Vec<f64>, Real) {
    let (mut w, id) = spinning_box(integrator, omega0, Vec3::ZERO);
    let e0 = w.diagnostics().kinetic;
    let mut flips = Vec::new();
    let mut prev = body_omega(&w, id).y;
    let mut worst: Real = 0.0;
    let steps = (duration / dt).round() as usize;
    for n in 1..=steps {
        w.step(dt).unwrap();
        let wy = body_omega(&w, id).y;
        if wy.signum() != prev.signum() {
            let t = (n as Real - 1.0 + prev / (prev - wy)) * dt;
            flips.push(t as f64);
        }
        prev = wy;
        worst = worst.max(((w.diagnostics().kinetic - e0) / e0).abs());
    }
    (flips, worst)
}

#[test]
fn intermediate_axis_flips_with_the_elliptic_period() {
    // Nudged by 0.1 rad/s: close enough to the separatrix for long, sharp flips, far
    // enough that L² − 2EI₂ (which sets the period) is not below f32's resolution.
    let omega0 = Vec3::new(0.1, 5.0, 0.0);
    let b = Shape::cuboid(Vec3::new(HALF[0] as Real, HALF[1] as Real, HALF[2] as Real))
        .mass_properties(1.0)
        .with_mass(2.0);
    let moments = [
        b.inertia.x_axis.x as f64,
        b.inertia.y_axis.y as f64,
        b.inertia.z_axis.z as f64,
    ];
    let period = euler_top_period(moments, [omega0.x as f64, omega0.y as f64, omega0.z as f64]);
    // ω_y ∝ sn, which changes sign every half period.
    let half = period / 2.0;
    for (integrator, dt, rel) in [
        (Integrator::SymplecticEuler, 1.0 / 240.0, 0.01_f64),
        (Integrator::VelocityVerlet, 1.0 / 240.0, 0.01),
        (Integrator::Rk4, 1.0 / 240.0, 0.002),
    ] {
        let (flips, energy_error) = flip_times(integrator, omega0, dt, 40.0);
        assert!(
            flips.len() >= 4,
            "{}: only {} flips ({flips:?}); T/2 = {half}",
            integrator.name(),
            flips.len()
        );
        for pair in flips.windows(2) {
            let gap = pair[1] - pair[0];
            // Near the separatrix the period depends on log(2E I₃ − L²), a difference
            // that f32 holds to a few digits only.
            let rel = rel.max(tol(0.0, 0.01) as f64);
            assert!(
                ((gap - half) / half).abs() < rel,
                "{}: flip gap {gap} vs T/2 = {half}",
                integrator.name()
            );
        }
        assert!(
            energy_error < 2e-3,
            "{}: energy error {energy_error}",
            integrator.name()
        );
    }
}

#[test]
fn default_integrator_keeps_a_tumbling_box_physical_where_explicit_euler_does_not() {
    // The trap named in the brief: spun about its middle axis at 5 rad/s, stepped at
    // 240 Hz for 20 s. The default must keep the energy; q += ½hωq pumps it up.
    let omega0 = Vec3::new(0.01, 5.0, 0.0);
    let (_, default_error) = flip_times(Integrator::default(), omega0, 1.0 / 240.0, 20.0);
    assert!(
        default_error < 2e-3,
        "symplectic Euler energy error {default_error}"
    );
    let (_, explicit_error) = flip_times(Integrator::ExplicitEuler, omega0, 1.0 / 240.0, 20.0);
    assert!(
        explicit_error > 0.2,
        "explicit Euler energy error only {explicit_error}"
    );
}

#[test]
fn spin_about_the_largest_and_smallest_axes_is_stable() {
    let m = Shape::cuboid(Vec3::new(HALF[0] as Real, HALF[1] as Real, HALF[2] as Real))
        .mass_properties(1.0);
    let moments = [m.inertia.x_axis.x, m.inertia.y_axis.y, m.inertia.z_axis.z];
    // Spin about axis a, nudged about b; c is the third. Euler's equations keep
    // I_b(I_a−I_b)ω_b² + I_c(I_a−I_c)ω_c² constant, so the body axis circles L on an
    // ellipse whose far point lies √(I_c(I_a−I_b) / (I_b(I_a−I_c))) times the start.
    for (a, b, c) in [(2usize, 0usize, 1usize), (0, 2, 1)] {
        let axis = [Vec3::X, Vec3::Y, Vec3::Z];
        let ratio = (moments[c] * (moments[a] - moments[b])
            / (moments[b] * (moments[a] - moments[c])))
            .sqrt();
        for integrator in [
            Integrator::SymplecticEuler,
            Integrator::Rk4,
            Integrator::VelocityVerlet,
        ] {
            let (mut w, id) = spinning_box(integrator, axis[a] * 5.0 + axis[b] * 0.05, Vec3::ZERO);
            let l = w.body(id).unwrap().angular_momentum().normalize();
            let angle = |w: &World| (w.body(id).unwrap().orientation() * axis[a]).angle_between(l);
            let bound = 1.1 * ratio.max(1.0) * angle(&w);
            let mut widest: Real = 0.0;
            for _ in 0..(20 * 240) {
                w.step(1.0 / 240.0).unwrap();
                widest = widest.max(angle(&w));
            }
            assert!(
                widest < bound,
                "{}: axis {a} wandered to {widest} (bound {bound})",
                integrator.name()
            );
            // And it does go round the ellipse, not sit still.
            assert!(
                widest > 0.9 * bound / 1.1,
                "{}: axis {a} reached only {widest}",
                integrator.name()
            );
        }
    }
}

#[test]
fn angular_momentum_is_conserved_and_angular_velocity_is_not() {
    for integrator in Integrator::ALL {
        let (mut w, id) = spinning_box(
            integrator,
            Vec3::new(0.3, 4.0, 1.0),
            Vec3::new(0.2, -0.1, 0.3),
        );
        let l0 = w.diagnostics().angular_momentum;
        let w0 = w.body(id).unwrap().angular_velocity();
        let spin0 = w.body(id).unwrap().angular_momentum();
        let mut omega_change: Real = 0.0;
        for _ in 0..100_000 {
            w.step(1e-3).unwrap();
            omega_change = omega_change.max((w.body(id).unwrap().angular_velocity() - w0).length());
        }
        // The spin part is carried exactly by every method (L̇ = N = 0 adds nothing).
        assert_eq!(
            w.body(id).unwrap().angular_momentum(),
            spin0,
            "{}",
            integrator.name()
        );
        // About the origin, x × p changes by the rounding of x += h v only.
        let l = w.diagnostics().angular_momentum;
        let rel = (l - l0).length() / l0.length();
        // (In f32 the 20 m of travel in 10⁵ additions of h·v costs about a percent.)
        assert!(
            rel < tol(1e-10, 5e-2),
            "{}: |ΔL|/|L| = {rel}",
            integrator.name()
        );
        assert!(
            omega_change > 1.0,
            "{}: ω stayed put ({omega_change})",
            integrator.name()
        );
    }
}
