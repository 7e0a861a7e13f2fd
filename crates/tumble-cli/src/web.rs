//! `tumble export-html` and `tumble view`: one self-contained page that plays a run in a
//! browser. The viewer (viewer/, three.js bundled by esbuild) is compiled into the binary,
//! and the run is recorded into the page as JSON, so the file opens with no network.

use std::io::{BufRead, BufReader, Write};
use std::net::{TcpListener, TcpStream};
use std::path::PathBuf;

use clap::Args;
use serde_json::{json, Value};
use tumble::{BodyKind, Real, World};
use tumble_render::mesh::Geometry;
use tumble_render::{Camera, Model, Rgb, Snapshot, BACKGROUND};
use tumble_scene::{RunPlan, Scene, SceneError};

use crate::args::{number, whole};
use crate::output::{check_distinct, inputs, scene_file, Target, Writer};
use crate::progress::Progress;
use crate::sample::{frame_count, run_frames};
use crate::Failure;

/// The built viewer (`npm run build` in viewer/; committed, so cargo needs no node).
pub const VIEWER_JS: &str = include_str!("../../../viewer/dist/viewer.js");
/// The page around it.
const PAGE: &str = include_str!("../../../viewer/src/page.html");
/// The most frames a page holds: beyond this the file grows past tens of megabytes.
const MAX_FRAMES: u64 = 20_000;

/// Options shared by `tumble export-html` and `tumble view`.
#[derive(Args, Debug)]
pub struct PageArgs {
    /// Scene: a built-in name (see `tumble scenes`), a JSON scene file, or a URDF model
    /// (`.urdf`: z-up gravity, base fixed).
    #[arg(value_name = "SCENE")]
    pub scene: String,

    /// Simulated time to record, in seconds (s); default: the scene's `duration`.
    #[arg(long, value_name = "SECONDS", allow_negative_numbers = true, value_parser = number)]
    pub duration: Option<Real>,

    /// Frames recorded per second of simulated time.
    #[arg(
        long,
        value_name = "N",
        default_value_t = 30.0,
        allow_negative_numbers = true,
        value_parser = number
    )]
    pub fps: Real,

    /// Threads the steps run on (default: TUMBLE_THREADS, else every core); results are
    /// bit-identical for every count.
    #[arg(long, value_name = "N", allow_negative_numbers = true, value_parser = crate::args::threads)]
    pub threads: Option<usize>,

    /// Show no progress bar and print nothing on standard output but the address
    /// (`view`).
    #[arg(long, short)]
    pub quiet: bool,
}

/// Options of `tumble export-html`.
#[derive(Args, Debug)]
pub struct ExportArgs {
    #[command(flatten)]
    pub page: PageArgs,

    /// The HTML file to write (as FILE.html.partial, renamed when complete).
    #[arg(long, value_name = "FILE.html")]
    pub out: PathBuf,
}

/// Options of `tumble view`.
#[derive(Args, Debug)]
pub struct ViewArgs {
    #[command(flatten)]
    pub page: PageArgs,

    /// Port on 127.0.0.1 to serve on; 0 picks a free one.
    #[arg(
        long,
        default_value_t = 0,
        allow_negative_numbers = true,
        value_parser = |t: &str| whole(t, 0, 65535).map(|p| p as u16)
    )]
    pub port: u16,

    /// Do not open a browser; only print the address.
    #[arg(long)]
    pub no_open: bool,

    /// Serve this many requests, then stop (for scripts and tests; default: until
    /// interrupted).
    #[arg(long, value_name = "N", hide = true, value_parser = |t: &str| whole(t, 1, u64::MAX))]
    pub requests: Option<u64>,
}

/// `tumble export-html`. The path is checked, and its partial file created, before the
/// run; a step that fails ends the run, and the page plays it up to the last good frame
/// (exit 1).
pub fn export(args: &ExportArgs) -> Result<(), Failure> {
    let target = Target::file("out", &args.out)?;
    check_distinct(&[&target], &inputs(&scene_file(&args.page.scene)))?;
    let mut out = Writer::create(target)?;
    let (html, stopped) = page(&args.page)?;
    out.write(format_args!("{html}"))?;
    let shown = out.target().shown().to_string();
    out.finish()?;
    if !args.page.quiet {
        writeln!(
            std::io::stdout(),
            "wrote '{shown}' ({} kB, opens offline in any browser)",
            html.len() / 1024
        )
        .map_err(crate::stdout_failure)?;
    }
    stopped.map_or(Ok(()), Err)
}

