//! `tumble render SCENE --out FILE`: pictures of a run, with no display and no GPU.

use std::io::Write;
use std::path::PathBuf;

use clap::Args;
use glam::Vec3;
use tumble::Real;
use tumble_render::encode::frame_name;
use tumble_render::{Camera, Encoder, Model, Output, Overlays, Renderer, Rgb, Snapshot};
use tumble_scene::{printable, RunPlan, SceneError};

use crate::args::{number, whole_u32};
use crate::output::{check_distinct, inputs, scene_file, Staged, StagedFolder, Target};
use crate::progress::Progress;
use crate::sample::{frame_count, run_frames};
use crate::Failure;

/// The most frames one command draws (an hour at 30 fps).
const MAX_FRAMES: u64 = 108_000;

/// Options of `tumble render`.
#[derive(Args, Debug)]
pub struct RenderArgs {
    /// Scene: a built-in name (see `tumble scenes`), a JSON scene file, or a URDF model
    /// (`.urdf`: z-up gravity, base fixed).
    #[arg(value_name = "SCENE")]
    pub scene: String,

    /// Where to write: FILE.gif (animation), FILE.png (one picture of the state at the end
    /// of --duration; --duration 0 for the initial state), FILE.mp4 (needs ffmpeg on the
    /// PATH), or a folder (a path with no extension, or an existing directory) of numbered
    /// PNG frames frame_00000.png, frame_00001.png, ... A file is written as FILE.partial
    /// and renamed when complete; frames go into FOLDER/frames.partial/ first.
    #[arg(long, value_name = "PATH")]
    pub out: PathBuf,

    /// Simulated time to show, in seconds (s); default: the scene's `duration`.
    #[arg(long, value_name = "SECONDS", allow_negative_numbers = true, value_parser = number)]
    pub duration: Option<Real>,

    /// Frames per second of simulated time (and of playback).
    #[arg(
        long,
        value_name = "N",
        default_value_t = 30.0,
        allow_negative_numbers = true,
        value_parser = number
    )]
    pub fps: Real,

    /// Picture width in pixels.
    #[arg(long, value_name = "PX", default_value_t = 480, allow_negative_numbers = true, value_parser = pixels)]
    pub width: u32,

    /// Picture height in pixels.
    #[arg(long, value_name = "PX", default_value_t = 360, allow_negative_numbers = true, value_parser = pixels)]
    pub height: u32,

    /// Eye position x,y,z (m, world frame). Default: framing every moving body over the
    /// whole run, seen from +z, a little to the right and above, with up against gravity
    /// (+y without gravity; a URDF model's +z, when it is seen from −y).
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    pub camera: Option<String>,

    /// Point the camera looks at, x,y,z (m). Default: the middle of the moving bodies'
    /// reach over the run.
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true)]
    pub target: Option<String>,

    /// Mark contact points (red dots).
    #[arg(long)]
    pub contacts: bool,

    /// Draw joints: a line between the two anchors and the joint axis (orange).
    #[arg(long)]
    pub joints: bool,

    /// Print nothing on standard output and show no progress bar.
    /// Threads the steps run on (default: TUMBLE_THREADS, else every core); results are
    /// bit-identical for every count.
    #[arg(long, value_name = "N", allow_negative_numbers = true, value_parser = crate::args::threads)]
    pub threads: Option<usize>,

    #[arg(long, short)]
    pub quiet: bool,
}

/// A point given on the command line as `x,y,z`.
pub fn parse_point(field: &str, text: &str) -> Result<Vec3, SceneError> {
    let parts: Vec<Option<f32>> = text
        .split(',')
        .map(|p| p.trim().parse::<f32>().ok().filter(|x| x.is_finite()))
        .collect();
    match parts[..] {
        [Some(x), Some(y), Some(z)] => Ok(Vec3::new(x, y, z)),
        _ => Err(SceneError::new(
            field,
            format!("expected three numbers x,y,z, got '{}'", printable(text)),
        )),
    }
}

/// `--width`, `--height`.
fn pixels(text: &str) -> Result<u32, String> {
    whole_u32(text, 16, 8192)
}

/// The options checked before anything runs.
struct Checked {
    output: Output,
    target: Target,
    plan: RunPlan,
    frames: u64,
    eye: Option<Vec3>,
    look_at: Option<Vec3>,
}

fn check(args: &RenderArgs, scene: &tumble_scene::Scene) -> Result<Checked, Failure> {
    if !(args.fps > 0.0 && args.fps <= 1000.0) {
        return Err(SceneError::new("fps", "must be > 0 and <= 1000").into());
    }
    let output = Output::from_path(&args.out).map_err(|e| SceneError::new("out", e))?;
    let target = match output {
        Output::Frames(_) => Target::folder("out", &args.out)?,
        _ => Target::file("out", &args.out)?,
    };
    check_distinct(&[&target], &inputs(&scene_file(&args.scene)))?;
    let plan = RunPlan::from_duration(args.duration.unwrap_or(scene.duration), scene.dt)?;
    let frames = frame_count(&plan, args.fps);
    if frames > MAX_FRAMES && !output.single_frame() {
        return Err(SceneError::new(
            "duration",
            format!("{frames} frames at this --fps; at most {MAX_FRAMES}"),
        )
        .into());
    }
    let point =
        |field, text: &Option<String>| text.as_deref().map(|t| parse_point(field, t)).transpose();
    let (eye, look_at) = (
        point("camera", &args.camera)?,
        point("target", &args.target)?,
    );
    if eye.is_some() && eye == look_at {
        return Err(SceneError::new("camera", "must differ from --target").into());
    }
    Ok(Checked {
        output,
        target,
        plan,
        frames,
        eye,
        look_at,
    })
}

