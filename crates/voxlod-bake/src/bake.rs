//! The source's looks baked onto a level: the level gets an atlas ([`crate::atlas`]) and
//! MikkTSpace tangents ([`crate::tangents`]); each texel a triangle covers
//! ([`crate::raster`]) stands for a point of the level, with its interpolated normal and
//! tangent frame; a ray cast from that point along its triangle's normal finds the source
//! ([`crate::cast`]; passing the texels an alpha-masked material shows nothing at, as a
//! viewer's ray passes a leaf card's gaps to the leaves behind, and meeting the open parts of a
//! double-sided material from their back too), whose looks there ([`crate::source`]), its
//! textures averaged over the texel's footprint ([`crate::mipmaps`]), are written to the texel:
//! base colour, the source's shading normal in the level's tangent frame,
//! occlusion-roughness-metallic and emissive where the source has them, alpha where it has
//! alpha: where the source lets light through, the texel's opacity and colour measured by
//! view rays through the level ([`crate::opacity`], averaged over neighbours in the chart),
//! and the level drawn blended. The charts' looks are then pushed into the gutters ([`crate::dilate`]) and the
//! textures encoded as PNG, or JPEG on request ([`crate::output`]). Several levels of one source
//! share its preparation ([`BakeSource`], [`bake_levels`]).
//!
//! The same job as Simplygon's or InstaLOD's material casting, xNormal's bake to a cage.
//!
//! Cost: the atlas's; then O(texels × log N) ray casts for N source triangles, on all cores
//! (with `1 + 2 × opacity_rays` casts a texel where the source lets light through).

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use voxlod_asset::Asset;
use voxlod_core::components::triangle_components;
use voxlod_core::glam::{Vec2, Vec3, Vec4};
use voxlod_core::manifold::on_open_edges;
use voxlod_core::weld::weld_vertices;
use voxlod_core::TriangleMesh;

use crate::cast::Cast;
use crate::dilate::{apply, dilation_sources, Dilation};
use crate::mipmaps::texels_per_unit;
use crate::opacity::{draw_of, smooth, Seen, ViewRays};
use crate::output::{proxy_asset, TexelValues, Textures};
use crate::raster::{Cover, Coverage, UNCOVERED};
use crate::slivers::{median_edge, SNAP_VOXELS};
use crate::source::{linear_to_srgb, Channels, Look, SourceLooks};
use crate::tangents::mikktspace;
use crate::{atlas, Atlas, AtlasOptions, BakeError, ImageFormat};

/// View rays per texel that measure its opacity by default ([`BakeOptions::opacity_rays`]).
pub const OPACITY_RAYS: u32 = 4;

/// Options of [`bake`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct BakeOptions {
    /// The atlas: texture size or density, padding, creases.
    pub atlas: AtlasOptions,
    /// How far from the level a ray looks for the source, in world units; `None`:
    /// [`cage_voxels`](Self::cage_voxels) voxels.
    pub cage: Option<f32>,
    /// The level's voxel size, for the cage and the atlas's slivers; `None`: the level's
    /// median edge length stands in (a marching cubes level's edges are about a voxel long).
    pub voxel_size: Option<f32>,
    /// The cage distance in voxels, where [`cage`](Self::cage) is not given.
    pub cage_voxels: f32,
    /// How far the charts' looks spread into the gutters.
    pub dilation: Dilation,
    /// How the base colour, ORM and emissive textures are encoded (the normal map is PNG
    /// either way; see [`crate::output`]).
    pub images: ImageFormat,
    /// View rays per texel that measure its opacity where the source lets light through
    /// ([`crate::opacity`]; the level is then drawn blended); 0: a texel takes the alpha of
    /// the point its bake ray found, and the level masks or blends as the source does.
    pub opacity_rays: u32,
}

impl Default for BakeOptions {
    /// A 1024² atlas, a cage of 2 voxels, the whole gutter filled, PNG textures, opacity
    /// from [`OPACITY_RAYS`] view rays.
    fn default() -> Self {
        BakeOptions {
            atlas: AtlasOptions::default(),
            cage: None,
            voxel_size: None,
            cage_voxels: 2.0,
            dilation: Dilation::Whole,
            images: ImageFormat::Png,
            opacity_rays: OPACITY_RAYS,
        }
    }
}

