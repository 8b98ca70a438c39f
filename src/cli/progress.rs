//! Progress on a terminal (stderr), silence otherwise.

use std::io::{IsTerminal, Write};

/// Prints progress lines on stderr when it is a terminal.
pub(crate) struct Progress {
    on: bool,
}

impl Progress {
    pub fn new() -> Self {
        Self {
            on: std::io::stderr().is_terminal(),
        }
    }

    /// Replaces the current progress line with `msg`.
    pub fn update(&self, msg: &str) {
        if self.on {
            let mut e = std::io::stderr().lock();
            let _ = write!(e, "\r\x1b[2K{msg}");
            let _ = e.flush();
        }
    }

    /// Clears the progress line.
    pub fn done(&self) {
        if self.on {
            let _ = write!(std::io::stderr().lock(), "\r\x1b[2K");
        }
    }
}

/// The progress line goes when the work ends, also on an error (the message then starts on a
/// clean line).
impl Drop for Progress {
    fn drop(&mut self) {
        self.done();
    }
}
