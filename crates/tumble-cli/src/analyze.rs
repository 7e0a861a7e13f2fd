//! `tumble analyze`: the seed's convergence, order and stability, measured.

use std::io::{self, Write};
use std::path::{Path, PathBuf};

use clap::Args;
use tumble_render::plot::{Figure, Panel, Series};

use tumble::analysis;
use tumble::Integrator;

use crate::output::{Staged, Target};
use crate::{stdout_failure, Failure};

/// Options of `tumble analyze`.
#[derive(Args, Debug, Default)]
pub struct AnalyzeArgs {
    /// Also draw the convergence measurements as a log-log PNG: phase-space error
    /// against dt for every integrator, each line labelled with its fitted slope (written
    /// as FILE.png.partial, renamed when complete).
    #[arg(long, value_name = "FILE.png")]
    pub plot: Option<PathBuf>,
}

/// Prints one row per integrator as soon as it is measured.
pub fn analyze(args: &AnalyzeArgs) -> Result<(), Failure> {
    // Refused before minutes of measuring, not after.
    let plot = args.plot.as_deref().map(plot_file).transpose()?;
    let mut series = Vec::new();
    let mut out = io::stdout().lock();
    let header = "Harmonic oscillator x'' = -w^2 x, w = 2*pi rad/s, x0 = 1 m, v0 = 0:\n\
        - order: slope of log(phase-space error at t = 1.125 s) against log(dt), dt = 0.0125 s / 2^k, k = 0..4\n  (in the f32 build: k = 0..2, and from 0.075 s for rk4, to stay above rounding)\n\
        - energy: (E - E0)/E0 after 100 periods at 20 steps a period (h*w = 0.31), and the largest |E - E0|/E0 on the way\n\
        - stable h*w: largest step (times w) keeping a stiff spring (w = 100 rad/s) within twice its amplitude for 100 periods\n";
    writeln!(out, "{header}").map_err(stdout_failure)?;
    writeln!(
        out,
        "{:<17} {:>6} {:>9} {:>14} {:>14} {:>10}",
        "integrator", "theory", "observed", "energy change", "max |dE|/E0", "stable h*w"
    )
    .map_err(stdout_failure)?;
    for integrator in Integrator::ALL {
        let (dt0, levels) = analysis::default_steps(integrator);
        let convergence = analysis::convergence(integrator, dt0, levels);
        let order = convergence.order;
        series.push(Series {
            label: format!("{} (slope {order:.2})", integrator.name()),
            x: convergence.dts.iter().map(|x| wide(*x)).collect(),
            y: convergence.errors.iter().map(|x| wide(*x)).collect(),
        });
        let energy = analysis::energy_behaviour(integrator, 0.05, 100);
        let stable = match analysis::largest_stable_step(integrator) {
            None => "none".to_string(),
            Some(h) if h >= 10.0 => ">= 10".to_string(),
            Some(h) => format!("{h:.3}"),
        };
        writeln!(
            out,
            "{:<17} {:>6} {:>9.3} {:>14.3e} {:>14.3e} {:>10}",
            integrator.name(),
            integrator.order(),
            order,
            energy.final_change,
            energy.max_deviation,
            stable
        )
        .map_err(stdout_failure)?;
    }
    if let Some(staged) = plot {
        let figure = Figure {
            x_label: "dt (s)".into(),
            panels: vec![Panel {
                title: "Convergence on the harmonic oscillator (log-log)".into(),
                y_label: "phase-space error at t = 1.125 s".into(),
                series,
                log_log: true,
                points: true,
            }],
            width: 900,
            height: 640,
        };
        figure
            .write_png(staged.path())
            .map_err(|e| staged.target().write_error(e))?;
        let shown = staged.target().shown().to_string();
        staged.commit()?;
        writeln!(out, "\nwrote '{shown}'").map_err(stdout_failure)?;
    }
    Ok(())
}

/// `--plot`: a .png path that can be written, its partial file made now.
fn plot_file(path: &Path) -> Result<Staged, Failure> {
    if path
        .extension()
        .is_none_or(|e| !e.eq_ignore_ascii_case("png"))
    {
        return Err(Failure::Input("plot: must be a .png file".into()));
    }
    Ok(Staged::create(Target::file("plot", path)?)?.0)
}

#[allow(clippy::unnecessary_cast)] // a no-op in the f64 build
fn wide(x: tumble::Real) -> f64 {
    x as f64
}
