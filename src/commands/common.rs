//! What the subcommands share: the error type, JSON reports, progress bars.

use std::time::Duration;

use indicatif::{ProgressBar, ProgressStyle};
use serde::Serialize;

/// Any failure of a subcommand, shown as one line: `voxlod: error: <message>`.
#[derive(Debug, thiserror::Error)]
pub enum CliError {
    #[error("{0}")]
    Message(String),
    #[error(transparent)]
    Core(#[from] voxlod_core::CoreError),
    #[error(transparent)]
    Io(#[from] voxlod_io::IoError),
}

impl CliError {
    pub fn msg(text: impl Into<String>) -> CliError {
        CliError::Message(text.into())
    }
}

/// Prints `report` as pretty JSON on standard output.
pub fn print_json<T: Serialize>(report: &T) -> Result<(), CliError> {
    let text = serde_json::to_string_pretty(report)
        .map_err(|e| CliError::msg(format!("cannot encode the JSON report: {e}")))?;
    println!("{text}");
    Ok(())
}

/// A progress bar on standard error for `len` steps, hidden when `quiet` (JSON mode) or when
/// standard error is not a terminal. It only draws after a second, so quick work stays silent.
pub fn progress(len: u64, message: &str, quiet: bool) -> ProgressBar {
    if quiet {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::with_draw_target(
        Some(len),
        indicatif::ProgressDrawTarget::stderr_with_hz(4),
    );
    bar.set_style(
        ProgressStyle::with_template("{msg:>12} [{bar:30}] {pos}/{len} {elapsed}")
            .expect("valid template")
            .progress_chars("=> "),
    );
    bar.set_message(message.to_string());
    bar.enable_steady_tick(Duration::from_millis(1000));
    bar
}
