//! Measured figures and skips that the test output always shows, so that a drift
//! shows in CI's log before it becomes a failure. Shared by the render and reference
//! test suites (the reference's `common` includes this file by path).
//!
//! Each line goes straight to the process's stderr, not through `eprintln!`, which
//! the test harness captures and shows only for failing tests. `.ci/run` collects the
//! `figure:` lines into a summary at the end of the log.

use std::io::Write;

/// Prints `figure: <what>: <measured> (bound <bound>)` on the test output.
pub fn figure(what: &str, measured: impl std::fmt::Display, bound: impl std::fmt::Display) {
    line(format!("figure: {what}: {measured} (bound {bound})\n"));
}

/// Prints `skipped: <what>: <why>` on the test output. Only for a device capability
/// a test cannot have everywhere; missing files and tools are failures.
pub fn skipped(what: &str, why: &str) {
    line(format!("skipped: {what}: {why}\n"));
}

/// A rate as a percentage, for figures and their bounds.
pub fn percent(rate: f64) -> String {
    format!("{:.3}%", 100.0 * rate)
}

/// One write of a whole line, so that tests running in parallel do not interleave.
fn line(text: String) {
    let _ = std::io::stderr().lock().write_all(text.as_bytes());
}