impl BakeOptions {
    /// A square texture of `texels` a side, the rest default.
    pub fn for_texture(texels: u32) -> Self {
        BakeOptions {
            atlas: AtlasOptions::for_texture(texels),
            ..BakeOptions::default()
        }
    }

    /// The atlas's options: [`atlas`](Self::atlas), its slivers measured in the level's
    /// voxels where the voxel is given and the atlas options do not set them.
    pub fn atlas_options(&self) -> AtlasOptions {
        let voxel_slivers = self.voxel_size.map(|v| SNAP_VOXELS * v);
        AtlasOptions {
            sliver_edge: self.atlas.sliver_edge.or(voxel_slivers),
            ..self.atlas.clone()
        }
    }
}

/// What a bake did, for a level's report.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct BakeReport {
    /// Texture width in texels.
    pub width: u32,
    /// Texture height in texels.
    pub height: u32,
    /// Charts of the atlas.
    pub charts: usize,
    /// Covered texels over all texels.
    pub utilisation: f64,
    /// Texels a triangle covers.
    pub texels: usize,
    /// Covered texels whose ray found the source.
    pub texels_hit: usize,
    /// Covered texels that took the source's nearest point instead.
    pub texels_fallback: usize,
    /// Covered texels whose opacity view rays measured (where the source lets light
    /// through; [`crate::opacity`]).
    pub texels_opacity: usize,
    /// The cage distance used.
    pub cage: f32,
    /// Seconds of the atlas.
    pub atlas_seconds: f64,
    /// Seconds in all.
    pub seconds: f64,
    /// What could not be baked as asked (an image not decoded, folded charts).
    pub warnings: Vec<String>,
}

/// A level with its looks baked.
#[derive(Clone, Debug)]
pub struct Baked {
    /// The level as an asset: one material, its textures as PNG (or JPEG as asked), texture
    /// coordinates, normals and tangents; ready for `voxlod_gltf::asset_glb`.
    pub asset: Asset,
    /// The atlas it was baked on.
    pub atlas: Atlas,
    /// What the bake did.
    pub report: BakeReport,
}

/// Bakes `source`'s looks onto `level` (see the module documentation). Refuses an invalid
/// source or level, bad options, and a texture the memory limit cannot hold (asked before
/// anything of the texture's size is allocated).
pub fn bake(
    source: &Asset,
    level: &TriangleMesh,
    options: &BakeOptions,
) -> Result<Baked, BakeError> {
    let start = Instant::now();
    options.images.check()?;
    let made = atlas(level, &options.atlas_options())?;
    let mut baked = bake_on(source, level, made, options)?;
    baked.report.seconds = start.elapsed().as_secs_f64();
    Ok(baked)
}

/// The atlases of several levels, each made as [`bake`] makes it (`atlas(level,
/// &options.atlas_options())`), side by side on all cores: xatlas packs one level's charts on
/// one core, and the packing is most of an atlas's time. `None` where a level is not to be
/// baked. Bake each with [`bake_on`], or make and bake them all with [`bake_levels`].
pub fn atlases(
    levels: &[Option<(&TriangleMesh, &BakeOptions)>],
) -> Vec<Option<Result<Atlas, BakeError>>> {
    levels
        .par_iter()
        .map(|l| l.map(|(level, options)| atlas(level, &options.atlas_options())))
        .collect()
}

/// A source made ready to bake from, once for any number of levels: its looks (decoded
/// images, mipmaps) and its ray-cast structures (two BVHs over its triangles, the costly
/// part: 0.65 s for a million triangles).
pub struct BakeSource<'a> {
    source: &'a Asset,
    looks: SourceLooks<'a>,
    cast: Cast,
}

