//! `tumble run`: load a scene, apply the command-line overrides, step it, record it.

use std::path::PathBuf;

use clap::Args;
use tumble::{Real, World};
use tumble_scene::{RunPlan, Scene, MAX_PASSES};

use crate::args::{whole, whole_u32, Span};
use crate::output::{check_distinct, inputs, scene_file, Target, Writer};
use crate::record::{
    CsvFile, CONTACT_IMPULSES_HEADER, DIAGNOSTICS_HEADER, JOINT_REACTIONS_HEADER,
    SENSOR_EVENTS_HEADER, TRAJECTORY_HEADER,
};
use crate::report::{SeedTable, Summary};
use crate::Failure;

/// The scene run when none is named: the seed's example.
pub const SEED_SCENE: &str = "free_fall";

/// Options of `tumble run`; `Default` is `tumble run` with no options.
#[derive(Args, Debug)]
pub struct RunArgs {
    /// Scene to run: a built-in name (free_fall, spring, double_spring, dzhanibekov,
    /// planar_spinner, dumbbell, resting, door, cradle, rope_bridge, ragdoll, pyramid,
    /// pendulum_chain, character_course; see `tumble scenes`) or the path of a JSON scene
    /// file (format: docs/scene-format.md), or a URDF model file (`.urdf`: run with z-up
    /// gravity, its base fixed). Built-in names win over files in the current
    /// directory. Omitted: the seed's free fall, printed as a table against the analytic
    /// solution.
    #[arg(value_name = "SCENE")]
    pub scene: Option<String>,

    /// --duration, --steps, --dt.
    #[command(flatten)]
    pub span: Span,

    /// Integration method; overrides the scene's `integrator`. One of: explicit_euler,
    /// symplectic_euler, implicit_euler, midpoint, rk4, verlet, velocity_verlet.
    #[arg(long, value_name = "NAME")]
    pub integrator: Option<String>,

    /// Write the trajectory as CSV to FILE: a row per body per recorded step, columns
    /// time (s), body (name, or index if unnamed), x,y,z (body frame origin, m),
    /// qx,qy,qz,qw (orientation), vx,vy,vz (centre-of-mass velocity, m/s) and wx,wy,wz
    /// (angular velocity, rad/s), all in the world frame.
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,

    /// Write energies and momenta as CSV to FILE, a row per recorded step: time (s),
    /// kinetic, potential, total (J), px,py,pz (linear momentum, kg·m/s), lx,ly,lz
    /// (angular momentum about the world origin, kg·m²/s).
    #[arg(long, value_name = "FILE")]
    pub diagnostics: Option<PathBuf>,

    /// Write every contact point of every recorded step as CSV to FILE: time (s),
    /// body_a, body_b, x,y,z (the point midway between the surfaces, m), nx,ny,nz (unit
    /// normal from body_a to body_b), normal_impulse and tangent_impulse (magnitude),
    /// applied over that step (N·s).
    #[arg(long, value_name = "FILE")]
    pub contacts: Option<PathBuf>,

    /// Write every joint of every recorded step as CSV to FILE: time (s), joint (its name
    /// or index), body, other ("world" for none), fx,fy,fz (N) and tx,ty,tz (N·m), the
    /// force and torque the joint applied to `other` over that step, broken (0 or 1), and
    /// the joint's coordinate and rate: position, velocity (rad, rad/s or m, m/s: hinges,
    /// sliders, distance joints) or position_x..z, velocity_x..z (ball and fixed joints:
    /// rotation vector and relative angular velocity in `other`'s frame).
    #[arg(long, value_name = "FILE")]
    pub joints: Option<PathBuf>,

    /// Write every sensor event as CSV to FILE, whatever --every says: time (s, the end of
    /// the step that found it), sensor and body (names, or indices), began (1 when the
    /// body started overlapping the sensor, 0 when it stopped).
    #[arg(long, value_name = "FILE")]
    pub sensors: Option<PathBuf>,

