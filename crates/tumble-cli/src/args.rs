//! The command line's own refusals: value parsers that say the rule a value broke, and
//! clap's errors turned into the one line `option: reason` every other error is.
//!
//! clap's messages span several lines (usage, tips, "For more information ..."); scripts
//! and people read the first line only, so a refusal is that one line, naming the option
//! without its dashes as the scene format names its fields (`dt: must be > 0` is the same
//! line for `--dt 0` and `"dt": 0`).

use std::error::Error as _;

use clap::error::{ContextKind, ContextValue, ErrorKind};
use clap::CommandFactory;
use tumble::Real;
use tumble_scene::{printable, whole_rule, RunPlan, Scene, SceneError, MAX_STEPS};

/// A number, in the options' unit; whether it is in range is checked where it is used, so
/// the message is the scene format's (`dt: must be > 0`).
pub fn number(text: &str) -> Result<Real, String> {
    text.trim()
        .parse::<Real>()
        .map_err(|_| format!("expected a number, got '{}'", printable(text)))
}

/// A whole number from `min` to `max`; anything else, `-1` and `0` alike when `min` is 1,
/// breaks the one rule the message states.
pub fn whole(text: &str, min: u64, max: u64) -> Result<u64, String> {
    text.trim()
        .parse::<u64>()
        .ok()
        .filter(|n| (min..=max).contains(n))
        .ok_or_else(|| format!("{}, got '{}'", whole_rule(min, max), printable(text)))
}

/// `--threads N`: how many threads the steps run on, 1 to `tumble::threads::MAX_THREADS`.
pub fn threads(text: &str) -> Result<usize, String> {
    let most = tumble::threads::MAX_THREADS as u64;
    // In range by construction, so the conversion cannot fail.
    whole(text, 1, most).map(|n| n as usize)
}

/// [`whole`] for options held in a `u32`.
pub fn whole_u32(text: &str, min: u32, max: u32) -> Result<u32, String> {
    // In range by construction, so the conversion cannot fail.
    whole(text, min.into(), max.into()).map(|n| n as u32)
}

/// What to do with a command line clap refused: help and version are printed as clap
/// prints them (exit 0); every other error becomes one line (exit 2).
pub enum Refusal {
    /// `--help` or `--version`: clap's own output and exit status.
    Show(clap::Error),
    /// The one line to print.
    Line(String),
}

/// Sorts a clap error into [`Refusal`].
pub fn refusal(e: clap::Error) -> Refusal {
    match e.kind() {
        ErrorKind::DisplayHelp
        | ErrorKind::DisplayVersion
        | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => Refusal::Show(e),
        _ => Refusal::Line(line(&e)),
    }
}

/// The one line for a clap error: the option first, then the reason.
fn line(e: &clap::Error) -> String {
    let arg = string(e, ContextKind::InvalidArg);
    let field = arg.as_deref().map(field_name);
    let reason = match e.kind() {
        // The value parsers above wrote the reason themselves.
        ErrorKind::ValueValidation => e.source().map(ToString::to_string),
        ErrorKind::InvalidValue => match string(e, ContextKind::InvalidValue).as_deref() {
            Some("") | None => Some("needs a value".to_string()),
            Some(v) => Some(format!("'{}' is not a valid value", printable(v))),
        },
        ErrorKind::UnknownArgument => {
            return unknown_argument(e, arg.as_deref().unwrap_or("?"));
        }
        ErrorKind::InvalidSubcommand => return unknown_command(e),
        ErrorKind::MissingRequiredArgument => return missing(e),
        ErrorKind::ArgumentConflict => strings(e, ContextKind::PriorArg).map(|prior| {
            let prior: Vec<String> = prior.iter().map(|p| option_name(p)).collect();
            format!("cannot be given together with {}", prior.join(", "))
        }),
        ErrorKind::TooManyValues => Some("takes no value".to_string()),
        _ => None,
    };
    match (field, reason) {
        (Some(field), Some(reason)) => format!("{field}: {reason}"),
        (field, None) => {
            let first = first_line(e);
            field.map_or_else(|| first.clone(), |f| format!("{f}: {first}"))
        }
        (None, Some(reason)) => reason,
    }
}

/// `--fly` or a stray word, with clap's suggestion when it has one.
fn unknown_argument(e: &clap::Error, arg: &str) -> String {
    let command = command_name(e);
    let what = if arg.starts_with('-') {
        format!("unknown option of '{command}'")
    } else {
        format!("unexpected argument of '{command}'")
    };
    let hint = match string(e, ContextKind::SuggestedArg) {
        Some(s) => format!(" (did you mean {s}?)"),
        None => format!(" (see '{command} --help')"),
    };
    format!("{}: {what}{hint}", printable(arg))
}