impl<'a> BakeSource<'a> {
    /// Prepares `source`; refuses what [`Cast::new`] and the looks refuse (an empty or
    /// invalid mesh, a structure over the memory limit).
    pub fn new(source: &'a Asset) -> Result<BakeSource<'a>, BakeError> {
        let looks = SourceLooks::new(source)?;
        let geometry = source.mesh.geometry();
        let both = seen_from_both_sides(source, &geometry, &looks);
        let cast = Cast::new(&geometry)?.with_two_sided(|t| both[t]);
        Ok(BakeSource {
            source,
            looks,
            cast,
        })
    }
}

/// Which of `source`'s triangles (its `geometry`) a viewer sees from both sides: those of a double-sided
/// material (glTF §3.9.4) in a part with an open edge once welded (a leaf card, a sheet). A
/// closed part's back faces are its inside, never seen, though exporters often mark every
/// material double-sided. Cost: a weld and a sort of the edges, O(F log F), only where some
/// material is double-sided.
fn seen_from_both_sides(source: &Asset, geometry: &TriangleMesh, looks: &SourceLooks) -> Vec<bool> {
    let count = geometry.triangles.len();
    if !source.materials.iter().any(|m| m.double_sided) {
        return vec![false; count];
    }
    let mut welded = geometry.clone();
    weld_vertices(&mut welded);
    let open_edge = on_open_edges(&welded.triangles);
    let mut both = vec![false; count];
    for part in triangle_components(&welded) {
        if part.iter().any(|&t| open_edge[t as usize]) {
            for t in part.into_iter().map(|t| t as usize) {
                both[t] = looks.double_sided(t);
            }
        }
    }
    both
}

/// Every level of `levels` (`None`: not baked) baked as [`bake`] bakes it, the source
/// prepared once ([`BakeSource`]), each level's bake begun as soon as its atlas is made (the
/// levels' atlases and bakes side by side on all cores: the largest level's atlas packs on one
/// core while the smaller levels bake on the others). `baked(k)` is called after level k's
/// bake; once it answers `false`, no bake begins, and the levels not baked are `None`.
/// Memory: the bakes that overlap hold their textures at once.
pub fn bake_levels(
    source: &Asset,
    levels: &[Option<(&TriangleMesh, &BakeOptions)>],
    baked: &(dyn Fn(usize) -> bool + Sync),
) -> Result<Vec<Option<Baked>>, BakeError> {
    let prepared = BakeSource::new(source)?;
    let stopped = AtomicBool::new(false);
    (levels.par_iter().enumerate())
        .map(|(k, l)| {
            let Some((level, options)) = l else {
                return Ok(None);
            };
            options.images.check()?;
            let made = atlas(level, &options.atlas_options())?;
            if stopped.load(Ordering::Relaxed) {
                return Ok(None);
            }
            let done = bake_from(&prepared, level, made, options)?;
            if !baked(k) {
                stopped.store(true, Ordering::Relaxed);
            }
            Ok(Some(done))
        })
        .collect()
}

/// [`bake`] on an atlas made already (`atlas(level, &options.atlas_options())`, perhaps by
/// [`atlases`] beside other levels'). Its report's seconds are
/// the atlas's and this call's. Refuses an atlas that is not `level`'s (another triangle
/// count, or a vertex copying no vertex of the level).
pub fn bake_on(
    source: &Asset,
    level: &TriangleMesh,
    atlas: Atlas,
    options: &BakeOptions,
) -> Result<Baked, BakeError> {
    let start = Instant::now();
    // Checked before the source is prepared, which costs far more than the check.
    check_inputs(level, &atlas, options)?;
    let mut baked = bake_checked(&BakeSource::new(source)?, level, atlas, options)?;
    baked.report.seconds = baked.report.atlas_seconds + start.elapsed().as_secs_f64();
    Ok(baked)
}

/// [`bake_on`] from a source prepared already (once for several levels).
pub fn bake_from(
    prepared: &BakeSource,
    level: &TriangleMesh,
    atlas: Atlas,
    options: &BakeOptions,
) -> Result<Baked, BakeError> {
    check_inputs(level, &atlas, options)?;
    bake_checked(prepared, level, atlas, options)
}

/// [`bake_from`] with its inputs checked already.
fn bake_checked(
    prepared: &BakeSource,
    level: &TriangleMesh,
    atlas: Atlas,
    options: &BakeOptions,
) -> Result<Baked, BakeError> {
    let start = Instant::now();
    let BakeSource {
        source,
        looks,
        cast,
    } = prepared;
    let tangents = mikktspace(
        &atlas.positions,
        &atlas.normals,
        &atlas.uv,
        &atlas.triangles,
    );
    let cage = cage_of(level, options)?;
    let cover = atlas.coverage();
    let emissive_scale = emissive_scale(source);
    let frame = Frame {
        atlas: &atlas,
        tangents: &tangents,
    };
    let texel_sizes = texel_sizes(&atlas);
    let rays = if looks.channels.alpha {
        options.opacity_rays
    } else {
        0
    };
    let own = (rays > 0).then(|| Cast::new(level)).transpose()?;
    let view_rays = own.as_ref().map(|own| ViewRays {
        level: own,
        source: cast,
        looks,
        rays,
        cage,
    });
    let baker = TexelBaker {
        frame,
        cast,
        looks,
        view_rays,
        cage,
        texel_sizes,
        emissive_scale,
    };
    let baked: Vec<(TexelValues, Texel, Option<Seen>)> = (cover.texels.par_iter().enumerate())
        .map(|(index, c)| baker.bake(index, c))
        .collect();
    let texels_hit = baked.iter().filter(|b| b.1 == Texel::Hit).count();
    let texels_opacity = baked.iter().filter(|b| b.1 == Texel::Opacity).count();
    let covered: Vec<bool> = baked.iter().map(|b| b.1 != Texel::Uncovered).collect();
    let seen: Vec<Option<Seen>> = baked.iter().map(|b| b.2).collect();
    let mut values: Vec<TexelValues> = baked.into_iter().map(|b| b.0).collect();
    if own.is_some() {
        with_opacity(&mut values, &seen, &cover, &atlas);
    }
    let sources = dilation_sources(&covered, cover.width, cover.height, options.dilation);
    apply(&mut values, &sources);
    let texels = covered.iter().filter(|&&c| c).count();
    drop(cover);
    let mut warnings = looks.warnings.clone();
    warnings.extend(folded(&atlas));
    warnings.extend(narrowed(&atlas, options.atlas.padding));
    let textures = Textures {
        width: atlas.width,
        height: atlas.height,
        values: &values,
        channels: looks.channels,
        opacity_measured: own.is_some(),
        level_open: on_open_edges(&level.triangles).iter().any(|&open| open),
        emissive_scale,
        format: options.images,
    };
    let (asset, noted) = proxy_asset(&atlas, &tangents, &textures, source)?;
    warnings.extend(noted);
    let report = BakeReport {
        width: atlas.width,
        height: atlas.height,
        charts: atlas.chart_count,
        utilisation: atlas.utilisation,
        texels,
        texels_hit,
        texels_fallback: texels - texels_hit - texels_opacity,
        texels_opacity,
        cage,
        atlas_seconds: atlas.seconds,
        seconds: atlas.seconds + start.elapsed().as_secs_f64(),
        warnings,
    };
    Ok(Baked {
        asset,
        atlas,
        report,
    })
}

/// One texel's bake: what [`bake_checked`] needs of the level, the source and the options.
struct TexelBaker<'a> {
    frame: Frame<'a>,
    cast: &'a Cast,
    looks: &'a SourceLooks<'a>,
    /// Where the texels' opacity is measured.
    view_rays: Option<ViewRays<'a>>,
    cage: f32,
    texel_sizes: Vec<f32>,
    emissive_scale: f32,
}