    /// Contact solver; overrides the scene's `solver`: soft_step (default) or pgs.
    #[arg(long, value_name = "NAME")]
    pub solver: Option<String>,

    /// How joint trees are solved; overrides the scene's `joint_trees`: maximal (default,
    /// the soft step) or reduced (contact-free trees of hinges, sliders, unlimited ball
    /// joints and welds in their joints' coordinates).
    #[arg(long, value_name = "WAY")]
    pub joint_trees: Option<String>,

    /// Solver substeps per step; overrides the scene's `substeps`.
    #[arg(long, value_name = "N", allow_negative_numbers = true, value_parser = passes)]
    pub substeps: Option<u32>,

    /// Solver iterations per substep; overrides the scene's `iterations`.
    #[arg(long, value_name = "N", allow_negative_numbers = true, value_parser = passes)]
    pub iterations: Option<u32>,

    /// Threads the steps run on (default: TUMBLE_THREADS, else every core); results are
    /// bit-identical for every count.
    #[arg(long, value_name = "N", allow_negative_numbers = true, value_parser = crate::args::threads)]
    pub threads: Option<usize>,

    /// Record every K-th step in the CSV files; step 0 and the last step are always
    /// recorded (and, when a step fails, the last good one).
    #[arg(
        long,
        value_name = "K",
        default_value_t = 1,
        allow_negative_numbers = true,
        value_parser = |t: &str| whole(t, 1, u64::MAX)
    )]
    pub every: u64,

    /// Print nothing on standard output and show no progress bar (errors still go to
    /// standard error).
    #[arg(long, short)]
    pub quiet: bool,

    /// Write the world at the end of the run to FILE.json: a scene file with the world's
    /// whole state (its "state" section), so that `tumble run FILE.json` continues it
    /// bit-identically. The continued run's clock goes on from the saved time, and
    /// --duration (default: this run's length) is how much longer to run.
    #[arg(long, value_name = "FILE.json")]
    pub save_state: Option<PathBuf>,
}

impl Default for RunArgs {
    fn default() -> Self {
        RunArgs {
            scene: None,
            span: Span::default(),
            integrator: None,
            out: None,
            diagnostics: None,
            contacts: None,
            joints: None,
            sensors: None,
            solver: None,
            joint_trees: None,
            substeps: None,
            iterations: None,
            threads: None,
            every: 1,
            quiet: false,
            save_state: None,
        }
    }
}

/// Runs the command. A step that fails ends the run: the files keep every step up to the
/// last good one and are put in place, and the step's account is the error (exit 1).
pub fn run(args: &RunArgs) -> Result<(), Failure> {
    let integrator = args
        .integrator
        .as_deref()
        .map(tumble_scene::parse_integrator)
        .transpose()?;
    let scene_name = args.scene.as_deref().unwrap_or(SEED_SCENE);
    let mut scene = crate::load_scene(scene_name)?;
    if let Some(integrator) = integrator {
        scene.world.set_integrator(integrator);
    }
    apply_solver_options(args, &mut scene.world)?;
    if let Some(n) = args.threads {
        scene
            .world
            .set_threads(n)
            .map_err(|e| Failure::Input(e.to_string()))?;
    }
    let plan = args.span.plan(&scene)?;
    let times = Times::new(plan, scene.world.step_count());
    let mut sinks = Sinks::open(args, &scene, &plan)?;
    let mut progress = crate::progress::Progress::new(plan.steps, "running", args.quiet);
    let stopped = step_all(&mut scene, &times, args.every, &mut sinks, &mut progress)?;
    progress.finish();
    sinks.finish(&scene, &plan, stopped.is_none())?;
    stopped.map_or(Ok(()), Err)
}

