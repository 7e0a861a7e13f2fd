//! What `tumble` prints on standard output: the seed's table, the run summary, the list
//! of built-in scenes. Tables are for people, so numbers here are rounded; the CSV files
//! carry the full precision.

use std::io::{self, Write};

use tumble::limits::short;
use tumble::{Diagnostics, Real, World};
use tumble_scene::{RunPlan, Scene};

use crate::{stdout_failure, Failure};

/// Seconds between the seed table's rows.
const TABLE_INTERVAL: Real = 0.1;

pub fn say(args: std::fmt::Arguments<'_>) -> Result<(), Failure> {
    writeln!(io::stdout(), "{args}").map_err(stdout_failure)
}

/// `x` with `decimals` digits after the point, as a table shows it; in exponent form when
/// it is too large for that (`{:.6}` of 1e300 is 307 characters) or not finite.
fn fixed(x: Real, decimals: usize) -> String {
    if x.is_finite() && x.abs() < 1e9 {
        format!("{x:.decimals$}")
    } else {
        format!("{x:.decimals$e}")
    }
}

/// The seed's output: the first body's height every 0.1 s against the closed form for
/// constant gravity, y(t) = y₀ + v₀ t + ½ g t².
pub struct SeedTable {
    /// Steps between rows.
    stride: u64,
    last: u64,
    y0: Real,
    vy0: Real,
    gy: Real,
    /// Standard output was closed: the run goes on for its files, silently.
    closed: bool,
}

impl SeedTable {
    /// Prints the heading and remembers the initial height and velocity.
    pub fn new(world: &World, plan: &RunPlan) -> Result<SeedTable, Failure> {
        let Some((_, body)) = world.bodies().next() else {
            return Err(Failure::Input("scene: the seed table needs a body".into()));
        };
        let stride = (TABLE_INTERVAL / plan.dt).round().max(1.0) as u64;
        let mut table = SeedTable {
            stride,
            last: plan.steps,
            y0: body.position().y,
            vy0: body.linear_velocity().y,
            gy: world.gravity().y,
            closed: false,
        };
        table.say(format_args!(
            "free fall ({}, dt = {} s): numerical height against 5 - 1/2 g t^2",
            world.integrator().name(),
            short(plan.dt)
        ))?;
        table.say(format_args!(
            "{:>8}  {:>12}  {:>12}  {:>12}",
            "time (s)", "height (m)", "analytic (m)", "error (m)"
        ))?;
        Ok(table)
    }

    /// A line of the table. Once standard output is closed (`tumble run | head`) the
    /// table stops, but not the run: its files are still wanted whole.
    fn say(&mut self, args: std::fmt::Arguments<'_>) -> Result<(), Failure> {
        if self.closed {
            return Ok(());
        }
        match say(args) {
            Err(Failure::Closed) => {
                self.closed = true;
                Ok(())
            }
            other => other,
        }
    }

    fn analytic(&self, t: Real) -> Real {
        self.y0 + self.vy0 * t + 0.5 * self.gy * t * t
    }

    fn height(world: &World) -> Real {
        world.bodies().next().map_or(0.0, |(_, b)| b.position().y)
    }

    /// Prints a row every 0.1 s and at the last step.
    pub fn observe(&mut self, k: u64, time: Real, world: &World) -> Result<(), Failure> {
        if k % self.stride != 0 && k != self.last {
            return Ok(());
        }
        let (y, exact) = (Self::height(world), self.analytic(time));
        self.say(format_args!(
            "{:>8}  {:>12}  {:>12}  {:>12.3e}",
            fixed(time, 3),
            fixed(y, 8),
            fixed(exact, 8),
            y - exact
        ))
    }

    /// The one-line summary.
    pub fn finish(mut self, world: &World, plan: &RunPlan) -> Result<(), Failure> {
        let t = plan.end_time;
        let (y, exact) = (Self::height(world), self.analytic(t));
        self.say(format_args!(
            "after {} steps (t = {} s): height {} m, analytic {} m, error {} m",
            plan.steps,
            short(t),
            fixed(y, 6),
            fixed(exact, 6),
            fixed(y - exact, 6)
        ))
    }
}

/// The summary of a scene's run: steps, final positions, energy drift.
pub struct Summary {
    start: Diagnostics,
}

impl Summary {
    /// Takes the initial energy.
    pub fn new(scene: &Scene) -> Summary {
        Summary {
            start: scene.world.diagnostics(),
        }
    }

    /// Prints the summary of the finished run.
    pub fn print(&self, scene: &Scene, plan: &RunPlan) -> Result<(), Failure> {
        let world = &scene.world;
        say(format_args!(
            "scene '{}': {}, {}, {}",
            scene.name.as_deref().unwrap_or("unnamed"),
            count(world.body_count(), "body", "bodies"),
            count(world.forces().count(), "force element", "force elements"),
            world.integrator().name()
        ))?;
        say(format_args!(
            "{} steps of dt = {} s, final time {} s",
            plan.steps,
            short(plan.dt),
            short(plan.end_time)
        ))?;
        let width = scene.body_names.iter().map(String::len).max().unwrap_or(0);
        say(format_args!("final positions (m):"))?;
        for ((_, body), label) in world.bodies().zip(&scene.body_names) {
            let p = body.position();
            say(format_args!(
                "  {label:<width$}  {:>14} {:>14} {:>14}",
                fixed(p.x, 6),
                fixed(p.y, 6),
                fixed(p.z, 6)
            ))?;
        }
        self.energy(world.diagnostics().total)
    }

    fn energy(&self, end: Real) -> Result<(), Failure> {
        let start = self.start.total;
        let change = end - start;
        let relative = if start != 0.0 {
            format!(" ({:+.3e} relative)", change / start.abs())
        } else {
            String::new()
        };
        say(format_args!(
            "total energy (J): start {}, end {}, change {change:+.3e}{relative}",
            fixed(start, 9),
            fixed(end, 9)
        ))
    }
}

fn count(n: usize, one: &str, many: &str) -> String {
    format!("{n} {}", if n == 1 { one } else { many })
}

/// One line per CSV file written.
pub fn print_written(files: &[(String, u64)]) -> Result<(), Failure> {
    for (path, rows) in files {
        say(format_args!("wrote '{path}' ({rows} rows)"))?;
    }
    Ok(())
}

/// `tumble scenes`: every built-in scene and what it shows.
pub fn list_scenes() -> Result<(), Failure> {
    for name in tumble_scene::builtin_names() {
        // A built-in that fails to load is a bug the tests catch; still, no panic here.
        let description = match tumble_scene::load(name) {
            Ok(scene) => scene.description.unwrap_or_default(),
            Err(e) => format!("(broken: {e})"),
        };
        say(format_args!("{name:<16} {description}"))?;
    }
    Ok(())
}