impl TexelBaker<'_> {
    /// Texel `index` (covering `c`): its values, how it was baked, and what its view rays saw
    /// where they were cast (texels whose bake ray missed, or met a see-through material).
    fn bake(&self, index: usize, c: &Cover) -> (TexelValues, Texel, Option<Seen>) {
        if c.triangle == UNCOVERED {
            return (TexelValues::default(), Texel::Uncovered, None);
        }
        let (looks, frame) = (self.looks, &self.frame);
        let (p, n, t) = frame.at(c);
        let found = (self.cast).find(p, frame.face(c), self.cage, &|t, w| looks.clear(t, w));
        let footprint = self.texel_sizes[c.triangle as usize];
        let look = looks.at(found.triangle, found.weights, n, footprint);
        let (texel, seen) = match &self.view_rays {
            Some(rays) if !found.hit || looks.see_through(found.triangle) => {
                let seen = rays.seen_through(p, (n, t.truncate()), draw_of(index), footprint);
                (Texel::Opacity, Some(seen))
            }
            _ if found.hit => (Texel::Hit, None),
            _ => (Texel::Fallback, None),
        };
        let values = encode(&look, n, t, &looks.channels, self.emissive_scale);
        (values, texel, seen)
    }
}

/// The opacity and colour the view rays saw (`seen`, per texel), averaged over neighbours in
/// the chart ([`smooth`]), written into the base colour of `values`.
fn with_opacity(
    values: &mut [TexelValues],
    seen: &[Option<Seen>],
    cover: &Coverage,
    atlas: &Atlas,
) {
    let chart_of = |c: &Cover| atlas.chart.get(c.triangle as usize).copied();
    let chart: Vec<u32> = (cover.texels.iter())
        .map(|c| chart_of(c).unwrap_or(u32::MAX))
        .collect();
    let smoothed = smooth(seen, &chart, cover.width, cover.height);
    for (v, s) in values.iter_mut().zip(smoothed) {
        if let Some(s) = s {
            v.base = base_bytes(s.colour.extend(s.opacity), v.base);
        }
    }
}

