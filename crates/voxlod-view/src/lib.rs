//! `voxlod view`: one self-contained HTML page that shows level chains and layered shells in a
//! browser with WebGL2 — no network at view time: the script and the `.glb` data are inlined.
//!
//! What it draws (the script is `src/viewer.js`, embedded with `include_str!`):
//! - an `MSFT_lod` chain (`voxlod lod --format glb`), switching levels by screen coverage with the
//!   file's `MSFT_screencoverage`, i.e. `voxlod select`'s pixel-size rule (Low–Tan's display
//!   step; the pyramid of He et al. 1995 §2); an overlay names the level and its triangles;
//! - layered shells (`voxlod layers`, paper §3) blended back to front with the stored order of
//!   the view direction's octant, switching the index buffer as the camera crosses an octant
//!   boundary — while the filter radius on screen is at most 0.45 px, where BENCHMARKS.md
//!   measured the layers beating the single surface; closer, the single surface is drawn;
//! - a chain of layered levels (`voxlod layers --lod`): the coarsest level whose filter radius
//!   on screen is at most the file's limit (0.45 px), drawn as layered shells; closer than the
//!   finest level allows, its single surface; a second patch shows the level;
//! - the same chain as one scene node per level named `LOD0`, `LOD1`, … (`--layout lod-nodes`,
//!   the importers' LOD-group convention), switched by the rule voxlod's writer uses for its
//!   default `MSFT_screencoverage` (half the square root of the next level's share of level 0's
//!   triangles, from the nodes' `extras.voxlod.triangles` or counted), so both layouts of the
//!   same levels switch at the same distances; equal steps where the triangles do not decrease;
//! - any other glTF 2.0 binary (a `voxlod cluster` chain too): triangles shaded, lines as thick
//!   screen-space quads (3 px, or their `_WIDTH` in object units on screen if wider), points.
//!
//! **Looks** (triangles of chains and plain files; the layered shells and the lines keep their
//! flat colours): the material's base colour factor × its base colour texture × `COLOR_0`
//! (vec3 or vec4, float or normalized integers), with `TEXCOORD_0`/`TEXCOORD_1` (float or
//! normalized integers, as `KHR_mesh_quantization` writes them), the texture's sampler (wrap,
//! filters, mipmaps) and `KHR_texture_transform` (offset, rotation, scale, texCoord); alpha
//! `MASK` (cutoff) and `BLEND` (drawn after the opaque draws, back to front by their bounds, a
//! single-sided one with its back faces culled);
//! a tangent-space normal map (through `TANGENT` where the file has it, else a frame from
//! screen-space derivatives) and emissive factor × texture × `KHR_materials_emissive_strength`.
//! Colour textures are `SRGB8_ALPHA8` (decoded to linear by the GPU), shading is in linear light
//! and the result sRGB-encoded, as glTF defines its colours. Images (PNG, JPEG, WebP from a
//! buffer view or a `data:` URI) decode asynchronously after the first frame, which draws
//! a white stand-in; each decoded image draws the view again. What the page cannot show (a KTX2
//! image, a third texture coordinate set, an image the browser fails to decode) is named in the
//! overlay and drawn without; an image outside the `.glb` is refused by [`check_glb`].
//!
//! **Compressed files**: `EXT_meshopt_compression` and `KHR_draco_mesh_compression` are
//! decoded in Rust before the page is made ([`voxlod_gltf::decompress_glb`], with the `meshopt`
//! and `draco-core` crates), so the page holds plain views and needs no decoder of its own;
//! quantized attributes stay quantized (WebGL reads them), and GPU instances
//! (`EXT_mesh_gpu_instancing`) become child nodes. Other required extensions the page does not
//! read are refused with an error naming the extension.
//!
//! **Why our own renderer and not three.js**: the page needs a glTF subset (float and quantized
//! attributes, three primitive modes, node transforms, metallic-roughness materials' colour,
//! normal and emissive textures), a shaded and a material program, instanced quads for
//! thick lines and control over the index buffer and blend order per frame. three.js would add
//! about 700 kB minified (plus its GLTFLoader and a meshopt decoder), a lockfile and a bundling
//! step, and would still need custom code for the octant orders, which its renderer sorts
//! itself. The renderer here is about 850 lines; meshopt and Draco data are decoded in Rust
//! ([`voxlod_gltf::decompress_glb`]) so the page needs no decoder.
//!
//! For tests and scripts: the hash `#camera=DISTANCE,DX,DY,DZ&model=I` (direction from the
//! object's centre to the eye) or `window.voxlodView.setCamera(distance, [dx, dy, dz])`; the
//! page's title reports what is drawn (`voxlod level=K triangles=N` or `voxlod order=NAME …`)
//! and a 24-pixel patch at the top left shows it in colour (level or octant; black for the
//! single surface). `voxlod_testkit::browser::screenshot` takes a headless Chromium's picture of a page for the
//! tests.
//!
//! Beyond the paper: the paper rendered offline; the viewer and its switching rules are ours.
//! Cost: building a page is linear in the inputs.

pub mod check;
pub mod error;
pub mod page;

pub use check::{check_glb, CheckedGlb};
pub use error::ViewError;
pub use page::{page_html, read_model, write_page, PageModel, ViewOptions};

/// The level patch colours of the page, by level (or octant) index, as 8-bit RGB.
pub const PATCH_COLORS: [[u8; 3]; 8] = [
    [230, 25, 75],
    [60, 180, 75],
    [0, 130, 200],
    [245, 130, 48],
    [145, 30, 180],
    [70, 240, 240],
    [240, 50, 230],
    [210, 245, 60],
];
