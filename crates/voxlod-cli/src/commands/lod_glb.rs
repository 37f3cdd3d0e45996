//! `voxlod lod --format glb`: every level in one `DIR/lod.glb`, chained with `MSFT_lod` from the
//! finest to the coarsest, with `MSFT_screencoverage` from `voxlod select`'s pixel-size rule
//! (`voxlod::lod_glb`); `--split` writes the level files too, `--compress meshopt` quantizes
//! and encodes the geometry as gltfpack does. `--layout lod-nodes` writes one scene node per
//! level named `LOD0`, `LOD1`, … instead (compressed too with `--compress`).

use std::path::Path;

use clap::{Args, ValueEnum};
use serde::Serialize;
use voxlod::gltf::{AssetGlbOptions, ChainOptions, Compression, Layout};
use voxlod::io::OutputSet;
use voxlod::Lod;

use super::common::{in_dir, in_file, CliError, MeshExtension};
use super::lod_asset::LayoutArg;

/// The name of the chain file in the output folder.
pub const CHAIN_FILE: &str = "lod.glb";

/// Format of `lod`'s output: level meshes, or one glTF chain.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum LodFormat {
    /// PLY level files; an asset's with vertex colours, texture coordinates and its texture
    Ply,
    /// OBJ level files; an asset's with its MTL materials and textures beside them
    Obj,
    Stl,
    Vtp,
    Vtk,
    /// One DIR/lod.glb with every level (MSFT_lod, or LOD nodes with --layout); level files as
    /// PLY with --split (as .glb for an asset)
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
    /// EXT_meshopt_compression with KHR_mesh_quantization (14-bit positions, 8-bit normals and
    /// tangents, 16-bit texture coordinates in 0..1 and colours)
    Meshopt,
}

impl CompressArg {
    /// How an asset's `.glb` is stored for `--compress` given or not.
    pub fn compression(asked: Option<CompressArg>) -> Compression {
        match asked {
            Some(CompressArg::Meshopt) => Compression::Meshopt,
            None => Compression::None,
        }
    }
}

/// The flags of the chain file.
#[derive(Args, Debug, Clone)]
pub struct GlbArgs {
    /// With --format glb: write the level files (PLY) beside lod.glb
    #[arg(long)]
    pub split: bool,
    /// With --format glb: compress the geometry and an asset's attributes, in either layout
    /// (OBJ and PLY level files are written uncompressed)
    #[arg(long, value_enum, value_name = "METHOD")]
    pub compress: Option<CompressArg>,
    /// With --format glb: how the levels sit in the .glb. msft-lod: one node switching levels
    /// with MSFT_lod, for engines with the extension; lod-nodes: one node per level named
    /// LOD0, LOD1, …, for Blender's, Unity's and Unreal's importers and three.js users
    #[arg(long, value_enum, default_value = "msft-lod")]
    pub layout: LayoutArg,
}

impl GlbArgs {
    /// Refuses the flags without `--format glb`, naming the flag.
    pub fn check(&self, format: LodFormat) -> Result<(), CliError> {
        let name = format
            .to_possible_value()
            .map(|v| v.get_name().to_uppercase())
            .unwrap_or_default();
        if format != LodFormat::Glb && self.compress.is_some() {
            return Err(CliError::usage(format!(
                "--compress needs --format glb: {name} level files are written uncompressed"
            )));
        }
        if format != LodFormat::Glb && self.split {
            return Err(CliError::usage(format!(
                "--split needs --format glb: with --format {} every level is its own file \
                 already",
                name.to_lowercase()
            )));
        }
        if format != LodFormat::Glb && self.layout != LayoutArg::MsftLod {
            return Err(CliError::usage("--layout needs --format glb"));
        }
        Ok(())
    }

    /// How `--compress` asks the `.glb` to be stored.
    pub fn compression(&self) -> Compression {
        CompressArg::compression(self.compress)
    }
}

/// What the report says about the chain file.
#[derive(Clone, Debug, Serialize)]
pub struct GlbReport {
    pub file: String,
    pub bytes: usize,
    pub compression: Option<&'static str>,
    /// `msft-lod` or `lod-nodes`.
    pub layout: &'static str,
    pub levels: usize,
    pub screen_coverage: Vec<f64>,
}

/// Encodes the levels of `lod` that have a surface as one chain and adds `DIR/lod.glb` to `out`.
pub fn add_chain(
    out: &mut OutputSet,
    dir: &Path,
    lod: &Lod,
    args: &GlbArgs,
) -> Result<GlbReport, CliError> {
    if args.layout == LayoutArg::LodNodes {
        return add_lod_nodes(out, dir, lod, args);
    }
    let options = match args.compress {
        Some(CompressArg::Meshopt) => ChainOptions::meshopt(),
        None => ChainOptions::default(),
    };
    let path = in_dir(dir, CHAIN_FILE);
    let (bytes, screen_coverage) = voxlod::lod_glb(lod, &options).map_err(|e| in_file(&path, e))?;
    out.bytes(&path, &bytes)?;
    Ok(GlbReport {
        file: CHAIN_FILE.into(),
        bytes: bytes.len(),
        compression: args.compress.map(|_| "meshopt"),
        layout: "msft-lod",
        levels: screen_coverage.len(),
        screen_coverage,
    })
}

/// `DIR/lod.glb` with one scene node per level that has a surface, named `LOD0`, `LOD1`, …
/// (positions and normals; `voxlod::gltf::asset_glb`'s `LodNodes` layout, compressed with
/// `--compress`).
fn add_lod_nodes(
    out: &mut OutputSet,
    dir: &Path,
    lod: &Lod,
    args: &GlbArgs,
) -> Result<GlbReport, CliError> {
    let levels: Vec<_> = lod
        .levels
        .iter()
        .filter(|l| !l.mesh.is_empty())
        .map(|l| voxlod::asset::Asset {
            mesh: voxlod::asset::AssetMesh {
                positions: l.mesh.positions.clone(),
                triangles: l.mesh.triangles.clone(),
                normals: l.mesh.normals.clone(),
                ..Default::default()
            },
            ..Default::default()
        })
        .collect();
    let options = AssetGlbOptions {
        layout: Layout::LodNodes,
        compression: args.compression(),
        ..AssetGlbOptions::default()
    };
    let path = in_dir(dir, CHAIN_FILE);
    let bytes = voxlod::gltf::asset_glb(&levels, &options).map_err(|e| in_file(&path, e))?;
    out.bytes(&path, &bytes)?;
    Ok(GlbReport {
        file: CHAIN_FILE.into(),
        bytes: bytes.len(),
        compression: args.compress.map(|_| "meshopt"),
        layout: "lod-nodes",
        levels: levels.len(),
        screen_coverage: Vec::new(),
    })
}
