//! `voxlod lod --format glb`: every level in one `DIR/lod.glb`, chained with `MSFT_lod` from the
//! finest to the coarsest, with `MSFT_screencoverage` from `voxlod select`'s pixel-size rule
//! (crate `voxlod-gltf`); `--split` writes the level files too, `--compress meshopt` quantizes
//! and encodes the geometry as gltfpack does.

use std::path::Path;

use clap::{Args, ValueEnum};
use serde::Serialize;
use voxlod::core::TriangleMesh;
use voxlod::io::OutputSet;
use voxlod_gltf::{chain_document, to_glb, ChainLevel, ChainOptions, Compression};

use super::common::{in_dir, CliError, MeshExtension};

/// The name of the chain file in the output folder.
pub const CHAIN_FILE: &str = "lod.glb";

/// Format of `lod`'s output: level meshes, or one glTF chain.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum LodFormat {
    Ply,
    Obj,
    Stl,
    Vtp,
    Vtk,
    /// One DIR/lod.glb with every level (MSFT_lod); level files as PLY with --split
    Glb,
}

impl LodFormat {
    /// The extension of the level files.
    pub fn level_extension(self) -> MeshExtension {
        match self {
            LodFormat::Ply | LodFormat::Glb => MeshExtension::Ply,
            LodFormat::Obj => MeshExtension::Obj,
            LodFormat::Stl => MeshExtension::Stl,
            LodFormat::Vtp => MeshExtension::Vtp,
            LodFormat::Vtk => MeshExtension::Vtk,
        }
    }
}

/// Geometry compression of the chain.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum CompressArg {
    /// EXT_meshopt_compression with KHR_mesh_quantization (14-bit positions, 8-bit normals)
    Meshopt,
}

/// The flags of the chain file.
#[derive(Args, Debug, Clone)]
pub struct GlbArgs {
    /// With --format glb: write the level files (PLY) beside lod.glb
    #[arg(long)]
    pub split: bool,
    /// With --format glb: compress the geometry
    #[arg(long, value_enum, value_name = "METHOD")]
    pub compress: Option<CompressArg>,
}

impl GlbArgs {
    /// Refuses the flags without `--format glb`.
    pub fn check(&self, format: LodFormat) -> Result<(), CliError> {
        if format != LodFormat::Glb && (self.split || self.compress.is_some()) {
            return Err(CliError::usage("--split and --compress need --format glb"));
        }
        Ok(())
    }
}

/// What the report says about the chain file.
#[derive(Clone, Debug, Serialize)]
pub struct GlbReport {
    pub file: String,
    pub bytes: usize,
    pub compression: Option<&'static str>,
    pub levels: usize,
    pub screen_coverage: Vec<f64>,
}

/// Encodes the chain of `levels` (level, mesh, voxel size) and adds `DIR/lod.glb` to `out`.
pub fn add_chain(
    out: &mut OutputSet,
    dir: &Path,
    levels: &[(usize, TriangleMesh, f64)],
    args: &GlbArgs,
) -> Result<GlbReport, CliError> {
    let chain: Vec<ChainLevel> = levels
        .iter()
        .map(|(level, mesh, cell_size)| ChainLevel::new(*level, mesh, *cell_size))
        .collect();
    let options = match args.compress {
        Some(CompressArg::Meshopt) => ChainOptions::meshopt(),
        None => ChainOptions::default(),
    };
    let path = in_dir(dir, CHAIN_FILE);
    let fail = |e: voxlod_gltf::GltfError| CliError::msg(format!("{}: {e}", path.display()));
    let (doc, bin) = chain_document(&chain, &options).map_err(fail)?;
    let bytes = to_glb(&doc, bin).map_err(fail)?;
    out.bytes(&path, &bytes)?;
    let screen_coverage =
        serde_json::from_value(doc["nodes"][0]["extras"]["MSFT_screencoverage"].clone())
            .unwrap_or_default();
    Ok(GlbReport {
        file: CHAIN_FILE.into(),
        bytes: bytes.len(),
        compression: (options.compression == Compression::Meshopt).then_some("meshopt"),
        levels: chain
            .iter()
            .filter(|l| !l.mesh.triangles.is_empty())
            .count(),
        screen_coverage,
    })
}
