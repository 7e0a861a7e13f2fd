//! The Rust side of the Python overhead benchmark (crates/tumble-py/bench/overhead.py):
//! 1,000 free spheres in a 10 × 10 × 10 grid stepped 1,000 times with dt = 0.01 s, every
//! step's position, orientation, velocity and angular velocity copied out as f64, as
//! Python's `World.simulate` does; then the cost of one step of an empty world.
//!
//! `cargo run --release -p tumble --example simulate_bodies [-- BODIES STEPS REPEATS]`

use std::time::Instant;

use tumble::prelude::*;

fn world(bodies: usize) -> World {
    let mut world = World::new(&WorldDef::default());
    for i in 0..bodies {
        let (x, y, z) = (i % 10, (i / 10) % 10, i / 100);
        let def = BodyDef {
            position: Vec3::new(x as Real, y as Real, z as Real),
            mass: MassSpec::Mass(1.0),
            ..Default::default()
        };
        world
            .create_body(&def, Shape::sphere(0.1))
            .expect("a valid body");
    }
    world
}

/// What `simulate` records per body and frame, as f64.
// The cast is the identity in the default build and widens under `tumble/f32`.
#[allow(clippy::unnecessary_cast)]
fn record(world: &World, out: &mut Vec<f64>) {
    for (_, b) in world.bodies() {
        let (p, q, v, w) = (
            b.position(),
            b.orientation(),
            b.linear_velocity(),
            b.angular_velocity(),
        );
        for x in [
            p.x, p.y, p.z, q.x, q.y, q.z, q.w, v.x, v.y, v.z, w.x, w.y, w.z,
        ] {
            out.push(x as f64);
        }
    }
}

fn main() {
    let args: Vec<usize> = std::env::args()
        .skip(1)
        .map(|a| a.parse().expect("BODIES STEPS REPEATS as whole numbers"))
        .collect();
    let (bodies, steps, repeats) = match args[..] {
        [b, s, r] => (b, s, r),
        _ => (1000, 1000, 3),
    };
    let mut best = f64::INFINITY;
    for _ in 0..repeats {
        let mut w = world(bodies);
        let start = Instant::now();
        let mut out = Vec::with_capacity((steps + 1) * bodies * 13);
        record(&w, &mut out);
        for _ in 0..steps {
            w.step(0.01).expect("a valid step");
            record(&w, &mut out);
        }
        best = best.min(start.elapsed().as_secs_f64());
        std::hint::black_box(&out);
    }
    println!("simulate_s {best:.6}");
    let mut empty = World::new(&WorldDef::default());
    let n = 1_000_000;
    let start = Instant::now();
    for _ in 0..n {
        empty.step(0.01).expect("a valid step");
    }
    println!(
        "empty_step_us {:.4}",
        start.elapsed().as_secs_f64() / n as f64 * 1e6
    );
}