/// `tumble view`: serves the page on localhost and opens it. A run that failed part way is
/// served up to its last good frame, its account printed first and the exit status 1.
pub fn view(args: &ViewArgs) -> Result<(), Failure> {
    let (html, stopped) = page(&args.page)?;
    let listener = TcpListener::bind(("127.0.0.1", args.port))
        .map_err(|e| Failure::Input(format!("port: cannot listen on {}: {e}", args.port)))?;
    let address = listener
        .local_addr()
        .map_err(|e| Failure::Input(format!("port: {e}")))?;
    if let Some(Failure::Runtime(line)) = &stopped {
        let _ = writeln!(std::io::stderr(), "{line}");
    }
    let url = format!("http://{address}/");
    let mut out = std::io::stdout();
    writeln!(out, "serving {url} (Ctrl-C to stop)").map_err(crate::stdout_failure)?;
    out.flush().map_err(crate::stdout_failure)?;
    if !args.no_open {
        open_browser(&url);
    }
    for (served, stream) in listener.incoming().enumerate() {
        // One bad connection must not stop the server.
        if let Ok(stream) = stream {
            let _ = respond(stream, &html);
        }
        if args.requests.is_some_and(|n| served as u64 + 1 >= n) {
            break;
        }
    }
    // The account was printed before serving; only the exit status is left to give.
    stopped.map_or(Ok(()), |_| Err(Failure::Reported(1)))
}

fn respond(mut stream: TcpStream, html: &str) -> std::io::Result<()> {
    let mut reader = BufReader::new(&stream);
    let mut request = String::new();
    reader.read_line(&mut request)?;
    // Read the headers too: closing with unread input would reset the connection
    // before the client has read the reply.
    let mut header = String::new();
    while reader.read_line(&mut header)? > 2 {
        header.clear();
    }
    let path = request.split_whitespace().nth(1).unwrap_or("/");
    let (status, body) = if path == "/" || path.starts_with("/?") || path == "/index.html" {
        ("200 OK", html)
    } else {
        ("404 Not Found", "not found")
    };
    let kind = if status.starts_with("200") {
        "text/html; charset=utf-8"
    } else {
        "text/plain"
    };
    write!(
        stream,
        "HTTP/1.1 {status}\r\nContent-Type: {kind}\r\nContent-Length: {}\r\nConnection: close\r\n\r\n{body}",
        body.len()
    )?;
    stream.flush()
}

/// Starts the desktop's browser on `url`, if there is a way to; the address is printed
/// either way.
fn open_browser(url: &str) {
    let opener = if cfg!(target_os = "macos") {
        "open"
    } else if cfg!(target_os = "windows") {
        "explorer"
    } else {
        "xdg-open"
    };
    let _ = std::process::Command::new(opener)
        .arg(url)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn();
}

/// The whole page for the options: run the scene, record it, wrap it with the viewer.
/// The failure of a step, if one ended the run early, comes second.
pub fn page(args: &PageArgs) -> Result<(String, Option<Failure>), Failure> {
    let mut scene = crate::load_scene(&args.scene)?;
    if let Some(n) = args.threads {
        scene
            .world
            .set_threads(n)
            .map_err(|e| Failure::Input(e.to_string()))?;
    }
    if !(args.fps > 0.0 && args.fps <= 1000.0) {
        return Err(SceneError::new("fps", "must be > 0 and <= 1000").into());
    }
    let plan = RunPlan::from_duration(args.duration.unwrap_or(scene.duration), scene.dt)?;
    let frames = frame_count(&plan, args.fps);
    if frames > MAX_FRAMES {
        return Err(SceneError::new(
            "duration",
            format!("{frames} frames at this --fps; a page holds at most {MAX_FRAMES}"),
        )
        .into());
    }
    let (data, stopped) = record(&mut scene, &plan, args)?;
    // Inside <script>, "</" could end the element early; "<\/" means the same in JSON.
    let json = data.to_string().replace("</", "<\\/");
    let title = scene.name.as_deref().unwrap_or(&args.scene);
    let title = title.replace('&', "&amp;").replace('<', "&lt;");
    let html = PAGE
        .replace("{{TITLE}}", &title)
        .replace("{{VIEWER}}", VIEWER_JS)
        .replace("{{DATA}}", &json);
    Ok((html, stopped))
}