/// `--solver`, `--joint-trees`, `--substeps`, `--iterations` over the scene's settings.
fn apply_solver_options(args: &RunArgs, world: &mut World) -> Result<(), Failure> {
    let mut settings = world.solver_settings();
    if let Some(name) = &args.solver {
        settings.kind = tumble_scene::parse_solver(name)?;
    }
    if let Some(name) = &args.joint_trees {
        settings.joint_trees = tumble_scene::parse_joint_trees(name)?;
    }
    settings.substeps = args.substeps.unwrap_or(settings.substeps);
    settings.iterations = args.iterations.unwrap_or(settings.iterations);
    world
        .set_solver_settings(settings)
        .map_err(|e| Failure::Input(e.to_string()))
}

/// The times a run reports: k·dt after step k, counted from the start of the world's
/// run, so that a world saved after `first` steps of dt (`--save-state`) and run on
/// reports the times the run that never stopped does.
struct Times {
    plan: RunPlan,
    first: u64,
    /// The plan of the whole run, from the world's first step.
    whole: RunPlan,
}

impl Times {
    fn new(plan: RunPlan, first: u64) -> Times {
        let steps = first.saturating_add(plan.steps);
        let whole = if plan.last_dt == plan.dt {
            RunPlan::from_steps(steps, plan.dt).unwrap_or(plan)
        } else {
            RunPlan {
                steps,
                end_time: first as Real * plan.dt + plan.end_time,
                ..plan
            }
        };
        Times { plan, first, whole }
    }

    /// The time after step `k` of this run.
    fn after(&self, k: u64) -> Real {
        if self.first == 0 {
            self.plan.time_after(k)
        } else {
            self.whole.time_after(self.first + k)
        }
    }
}

/// `--substeps`, `--iterations`: the scene format's rule for its keys of the same names.
fn passes(text: &str) -> Result<u32, String> {
    whole_u32(text, 1, MAX_PASSES)
}

/// Steps the scene through `plan` (its character's move, then the world's step),
/// showing step 0, every `every`-th step and the last to the sinks. A failed step stops
/// the run: the last good step (the world as it was before the failed one) is recorded
/// if it was not already, and the step's failure returned.
fn step_all(
    scene: &mut Scene,
    times: &Times,
    every: u64,
    sinks: &mut Sinks,
    progress: &mut crate::progress::Progress,
) -> Result<Option<Failure>, Failure> {
    let plan = &times.plan;
    sinks.observe(0, times.after(0), &scene.world, true)?;
    for k in 1..=plan.steps {
        if let Err(e) = scene.step(plan.step_dt(k)) {
            let good = k - 1;
            if good % every != 0 {
                sinks.record(times.after(good), &scene.world)?;
            }
            return Ok(Some(crate::sample::step_failure(k, e)));
        }
        let record = k % every == 0 || k == plan.steps;
        sinks.observe(k, times.after(k), &scene.world, record)?;
        progress.inc(1);
    }
    Ok(None)
}

/// `--save-state`: the world as a scene file with its state, the run's dt, and its length
/// as the default length of the run that continues it. Written whether or not the run
/// completed: a failed step was undone, so the world is the last good step's.
fn save_state(target: Target, scene: &Scene, plan: &RunPlan, quiet: bool) -> Result<(), Failure> {
    let options = tumble_scene::SaveOptions {
        name: scene.name.clone(),
        description: scene.description.clone(),
        dt: plan.dt,
        duration: plan.end_time,
        colors: scene.body_colors.clone(),
        state: true,
        character: scene.character.clone(),
    };
    let text = tumble_scene::save_with(&scene.world, &options);
    let shown = target.shown().to_string();
    let mut out = Writer::create(target)?;
    out.write(format_args!("{text}"))?;
    out.finish()?;
    if !quiet {
        let time = crate::record::Num(scene.world.time());
        crate::report::say(format_args!("wrote '{shown}' (the world at t = {time} s)"))?;
    }
    Ok(())
}

/// Everything that watches the run: the CSV files and the printed reports.
struct Sinks {
    trajectory: Option<CsvFile>,
    diagnostics: Option<CsvFile>,
    contacts: Option<CsvFile>,
    joints: Option<CsvFile>,
    sensors: Option<CsvFile>,
    /// `--save-state`: where the world goes at the end.
    state: Option<Target>,
    seed_table: Option<SeedTable>,
    summary: Option<Summary>,
    labels: Vec<String>,
    quiet: bool,
}

