//! Runs each scene in Tumble and in rapier3d (f64 and f32) in the same process and prints
//! ms per step, a check of each run (the pyramid's drift, where the rain landed, the joint
//! grid's largest joint gap and lowest point) and the ratio Tumble / rapier at Tumble's
//! precision.
//!
//! ```sh
//! cargo run --release -p tumble-bench --bin compare                       # Tumble f64
//! cargo run --release -p tumble-bench --bin compare --features tumble/f32 # Tumble f32
//! cargo run --release -p tumble-bench --bin compare -- --scene rain --repeats 3
//! cargo run --release -p tumble-bench --bin compare -- --scene joints
//! ```
//!
//! Every engine first steps the pyramid 30 times untimed (warm-up). Then, with
//! `--repeats N` (default 3), every engine runs each scene N times, interleaved (Tumble,
//! rapier f64, rapier f32, Tumble, ...) so background load hits them alike; the figures
//! printed are medians over the N runs of each run's mean ms per step. Building a world is
//! never timed.

use std::process::ExitCode;
use tumble_bench::{
    count_rain, joint_grid, measure_joint_grid, measure_pyramid, median, pyramid, rain, rapier_f32,
    rapier_f64, timed_steps, tumble_engine, SceneSpec, Simulation, JOINT_GRID_SETTLE_STEPS,
    JOINT_GRID_TIMED_STEPS, PYRAMID_SETTLE_STEPS, PYRAMID_TIMED_STEPS, RAIN_TIMED_STEPS,
};

/// Every scene, in the order `all` runs them.
const SCENES: [&str; 3] = ["pyramid", "rain", "joints"];

const USAGE: &str =
    "usage: compare [--scene pyramid|rain|joints|all] [--repeats N] [--no-other-precision]

  --scene S              run one scene (default: all)
  --repeats N            runs per engine and scene, interleaved; medians are printed (default 3)
  --no-other-precision   skip rapier at the precision Tumble was not built with";

/// Untimed pyramid steps each engine takes before the first measurement.
const WARMUP_STEPS: usize = 30;

struct Options {
    scenes: Vec<&'static str>,
    repeats: usize,
    other_precision: bool,
}

fn parse(args: &[String]) -> Result<Options, String> {
    let mut o = Options {
        scenes: SCENES.to_vec(),
        repeats: 3,
        other_precision: true,
    };
    let mut it = args.iter();
    while let Some(a) = it.next() {
        match a.as_str() {
            "--scene" => {
                o.scenes = match it.next().map(String::as_str) {
                    Some("all") => SCENES.to_vec(),
                    Some(name) if SCENES.contains(&name) => {
                        SCENES.iter().copied().filter(|s| *s == name).collect()
                    }
                    other => return Err(format!("--scene: unknown scene {other:?}")),
                }
            }
            "--repeats" => {
                o.repeats = it
                    .next()
                    .and_then(|n| n.parse().ok())
                    .filter(|n| *n >= 1)
                    .ok_or("--repeats: expected a whole number >= 1")?
            }
            "--no-other-precision" => o.other_precision = false,
            "-h" | "--help" => return Err(String::new()),
            other => return Err(format!("unknown argument '{other}'")),
        }
    }
    Ok(o)
}

/// One engine at one precision.
#[derive(Clone, Copy, PartialEq)]
enum Engine {
    Tumble,
    RapierF64,
    RapierF32,
}

impl Engine {
    fn build(self, spec: &SceneSpec) -> Box<dyn Simulation> {
        match self {
            Engine::Tumble => Box::new(tumble_engine::build(spec)),
            Engine::RapierF64 => Box::new(rapier_f64::build(spec)),
            Engine::RapierF32 => Box::new(rapier_f32::build(spec)),
        }
    }
}

/// What one engine did on one scene over the repeats.
struct Row {
    engine: &'static str,
    precision: &'static str,
    means: Vec<f64>,
    medians: Vec<f64>,
    note: String,
}

