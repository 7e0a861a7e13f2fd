//! Runs each scene in Tumble and in rapier3d (f64 and f32) in the same process and prints
//! ms per step, a quality check of each run beside it (the pyramids' drift, where the
//! rain landed, the joint grid's largest joint gap and lowest point), the thread count
//! each engine stepped on, and the ratio Tumble / rapier at Tumble's precision.
//!
//! ```sh
//! cargo run --release -p tumble-bench --bin compare                       # Tumble f64
//! cargo run --release -p tumble-bench --bin compare --features tumble/f32 # Tumble f32
//! cargo run --release -p tumble-bench --bin compare -- --scene rain --repeats 3
//! cargo run --release -p tumble-bench --bin compare -- --scene joints
//! cargo run --release -p tumble-bench --bin compare -- --scale            # Box3D's sizes
//! cargo run --release -p tumble-bench --bin compare -- --scale --threads 2
//! ```
//!
//! `all` (the default) runs the three small scenes, `--scale` (or `--scene scale`) the
//! four large ones of [`tumble_bench::scale`]. `--threads N` (default: `TUMBLE_THREADS`,
//! else 1) steps Tumble on N threads (`WorldDef::threads`) and rapier on N (its
//! `parallel` feature, each step run inside a rayon pool of N threads); the `thr` column
//! is the count each engine reported from where its step runs.
//!
//! Every engine first steps the pyramid 30 times untimed (warm-up). Then, with
//! `--repeats N` (default 3), every engine runs each scene N times, interleaved (Tumble,
//! rapier f64, rapier f32, Tumble, ...) so background load hits them alike; the figures
//! printed are medians over the N runs of each run's mean ms per step, and the check is
//! the last run's. Building a world is
//! never timed.

use std::process::ExitCode;
use tumble_bench::scenes::{self, SCALE_SCENES as SCALE, SMALL_SCENES as SCENES};
use tumble_bench::{median, pyramid, rapier_f32, rapier_f64, tumble_engine, SceneSpec, Simulation};

const USAGE: &str =
    "usage: compare [--scene NAME|all|scale] [--scale] [--threads N] [--repeats N] \
     [--no-other-precision] [--rapier-substeps N]

  --scene S              run one scene: pyramid, rain, joints, large_pyramid, many_pyramids,
                         joint_grid_large, rain_large; or all (the three small ones, the
                         default) or scale (the four large ones)
  --scale                the same as --scene scale
  --threads N            threads for Tumble and for rapier alike (default: TUMBLE_THREADS, else 1)
  --repeats N            runs per engine and scene, interleaved; medians are printed (default 3)
  --no-other-precision   skip rapier at the precision Tumble was not built with
  --rapier-substeps N    rapier's substeps (default 4, Tumble's): to time it at the
                         substeps that hold a tall stack as still as Tumble's finer ones";

/// Untimed pyramid steps each engine takes before the first measurement.
const WARMUP_STEPS: usize = 30;

struct Options {
    scenes: Vec<&'static str>,
    repeats: usize,
    other_precision: bool,
    threads: usize,
}

/// The scenes `--scene name` selects.
fn scenes_named(name: Option<&str>) -> Result<Vec<&'static str>, String> {
    match name {
        Some("all") => Ok(SCENES.to_vec()),
        Some("scale") => Ok(SCALE.to_vec()),
        Some(name) => SCENES
            .iter()
            .chain(&SCALE)
            .find(|s| **s == name)
            .map(|s| vec![*s])
            .ok_or_else(|| format!("--scene: unknown scene {name:?}")),
        None => Err("--scene: expected a scene name".into()),
    }
}

/// A whole number >= 1 after `flag`.
fn count(flag: &str, text: Option<&String>) -> Result<usize, String> {
    text.and_then(|n| n.trim().parse().ok())
        .filter(|n| *n >= 1)
        .ok_or_else(|| match text {
            Some(t) => format!("{flag}: expected a whole number >= 1, got {t:?}"),
            None => format!("{flag}: expected a whole number >= 1"),
        })
}

