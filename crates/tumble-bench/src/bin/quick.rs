//! Tumble alone on one scene, for quick before/after timings while optimising (the full
//! `compare` takes minutes because it runs rapier too). Prints ms per step (median over
//! runs of each run's mean), the scene's check (as `compare` prints it), and a checksum of
//! the final positions, so a change that alters results beyond rounding shows at once.
//!
//! ```sh
//! cargo run --release -p tumble-bench --bin quick -- pyramid 5   # or rain, landing, joints
//! cargo run --release -p tumble-bench --bin quick -- large_pyramid 1   # or another scale scene
//! ```
//!
//! `landing` is the rain's steps 30–90 (as the criterion bench `peers` times them: the
//! bodies land and pile), with the checksum at step 90. Tumble runs on one thread, or on
//! as many as `TUMBLE_THREADS` asks for.

use std::process::ExitCode;
use tumble_bench::scenes::{self, Check, Window};
use tumble_bench::{median, rain, tumble_engine, Simulation, RAIN_HALF_WIDTH};

/// The landing window: steps skipped, then timed (the criterion bench's `RAIN_SKIP` and
/// `RAIN_TIMED`).
const LANDING: Window = Window {
    settle: 30,
    timed: 60,
    check: Check::Rain(RAIN_HALF_WIDTH),
};

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let scene = args.first().map(String::as_str).unwrap_or("pyramid");
    let runs: usize = args.get(1).and_then(|n| n.parse().ok()).unwrap_or(3);
    let (spec, window) = if scene == "landing" {
        (rain(), LANDING)
    } else {
        match (scenes::scene_named(scene), scenes::window(scene)) {
            (Some(spec), Some(window)) => (spec, window),
            _ => {
                eprintln!("quick: unknown scene {scene:?}");
                return ExitCode::from(2);
            }
        }
    };
    let mut means = Vec::new();
    for _ in 0..runs {
        let mut sim = tumble_engine::build(&spec);
        let (timing, note) = scenes::measure(window, &mut sim);
        let mean = timing.mean();
        let sum: f64 = sim
            .dynamic_positions()
            .iter()
            .flatten()
            .map(|x| x.abs())
            .sum();
        println!("{scene}: {mean:.3} ms/step  {note}  checksum {sum:.9}");
        means.push(mean);
    }
    println!("{scene}: median {:.3} ms/step", median(&means));
    ExitCode::SUCCESS
}