/// The atlas's folded triangles, in words, where it has any.
fn folded(atlas: &Atlas) -> Option<String> {
    (atlas.flipped > 0).then(|| {
        format!(
            "{} triangles are folded over in their chart (their texels may be shared)",
            atlas.flipped
        )
    })
}

/// The warning where `atlas` has less padding than `asked` between its charts.
fn narrowed(atlas: &Atlas, asked: u32) -> Option<String> {
    (atlas.padding < asked).then(|| {
        format!(
            "{} charts fit the {}×{} texture only with {} texels of padding, not {asked} \
             (mipmaps may bleed between charts): give a larger texture",
            atlas.chart_count, atlas.width, atlas.height, atlas.padding
        )
    })
}

/// How a texel was baked.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Texel {
    /// No triangle covers it.
    Uncovered,
    /// Its ray found the source.
    Hit,
    /// It took the source's nearest point.
    Fallback,
    /// View rays measured its opacity and colour.
    Opacity,
}

/// Refuses image options that cannot be encoded and an atlas of another level than `level`.
fn check_inputs(
    level: &TriangleMesh,
    atlas: &Atlas,
    options: &BakeOptions,
) -> Result<(), BakeError> {
    options.images.check()?;
    check_atlas_of(atlas, level)
}

/// Refuses an atlas made from another level than `level`.
fn check_atlas_of(atlas: &Atlas, level: &TriangleMesh) -> Result<(), BakeError> {
    let n = level.positions.len();
    let (have, want) = (atlas.triangles.len(), level.triangles.len());
    let stray = atlas.level_vertex.iter().any(|&v| v as usize >= n);
    let inside = atlas.positions.len() == atlas.level_vertex.len()
        && atlas.uv.len() == atlas.positions.len()
        && (atlas.triangles.iter().flatten()).all(|&v| (v as usize) < atlas.positions.len());
    if have != want || stray || !inside {
        return Err(BakeError::Invalid(format!(
            "the atlas ({have} triangles, {} vertices) was not made from this level ({want} \
             triangles, {n} vertices)",
            atlas.positions.len()
        )));
    }
    Ok(())
}

/// Per triangle of `atlas`, the side of one of its texels on the level's surface (world
/// units): the square root of its world area over its area in texels (0 where it has none).
fn texel_sizes(atlas: &Atlas) -> Vec<f32> {
    let scale = Vec2::new(atlas.width as f32, atlas.height as f32);
    let size = |t: &[u32; 3]| {
        let density = texels_per_unit(
            t.map(|v| atlas.positions[v as usize]),
            t.map(|v| atlas.uv[v as usize] * scale),
        );
        if density > 0.0 {
            1.0 / density
        } else {
            0.0
        }
    };
    atlas.triangles.iter().map(size).collect()
}

/// The level's surface at a texel: position, unit normal, tangent frame.
struct Frame<'a> {
    atlas: &'a Atlas,
    tangents: &'a [Vec4],
}