fn parse(args: &[String]) -> Result<Options, String> {
    let threads = tumble::threads::threads_from_env()
        .map_err(|e| e.to_string())?
        .unwrap_or(1);
    let mut o = Options {
        scenes: SCENES.to_vec(),
        repeats: 3,
        other_precision: true,
        threads,
    };
    let mut it = args.iter();
    while let Some(a) = it.next() {
        match a.as_str() {
            "--scene" => o.scenes = scenes_named(it.next().map(String::as_str))?,
            "--scale" => o.scenes = SCALE.to_vec(),
            "--threads" => {
                o.threads = count("--threads", it.next())?;
                if o.threads > tumble::threads::MAX_THREADS {
                    return Err(format!(
                        "--threads: at most {}, got {}",
                        tumble::threads::MAX_THREADS,
                        o.threads
                    ));
                }
            }
            "--repeats" => o.repeats = count("--repeats", it.next())?,
            "--no-other-precision" => o.other_precision = false,
            "--rapier-substeps" => {
                let n = count("--rapier-substeps", it.next())?;
                tumble_bench::set_rapier_substeps(n.min(1024) as u32);
            }
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
    fn build(self, spec: &SceneSpec, threads: usize) -> Box<dyn Simulation> {
        match self {
            Engine::Tumble => Box::new(tumble_engine::build_with_threads(spec, threads)),
            Engine::RapierF64 => Box::new(rapier_f64::build_with_threads(spec, threads)),
            Engine::RapierF32 => Box::new(rapier_f32::build_with_threads(spec, threads)),
        }
    }
}

/// What one engine did on one scene over the repeats.
#[derive(Default)]
struct Row {
    engine: &'static str,
    precision: &'static str,
    threads: usize,
    means: Vec<f64>,
    medians: Vec<f64>,
    note: String,
}

fn run_once(scene: &str, spec: &SceneSpec, engine: Engine, threads: usize, row: &mut Row) {
    let mut sim = engine.build(spec, threads);
    row.engine = sim.engine();
    row.precision = sim.precision();
    row.threads = sim.threads();
    let window = scenes::window(scene).expect("a known scene");
    let (timing, note) = scenes::measure(window, sim.as_mut());
    row.note = note;
    row.means.push(timing.mean());
    row.medians.push(timing.median());
}

/// Runs `scene` `repeats` times in every engine, interleaved, and prints its rows.
fn run_scene(scene: &str, engines: &[Engine], options: &Options) {
    let spec = scenes::scene_named(scene).expect("a known scene");
    let mut rows: Vec<Row> = engines.iter().map(|_| Row::default()).collect();
    for _ in 0..options.repeats {
        for (engine, row) in engines.iter().zip(rows.iter_mut()) {
            run_once(scene, &spec, *engine, options.threads, row);
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
            "{:<16} {:<9} {:<4} {:>3} {:>9.3} {:>11.3} {:>14}  {}",
            scene,
            row.engine,
            row.precision,
            row.threads,
            median(&row.means),
            median(&row.medians),
            ratio,
            row.note
        );
    }
}

fn print_header(options: &Options) {
    let rapier_threads =
        tumble_bench::rayon_pool(options.threads).install(rayon::current_num_threads);
    println!(
        "rapier3d {}, threads: Tumble {} (WorldDef::threads), rapier {} (rayon::current_num_threads() \
         in the pool its steps run in); dt = 1/60 s, {} substeps (rapier {}); {} run(s) per \
         engine; ms/step = median over runs of each run's mean (and of its median step)",
        rapier3d::VERSION,
        options.threads,
        rapier_threads,
        tumble_bench::SUBSTEPS,
        tumble_bench::rapier_substeps(),
        options.repeats
    );
    for scene in &options.scenes {
        let spec = scenes::scene_named(scene).expect("a known scene");
        println!(
            "{scene}: {} dynamic bodies, {} joints; {}",
            spec.dynamic_count(),
            spec.joints.len(),
            scenes::describe(scenes::window(scene).expect("a known scene"))
        );
    }
    println!();
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
    print_header(&options);
    for engine in &engines {
        let mut sim = engine.build(&pyramid(), options.threads);
        for _ in 0..WARMUP_STEPS {
            sim.step();
        }
    }
    println!(
        "{:<16} {:<9} {:<4} {:>3} {:>9} {:>11} {:>14}  check",
        "scene", "engine", "prec", "thr", "ms/step", "median-step", "Tumble/rapier"
    );
    for scene in &options.scenes {
        run_scene(scene, &engines, &options);
    }
    ExitCode::SUCCESS
}