fn run_once(scene: &str, spec: &SceneSpec, engine: Engine, row: &mut Row) {
    let mut sim = engine.build(spec);
    row.engine = sim.engine();
    row.precision = sim.precision();
    let timing = match scene {
        "pyramid" => {
            let r = measure_pyramid(sim.as_mut(), PYRAMID_SETTLE_STEPS, PYRAMID_TIMED_STEPS);
            row.note = format!(
                "drift {:.2} mm (from t = 0: {:.2} mm)",
                r.drift * 1e3,
                r.drift_from_start * 1e3
            );
            r.timing
        }
        "rain" => {
            let t = timed_steps(sim.as_mut(), RAIN_TIMED_STEPS);
            let c = count_rain(&sim.dynamic_positions());
            row.note = format!(
                "inside {} / outside {} / off floor {}",
                c.inside, c.outside, c.off_floor
            );
            t
        }
        _ => {
            let r = measure_joint_grid(
                sim.as_mut(),
                JOINT_GRID_SETTLE_STEPS,
                JOINT_GRID_TIMED_STEPS,
            );
            row.note = format!(
                "max joint gap {:.2} mm, lowest y {:.3} m",
                r.max_gap * 1e3,
                r.lowest_y
            );
            r.timing
        }
    };
    row.means.push(timing.mean());
    row.medians.push(timing.median());
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let options = match parse(&args) {
        Ok(o) => o,
        Err(e) => {
            if !e.is_empty() {
                eprintln!("compare: {e}");
            }
            eprintln!("{USAGE}");
            return ExitCode::from(if e.is_empty() { 0 } else { 2 });
        }
    };
    let tumble_f32 = std::mem::size_of::<tumble::Real>() == 4;
    let (same, other) = if tumble_f32 {
        (Engine::RapierF32, Engine::RapierF64)
    } else {
        (Engine::RapierF64, Engine::RapierF32)
    };
    let mut engines = vec![Engine::Tumble, same];
    if options.other_precision {
        engines.push(other);
    }
    println!(
        "rapier3d {}, one thread, dt = 1/60 s, {} substeps; {} run(s) per engine; \
         ms/step = median over runs of each run's mean (and of its median step)",
        rapier3d::VERSION,
        tumble_bench::SUBSTEPS,
        options.repeats
    );
    println!(
        "pyramid: steps {PYRAMID_SETTLE_STEPS}-{} timed, drift = largest box displacement \
         t = 1 s -> 11 s (and t = 0 -> 11 s);\nrain: first {RAIN_TIMED_STEPS} steps timed, \
         where the bodies are after them;\njoints: steps {JOINT_GRID_SETTLE_STEPS}-{} timed, \
         largest distance between a joint's two anchors and lowest body after them",
        PYRAMID_SETTLE_STEPS + PYRAMID_TIMED_STEPS,
        JOINT_GRID_SETTLE_STEPS + JOINT_GRID_TIMED_STEPS
    );
    println!();
    for engine in &engines {
        let mut sim = engine.build(&pyramid());
        for _ in 0..WARMUP_STEPS {
            sim.step();
        }
    }
    println!(
        "{:<8} {:<9} {:<4} {:>9} {:>11} {:>14}  check",
        "scene", "engine", "prec", "ms/step", "median-step", "Tumble/rapier"
    );
    for scene in &options.scenes {
        let spec = match *scene {
            "pyramid" => pyramid(),
            "rain" => rain(),
            _ => joint_grid(),
        };
        let mut rows: Vec<Row> = engines
            .iter()
            .map(|_| Row {
                engine: "",
                precision: "",
                means: Vec::new(),
                medians: Vec::new(),
                note: String::new(),
            })
            .collect();
        for _ in 0..options.repeats {
            for (engine, row) in engines.iter().zip(rows.iter_mut()) {
                run_once(scene, &spec, *engine, row);
            }
        }
        let tumble_ms = median(&rows[0].means);
        let rapier_ms = median(&rows[1].means);
        for row in &rows {
            let ratio = if row.engine == "Tumble" {
                format!("{:.2}", tumble_ms / rapier_ms)
            } else {
                String::new()
            };
            println!(
                "{:<8} {:<9} {:<4} {:>9.3} {:>11.3} {:>14}  {}",
                scene,
                row.engine,
                row.precision,
                median(&row.means),
                median(&row.medians),
                ratio,
                row.note
            );
        }
    }
    ExitCode::SUCCESS
}
