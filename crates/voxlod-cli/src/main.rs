//! The `voxlod` command: every stage of the library behind one binary with subcommands.

use std::process::ExitCode;

use clap::error::ErrorKind;
use clap::Parser;

use voxlod_cli::commands::{self, one_line, Cli};

fn main() -> ExitCode {
    // Before any thread starts: SIGINT, SIGTERM and SIGHUP then remove unfinished files and end
    // the run with 130, 143 or 129.
    voxlod::io::atomic::remove_temporaries_on_signals(
        "voxlod: stopped; files not yet finished were discarded",
    );
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => return usage_error(e),
    };
    // A malformed VOXLOD_MAX_MEMORY is reported before any work, not at the first large buffer.
    let budget = voxlod::core::memory::available_bytes().map_err(commands::CliError::from);
    match budget.and_then(|_| commands::run(cli)) {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            eprintln!("voxlod: error: {}", one_line(&err.to_string()));
            ExitCode::from(err.exit_code())
        }
    }
}

/// Help and version go out as clap writes them; a usage error becomes one line,
/// `voxlod: error: …`, with clap's exit code (2).
fn usage_error(e: clap::Error) -> ExitCode {
    match e.kind() {
        ErrorKind::DisplayHelp
        | ErrorKind::DisplayVersion
        | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => e.exit(),
        _ => {
            eprintln!(
                "voxlod: error: {}",
                commands::usage_error_line(&e.render().to_string())
            );
            ExitCode::from(e.exit_code().clamp(1, 255) as u8)
        }
    }
}
