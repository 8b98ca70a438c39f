//! Stopping long work on Ctrl-C. Long loops (excitation design, simulation, identification of
//! big logs, the paper) call [`check`], which fails with [`Error::Interrupted`] once an
//! interrupt was asked for; callers write their outputs only after the work, so an interrupted
//! command leaves earlier outputs as they were.
//!
//! An interrupt is asked for by [`request`] (the `perturbid` binary's SIGINT handler calls it)
//! or seen by the front end's [`set_checker`] hook (Python's signal check, run at most every
//! 50 ms, so that Ctrl-C in a Python session raises `KeyboardInterrupt` within a second).

use std::cell::Cell;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

use crate::error::{Error, Result};

static REQUESTED: AtomicBool = AtomicBool::new(false);
static CHECKER: OnceLock<fn() -> bool> = OnceLock::new();
const CHECK_EVERY: Duration = Duration::from_millis(50);

thread_local! {
    static LAST_CHECK: Cell<Option<Instant>> = const { Cell::new(None) };
}

/// Asks every running [`check`] to fail (safe to call from a signal handler).
pub fn request() {
    REQUESTED.store(true, Ordering::SeqCst);
}

/// Forgets an earlier interrupt: called when a new piece of work starts.
pub fn reset() {
    REQUESTED.store(false, Ordering::SeqCst);
}

/// Installs the front end's own way of seeing an interrupt (once per process).
pub fn set_checker(checker: fn() -> bool) {
    let _ = CHECKER.set(checker);
}

/// Whether an interrupt was asked for (asking the front end's checker at most every 50 ms).
pub fn requested() -> bool {
    if REQUESTED.load(Ordering::Relaxed) {
        return true;
    }
    let Some(checker) = CHECKER.get() else {
        return false;
    };
    let now = Instant::now();
    let due = LAST_CHECK.with(|last| match last.get() {
        Some(t) if now.duration_since(t) < CHECK_EVERY => false,
        _ => {
            last.set(Some(now));
            true
        }
    });
    if due && checker() {
        request();
        return true;
    }
    false
}

/// Fails with [`Error::Interrupted`] naming `context` once an interrupt was asked for.
pub fn check(context: &str) -> Result<()> {
    if requested() {
        return Err(Error::Interrupted {
            context: context.into(),
        });
    }
    Ok(())
}
