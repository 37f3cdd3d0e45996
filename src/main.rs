//! The `voxlod` command: every stage of the library behind one binary with subcommands.

use std::process::ExitCode;

use clap::Parser;

use voxlod::commands::{self, Cli};

fn main() -> ExitCode {
    let cli = Cli::parse();
    match commands::run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            eprintln!("voxlod: error: {err}");
            ExitCode::FAILURE
        }
    }
}
