//! `tumble sweep SCENE --set PATH=V1,V2 ... --metric NAME ...`: every combination of a grid
//! of scene values, run one after another in this process, as a CSV table; with `--ray
//! ADDRESS` the same sweep handed to Python's `python -m tumble.sweep` on a Ray cluster.
//!
//! Paths and metrics are the Python `tumble.sweep`'s (crates/tumble-py/python/tumble/
//! sweep.py), with the same messages, and the table is the same: a run here and a run
//! there load the same patched document with the same loader and step it the same way, so
//! the numbers agree bit for bit (the tests compare them).

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;

use clap::Args;
use serde_json::Value;
use tumble::{BodyKind, Real};
use tumble_scene::RunPlan;

use crate::output::{check_distinct, Target, Writer};
use crate::record::{csv_text, Num};
use crate::Failure;

/// The menu of metrics: `BODY.QUANTITY` (BODY a body's name or index) or a world's.
pub const BODY_METRICS: [&str; 8] = ["x", "y", "z", "vx", "vy", "vz", "speed", "max_y"];
/// Metrics of the whole world.
pub const WORLD_METRICS: [&str; 3] = ["kinetic_energy", "asleep", "time"];

/// Options of `tumble sweep`.
#[derive(Args, Debug)]
pub struct SweepArgs {
    /// Scene: a built-in name (see `tumble scenes`) or a JSON scene file.
    #[arg(value_name = "SCENE")]
    pub scene: String,
    /// A parameter and its values, PATH=V1,V2,... (repeatable). PATH as the loader's errors
    /// name fields: gravity, dt, substeps, bodies[3].restitution, bodies[ball].shape.radius
    /// (a name for an index). Values are JSON (numbers, [x,y,z], strings), split at commas
    /// outside brackets; the first --set varies slowest.
    #[arg(long = "set", value_name = "PATH=V1,V2,...", required = true)]
    pub set: Vec<String>,
    /// A metric measured at the end of each run (repeatable): BODY.x, .y, .z (final
    /// position, m), BODY.vx, .vy, .vz, BODY.speed (final velocity, m/s), BODY.max_y (the
    /// highest y its origin reached, step 0 included), kinetic_energy (J, dynamic bodies),
    /// asleep (dynamic bodies asleep), time (s). BODY is a body's name or index.
    #[arg(long = "metric", value_name = "NAME", required = true)]
    pub metric: Vec<String>,
    /// Seconds per run (default: the scene's duration); steps of the scene's dt, cut as
    /// `tumble run` cuts them.
    #[arg(long, value_name = "SECONDS")]
    pub duration: Option<f64>,
    /// Run on a Ray cluster through Python's `python -m tumble.sweep` (needs the tumble
    /// Python package and ray; `local` starts a local cluster). The interpreter is
    /// $TUMBLE_PYTHON, else python3.
    #[arg(long, value_name = "ADDRESS")]
    pub ray: Option<String>,
    /// Write the table here (CSV) instead of standard output.
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
    /// No progress lines on standard error.
    #[arg(long)]
    pub quiet: bool,
}

/// One combination's outcome: the metrics' values, or the run's one-line error.
type Outcome = Result<Vec<Cell>, String>;

/// A table cell of a metric.
#[derive(Debug, Clone, Copy)]
enum Cell {
    Number(Real),
    Count(usize),
}

/// Runs `tumble sweep`.
pub fn sweep(args: &SweepArgs) -> Result<(), Failure> {
    if let Some(address) = &args.ray {
        return on_ray(args, address);
    }
    let (doc, dir) = document(&args.scene)?;
    let grid = args
        .set
        .iter()
        .map(|s| parse_set(s))
        .collect::<Result<Vec<_>, _>>()?;
    for (path, _) in &grid {
        resolve(&mut doc.clone(), path).map_err(Failure::Input)?;
    }
    let metrics = args
        .metric
        .iter()
        .map(|m| parse_metric(m))
        .collect::<Result<Vec<_>, _>>()?;
    if let Some(d) = args.duration {
        if !(d.is_finite() && d >= 0.0) {
            return Err(Failure::Input(format!(
                "duration: must be a finite number >= 0, got {d}"
            )));
        }
    }
    let mut out = match &args.out {
        Some(path) => {
            let target = Target::file("out", path)?;
            check_distinct(&[&target], &[("scene", Path::new(&args.scene))])?;
            Some(Writer::create(target)?)
        }
        None => None,
    };
    let combos = combinations(&grid);
    let mut text = header(&grid, &args.metric);
    for (k, combo) in combos.iter().enumerate() {
        let outcome = run_one(&doc, &dir, combo, &metrics, args.duration);
        if !args.quiet {
            progress(k + 1, combos.len(), combo, &outcome);
        }
        text.push_str(&row(combo, metrics.len(), &outcome));
    }
    match &mut out {
        Some(w) => w.write(format_args!("{text}"))?,
        None => print!("{text}"),
    }
    if let Some(w) = out {
        w.finish()?;
    }
    Ok(())
}

