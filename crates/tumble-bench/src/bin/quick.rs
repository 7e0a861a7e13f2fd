//! Tumble alone on one scene, for quick before/after timings while optimising (the full
//! `compare` takes minutes because it runs rapier too). Prints ms per step (median over
//! runs of each run's mean), the pyramid drift or rain count, and a checksum of the final
//! positions, so a change that alters results beyond rounding shows at once.
//!
//! ```sh
//! cargo run --release -p tumble-bench --bin quick -- pyramid 5   # or rain, landing, joints
//! ```
//!
//! `landing` is the rain's steps 30–90 (as the criterion bench `peers` times them: the
//! bodies land and pile), with the checksum at step 90.

use tumble_bench::{
    count_rain, joint_grid, measure_joint_grid, measure_pyramid, median, pyramid, rain,
    timed_steps, tumble_engine, Simulation, JOINT_GRID_SETTLE_STEPS, JOINT_GRID_TIMED_STEPS,
    PYRAMID_SETTLE_STEPS, PYRAMID_TIMED_STEPS, RAIN_TIMED_STEPS,
};

/// The landing window: steps skipped, then timed (the criterion bench's `RAIN_SKIP` and
/// `RAIN_TIMED`).
const LANDING_SKIP: usize = 30;
const LANDING_TIMED: usize = 60;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let scene = args.first().map(String::as_str).unwrap_or("pyramid");
    let runs: usize = args.get(1).and_then(|n| n.parse().ok()).unwrap_or(3);
    let mut means = Vec::new();
    for _ in 0..runs {
        let (mean, note, positions) = if scene == "joints" {
            let mut sim = tumble_engine::build(&joint_grid());
            let r = measure_joint_grid(&mut sim, JOINT_GRID_SETTLE_STEPS, JOINT_GRID_TIMED_STEPS);
            let note = format!("gap {:.2} mm", r.max_gap * 1e3);
            (r.timing.mean(), note, sim.dynamic_positions())
        } else if scene == "landing" {
            let mut sim = tumble_engine::build(&rain());
            for _ in 0..LANDING_SKIP {
                sim.step();
            }
            let t = timed_steps(&mut sim, LANDING_TIMED);
            (t.mean(), String::new(), sim.dynamic_positions())
        } else if scene == "rain" {
            let mut sim = tumble_engine::build(&rain());
            let t = timed_steps(&mut sim, RAIN_TIMED_STEPS);
            let p = sim.dynamic_positions();
            let c = count_rain(&p);
            let note = format!(
                "inside {} outside {} off {}",
                c.inside, c.outside, c.off_floor
            );
            (t.mean(), note, p)
        } else {
            let mut sim = tumble_engine::build(&pyramid());
            let r = measure_pyramid(&mut sim, PYRAMID_SETTLE_STEPS, PYRAMID_TIMED_STEPS);
            let note = format!("drift {:.4} mm", r.drift * 1e3);
            (r.timing.mean(), note, sim.dynamic_positions())
        };
        let sum: f64 = positions.iter().flatten().map(|x| x.abs()).sum();
        println!("{scene}: {mean:.3} ms/step  {note}  checksum {sum:.9}");
        means.push(mean);
    }
    println!("{scene}: median {:.3} ms/step", median(&means));
}
