//! Helpers shared by the physics tests.
#![allow(dead_code)]

use tumble::prelude::*;

/// The tolerance for the build's precision: `f64_tol` normally, `f32_tol` with `--features f32`.
pub fn tol(f64_tol: f64, f32_tol: f64) -> Real {
    if std::mem::size_of::<Real>() == 8 {
        f64_tol as Real
    } else {
        f32_tol as Real
    }
}

/// True in the f32 build.
pub fn single_precision() -> bool {
    std::mem::size_of::<Real>() == 4
}

/// A hinge with nothing on its free axis: no limits, motor, spring or servo.
pub fn free_hinge() -> JointKind {
    JointKind::Hinge {
        limits: None,
        motor: None,
        spring: None,
        servo: None,
    }
}

/// A slider with nothing on its free axis.
pub fn free_slider() -> JointKind {
    JointKind::Slider {
        limits: None,
        motor: None,
        spring: None,
        servo: None,
    }
}

/// A world with the given gravity and integrator.
pub fn world(gravity: Vec3, integrator: Integrator) -> World {
    World::new(&WorldDef {
        gravity,
        integrator,
        ..Default::default()
    })
}

/// A world with the given gravity and sleeping off.
pub fn awake(gravity: Vec3) -> World {
    World::new(&WorldDef {
        gravity,
        sleep: false,
        ..Default::default()
    })
}

/// A world with the given gravity, sleeping off, on a static ground plane y = 0 (default
/// material).
pub fn awake_on_ground(gravity: Vec3) -> World {
    let mut w = awake(gravity);
    let ground = BodyDef {
        kind: BodyKind::Static,
        ..Default::default()
    };
    w.create_body(&ground, Shape::plane(Vec3::Y, 0.0)).unwrap();
    w
}

/// A 1 kg ball of radius 0.1 m at `position`.
pub fn ball(world: &mut World, position: Vec3) -> BodyId {
    world
        .create_body(
            &BodyDef {
                position,
                mass: MassSpec::Mass(1.0),
                ..Default::default()
            },
            Shape::sphere(0.1),
        )
        .unwrap()
}

/// Steps `n` times.
pub fn run(world: &mut World, dt: Real, n: usize) {
    for _ in 0..n {
        world.step(dt).unwrap();
    }
}

/// Complete elliptic integral of the first kind K(k), by the arithmetic–geometric mean
/// (a pendulum's period at amplitude θ₀ is the small-swing one times 2K(sin(θ₀/2))/π).
pub fn elliptic_k(k: f64) -> f64 {
    let (mut a, mut b) = (1.0f64, (1.0 - k * k).sqrt());
    for _ in 0..30 {
        (a, b) = (0.5 * (a + b), (a * b).sqrt());
    }
    std::f64::consts::PI / (2.0 * a)
}
