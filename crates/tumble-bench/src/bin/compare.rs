//! Runs each scene in Tumble and in rapier3d (f64 and f32) in the same process and prints
//! ms per step, the pyramid's drift and the ratio Tumble / rapier at Tumble's precision.
//!
//! ```sh
//! cargo run --release -p tumble-bench --bin compare                       # Tumble f64
//! cargo run --release -p tumble-bench --bin compare --features tumble/f32 # Tumble f32
//! cargo run --release -p tumble-bench --bin compare -- --scene rain --repeats 3
//! ```
//!
//! Every engine first steps the pyramid 30 times untimed (warm-up). Then, with
//! `--repeats N` (default 3), every engine runs each scene N times, interleaved (Tumble,
//! rapier f64, rapier f32, Tumble, ...) so background load hits them alike; the figures
//! printed are medians over the N runs of each run's mean ms per step. Building a world is
//! never timed.

use std::process::ExitCode;
use tumble_bench::{
    count_rain, measure_pyramid, median, pyramid, rain, rapier_f32, rapier_f64, timed_steps,
    tumble_engine, SceneSpec, Simulation, PYRAMID_SETTLE_STEPS, PYRAMID_TIMED_STEPS,
    RAIN_TIMED_STEPS,
};

const USAGE: &str = "usage: compare [--scene pyramid|rain|all] [--repeats N] [--no-other-precision]

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
        scenes: vec!["pyramid", "rain"],
        repeats: 3,
        other_precision: true,
    };
    let mut it = args.iter();
    while let Some(a) = it.next() {
        match a.as_str() {
            "--scene" => {
                o.scenes = match it.next().map(String::as_str) {
                    Some("pyramid") => vec!["pyramid"],
                    Some("rain") => vec!["rain"],
                    Some("all") => vec!["pyramid", "rain"],
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
    let timing = if scene == "pyramid" {
        let r = measure_pyramid(sim.as_mut(), PYRAMID_SETTLE_STEPS, PYRAMID_TIMED_STEPS);
        row.note = format!(
            "drift {:.2} mm (from t = 0: {:.2} mm)",
            r.drift * 1e3,
            r.drift_from_start * 1e3
        );
        r.timing
    } else {
        let t = timed_steps(sim.as_mut(), RAIN_TIMED_STEPS);
        let c = count_rain(&sim.dynamic_positions());
        row.note = format!(
            "inside {} / outside {} / off floor {}",
            c.inside, c.outside, c.off_floor
        );
        t
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
         where the bodies are after them",
        PYRAMID_SETTLE_STEPS + PYRAMID_TIMED_STEPS
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
        let spec = if *scene == "pyramid" {
            pyramid()
        } else {
            rain()
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
