//! Subcommands of the `voxlod` binary. Each lives in its own file with an `Args` struct (clap)
//! and a `run` function; this module only lists them and holds what they share.

use clap::{Parser, Subcommand};

pub mod camera;
pub mod cluster;
pub mod common;
pub mod compare;
pub mod contour;
pub mod demo;
pub mod envelope;
pub mod evaluate;
pub mod inspect;
pub mod labels;
pub mod layers;
pub mod layers_lod;
pub mod lod;
pub mod lod_asset;
pub mod lod_budget;
pub mod lod_glb;
pub mod proxy;
pub mod render;
pub mod select;
pub mod source;
pub mod values;
pub mod view;
pub mod voxelize;
pub mod world;

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
    Proxy(proxy::ProxyArgs),
    Demo(demo::DemoArgs),
    Voxelize(voxelize::VoxelizeArgs),
    Contour(contour::ContourArgs),
    Cluster(cluster::ClusterArgs),
    Envelope(envelope::EnvelopeArgs),
    Select(select::SelectArgs),
    Inspect(inspect::InspectArgs),
    Labels(labels::LabelsArgs),
    Compare(compare::CompareArgs),
    Evaluate(evaluate::EvaluateArgs),
    Layers(layers::LayersArgs),
    Render(render::RenderArgs),
    View(view::ViewArgs),
}

/// Runs the chosen subcommand.
pub fn run(cli: Cli) -> Result<(), CliError> {
    match cli.command {
        Command::Lod(args) if lod_asset::is_gltf(&args.input) => lod_asset::run(&args, None),
        Command::Lod(args) if lod_asset::may_have_looks(&args) => match lod_asset::looks_of(&args)?
        {
            Some(read) => lod_asset::run(&args, Some(read)),
            None if args.triangles.is_some() || args.error.is_some() => lod_budget::run(&args),
            None => lod::run(args),
        },
        Command::Lod(args) if args.triangles.is_some() || args.error.is_some() => {
            lod_budget::run(&args)
        }
        Command::Lod(args) => lod::run(args),
        Command::Proxy(args) => proxy::run(args),
        Command::Demo(args) => demo::run(args),
        Command::Voxelize(args) => voxelize::run(args),
        Command::Contour(args) => contour::run(args),
        Command::Cluster(args) => cluster::run(args),
        Command::Envelope(args) => envelope::run(args),
        Command::Select(args) => select::run(args),
        Command::Inspect(args) => inspect::run(args),
        Command::Labels(args) => labels::run(args),
        Command::Compare(args) => compare::run(args),
        Command::Evaluate(args) => evaluate::run(args),
        Command::Layers(args) => layers::run(args),
        Command::Render(args) => render::run(args),
        Command::View(args) => view::run(args),
    }
}

/// A message as one line: its lines joined with "; ", or with a space after a colon (an
/// error is always one line).
pub fn one_line(text: &str) -> String {
    let mut out = String::new();
    for line in text.lines().map(str::trim).filter(|l| !l.is_empty()) {
        if out.ends_with(':') {
            out.push(' ');
        } else if !out.is_empty() {
            out.push_str("; ");
        }
        out.push_str(line);
    }
    out
}

/// clap's rendered usage error as one line: the error and its tips, without the usage
/// synopsis, and a pointer to `--help`.
pub fn usage_error_line(rendered: &str) -> String {
    let body: Vec<&str> = rendered
        .lines()
        .take_while(|l| !l.starts_with("Usage:") && !l.starts_with("For more information"))
        .collect();
    let text = one_line(&body.join("\n"));
    let text = text.strip_prefix("error: ").unwrap_or(&text);
    format!("{text} (see --help)")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn usage_errors_become_one_line() {
        let rendered = "error: unexpected argument '-x' found\n\n  tip: to pass '-x' as a value, \
                        use '-- -x'\n\nUsage: voxlod contour [OPTIONS] <VOLUME>\n\nFor more \
                        information, try '--help'.\n";
        assert_eq!(
            usage_error_line(rendered),
            "unexpected argument '-x' found; tip: to pass '-x' as a value, use '-- -x' \
             (see --help)"
        );
        let e = Cli::try_parse_from(["voxlod", "contour", "v.nrrd", "--iso", "1"]).unwrap_err();
        let line = usage_error_line(&e.render().to_string());
        assert_eq!(
            line,
            "the following required arguments were not provided: --output <MESH> (see --help)"
        );
    }
}