/// The `--ray` path: the same arguments to `python -m tumble.sweep`.
fn on_ray(args: &SweepArgs, address: &str) -> Result<(), Failure> {
    let python = std::env::var("TUMBLE_PYTHON").unwrap_or_else(|_| "python3".into());
    let mut cmd = Command::new(&python);
    cmd.args(["-m", "tumble.sweep", &args.scene, "--ray", address]);
    for s in &args.set {
        cmd.arg("--set").arg(s);
    }
    for m in &args.metric {
        cmd.arg("--metric").arg(m);
    }
    if let Some(d) = args.duration {
        cmd.arg("--duration").arg(d.to_string());
    }
    if let Some(out) = &args.out {
        cmd.arg("--out").arg(out);
    }
    if args.quiet {
        cmd.arg("--quiet");
    }
    let status = cmd.status().map_err(|e| {
        Failure::Input(format!(
            "ray: cannot start '{python} -m tumble.sweep' (it needs the tumble Python package \
             and ray): {e}"
        ))
    })?;
    match status.code() {
        Some(0) => Ok(()),
        Some(code) => Err(Failure::Reported(u8::try_from(code).unwrap_or(1))),
        None => Err(Failure::Reported(1)),
    }
}

/// The scene's JSON document and the folder its model files are found from.
fn document(scene: &str) -> Result<(Value, PathBuf), Failure> {
    let (text, dir) = match tumble_scene::builtin(scene) {
        Some(json) => (json.to_string(), PathBuf::new()),
        None => {
            let path = Path::new(scene);
            if tumble_scene::FileKind::of(path) != tumble_scene::FileKind::Scene {
                return Err(Failure::Input(format!(
                    "scene: a sweep patches a JSON scene; '{scene}' is a model file"
                )));
            }
            let text = std::fs::read_to_string(path).map_err(|e| {
                Failure::Input(format!(
                    "scene: '{scene}' is neither a built-in scene ({}) nor a readable file ({e})",
                    tumble_scene::builtin_names().join(", ")
                ))
            })?;
            (
                text,
                path.parent().map(Path::to_path_buf).unwrap_or_default(),
            )
        }
    };
    // The loader's own message for text that is not JSON.
    let doc = serde_json::from_str(&text).map_err(|_| match tumble_scene::load_str(&text) {
        Err(e) => Failure::Input(e.to_string()),
        Ok(_) => Failure::Input("scene: invalid JSON".into()),
    })?;
    Ok((doc, dir))
}

/// `PATH=V1,V2,...` as the path and its values.
fn parse_set(s: &str) -> Result<(String, Vec<Value>), Failure> {
    match s.split_once('=') {
        Some((path, values)) if !path.is_empty() && !values.is_empty() => {
            Ok((path.to_string(), split_values(values)))
        }
        _ => Err(Failure::Input(format!(
            "set: expected PATH=V1,V2,..., got '{}'",
            s.escape_default()
        ))),
    }
}

/// Values split at commas outside brackets; each JSON if it parses, else a string.
pub fn split_values(text: &str) -> Vec<Value> {
    let mut pieces = Vec::new();
    let (mut depth, mut start) = (0i32, 0);
    for (i, ch) in text.char_indices() {
        match ch {
            '[' | '{' => depth += 1,
            ']' | '}' => depth -= 1,
            ',' if depth == 0 => {
                pieces.push(&text[start..i]);
                start = i + 1;
            }
            _ => {}
        }
    }
    pieces.push(&text[start..]);
    pieces
        .into_iter()
        .map(|p| {
            let p = p.trim();
            serde_json::from_str(p).unwrap_or_else(|_| Value::String(p.to_string()))
        })
        .collect()
}

