//! Mass properties against closed forms and independent integrations, and the checks that
//! reject impossible bodies.

// Casts between Real and f64 are no-ops in the default build but needed in the f32 one.
#![allow(clippy::unnecessary_cast)]

use crate::common::*;
use tumble::math::PI;
use tumble::prelude::*;

fn close(a: Mat3, b: Mat3, rel: Real) -> bool {
    let scale = b
        .to_cols_array()
        .iter()
        .fold(0.0 as Real, |m, x| m.max(x.abs()));
    a.to_cols_array()
        .iter()
        .zip(b.to_cols_array())
        .all(|(x, y)| (x - y).abs() <= rel * scale)
}

/// Mass and inertia of a solid of revolution about y, from disk slices of radius ρ(y):
/// dm = ρ_d π ρ² dy, dI_yy = ½ dm ρ², dI_xx = dm (ρ²/4 + y²). Composite Simpson; the
/// integrands are polynomials in y for cylinders and spherical caps, so it is exact
/// up to the quartic term's tiny remainder. Always summed in f64, as a reference.
fn revolve(density: Real, y0: Real, y1: Real, rho2: impl Fn(f64) -> f64) -> (Real, Real, Real) {
    let (density, y0, y1) = (density as f64, y0 as f64, y1 as f64);
    let pi = std::f64::consts::PI;
    let n = 20_000;
    let h = (y1 - y0) / n as f64;
    let (mut m, mut iyy, mut ixx) = (0.0, 0.0, 0.0);
    for i in 0..=n {
        let y = y0 + i as f64 * h;
        let w = if i == 0 || i == n {
            1.0
        } else if i % 2 == 1 {
            4.0
        } else {
            2.0
        };
        let r2 = rho2(y);
        let dm = density * pi * r2;
        m += w * dm;
        iyy += w * 0.5 * dm * r2;
        ixx += w * dm * (r2 / 4.0 + y * y);
    }
    (
        (m * h / 3.0) as Real,
        (iyy * h / 3.0) as Real,
        (ixx * h / 3.0) as Real,
    )
}

#[test]
fn primitives_match_their_closed_forms() {
    let d = 700.0;
    let s = Shape::sphere(0.3).mass_properties(d);
    let m = d * 4.0 / 3.0 * PI * 0.027;
    assert!((s.mass - m).abs() < tol(1e-12, 1e-5) * m);
    assert!(close(
        s.inertia,
        Mat3::from_diagonal(Vec3::splat(0.4 * m * 0.09)),
        tol(1e-14, 1e-6)
    ));

    let b = Shape::cuboid(Vec3::new(0.5, 1.0, 1.5)).mass_properties(d);
    let m = d * 1.0 * 2.0 * 3.0;
    // I_xx = m/12 (h² + w²) with full side lengths 1, 2, 3.
    let expect = Mat3::from_diagonal(Vec3::new(4.0 + 9.0, 1.0 + 9.0, 1.0 + 4.0) * (m / 12.0));
    assert!(
        (b.mass - m).abs() < tol(1e-12, 1e-5) * m && close(b.inertia, expect, tol(1e-14, 1e-6))
    );
}

#[test]
fn capsule_and_cylinder_match_slice_integration() {
    let (d, r, h) = (1200.0, 0.25, 0.6);
    let c = Shape::cylinder(r, h).mass_properties(d);
    let (m, iyy, ixx) = revolve(d, -h, h, |_| (r * r) as f64);
    assert!((c.mass - m).abs() < tol(1e-10, 1e-4) * m);
    assert!(close(
        c.inertia,
        Mat3::from_diagonal(Vec3::new(ixx, iyy, ixx)),
        tol(1e-10, 1e-4)
    ));

    let cap = Shape::capsule(r, h).mass_properties(d);
    let (r64, h64) = (r as f64, h as f64);
    let rho2 = |y: f64| {
        let over = (y.abs() - h64).max(0.0);
        r64 * r64 - over * over
    };
    // Integrate the three pieces separately so Simpson never straddles a kink.
    let parts = [
        revolve(d, -h - r, -h, rho2),
        revolve(d, -h, h, rho2),
        revolve(d, h, h + r, rho2),
    ];
    let (m, iyy, ixx) = parts
        .iter()
        .fold((0.0, 0.0, 0.0), |a, p| (a.0 + p.0, a.1 + p.1, a.2 + p.2));
    assert!(
        (cap.mass - m).abs() < tol(1e-10, 1e-4) * m,
        "{} vs {m}",
        cap.mass
    );
    assert!(
        close(
            cap.inertia,
            Mat3::from_diagonal(Vec3::new(ixx, iyy, ixx)),
            tol(1e-10, 1e-4)
        ),
        "{:?} vs {ixx} {iyy}",
        cap.inertia
    );
}

