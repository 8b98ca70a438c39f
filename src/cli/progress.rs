//! Progress on a terminal (stderr, through `indicatif`), silence otherwise: a spinner with a
//! message for open-ended work, a bar with counts and time left for counted work.

use std::io::IsTerminal;
use std::time::Duration;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// A progress line on stderr, drawn only when stderr is a terminal (a log file or a pipe gets
/// nothing), at most 10 times a second.
pub(crate) struct Progress {
    bar: ProgressBar,
}

fn target() -> ProgressDrawTarget {
    if std::io::stderr().is_terminal() {
        ProgressDrawTarget::stderr_with_hz(10)
    } else {
        ProgressDrawTarget::hidden()
    }
}

impl Progress {
    /// A spinner with a message ([`Progress::update`]).
    pub fn new() -> Self {
        let bar = ProgressBar::with_draw_target(None, target());
        bar.set_style(
            ProgressStyle::with_template("{spinner} {elapsed} {wide_msg}")
                .unwrap_or_else(|_| ProgressStyle::default_spinner()),
        );
        bar.enable_steady_tick(Duration::from_millis(200));
        Self { bar }
    }

    /// A bar over `total` steps ([`Progress::set_position`]) labelled `what`.
    pub fn counted(total: u64, what: &str) -> Self {
        let bar = ProgressBar::with_draw_target(Some(total), target());
        bar.set_style(
            ProgressStyle::with_template(
                "{prefix} [{bar:30}] {pos}/{len} {elapsed} (left {eta}) {wide_msg}",
            )
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> "),
        );
        bar.set_prefix(what.to_string());
        Self { bar }
    }

    /// Replaces the message with `msg`.
    pub fn update(&self, msg: &str) {
        self.bar.set_message(msg.to_string());
    }

    /// Sets the number of steps done.
    pub fn set_position(&self, done: u64) {
        self.bar.set_position(done);
    }

    /// Clears the progress line.
    pub fn done(&self) {
        self.bar.finish_and_clear();
    }
}

/// The progress line goes when the work ends, also on an error (the message then starts on a
/// clean line).
impl Drop for Progress {
    fn drop(&mut self) {
        self.done();
    }
}