impl Frame<'_> {
    /// Position, unit normal and tangent (xyz unit, perpendicular to the normal; w the
    /// bitangent's sign) at the point a texel stands for.
    /// The unit normal of the texel's triangle: the direction it is cast along. A large flat
    /// triangle of a level whose corners are rounded (a voxel level's bevels) has vertex
    /// normals tilted towards its neighbours; cast along them, the rays fan out across it and
    /// what lies behind a flat face (a facade's recessed windows) is sampled sheared, in the
    /// shape of the triangulation. Along the face normal every texel of a flat face looks
    /// straight in, as a viewer in front of it does.
    fn face(&self, c: &Cover) -> Vec3 {
        let tri = self.atlas.triangles[c.triangle as usize].map(|v| v as usize);
        let [a, b, e] = tri.map(|v| self.atlas.positions[v]);
        (b - a).cross(e - a).try_normalize().unwrap_or(Vec3::Z)
    }

    fn at(&self, c: &Cover) -> (Vec3, Vec3, Vec4) {
        let tri = self.atlas.triangles[c.triangle as usize].map(|v| v as usize);
        let w = c.weights;
        let mix3 = |v: &[Vec3]| v[tri[0]] * w[0] + v[tri[1]] * w[1] + v[tri[2]] * w[2];
        let p = mix3(&self.atlas.positions);
        let [a, b, e] = tri.map(|v| self.atlas.positions[v]);
        let face = (b - a).cross(e - a).try_normalize().unwrap_or(Vec3::Z);
        let n = mix3(&self.atlas.normals).try_normalize().unwrap_or(face);
        let t4 = self.tangents[tri[0]] * w[0]
            + self.tangents[tri[1]] * w[1]
            + self.tangents[tri[2]] * w[2];
        let t = (t4.truncate() - n * n.dot(t4.truncate()))
            .try_normalize()
            .unwrap_or_else(|| n.any_orthonormal_vector());
        let sign = if self.tangents[tri[0]].w < 0.0 {
            -1.0
        } else {
            1.0
        };
        (p, n, t.extend(sign))
    }
}

/// A base colour texel of linear `colour` and opacity; where nothing was seen (opacity 0),
/// `before`'s colour with opacity 0, so that filtering at a clear texel's edge keeps the
/// colour beside it.
fn base_bytes(colour: Vec4, before: [u8; 4]) -> [u8; 4] {
    let byte = |v: f32| (v.clamp(0.0, 1.0) * 255.0).round() as u8;
    if colour.w <= 0.0 {
        return [before[0], before[1], before[2], 0];
    }
    let srgb = |v: f32| byte(linear_to_srgb(v.clamp(0.0, 1.0)));
    [
        srgb(colour.x),
        srgb(colour.y),
        srgb(colour.z),
        byte(colour.w),
    ]
}

/// A look as 8-bit texel values, the normal in the frame (`n`, `t`).
fn encode(look: &Look, n: Vec3, t: Vec4, channels: &Channels, emissive_scale: f32) -> TexelValues {
    let byte = |v: f32| (v.clamp(0.0, 1.0) * 255.0).round() as u8;
    let srgb = |v: f32| byte(linear_to_srgb(v.clamp(0.0, 1.0)));
    let tangent = t.truncate();
    let bitangent = n.cross(tangent) * t.w;
    let m = Vec3::new(
        look.normal.dot(tangent),
        look.normal.dot(bitangent),
        look.normal.dot(n),
    );
    // A source normal facing away from the level (a fold) is kept on the level's side.
    let m = Vec3::new(m.x, m.y, m.z.max(0.0))
        .try_normalize()
        .unwrap_or(Vec3::Z);
    let alpha = if channels.alpha { look.base.w } else { 1.0 };
    let e = look.emissive / emissive_scale;
    TexelValues {
        base: [
            srgb(look.base.x),
            srgb(look.base.y),
            srgb(look.base.z),
            byte(alpha),
        ],
        normal: [
            byte(m.x * 0.5 + 0.5),
            byte(m.y * 0.5 + 0.5),
            byte(m.z * 0.5 + 0.5),
            255,
        ],
        orm: [
            byte(look.occlusion),
            byte(look.roughness),
            byte(look.metallic),
            255,
        ],
        emissive: [srgb(e.x), srgb(e.y), srgb(e.z), 255],
    }
}

/// The largest emitted value of the source's materials (at least 1): the baked emissive
/// texture holds emission over it, the material's emissive strength restores it.
fn emissive_scale(source: &Asset) -> f32 {
    source
        .materials
        .iter()
        .flat_map(|m| m.emissive.map(|e| e * m.emissive_strength))
        .fold(1.0f32, f32::max)
}

/// The cage distance: given, or `cage_voxels` voxels (the voxel size given, or the level's
/// median edge length).
fn cage_of(level: &TriangleMesh, options: &BakeOptions) -> Result<f32, BakeError> {
    let cage = match (options.cage, options.voxel_size) {
        (Some(c), _) => c,
        (None, Some(v)) => options.cage_voxels * v,
        (None, None) => options.cage_voxels * median_edge(level),
    };
    if !(cage.is_finite() && cage > 0.0) {
        return Err(BakeError::Invalid(format!(
            "the cage distance {cage} is not a positive number"
        )));
    }
    Ok(cage)
}
