//! Subcommands of the `voxlod` binary. Each lives in its own file with an `Args` struct (clap)
//! and a `run` function; this module only lists them and holds what they share.

use clap::{Parser, Subcommand};

pub mod cluster;
pub mod common;
pub mod compare;
pub mod contour;
pub mod demo;
pub mod envelope;
pub mod evaluate;
pub mod inspect;
pub mod layers;
pub mod lod;
pub mod render;
pub mod select;
pub mod source;
pub mod voxelize;

pub use common::CliError;

/// voxlod turns polygon meshes and scanned volumes into levels of detail by low-pass filtering
/// them into a pyramid of volumes and running marching cubes on each level.
///
/// Start with `voxlod demo` (no input needed), then `voxlod lod MESH -o DIR`.
#[derive(Parser, Debug)]
#[command(name = "voxlod", version, about, long_about = None, propagate_version = true)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    Lod(lod::LodArgs),
    Demo(demo::DemoArgs),
    Voxelize(voxelize::VoxelizeArgs),
    Contour(contour::ContourArgs),
    Cluster(cluster::ClusterArgs),
    Envelope(envelope::EnvelopeArgs),
    Select(select::SelectArgs),
    Inspect(inspect::InspectArgs),
    Compare(compare::CompareArgs),
    Evaluate(evaluate::EvaluateArgs),
    Layers(layers::LayersArgs),
    Render(render::RenderArgs),
}

/// Runs the chosen subcommand.
pub fn run(cli: Cli) -> Result<(), CliError> {
    match cli.command {
        Command::Lod(args) => lod::run(args),
        Command::Demo(args) => demo::run(args),
        Command::Voxelize(args) => voxelize::run(args),
        Command::Contour(args) => contour::run(args),
        Command::Cluster(args) => cluster::run(args),
        Command::Envelope(args) => envelope::run(args),
        Command::Select(args) => select::run(args),
        Command::Inspect(args) => inspect::run(args),
        Command::Compare(args) => compare::run(args),
        Command::Evaluate(args) => evaluate::run(args),
        Command::Layers(args) => layers::run(args),
        Command::Render(args) => render::run(args),
    }
}