#[test]
fn compounds_add_with_parallel_axis_shifts_and_rotations() {
    // Two unit cubes side by side are one 2 x 1 x 1 box.
    let cube = Shape::cuboid(Vec3::splat(0.5));
    let child = |x: Real, q: Quat| CompoundChild {
        shape: cube.clone(),
        position: Vec3::new(x, 0.3, 0.0),
        orientation: q,
    };
    let pair = Shape::Compound(vec![
        child(-0.5, Quat::IDENTITY),
        child(0.5, Quat::from_rotation_y(0.7)),
    ]);
    let p = pair.mass_properties(1000.0);
    let long = Shape::cuboid(Vec3::new(1.0, 0.5, 0.5)).mass_properties(1000.0);
    assert!((p.mass - long.mass).abs() < tol(1e-12, 1e-5) * long.mass);
    assert!((p.center - Vec3::new(0.0, 0.3, 0.0)).length() < tol(1e-14, 1e-6));
    // A cube's tensor is isotropic, so the rotated child changes nothing.
    assert!(close(p.inertia, long.inertia, tol(1e-13, 1e-5)));

    // A box rotated 90° about z is the box with x and y extents swapped.
    let turned = Shape::Compound(vec![CompoundChild {
        shape: Shape::cuboid(Vec3::new(0.1, 0.4, 0.2)),
        position: Vec3::new(1.0, 2.0, 3.0),
        orientation: Quat::from_rotation_z(PI / 2.0),
    }])
    .mass_properties(500.0);
    let swapped = Shape::cuboid(Vec3::new(0.4, 0.1, 0.2)).mass_properties(500.0);
    assert!((turned.center - Vec3::new(1.0, 2.0, 3.0)).length() < tol(1e-14, 1e-5));
    assert!(close(turned.inertia, swapped.inertia, tol(1e-13, 1e-5)));
}

#[test]
fn body_mass_can_be_given_scaled_or_overridden() {
    let mut w = World::new(&WorldDef::default());
    let id = w
        .create_body(
            &BodyDef {
                mass: MassSpec::Mass(2.0),
                orientation: Quat::from_rotation_x(0.4),
                ..Default::default()
            },
            Shape::cuboid(Vec3::new(0.3, 0.2, 0.1)),
        )
        .unwrap();
    let b = w.body(id).unwrap();
    assert!((b.mass() - 2.0).abs() < tol(1e-14, 1e-6));
    let i_xx = 2.0 / 3.0 * (0.04 + 0.01);
    assert!((b.inertia_local().x_axis.x - i_xx).abs() < tol(1e-14, 1e-6));
    // World inertia is R I Rᵀ.
    let r = Mat3::from_quat(Quat::from_rotation_x(0.4));
    assert!(close(
        b.inertia_world(),
        r * b.inertia_local() * r.transpose(),
        tol(1e-14, 1e-6)
    ));

    let over = w
        .create_body(
            &BodyDef {
                inertia: Some(InertiaSpec::Principal(Vec3::new(1.0, 2.0, 2.5))),
                center_of_mass: Some(Vec3::new(0.1, 0.0, 0.0)),
                ..Default::default()
            },
            Shape::sphere(0.5),
        )
        .unwrap();
    let b = w.body(over).unwrap();
    assert_eq!(
        b.inertia_local(),
        Mat3::from_diagonal(Vec3::new(1.0, 2.0, 2.5))
    );
    assert_eq!(b.center_of_mass(), Vec3::new(0.1, 0.0, 0.0));
    assert_eq!(b.position(), Vec3::ZERO);
}

