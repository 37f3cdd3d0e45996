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
    match commands::run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            eprintln!("voxlod: error: {err}");
            ExitCode::FAILURE
        }
    }
}