/// Rounds for the page: 6 significant digits is more than a screen shows.
#[allow(clippy::unnecessary_cast)] // a no-op in the f64 build
fn r(x: Real) -> Value {
    let x = x as f64;
    if x == 0.0 || !x.is_finite() {
        return json!(0.0);
    }
    let scale = 10f64.powi(5 - x.abs().log10().floor() as i32);
    json!((x * scale).round() / scale)
}

fn v3(out: &mut Vec<Value>, v: tumble::Vec3) {
    out.extend([r(v.x), r(v.y), r(v.z)]);
}

/// The run as the viewer reads it (viewer/src/main.js).
fn record(
    scene: &mut Scene,
    plan: &RunPlan,
    args: &PageArgs,
) -> Result<(Value, Option<Failure>), Failure> {
    let colours: Vec<Option<Rgb>> = scene.body_colors.iter().map(|c| c.map(Rgb)).collect();
    let model = Model::new(&scene.world, &colours, f32::INFINITY);
    let mut times = Vec::new();
    let (mut position, mut orientation, mut velocity, mut omega, mut momentum) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let (mut kinetic, mut potential, mut total, mut l_norm) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut snapshots = Vec::new();
    let mut progress = Progress::new(plan.steps, "recording", args.quiet);
    let stopped = run_frames(scene, plan, args.fps, &mut progress, |world: &World, k| {
        times.push(r(k as Real / args.fps));
        let (mut p, mut q, mut v, mut w, mut l) = (vec![], vec![], vec![], vec![], vec![]);
        for (_, body) in world.bodies() {
            v3(&mut p, body.position());
            let o = body.orientation();
            q.extend([r(o.x), r(o.y), r(o.z), r(o.w)]);
            v3(&mut v, body.linear_velocity());
            v3(&mut w, body.angular_velocity());
            v3(&mut l, body.angular_momentum());
        }
        position.push(Value::Array(p));
        orientation.push(Value::Array(q));
        velocity.push(Value::Array(v));
        omega.push(Value::Array(w));
        momentum.push(Value::Array(l));
        let d = world.diagnostics();
        kinetic.push(r(d.kinetic));
        potential.push(r(d.potential));
        total.push(r(d.total));
        l_norm.push(r(d.angular_momentum.length()));
        // Enough snapshots to frame the run, not all of them.
        if k % 8 == 0 {
            snapshots.push(Snapshot::capture(world));
        }
        Ok(())
    })?;
    snapshots.push(Snapshot::capture(&scene.world));
    progress.finish();

    let (min, max) = model
        .bounds(&snapshots)
        .unwrap_or((glam::Vec3::splat(-1.0), glam::Vec3::splat(1.0)));
    let camera = Camera::framing(min, max, 16, 10);
    let bodies = bodies(scene, &model);
    let data = json!({
        "name": scene.name.clone().unwrap_or_else(|| args.scene.clone()),
        "description": scene.description.clone().unwrap_or_default(),
        "fps": args.fps,
        "background": BACKGROUND.hex(),
        "scale": (max - min).length().max(0.5),
        "camera": {
            "eye": camera.eye.to_array(),
            "target": camera.target.to_array(),
            "fov_degrees": tumble_render::camera::FOV_Y.to_degrees(),
        },
        "bodies": bodies,
        "times": times,
        "frames": {
            "position": position,
            "orientation": orientation,
            "velocity": velocity,
            "omega": omega,
            "angular_momentum": momentum,
        },
        "energy": {
            "kinetic": kinetic,
            "potential": potential,
            "total": total,
            "angular_momentum": l_norm,
        },
    });
    Ok((data, stopped))
}

/// Each body's name, kind, colour and shape (a plane, or its triangles) for the viewer.
fn bodies(scene: &Scene, model: &Model) -> Vec<Value> {
    scene
        .world
        .bodies()
        .zip(&model.bodies)
        .zip(&scene.body_names)
        .map(|(((_, body), m), name)| {
            let kind = match body.kind() {
                BodyKind::Static => "static",
                BodyKind::Kinematic => "kinematic",
                BodyKind::Dynamic => "dynamic",
            };
            let mut b = json!({"name": name, "kind": kind, "color": m.colour.hex()});
            match &m.geometry {
                Geometry::Plane { normal, offset } => {
                    b["plane"] = json!({"normal": normal.to_array(), "offset": offset});
                }
                Geometry::Solid(tris) => {
                    let flat: Vec<Value> = tris
                        .iter()
                        .flatten()
                        .flat_map(|p| p.to_array())
                        .map(|x| r(x as Real))
                        .collect();
                    b["mesh"] = Value::Array(flat);
                }
            }
            b
        })
        .collect()
}
