//! `tumble`: run rigid-body scenes from the command line.
//!
//! Exit status: 0 on success; 2 for bad input (command-line options, scene files, output
//! paths) or an output that cannot be written, with one line on stderr naming the option or
//! field, e.g. `bodies[3].shape.radius: must be > 0`; 1 when a run fails part way (a step
//! the engine refuses, such as one that goes unstable), with the engine's one line, e.g.
//! `step 41 (t = 0.683 s): bodies[7] "pelvis": velocity is not finite`, and every output
//! file complete up to the last good step.

mod analyze;
mod args;
mod contacts;
mod export_gltf;
mod glb;
mod output;
mod plot;
mod progress;
mod record;
mod render;
mod report;
mod run;
mod sample;
mod sweep;
mod web;

use std::io::{self, Write};
use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// Tumble, a rigid-body physics engine: run scenes and record their trajectories.
#[derive(Parser, Debug)]
#[command(
    name = "tumble",
    version,
    propagate_version = true,
    after_help = "Exit status: 0 on success; 2 for bad input (options, scene, output paths) \
                  or an output that cannot be written, with one line on stderr naming the \
                  option or field, e.g. `bodies[3].shape.radius: must be > 0`; 1 when a run \
                  fails part way (a step goes unstable), with one line naming the step, the \
                  time, the body and the quantity, and every output complete up to the last \
                  good step.\n\n\
                  Output files are written as NAME.partial beside NAME and renamed into \
                  place when complete: a failed or killed command never leaves a \
                  half-written NAME (nor truncates an existing one); only NAME.partial \
                  remains after a kill. Devices and fifos (/dev/null, /dev/stdout) are \
                  written directly. An output may not be the scene file, nor another output."
)]
struct Cli {
    /// What to do; with none, `tumble` runs the seed's free-fall example (`tumble run`).
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Run a scene; write its trajectory and energies as CSV, or print a summary.
    ///
    /// Without SCENE, runs the seed's example (the built-in `free_fall`: a 1 kg ball
    /// dropped from 5 m, dt = 0.01 s, 1 s) and prints its height every 0.1 s against the
    /// analytic 5 − ½·9.8·t².
    ///
    /// The run takes ⌈duration / dt⌉ steps of dt; when duration / dt is not a whole
    /// number the last step is shortened so the run ends exactly at `duration`. With
    /// --steps, exactly N steps of dt.
    Run(Box<run::RunArgs>),
    /// Measure every integrator: observed order of convergence and energy behaviour on a
    /// harmonic oscillator, and the largest stable step on a stiff spring; print a table.
    Analyze(analyze::AnalyzeArgs),
    /// List the built-in scenes with their descriptions.
    Scenes,
    /// Print the contact points of a scene's initial state as CSV:
    /// body_a,body_b,x,y,z,nx,ny,nz,separation (normal from body_a to body_b, separation
    /// in m, negative when penetrating; x,y,z midway between the two surfaces).
    Contacts(contacts::ContactsArgs),
    /// Draw a run as pictures, with no display and no GPU: an animated GIF, one PNG, a
    /// folder of numbered PNG frames, or an MP4 (with ffmpeg). Every body drawn solid and
    /// shaded in its own colour (or the scene's `color`), planes as a ground grid, the
    /// time in the top-left corner.
    Render(render::RenderArgs),
    /// Plot the columns of a CSV file against its first column as PNG, e.g. the energies
    /// and momenta of `tumble run --diagnostics diag.csv`: energies in one panel, the other
    /// columns in a second.
    Plot(plot::PlotArgs),
    /// Write one self-contained HTML file that plays the run in a browser (no network
    /// needed): orbit camera, play, pause, speed, a time scrubber, click a body for its
    /// position, velocity, ω and L, and live plots of the energies and |L|.
    ExportHtml(web::ExportArgs),
    /// Serve the page of `export-html` on localhost and open it in the browser.
    View(web::ViewArgs),
    /// Write a run as glTF 2.0 (.glb, or .gltf with its buffer embedded) for Blender,
    /// three.js and model viewers: a node per body named as the body, its shape as a mesh
    /// in its colour, and its translation and rotation keyframed at every recorded step
    /// (the steps `tumble run --out` records with the same options), time in seconds.
    ExportGltf(export_gltf::GltfArgs),
    /// Run every combination of a grid of scene values (--set PATH=V1,V2,...) and print a
    /// CSV table of metrics from a fixed menu (--metric), one row per run in the grid's
    /// order; a failed run keeps its parameters and its one-line error. Runs here, one
    /// after another; with --ray ADDRESS on a Ray cluster through Python's tumble.sweep.
    Sweep(sweep::SweepArgs),
}

/// Why the program stops early.
#[derive(Debug)]
pub enum Failure {
    /// Bad input from the user (options, scene, output paths) or an output that cannot be
    /// written. Exit status 2.
    Input(String),
    /// The run failed part way: a step the engine refused. Exit status 1.
    Runtime(String),
    /// Already reported on standard error; only the exit status is left.
    Reported(u8),
    /// Standard output was closed (`tumble run | head`): stop quietly.
    Closed,
}

impl From<tumble_scene::SceneError> for Failure {
    fn from(e: tumble_scene::SceneError) -> Self {
        Failure::Input(e.to_string())
    }
}

/// Loads what a command names: a built-in scene, a JSON scene file, or a model file (by
/// extension, see `tumble_scene::FileKind`). What a model file held that could not be
/// built as written is printed on stderr, a `warning: ` line each, and the run goes on.
pub fn load_scene(name: &str) -> Result<tumble_scene::Scene, Failure> {
    let scene = tumble_scene::load(name)?;
    for warning in &scene.warnings {
        let _ = writeln!(io::stderr(), "warning: {warning}");
    }
    Ok(scene)
}

/// Writing to standard output; a closed pipe is not an error worth a message.
pub fn stdout_failure(e: io::Error) -> Failure {
    if e.kind() == io::ErrorKind::BrokenPipe {
        Failure::Closed
    } else {
        Failure::Input(format!("stdout: cannot write: {e}"))
    }
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => match args::refusal(e) {
            // Help and version as clap prints them, with its exit status (0).
            args::Refusal::Show(e) => e.exit(),
            args::Refusal::Line(line) => return fail(&line, 2),
        },
    };
    let command = cli.command.unwrap_or_else(|| Command::Run(Box::default()));
    let result = match command {
        Command::Run(args) => run::run(&args),
        Command::Analyze(args) => analyze::analyze(&args),
        Command::Plot(args) => plot::plot(&args),
        Command::ExportHtml(args) => web::export(&args),
        Command::View(args) => web::view(&args),
        Command::ExportGltf(args) => export_gltf::export(&args),
        Command::Scenes => report::list_scenes(),
        Command::Contacts(args) => contacts::contacts(&args),
        Command::Render(args) => render::render(&args),
        Command::Sweep(args) => sweep::sweep(&args),
    };
    match result {
        Ok(()) | Err(Failure::Closed) => ExitCode::SUCCESS,
        Err(Failure::Input(line)) => fail(&line, 2),
        Err(Failure::Runtime(line)) => fail(&line, 1),
        Err(Failure::Reported(code)) => ExitCode::from(code),
    }
}

/// The one line on stderr; `eprintln!` would panic if stderr were closed.
fn fail(line: &str, code: u8) -> ExitCode {
    let _ = writeln!(io::stderr(), "{line}");
    ExitCode::from(code)
}
