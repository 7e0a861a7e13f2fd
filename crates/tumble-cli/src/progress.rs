//! Progress bars (indicatif) for work that takes a while: shown on standard error only
//! when it is a terminal, not with --quiet, and only once the work has run for a second,
//! so quick runs and pipes stay silent.

use std::io::IsTerminal;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// How long work runs before its bar appears.
const DELAY: Duration = Duration::from_secs(1);

/// A bar that appears only if it is wanted and the work is slow.
pub struct Progress {
    bar: ProgressBar,
    start: Instant,
    /// Still waiting to decide whether to show the bar.
    pending: bool,
}

impl Progress {
    /// A bar for `len` units of work called `what`; hidden for good when `quiet` or when
    /// standard error is not a terminal.
    pub fn new(len: u64, what: &str, quiet: bool) -> Progress {
        let bar = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::hidden());
        let style = ProgressStyle::with_template(
            "{msg:>10} [{wide_bar}] {percent:>3}%  {elapsed} elapsed, ETA {eta}",
        )
        .expect("the template is valid")
        .progress_chars("=> ");
        bar.set_style(style);
        bar.set_message(what.to_string());
        Progress {
            bar,
            start: Instant::now(),
            pending: !quiet && std::io::stderr().is_terminal(),
        }
    }

    /// `n` more units done.
    pub fn inc(&mut self, n: u64) {
        self.bar.inc(n);
        if self.pending && self.start.elapsed() > DELAY {
            self.pending = false;
            self.bar.set_draw_target(ProgressDrawTarget::stderr());
        }
    }

    /// Removes the bar from the terminal.
    pub fn finish(self) {
        self.bar.finish_and_clear();
    }
}
