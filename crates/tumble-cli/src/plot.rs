//! `tumble plot FILE.csv --out FILE.png`: the columns of a CSV file against its first.

use std::io::Write;
use std::path::PathBuf;

use clap::Args;
use tumble_render::plot::{Figure, Panel, Series};
use tumble_scene::{printable, SceneError};

use crate::output::{check_distinct, Staged, Target};
use crate::Failure;

/// Columns that are energies (J) and share a panel.
const ENERGIES: [&str; 3] = ["kinetic", "potential", "total"];

/// Options of `tumble plot`.
#[derive(Args, Debug)]
pub struct PlotArgs {
    /// A CSV file with a header row and numbers in every column, such as the diagnostics
    /// of `tumble run --diagnostics` (time, kinetic, potential, total, px..lz).
    #[arg(value_name = "FILE.csv")]
    pub file: PathBuf,

    /// The PNG to write (as FILE.png.partial, renamed when complete).
    #[arg(long, value_name = "FILE.png")]
    pub out: PathBuf,

    /// Columns to plot, comma-separated (default: every column after the first).
    #[arg(long, value_name = "A,B,..")]
    pub columns: Option<String>,

    /// Picture width in pixels.
    #[arg(long, value_name = "PX", default_value_t = 900, allow_negative_numbers = true, value_parser = pixels)]
    pub width: u32,

    /// Picture height in pixels.
    #[arg(long, value_name = "PX", default_value_t = 640, allow_negative_numbers = true, value_parser = pixels)]
    pub height: u32,
}

/// `--width`, `--height`.
fn pixels(text: &str) -> Result<u32, String> {
    crate::args::whole_u32(text, 100, 8192)
}

/// The header and the columns of a CSV file of numbers.
fn read_csv(args: &PlotArgs) -> Result<(Vec<String>, Vec<Vec<f64>>), Failure> {
    let name = printable(&args.file.display().to_string());
    let text = std::fs::read_to_string(&args.file)
        .map_err(|e| Failure::Input(format!("file: cannot read '{name}': {e}")))?;
    let mut lines = text.lines();
    let header: Vec<String> = lines
        .next()
        .ok_or_else(|| Failure::Input(format!("file: '{name}' is empty")))?
        .split(',')
        .map(|h| h.trim().to_string())
        .collect();
    let mut columns = vec![Vec::new(); header.len()];
    for (row, line) in lines.enumerate().filter(|(_, l)| !l.trim().is_empty()) {
        let cells: Vec<&str> = line.split(',').collect();
        if cells.len() != header.len() {
            return Err(Failure::Input(format!(
                "file: row {} has {} fields, the header {}",
                row + 2,
                cells.len(),
                header.len()
            )));
        }
        for (k, cell) in cells.iter().enumerate() {
            let x = cell.trim().parse::<f64>().map_err(|_| {
                Failure::Input(format!(
                    "file: row {}, column '{}': '{}' is not a number",
                    row + 2,
                    printable(&header[k]),
                    printable(cell)
                ))
            })?;
            columns[k].push(x);
        }
    }
    Ok((header, columns))
}

/// Runs the command.
pub fn plot(args: &PlotArgs) -> Result<(), Failure> {
    if args
        .out
        .extension()
        .is_none_or(|e| !e.eq_ignore_ascii_case("png"))
    {
        return Err(SceneError::new("out", "must be a .png file").into());
    }
    let target = Target::file("out", &args.out)?;
    check_distinct(&[&target], &[("file", &args.file)])?;
    let (header, columns) = read_csv(args)?;
    if header.len() < 2 {
        return Err(SceneError::new("file", "needs at least two columns").into());
    }
    let wanted: Vec<String> = match &args.columns {
        Some(list) => list.split(',').map(|c| c.trim().to_string()).collect(),
        None => header[1..].to_vec(),
    };
    let mut energies = Vec::new();
    let mut others = Vec::new();
    for name in &wanted {
        let k = header.iter().position(|h| h == name).ok_or_else(|| {
            SceneError::new(
                "columns",
                format!(
                    "no column '{}' (the file has: {})",
                    printable(name),
                    header.join(", ")
                ),
            )
        })?;
        let series = Series {
            label: name.clone(),
            x: columns[0].clone(),
            y: columns[k].clone(),
        };
        if ENERGIES.contains(&name.as_str()) {
            energies.push(series);
        } else {
            others.push(series);
        }
    }
    let panel = |title: &str, y_label: &str, series| Panel {
        title: title.into(),
        y_label: y_label.into(),
        series,
        log_log: false,
        points: false,
    };
    let mut panels = Vec::new();
    if !energies.is_empty() {
        panels.push(panel("Energy", "J", energies));
    }
    if !others.is_empty() {
        let title = if panels.is_empty() {
            ""
        } else {
            "Other columns"
        };
        panels.push(panel(title, "", others));
    }
    let figure = Figure {
        x_label: header[0].clone(),
        panels,
        width: args.width,
        height: args.height,
    };
    let (staged, _) = Staged::create(target)?;
    figure
        .write_png(staged.path())
        .map_err(|e| staged.target().write_error(e))?;
    let out = staged.target().shown().to_string();
    staged.commit()?;
    writeln!(
        std::io::stdout(),
        "wrote '{out}' ({} columns against {})",
        wanted.len(),
        printable(&header[0])
    )
    .map_err(crate::stdout_failure)
}
