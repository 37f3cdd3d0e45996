//! The `voxlod` command line as a library of subcommands ([`commands`]), so that its argument
//! definitions can be tested; the binary is `src/main.rs`.

pub mod commands;