#[test]
fn impossible_bodies_are_refused_with_the_field_named() {
    let mut w = World::new(&WorldDef::default());
    let mut err = |def: BodyDef, shape: Shape| w.create_body(&def, shape).unwrap_err().to_string();
    assert_eq!(
        err(BodyDef::default(), Shape::sphere(-1.0)),
        "shape.radius: must be > 0"
    );
    assert_eq!(
        err(BodyDef::default(), Shape::cuboid(Vec3::new(1.0, 0.0, 1.0))),
        "shape.half_extents: every component must be > 0"
    );
    assert_eq!(
        err(BodyDef::default(), Shape::capsule(Real::NAN, 1.0)),
        "shape.radius: must be a finite number"
    );
    assert_eq!(
        err(BodyDef::default(), Shape::Compound(vec![])),
        "shape.children: must not be empty"
    );
    assert_eq!(
        err(
            BodyDef::default(),
            Shape::Compound(vec![CompoundChild {
                shape: Shape::sphere(0.0),
                position: Vec3::ZERO,
                orientation: Quat::IDENTITY
            }])
        ),
        "shape.children[0].shape.radius: must be > 0"
    );
    assert_eq!(
        err(
            BodyDef {
                mass: MassSpec::Mass(0.0),
                ..Default::default()
            },
            Shape::sphere(1.0)
        ),
        "mass: must be > 0"
    );
    assert_eq!(
        err(
            BodyDef {
                mass: MassSpec::Density(-3.0),
                ..Default::default()
            },
            Shape::sphere(1.0)
        ),
        "density: must be > 0"
    );
    assert_eq!(
        err(
            BodyDef {
                orientation: Quat::from_xyzw(0.0, 0.0, 0.0, 0.0),
                ..Default::default()
            },
            Shape::sphere(1.0)
        ),
        "orientation: must be a non-zero quaternion [x, y, z, w]"
    );
    assert_eq!(
        err(
            BodyDef {
                position: Vec3::new(0.0, Real::INFINITY, 0.0),
                ..Default::default()
            },
            Shape::sphere(1.0)
        ),
        "position: must be finite numbers"
    );
    assert!(err(
        BodyDef {
            inertia: Some(InertiaSpec::Principal(Vec3::new(1.0, 1.0, 3.0))),
            ..Default::default()
        },
        Shape::sphere(1.0)
    )
    .starts_with("inertia: violates the triangle inequality"));
    // A rod's tensor with off-diagonal terms (PyBullet's biped2d sliders): principal
    // moments 0.215, 0.215 and zero to rounding, which must not pass as positive.
    let rod = Mat3::from_cols(
        Vec3::new(0.2125, -0.005, 0.0225),
        Vec3::new(-0.005, 0.205, 0.045),
        Vec3::new(0.0225, 0.045, 0.0125),
    );
    assert_eq!(
        err(
            BodyDef {
                inertia: Some(InertiaSpec::Tensor(rod)),
                ..Default::default()
            },
            Shape::sphere(1.0)
        ),
        "inertia: must be positive definite"
    );
    let skewed = Mat3::from_cols(
        Vec3::new(1.0, 0.5, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::new(0.0, 0.0, 1.0),
    );
    assert_eq!(
        err(
            BodyDef {
                inertia: Some(InertiaSpec::Tensor(skewed)),
                ..Default::default()
            },
            Shape::sphere(1.0)
        ),
        "inertia: must be a symmetric 3x3 matrix"
    );
    assert!(err(BodyDef::default(), Shape::sphere(tol(1e-120, 1e-30)))
        .starts_with("shape: mass and inertia come out at 0 kg"));
    let dense = BodyDef {
        mass: MassSpec::Density(tol(1e308, 1e38)),
        ..Default::default()
    };
    assert_eq!(
        err(dense, Shape::sphere(1.0)),
        "density: must be at most 1e15 in magnitude"
    );
    // Within every bound, but the product is a body no step can move.
    let light = BodyDef {
        mass: MassSpec::Density(1e-14),
        ..Default::default()
    };
    assert!(err(light, Shape::sphere(1e-3)).starts_with("density: mass and inertia come out at "));
    // Nothing was created by the failed calls.
    assert_eq!(w.body_count(), 0);
    assert!(
        World::new(&WorldDef::default())
            .step(0.0)
            .unwrap_err()
            .to_string()
            == "dt: must be > 0"
    );
}
