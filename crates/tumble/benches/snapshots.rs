//! Snapshot and restore cost against one step's (issue 18): the settled 385-box pyramid
//! and the 2,000-body rain mid-landing, on one thread. Run with
//! `cargo bench -p tumble --bench snapshots`.
//!
//! Rollback of several frames per frame is practical when a snapshot plus a restore cost
//! less than a step.

use criterion::{criterion_group, criterion_main, Criterion};
use std::time::Duration;
use tumble::prelude::*;

fn world() -> World {
    World::try_new(&WorldDef {
        gravity: Vec3::new(0.0, -9.81, 0.0),
        sleep: false,
        threads: Some(1),
        ..Default::default()
    })
    .expect("valid settings")
}

fn fixed(position: Vec3) -> BodyDef {
    BodyDef {
        kind: BodyKind::Static,
        position,
        ..Default::default()
    }
}

/// 385 unit boxes in a square pyramid with a 10×10 base (as tumble-bench's `pyramid`),
/// settled for 2 s.
fn pyramid() -> World {
    let mut w = world();
    w.create_body(&fixed(Vec3::ZERO), Shape::plane(Vec3::Y, 0.0))
        .unwrap();
    for k in 0..10 {
        let n = 10 - k;
        let first = -0.5 * (n as Real - 1.0);
        for i in 0..n {
            for j in 0..n {
                let p = Vec3::new(first + i as Real, 0.5 + k as Real, first + j as Real);
                let def = BodyDef {
                    position: p,
                    ..Default::default()
                };
                w.create_body(&def, Shape::cuboid(Vec3::splat(0.5)))
                    .unwrap();
            }
        }
    }
    for _ in 0..200 {
        w.step(1.0 / 60.0).unwrap();
    }
    w
}

/// 1,000 balls and 1,000 boxes (0.25 m) in a 10 × 10 × 20 grid falling into a walled
/// 10 m box (as tumble-bench's `rain`, without its jitter), 1.5 s in: landing.
fn rain() -> World {
    let mut w = world();
    w.create_body(
        &fixed(Vec3::new(0.0, -0.5, 0.0)),
        Shape::cuboid(Vec3::new(20.0, 0.5, 20.0)),
    )
    .unwrap();
    for (x, z, hx, hz) in [
        (-5.25, 0.0, 0.25, 5.5),
        (5.25, 0.0, 0.25, 5.5),
        (0.0, -5.25, 5.0, 0.25),
        (0.0, 5.25, 5.0, 0.25),
    ] {
        w.create_body(
            &fixed(Vec3::new(x, 1.5, z)),
            Shape::cuboid(Vec3::new(hx, 1.5, hz)),
        )
        .unwrap();
    }
    for layer in 0..20 {
        for i in 0..10 {
            for j in 0..10 {
                let p = Vec3::new(
                    -4.5 + i as Real,
                    4.0 + 0.9 * layer as Real,
                    -4.5 + j as Real,
                );
                let def = BodyDef {
                    position: p,
                    orientation: Quat::from_rotation_z(0.1 * (i + j) as Real),
                    ..Default::default()
                };
                let shape = if (i + j + layer) % 2 == 0 {
                    Shape::sphere(0.25)
                } else {
                    Shape::cuboid(Vec3::splat(0.25))
                };
                w.create_body(&def, shape).unwrap();
            }
        }
    }
    for _ in 0..90 {
        w.step(1.0 / 60.0).unwrap();
    }
    w
}

fn bench(c: &mut Criterion) {
    for (name, mut w) in [("pyramid", pyramid()), ("rain", rain())] {
        let bytes = w.snapshot();
        println!(
            "{name}: {} bodies, {} contacts, snapshot {} bytes",
            w.body_ids().len(),
            w.contacts().len(),
            bytes.len()
        );
        let mut g = c.benchmark_group(name);
        g.sample_size(20).measurement_time(Duration::from_secs(4));
        g.bench_function("step", |b| {
            b.iter(|| {
                w.restore(&bytes).unwrap();
                w.step(1.0 / 60.0).unwrap();
            })
        });
        g.bench_function("snapshot", |b| b.iter(|| w.snapshot()));
        g.bench_function("restore", |b| b.iter(|| w.restore(&bytes).unwrap()));
        g.bench_function("snapshot_and_restore", |b| {
            b.iter(|| {
                let s = w.snapshot();
                w.restore(&s).unwrap();
            })
        });
        g.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
