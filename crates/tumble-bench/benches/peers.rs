//! Criterion benchmarks of the contact scenes beside rapier3d 0.36, in one run: the
//! 385-box pyramid (settled, steady state) and the rain of 2,000 spheres and boxes into a
//! walled container (steps 30–90 of a fresh rain, while the bodies land and pile), both
//! at dt = 1/60 s with 4 substeps, one thread. rapier runs at Tumble's precision (f64, or
//! f32 with `--features tumble/f32`). After each scene the bench prints ms per step for
//! both engines and the ratio Tumble / rapier.
//!
//! ```sh
//! cargo bench -p tumble-bench --bench peers
//! cargo bench -p tumble-bench --bench peers --features tumble/f32
//! ```
//!
//! `compare` (src/bin) runs the same scenes with drift and landing checks and f64 and f32
//! rapier side by side; this bench gives criterion's statistics on the step time alone.

use criterion::{criterion_group, criterion_main, Criterion};
use std::time::{Duration, Instant};
use tumble_bench::{
    pyramid, rain, rapier_f32, rapier_f64, tumble_engine, SceneSpec, Simulation,
    PYRAMID_SETTLE_STEPS,
};

/// Rain steps taken untimed from a fresh scene, then timed, per benchmark iteration.
const RAIN_SKIP: usize = 30;
const RAIN_TIMED: usize = 60;

fn tumble_is_f32() -> bool {
    std::mem::size_of::<tumble::Real>() == 4
}

/// Builds a scene in one engine.
type Builder = fn(&SceneSpec) -> Box<dyn Simulation>;

/// Each engine, by name, with a builder for a scene.
fn engines() -> [(&'static str, Builder); 2] {
    let rapier: Builder = if tumble_is_f32() {
        |s| Box::new(rapier_f32::build(s))
    } else {
        |s| Box::new(rapier_f64::build(s))
    };
    [
        ("Tumble", |s| Box::new(tumble_engine::build(s))),
        ("rapier3d", rapier),
    ]
}

/// Prints each engine's mean ms per step and the ratio.
fn report(scene: &str, ms: &[(&str, f64)]) {
    let precision = if tumble_is_f32() { "f32" } else { "f64" };
    let line: Vec<String> = ms
        .iter()
        .map(|(name, t)| format!("{name} {t:.3} ms/step"))
        .collect();
    println!(
        "{scene} ({precision}): {}; Tumble / rapier3d = {:.2}",
        line.join(", "),
        ms[0].1 / ms[1].1
    );
}

fn bench_pyramid(c: &mut Criterion) {
    let spec = pyramid();
    let mut group = c.benchmark_group("pyramid");
    group.sample_size(20);
    let mut means = Vec::new();
    for (name, build) in engines() {
        let mut sim = build(&spec);
        for _ in 0..PYRAMID_SETTLE_STEPS {
            sim.step();
        }
        let (mut total, mut steps) = (Duration::ZERO, 0u64);
        group.bench_function(name, |b| {
            b.iter_custom(|iters| {
                let start = Instant::now();
                for _ in 0..iters {
                    sim.step();
                }
                let t = start.elapsed();
                (total, steps) = (total + t, steps + iters);
                t
            })
        });
        means.push((name, total.as_secs_f64() * 1e3 / steps as f64));
    }
    group.finish();
    report("pyramid", &means);
}

fn bench_rain(c: &mut Criterion) {
    let spec = rain();
    let mut group = c.benchmark_group("rain");
    group.sample_size(10);
    group.measurement_time(Duration::from_secs(20));
    let mut means = Vec::new();
    for (name, build) in engines() {
        let (mut total, mut steps) = (Duration::ZERO, 0u64);
        group.bench_function(format!("{name} ({RAIN_TIMED} steps)"), |b| {
            b.iter_custom(|iters| {
                let mut t = Duration::ZERO;
                for _ in 0..iters {
                    let mut sim = build(&spec);
                    for _ in 0..RAIN_SKIP {
                        sim.step();
                    }
                    let start = Instant::now();
                    for _ in 0..RAIN_TIMED {
                        sim.step();
                    }
                    t += start.elapsed();
                }
                (total, steps) = (total + t, steps + iters * RAIN_TIMED as u64);
                t
            })
        });
        means.push((name, total.as_secs_f64() * 1e3 / steps as f64));
    }
    group.finish();
    report("rain", &means);
}

criterion_group!(benches, bench_pyramid, bench_rain);
criterion_main!(benches);