/// A path's steps: keys and bracketed indices or names (`bodies[ball].shape.radius`).
fn parse_path(path: &str) -> Result<Vec<String>, String> {
    let bad = || format!("{path}: not a parameter path (write it as bodies[ball].restitution)");
    let mut steps = Vec::new();
    let mut rest = path;
    let mut expect_key = true;
    while !rest.is_empty() {
        if let Some(r) = rest.strip_prefix('[') {
            let end = r.find(']').ok_or_else(bad)?;
            if steps.is_empty() || r[..end].contains('[') {
                return Err(bad());
            }
            steps.push(format!("[{}]", &r[..end]));
            rest = &r[end + 1..];
        } else if let Some(r) = rest.strip_prefix('.') {
            if expect_key {
                return Err(bad());
            }
            expect_key = true;
            rest = r;
        } else {
            let end = rest.find(['.', '[', ']']).unwrap_or(rest.len());
            if !expect_key || end == 0 {
                return Err(bad());
            }
            steps.push(rest[..end].to_string());
            expect_key = false;
            rest = &rest[end..];
        }
    }
    if expect_key || steps.is_empty() {
        return Err(bad());
    }
    Ok(steps)
}

/// The index `token` ([3] or [name]) names in `items`, at `place`.
fn index_of(items: &[Value], place: &str, token: &str) -> Result<usize, String> {
    if let Ok(i) = token.parse::<i64>() {
        return usize::try_from(i)
            .ok()
            .filter(|&i| i < items.len())
            .ok_or_else(|| {
                let n = items.len();
                let what = if n == 1 { "entry" } else { "entries" };
                format!("{place}[{i}]: index out of range ({place} has {n} {what})")
            });
    }
    if let Some(i) = items
        .iter()
        .position(|v| v.get("name").and_then(Value::as_str) == Some(token))
    {
        return Ok(i);
    }
    let field = place.rsplit('.').next().unwrap_or(place);
    let kind = match field {
        "bodies" => "body",
        "forces" => "force",
        "joints" => "joint",
        "models" => "model",
        _ => "entry",
    };
    Err(format!("{place}[{token}]: no {kind} named '{token}'"))
}

/// The field `path` names in `doc`, made if missing (objects on the way too).
fn resolve<'a>(doc: &'a mut Value, path: &str) -> Result<&'a mut Value, String> {
    let steps = parse_path(path)?;
    let mut node = doc;
    let mut place = String::new();
    for (n, step) in steps.iter().enumerate() {
        let next_is_index = steps.get(n + 1).is_some_and(|s| s.starts_with('['));
        let shown = if place.is_empty() { "scene" } else { &place };
        if let Some(token) = step.strip_prefix('[').and_then(|s| s.strip_suffix(']')) {
            let Value::Array(items) = node else {
                return Err(format!("{shown}: not an array, cannot take {step}"));
            };
            let i = index_of(items, &place, token)?;
            place = format!("{place}[{i}]");
            node = &mut items[i];
        } else {
            let Value::Object(map) = node else {
                return Err(format!("{shown}: not an object, cannot take .{step}"));
            };
            place = if place.is_empty() {
                step.clone()
            } else {
                format!("{place}.{step}")
            };
            let fresh = if next_is_index {
                Value::Array(vec![])
            } else {
                Value::Object(Default::default())
            };
            let last = n + 1 == steps.len();
            node = map
                .entry(step.clone())
                .or_insert(if last { Value::Null } else { fresh });
        }
    }
    Ok(node)
}

/// A metric of the menu: (body, quantity), body empty for a world's.
fn parse_metric(name: &str) -> Result<(String, String), Failure> {
    let (body, what) = name.rsplit_once('.').unwrap_or(("", name));
    let ok = if body.is_empty() {
        WORLD_METRICS.contains(&what)
    } else {
        BODY_METRICS.contains(&what)
    };
    if ok {
        Ok((body.to_string(), what.to_string()))
    } else {
        Err(Failure::Input(format!(
            "metric: unknown metric '{}' (expected BODY.QUANTITY with QUANTITY one of {}, or \
             one of {})",
            name.escape_default(),
            BODY_METRICS.join(", "),
            WORLD_METRICS.join(", ")
        )))
    }
}

/// Every combination, the first parameter varying slowest.
fn combinations(grid: &[(String, Vec<Value>)]) -> Vec<Vec<(String, Value)>> {
    let mut combos: Vec<Vec<(String, Value)>> = vec![vec![]];
    for (path, values) in grid {
        combos = combos
            .into_iter()
            .flat_map(|c| {
                values.iter().map(move |v| {
                    let mut c = c.clone();
                    c.push((path.clone(), v.clone()));
                    c
                })
            })
            .collect();
    }
    combos
}