impl Sinks {
    fn open(args: &RunArgs, scene: &Scene, plan: &RunPlan) -> Result<Sinks, Failure> {
        // Every path is checked before any file is created, so that a bad one leaves the
        // others as they were.
        let check = |field, path: &Option<PathBuf>| {
            path.as_deref().map(|p| Target::file(field, p)).transpose()
        };
        let targets = [
            check("out", &args.out)?,
            check("diagnostics", &args.diagnostics)?,
            check("contacts", &args.contacts)?,
            check("joints", &args.joints)?,
            check("sensors", &args.sensors)?,
            check("save-state", &args.save_state)?,
        ];
        let scene_file = args.scene.as_deref().and_then(scene_file);
        check_distinct(
            &targets.iter().flatten().collect::<Vec<_>>(),
            &inputs(&scene_file),
        )?;
        let [out, diagnostics, contacts, joints, sensors, state] = targets;
        let csv =
            |target: Option<Target>, header| target.map(|t| CsvFile::create(t, header)).transpose();
        let seed = args.scene.is_none() && !args.quiet;
        Ok(Sinks {
            trajectory: csv(out, TRAJECTORY_HEADER)?,
            diagnostics: csv(diagnostics, DIAGNOSTICS_HEADER)?,
            contacts: csv(contacts, CONTACT_IMPULSES_HEADER)?,
            joints: csv(joints, JOINT_REACTIONS_HEADER)?,
            sensors: csv(sensors, SENSOR_EVENTS_HEADER)?,
            state,
            seed_table: seed
                .then(|| SeedTable::new(&scene.world, plan))
                .transpose()?,
            summary: (!seed && !args.quiet).then(|| Summary::new(scene)),
            labels: scene.body_names.clone(),
            quiet: args.quiet,
        })
    }

    /// After step `k` (0: the initial state) at `time`; `record` says whether the CSV
    /// files take this step.
    fn observe(&mut self, k: u64, time: Real, world: &World, record: bool) -> Result<(), Failure> {
        // Events are written at every step: a recorded step would miss a short visit.
        if let Some(csv) = self.sensors.as_mut().filter(|_| k > 0) {
            csv.sensors(world, &self.labels)?;
        }
        if record {
            self.record(time, world)?;
        }
        if let Some(table) = &mut self.seed_table {
            table.observe(k, time, world)?;
        }
        Ok(())
    }

    /// A row (or rows) of every CSV file for the state at `time`.
    fn record(&mut self, time: Real, world: &World) -> Result<(), Failure> {
        if let Some(csv) = &mut self.trajectory {
            csv.trajectory(time, world, &self.labels)?;
        }
        if let Some(csv) = &mut self.diagnostics {
            csv.diagnostics(time, world)?;
        }
        if let Some(csv) = &mut self.contacts {
            csv.contacts(time, world, &self.labels)?;
        }
        if let Some(csv) = &mut self.joints {
            csv.joints(time, world, &self.labels)?;
        }
        Ok(())
    }

    /// Puts the files in place, then reports; the seed table's last line and the summary
    /// only for a run that `completed`.
    fn finish(self, scene: &Scene, plan: &RunPlan, completed: bool) -> Result<(), Failure> {
        let mut written = Vec::new();
        for csv in [
            self.trajectory,
            self.diagnostics,
            self.contacts,
            self.joints,
            self.sensors,
        ]
        .into_iter()
        .flatten()
        {
            let path = csv.shown().to_string();
            written.push((path, csv.finish()?));
        }
        if let Some(target) = self.state {
            save_state(target, scene, plan, self.quiet)?;
        }
        if completed {
            if let Some(table) = self.seed_table {
                table.finish(&scene.world, plan)?;
            }
            if let Some(summary) = self.summary {
                summary.print(scene, plan)?;
            }
        }
        if self.quiet {
            return Ok(());
        }
        crate::report::print_written(&written)
    }
}
