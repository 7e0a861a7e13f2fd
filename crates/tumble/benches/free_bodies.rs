//! 10,000 free bodies under gravity, springs and drag: the cost of one step for each
//! integrator. Run with `cargo bench -p tumble --bench free_bodies`.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use tumble::prelude::*;

/// Boxes on a 100 x 100 grid, spinning, each tied by a damped spring to its right-hand
/// neighbour (chains of 10) and the first of each chain to a world point.
fn scene(integrator: Integrator) -> World {
    let mut world = World::new(&WorldDef {
        gravity: Vec3::new(0.0, -9.8, 0.0),
        integrator,
        ..Default::default()
    });
    let mut previous = None;
    for i in 0..10_000 {
        let (x, z) = ((i % 100) as Real, (i / 100) as Real);
        let id = world
            .create_body(
                &BodyDef {
                    position: Vec3::new(x, 10.0, z),
                    angular_velocity: Vec3::new(0.3, 2.0 + (i % 7) as Real, 0.1),
                    ..Default::default()
                },
                Shape::cuboid(Vec3::new(0.3, 0.2, 0.1)),
            )
            .expect("valid body");
        let other = match previous {
            Some(p) if i % 10 != 0 => SpringEnd::Body {
                body: p,
                anchor: Vec3::new(0.3, 0.0, 0.0),
            },
            _ => SpringEnd::World(Vec3::new(x, 11.0, z)),
        };
        world
            .add_force(Force::Spring(Spring {
                body: id,
                anchor: Vec3::new(-0.3, 0.0, 0.0),
                other,
                stiffness: 500.0,
                rest_length: 0.5,
                damping: 1.0,
            }))
            .expect("valid spring");
        world
            .add_force(Force::Drag(Drag {
                body: id,
                linear: 0.1,
                quadratic: 0.01,
            }))
            .expect("valid drag");
        previous = Some(id);
    }
    world
}

fn step_10k(c: &mut Criterion) {
    let mut group = c.benchmark_group("step_10k_bodies");
    group.sample_size(20);
    for integrator in Integrator::ALL {
        let mut world = scene(integrator);
        group.bench_function(BenchmarkId::from_parameter(integrator.name()), |b| {
            b.iter(|| world.step(1.0 / 60.0).expect("valid dt"))
        });
    }
    group.finish();
}

criterion_group!(benches, step_10k);
criterion_main!(benches);