/// One combination: patch, load, step, measure.
fn run_one(
    doc: &Value,
    dir: &Path,
    combo: &[(String, Value)],
    metrics: &[(String, String)],
    duration: Option<f64>,
) -> Outcome {
    let mut doc = doc.clone();
    for (path, value) in combo {
        *resolve(&mut doc, path)? = value.clone();
    }
    let text = serde_json::to_string(&doc).map_err(|e| format!("scene: {e}"))?;
    let mut scene = tumble_scene::load_str_in(&text, dir).map_err(|e| e.to_string())?;
    let length = duration.map_or(scene.duration, |d| d as Real);
    let plan = RunPlan::from_duration(length, scene.dt).map_err(|e| e.to_string())?;
    let world = &mut scene.world;
    let mut max_y: Vec<Real> = world.bodies().map(|(_, b)| b.position().y).collect();
    for k in 1..=plan.steps {
        world
            .step(plan.step_dt(k))
            .map_err(|e| failure_text(k, e))?;
        for ((_, b), m) in world.bodies().zip(max_y.iter_mut()) {
            *m = m.max(b.position().y);
        }
    }
    metrics
        .iter()
        .map(|(body, what)| measure(world, &max_y, body, what))
        .collect()
}

fn failure_text(k: u64, e: tumble::Error) -> String {
    match crate::sample::step_failure(k, e) {
        Failure::Runtime(s) | Failure::Input(s) => s,
        other => format!("{other:?}"),
    }
}

/// One metric of the world at the end of its run.
fn measure(world: &tumble::World, max_y: &[Real], body: &str, what: &str) -> Result<Cell, String> {
    if body.is_empty() {
        return Ok(match what {
            "kinetic_energy" => Cell::Number(world.diagnostics().kinetic),
            "asleep" => Cell::Count(
                world
                    .bodies()
                    .filter(|(_, b)| b.kind() == BodyKind::Dynamic && !b.is_awake())
                    .count(),
            ),
            _ => Cell::Number(world.time()),
        });
    }
    let count = world.body_count();
    let i = match body.parse::<usize>() {
        Ok(i) if i < count => i,
        Ok(i) => {
            return Err(format!(
                "metric: bodies[{i}]: index out of range ({count} bodies)"
            ))
        }
        Err(_) => world
            .bodies()
            .position(|(_, b)| b.name() == Some(body))
            .ok_or_else(|| format!("metric: no body named '{body}'"))?,
    };
    let b = world
        .bodies()
        .nth(i)
        .map(|(_, b)| b)
        .expect("index checked");
    let (p, v) = (b.position(), b.linear_velocity());
    Ok(Cell::Number(match what {
        "x" => p.x,
        "y" => p.y,
        "z" => p.z,
        "vx" => v.x,
        "vy" => v.y,
        "vz" => v.z,
        "speed" => v.length(),
        _ => max_y[i],
    }))
}

fn header(grid: &[(String, Vec<Value>)], metrics: &[String]) -> String {
    let names: Vec<_> = grid
        .iter()
        .map(|(p, _)| p.as_str())
        .chain(metrics.iter().map(String::as_str))
        .chain(["error"])
        .map(|s| csv_text(s).into_owned())
        .collect();
    names.join(",") + "\n"
}

fn value_cell(v: &Value) -> String {
    match v {
        Value::String(s) => csv_text(s).into_owned(),
        Value::Null => String::new(),
        other => csv_text(&other.to_string()).into_owned(),
    }
}

fn row(combo: &[(String, Value)], metrics: usize, outcome: &Outcome) -> String {
    let mut cells: Vec<String> = combo.iter().map(|(_, v)| value_cell(v)).collect();
    match outcome {
        Ok(values) => {
            cells.extend(values.iter().map(|c| match c {
                Cell::Number(x) => Num(*x).to_string(),
                Cell::Count(n) => n.to_string(),
            }));
            cells.push(String::new());
        }
        Err(e) => {
            cells.extend(std::iter::repeat_n(String::new(), metrics));
            cells.push(csv_text(e).into_owned());
        }
    }
    cells.join(",") + "\n"
}

fn progress(done: usize, total: usize, combo: &[(String, Value)], outcome: &Outcome) {
    let params: Vec<String> = combo.iter().map(|(p, v)| format!("{p}={v}")).collect();
    let status = match outcome {
        Ok(_) => "ok".to_string(),
        Err(e) => format!("error: {e}"),
    };
    let _ = writeln!(
        std::io::stderr(),
        "[{done}/{total}] {}: {status}",
        params.join(", ")
    );
}
