//! The `voxlod` command: every stage of the library behind one binary with subcommands.

use std::process::ExitCode;

use clap::Parser;

use voxlod::commands::{self, Cli};

fn main() -> ExitCode {
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
