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
//! - any other glTF 2.0 binary (a `voxlod cluster` chain too): triangles shaded, lines as thick
//!   screen-space quads (3 px, or their `_WIDTH` in object units on screen if wider), points.
//!
//! **Why our own renderer and not three.js**: the page needs a glTF subset (float and quantized
//! attributes, three primitive modes, node transforms), one shaded program, instanced quads for
//! thick lines and control over the index buffer and blend order per frame. three.js would add
//! about 700 kB minified (plus its GLTFLoader and a meshopt decoder), a lockfile and a bundling
//! step, and would still need custom code for the octant orders, which its renderer sorts
//! itself. The renderer here is about 450 lines; meshopt data is decoded in Rust
//! ([`voxlod_gltf::decompress_glb`]) so the page needs no decoder.
//!
//! For tests and scripts: the hash `#camera=DISTANCE,DX,DY,DZ&model=I` (direction from the
//! object's centre to the eye) or `window.voxlodView.setCamera(distance, [dx, dy, dz])`; the
//! page's title reports what is drawn (`voxlod level=K triangles=N` or `voxlod order=NAME …`)
//! and a 24-pixel patch at the top left shows it in colour (level or octant; black for the
//! single surface).
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
