//! The `voxlod` command: every stage of the library behind one binary with subcommands.

use std::process::ExitCode;

use clap::Parser;

use voxlod::commands::{self, Cli};

fn main() -> ExitCode {
    // Before any thread starts: SIGINT, SIGTERM and SIGHUP then remove unfinished files and end
    // the run with 130, 143 or 129.
    voxlod::io::atomic::remove_temporaries_on_signals(
        "voxlod: stopped; files not yet finished were discarded",
    );
    let cli = Cli::parse();
    // A malformed VOXLOD_MAX_MEMORY is reported before any work, not at the first large buffer.
    let budget = voxlod_core::memory::available_bytes().map_err(commands::CliError::from);
    match budget.and_then(|_| commands::run(cli)) {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            eprintln!("voxlod: error: {err}");
            ExitCode::FAILURE
        }
    }
}
