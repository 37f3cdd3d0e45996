//! Budget levels of a textured asset keep its texture where the portfolio chooses the input's
//! collapse: Spot (Keenan Crane's textured cow, 5856 triangles), written as `.glb` and read
//! back as a glTF asset, at 50 % and 5 % of its triangles. The collapse with attributes is
//! somewhat farther from the input than the geometric collapse, because its UV seams stay; it
//! is kept with its texture rather than the geometric level with the texture reduced to
//! vertex colours, which renders farther from the input. Where the portfolio chooses a voxel
//! level (a globe textured in two halves, under 1 % of its triangles), the textured collapse
//! replaces it where its colours are closer to the input's, and renders closer too.

use voxlod::asset::Asset;
use voxlod::gltf::{asset_glb, parse_scene, AssetGlbOptions};
use voxlod::portfolio::Looks;
use voxlod::{asset_lod_by_budget, run_to_end, BudgetOptions};
use voxlod_eval::appearance::{AppearanceOptions, AppearanceReference};

const TEST: &str = "a_textured_collapse_keeps_its_texture_when_a_little_farther";

fn spot_as_glb() -> Option<Asset> {
    let path = voxlod_testkit::data::shared_data_or_skip("assets/spot/spot.obj", TEST)?;
    let read = voxlod::io::read_asset(&path).unwrap().asset;
    let bytes = asset_glb(&[read], &AssetGlbOptions::default()).unwrap();
    Some(parse_scene(&bytes, None).unwrap().asset)
}

#[test]
fn a_textured_collapse_keeps_its_texture_when_a_little_farther() {
    let Some(input) = spot_as_glb() else {
        return;
    };
    let options = AppearanceOptions {
        views: 14,
        size: 128,
        supersample: 1,
    };
    let reference = AppearanceReference::new(&input, &options).unwrap();
    for budget in [2928, 293] {
        let lod_options = BudgetOptions::for_triangles(&[budget]);
        let made = asset_lod_by_budget(&input, &lod_options, &run_to_end).unwrap();
        let level = &made.assets[0];
        assert_eq!(level.looks, Looks::Kept, "{budget} triangles");
        let a = level.asset.as_ref().unwrap();
        assert!(!a.mesh.uv[0].is_empty());
        assert!(a.materials.iter().any(|m| m.base_color_texture.is_some()));
        // The kept level renders closer to the input than the same geometry's collapse with
        // its texture transferred to vertex colours.
        let transferred = voxlod::asset::transfer(&input, &a.mesh.geometry())
            .unwrap()
            .asset;
        let kept = reference.compare(a).unwrap().psnr;
        let colours = reference.compare(&transferred).unwrap().psnr;
        assert!(
            kept > colours,
            "{budget}: kept {kept} dB, transferred {colours} dB"
        );
    }
}

/// A latitude-longitude sphere (a vertex per segment at each pole, the meridian's vertices
/// doubled) textured with the two-halves image along its longitude: red on one side, blue
/// on the other.
fn halves_globe(rings: u32, segments: u32) -> Asset {
    let mut asset = voxlod_testkit::assets::textured_sphere(1);
    let centre = voxlod::core::glam::Vec3::ZERO;
    asset.mesh = voxlod_testkit::assets::uv_sphere(centre, 1.0, rings, segments);
    asset.mesh.material = vec![0; asset.mesh.triangles.len()];
    asset
}

#[test]
fn a_textured_collapse_replaces_a_voxel_level_where_its_colours_are_closer() {
    let input = halves_globe(48, 96);
    let options = AppearanceOptions {
        views: 14,
        size: 128,
        supersample: 1,
    };
    let reference = AppearanceReference::new(&input, &options).unwrap();
    for budget in [90, 40] {
        let portfolio = voxlod::portfolio::PortfolioOptions::for_triangles(&[budget]);
        let run = voxlod::portfolio::asset_levels(&input, &portfolio).unwrap();
        let geometric = voxlod::portfolio::levels(&input.mesh.geometry(), &portfolio).unwrap();
        let level = &run.levels[0];
        let chosen = &geometric.levels[0];
        assert_eq!(level.looks, Looks::Kept, "{budget} triangles");
        assert!(!level.asset.mesh.uv[0].is_empty());
        // Farther than the chosen level: kept by its colours, not by its distance.
        assert!(
            level.report.hausdorff > chosen.report.hausdorff,
            "{budget}: {} against {}",
            level.report.hausdorff,
            chosen.report.hausdorff
        );
        let transferred = voxlod::asset::transfer(&input, &geometric.levels[0].mesh)
            .unwrap()
            .asset;
        let kept = reference.compare(&level.asset).unwrap().psnr;
        let colours = reference.compare(&transferred).unwrap().psnr;
        assert!(
            kept > colours,
            "{budget}: kept {kept} dB, transferred {colours} dB"
        );
    }
}

#[test]
fn voxel_levels_of_a_textured_scene_are_baked_closer_than_vertex_colours() {
    // The pyramid's levels share no vertex with the input: each gets an atlas and a texture
    // cast from the scene, which renders closer than the scene's colours in its vertices.
    let scene = voxlod_testkit::assets::three_part_scene();
    let options = voxlod::LodOptions::halving(40, 2, voxlod::sampling::Filter::Hypercone);
    let made = voxlod::asset_lod(&scene, &options, &run_to_end).unwrap();
    let view = AppearanceOptions {
        views: 14,
        size: 128,
        supersample: 1,
    };
    let reference = AppearanceReference::new(&scene, &view).unwrap();
    for (level, lod_level) in made.assets.iter().zip(&made.lod.levels) {
        assert_eq!(level.looks, Looks::Baked);
        let a = level.asset.as_ref().unwrap();
        assert_eq!(a.materials.len(), 1);
        assert!(a.materials[0].base_color_texture.is_some());
        let transferred = voxlod::asset::transfer(&scene, &lod_level.mesh)
            .unwrap()
            .asset;
        let baked = reference.compare(a).unwrap().psnr;
        let colours = reference.compare(&transferred).unwrap().psnr;
        assert!(
            baked > colours,
            "baked {baked} dB, vertex colours {colours} dB"
        );
    }
}

#[test]
fn a_texture_that_cannot_be_decoded_is_named_not_fatal() {
    // A KTX2 base colour texture (passed through, never decoded): the levels are made, their
    // looks come from the material's factor, and a warning names the image.
    let mut asset = voxlod_testkit::assets::textured_sphere(4);
    asset.images[0].mime = "image/ktx2".into();
    asset.images[0].name = "swatch.ktx2".into();
    let options = BudgetOptions::for_triangles(&[2000, 200]);
    let made = asset_lod_by_budget(&asset, &options, &run_to_end).unwrap();
    assert_eq!(made.assets.len(), 2);
    assert!(made.assets.iter().all(|l| l.asset.is_some()));
    let named = made.lod.warnings.iter().any(|w| w.contains("swatch.ktx2"));
    let kept = made.assets.iter().all(|l| l.looks == Looks::Kept);
    // A kept level carries the texture slot unchanged and needs no decoding.
    assert!(named || kept, "{:?}", made.lod.warnings);
    let pyramid = voxlod::LodOptions::halving(24, 2, voxlod::sampling::Filter::Hypercone);
    let made = voxlod::asset_lod(&asset, &pyramid, &run_to_end).unwrap();
    for level in &made.assets {
        assert_eq!(
            level.looks,
            Looks::Transferred,
            "nothing decodes: nothing to bake"
        );
    }
    let named = made.lod.warnings.iter().any(|w| w.contains("swatch.ktx2"));
    assert!(named, "{:?}", made.lod.warnings);
}
