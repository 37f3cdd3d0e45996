//! Budget levels of a textured asset keep its texture where the portfolio chooses the input's
//! collapse: Spot (Keenan Crane's textured cow, 5856 triangles), written as `.glb` and read
//! back as a glTF asset, at 50 % and 5 % of its triangles. The collapse with attributes is
//! somewhat farther from the input than the geometric collapse, because its UV seams stay; it
//! is kept with its texture rather than the geometric level with the texture reduced to
//! vertex colours, which renders farther from the input.

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
