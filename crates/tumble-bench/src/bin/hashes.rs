//! State hashes of every built-in scene under every integrator, and of the benchmark
//! scenes, one line each: the record a refactoring that must not change results is
//! checked against (run before and after, then `diff`).
//!
//! ```sh
//! cargo run --release -p tumble-bench --bin hashes > before.txt
//! TUMBLE_LANES=scalar cargo run --release -p tumble-bench --bin hashes > scalar.txt
//! ```

use tumble::{Integrator, Real};
use tumble_bench::{joint_grid, pyramid, rain, tumble_engine, Simulation};

fn main() {
    for name in tumble_scene::builtin_names() {
        for integrator in Integrator::ALL {
            let mut scene = tumble_scene::load(name).expect("built-in scene loads");
            scene.world.set_integrator(integrator);
            let steps = (scene.duration / scene.dt).ceil() as usize;
            let mut line = format!("{name:16} {:18}", integrator.name());
            for k in 0..steps.min(600) {
                scene.world.step(scene.dt as Real).expect("step");
                if k == 0 || (k + 1) % 100 == 0 {
                    line.push_str(&format!(" {:016x}", scene.world.state_hash()));
                }
            }
            println!("{line}");
        }
    }
    for (name, spec, steps) in [
        ("bench-pyramid", pyramid(), 300),
        ("bench-rain", rain(), 150),
        ("bench-joints", joint_grid(), 150),
    ] {
        let mut sim = tumble_engine::build(&spec);
        let mut line = format!("{name:35}");
        for k in 0..steps {
            sim.step();
            if (k + 1) % 50 == 0 {
                line.push_str(&format!(" {:016x}", sim.world.state_hash()));
            }
        }
        println!("{line}");
    }
}