/// `tumble fly`.
fn unknown_command(e: &clap::Error) -> String {
    let name = string(e, ContextKind::InvalidSubcommand).unwrap_or_default();
    let known: Vec<String> = crate::Cli::command()
        .get_subcommands()
        .map(|c| c.get_name().to_string())
        .collect();
    format!(
        "command: unknown command '{}' (expected one of: {})",
        printable(&name),
        known.join(", ")
    )
}

/// `tumble render` without its scene or --out.
fn missing(e: &clap::Error) -> String {
    let args = strings(e, ContextKind::InvalidArg).unwrap_or_default();
    let fields: Vec<String> = args.iter().map(|a| field_name(a)).collect();
    format!(
        "{}: required; see '{} --help'",
        fields.join(", "),
        command_name(e)
    )
}

/// `--steps <N>` -> `steps`; `<SCENE>` -> `scene`: the name the messages use.
fn field_name(arg: &str) -> String {
    let head = arg.split_whitespace().next().unwrap_or(arg);
    head.trim_start_matches('-')
        .trim_matches(['<', '>'])
        .to_lowercase()
}

/// `--duration <SECONDS>` -> `--duration`: how the user spells the option.
fn option_name(arg: &str) -> String {
    arg.split_whitespace().next().unwrap_or(arg).to_string()
}

/// `tumble run` from the usage clap attaches (`Usage: tumble run [OPTIONS] [SCENE]`).
fn command_name(e: &clap::Error) -> String {
    let usage = match e.get(ContextKind::Usage) {
        Some(ContextValue::StyledStr(s)) => s.to_string(),
        _ => String::new(),
    };
    let words: Vec<&str> = usage
        .trim_start()
        .trim_start_matches("Usage:")
        .split_whitespace()
        .take_while(|w| !w.starts_with(['[', '<', '-']))
        .collect();
    if words.is_empty() {
        "tumble".into()
    } else {
        words.join(" ")
    }
}

/// clap's own first line, without its `error: ` prefix: for the kinds with no better
/// wording here.
fn first_line(e: &clap::Error) -> String {
    let text = e.render().to_string();
    let first = text.lines().next().unwrap_or_default();
    first.trim_start_matches("error: ").to_string()
}

fn string(e: &clap::Error, kind: ContextKind) -> Option<String> {
    match e.get(kind) {
        Some(ContextValue::String(s)) => Some(s.clone()),
        Some(ContextValue::Strings(v)) => v.first().cloned(),
        _ => None,
    }
}

fn strings(e: &clap::Error, kind: ContextKind) -> Option<Vec<String>> {
    match e.get(kind) {
        Some(ContextValue::String(s)) => Some(vec![s.clone()]),
        Some(ContextValue::Strings(v)) => Some(v.clone()),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_lose_their_dashes_and_brackets() {
        assert_eq!(field_name("--steps <N>"), "steps");
        assert_eq!(field_name("<SCENE>"), "scene");
        assert_eq!(option_name("--duration <SECONDS>"), "--duration");
    }

    #[test]
    fn counts_state_one_rule() {
        let rule = "must be a whole number from 1 to 10";
        assert_eq!(whole("-1", 1, 10).unwrap_err(), format!("{rule}, got '-1'"));
        assert_eq!(whole("0", 1, 10).unwrap_err(), format!("{rule}, got '0'"));
        assert_eq!(
            whole("1.5", 1, 10).unwrap_err(),
            format!("{rule}, got '1.5'")
        );
        assert_eq!(whole("10", 1, 10), Ok(10));
        assert_eq!(number("x").unwrap_err(), "expected a number, got 'x'");
    }
}

/// `--duration`, `--steps` and `--dt`: how long a run is and its step, each over the
/// scene's own (`tumble run` and `tumble export-gltf`).
#[derive(clap::Args, Debug, Default, Clone)]
pub struct Span {
    /// Simulated time to run, in seconds (s); overrides the scene's `duration`.
    #[arg(long, value_name = "SECONDS", allow_negative_numbers = true, value_parser = number)]
    pub duration: Option<Real>,

    /// Number of steps of dt to take, instead of --duration.
    #[arg(
        long,
        value_name = "N",
        conflicts_with = "duration",
        allow_negative_numbers = true,
        value_parser = |t: &str| whole(t, 0, MAX_STEPS)
    )]
    pub steps: Option<u64>,

    /// Time step, in seconds (s); overrides the scene's `dt`. Must be > 0.
    #[arg(long, value_name = "SECONDS", allow_negative_numbers = true, value_parser = number)]
    pub dt: Option<Real>,
}

impl Span {
    /// The run these options and `scene` make: `steps` of dt, else `duration`.
    pub fn plan(&self, scene: &Scene) -> Result<RunPlan, SceneError> {
        let dt = self.dt.unwrap_or(scene.dt);
        match self.steps {
            Some(steps) => RunPlan::from_steps(steps, dt),
            None => RunPlan::from_duration(self.duration.unwrap_or(scene.duration), dt),
        }
    }
}