/// Where the pictures go while they are drawn: a partial file, or a folder's staging
/// folder; created before the run, so that an unwritable path is refused first.
enum Sink {
    File(Staged),
    Folder(StagedFolder),
}

impl Sink {
    fn create(target: Target, output: &Output) -> Result<Sink, Failure> {
        Ok(match output {
            Output::Frames(_) => Sink::Folder(StagedFolder::create(target)?),
            _ => Sink::File(Staged::create(target)?.0),
        })
    }

    fn target(&self) -> &Target {
        match self {
            Sink::File(s) => s.target(),
            Sink::Folder(f) => f.target(),
        }
    }

    fn path(&self) -> &std::path::Path {
        match self {
            Sink::File(s) => s.path(),
            Sink::Folder(f) => f.path(),
        }
    }

    fn commit(self, frames: usize) -> Result<(), Failure> {
        match self {
            Sink::File(s) => s.commit(),
            Sink::Folder(f) => f.commit((0..frames).map(frame_name)),
        }
    }
}

/// Runs the command. A step that fails ends the run: the frames up to it are drawn and
/// written, and the step's account is the error (exit 1).
pub fn render(args: &RenderArgs) -> Result<(), Failure> {
    let mut scene = crate::load_scene(&args.scene)?;
    if let Some(n) = args.threads {
        scene
            .world
            .set_threads(n)
            .map_err(|e| Failure::Input(e.to_string()))?;
    }
    let c = check(args, &scene)?;
    let sink = Sink::create(c.target.clone(), &c.output)?;
    let (snapshots, stopped) = simulate(&mut scene, args, &c)?;
    let colours: Vec<Option<Rgb>> = scene.body_colors.iter().map(|c| c.map(Rgb)).collect();
    let (camera, scale) = camera(&scene.world, &colours, &snapshots, args, &c);
    let model = Model::new(&scene.world, &colours, scale / 12.0);
    let overlays = Overlays {
        contacts: args.contacts,
        joints: args.joints,
        time: true,
    };
    let renderer = Renderer::new(model, camera, overlays, scale);
    let failed = |e: std::io::Error| sink.target().write_error(e);
    let output = c.output.at(sink.path());
    let mut encoder =
        Encoder::create(&output, args.width, args.height, narrow(args.fps)).map_err(failed)?;
    let mut progress = Progress::new(snapshots.len() as u64, "drawing", args.quiet);
    for s in &snapshots {
        encoder.frame(&renderer.render(s)).map_err(failed)?;
        progress.inc(1);
    }
    progress.finish();
    encoder.finish().map_err(failed)?;
    sink.commit(snapshots.len())?;
    if !args.quiet {
        report(args, &c, snapshots.len())?;
    }
    stopped.map_or(Ok(()), Err)
}

/// Steps the run and keeps the snapshots to draw: every frame, or for a single picture
/// the latest (the last good state, if a step fails). The failure of a step, if any,
/// comes second.
fn simulate(
    scene: &mut tumble_scene::Scene,
    args: &RenderArgs,
    c: &Checked,
) -> Result<(Vec<Snapshot>, Option<Failure>), Failure> {
    let mut progress = Progress::new(c.plan.steps, "simulating", args.quiet);
    let mut snapshots = Vec::with_capacity(c.frames.min(MAX_FRAMES) as usize);
    let keep_all = !c.output.single_frame();
    let stopped = run_frames(scene, &c.plan, args.fps, &mut progress, |world, _| {
        if !keep_all {
            snapshots.clear();
        }
        snapshots.push(Snapshot::capture(world));
        Ok(())
    })?;
    progress.finish();
    Ok((snapshots, stopped))
}

/// The line on standard output: what was written.
fn report(args: &RenderArgs, c: &Checked, frames: usize) -> Result<(), Failure> {
    let what = if c.output.single_frame() {
        "picture"
    } else {
        "frames"
    };
    writeln!(
        std::io::stdout(),
        "wrote '{}' ({frames} {what}, {}x{} px)",
        c.target.shown(),
        args.width,
        args.height
    )
    .map_err(crate::stdout_failure)
}

/// The camera the options ask for, or one framing the run; and the size of what is in
/// view (m), which sets the ground grid and how finely shapes are cut.
fn camera(
    world: &tumble::World,
    colours: &[Option<Rgb>],
    snapshots: &[Snapshot],
    args: &RenderArgs,
    c: &Checked,
) -> (Camera, f32) {
    // A coarse model is enough to find the bounds: only radii are used.
    let bounds = Model::new(world, colours, f32::INFINITY).bounds(snapshots);
    let (min, max) = bounds.unwrap_or((Vec3::splat(-1.0), Vec3::splat(1.0)));
    // Up is against gravity (URDF models are z-up); +y in a world without gravity.
    let g = world.gravity();
    let up = -Vec3::new(narrow(g.x), narrow(g.y), narrow(g.z));
    let auto = Camera::framing_up(min, max, up, args.width, args.height);
    let target = c.look_at.unwrap_or(auto.target);
    let eye = c.eye.unwrap_or(target + (auto.eye - auto.target));
    let camera = Camera::look_at_up(eye, target, up, args.width, args.height).unwrap_or(auto);
    let scale = (max - min).length().max(0.5);
    (camera, scale)
}

#[allow(clippy::unnecessary_cast)] // a no-op in the f32 build
fn narrow(x: Real) -> f32 {
    x as f32
}
