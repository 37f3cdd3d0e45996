//! `voxlod evaluate` of a glTF asset with looks measures each level's appearance.

mod common;

use common::{arg, json, stderr, voxlod};
use voxlod::asset::{Asset, AssetMesh, Material};
use voxlod::core::glam::Vec4;
use voxlod::gltf::{asset_glb, AssetGlbOptions};

/// An icosphere of 1280 triangles, red above the equator and blue below.
fn two_colour_sphere() -> Asset {
    let sphere = voxlod_testkit::shapes::icosphere(3);
    let colors = (sphere.positions.iter())
        .map(|p| {
            if p.y > 0.0 {
                Vec4::new(1.0, 0.0, 0.0, 1.0)
            } else {
                Vec4::new(0.0, 0.0, 1.0, 1.0)
            }
        })
        .collect();
    Asset {
        mesh: AssetMesh {
            normals: sphere.positions.iter().map(|p| p.normalize()).collect(),
            material: vec![0; sphere.triangles.len()],
            positions: sphere.positions,
            triangles: sphere.triangles,
            colors,
            ..Default::default()
        },
        materials: vec![Material {
            metallic: 0.0,
            ..Material::default()
        }],
        ..Default::default()
    }
}

#[test]
fn evaluate_reports_the_appearance_of_an_asset_s_levels() {
    let dir = tempfile::tempdir().unwrap();
    let glb = dir.path().join("sphere.glb");
    let bytes = asset_glb(&[two_colour_sphere()], &AssetGlbOptions::default()).unwrap();
    std::fs::write(&glb, bytes).unwrap();
    let out = dir.path().join("eval");
    let o = voxlod(&[
        "evaluate",
        arg(&glb),
        "-o",
        arg(&out),
        "--methods",
        "rossignac-borrel",
        "--budgets",
        "300",
        "--views",
        "0",
        "--samples",
        "2000",
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let report = json(&o);
    assert_eq!(report["appearance_views"], 14);
    let point = &report["curves"][0]["points"][0];
    let (psnr, ssim) = (
        point["appearance"]["psnr"].as_f64().unwrap(),
        point["appearance"]["ssim"].as_f64().unwrap(),
    );
    assert!(psnr > 15.0 && psnr.is_finite(), "{point}");
    assert!(ssim > 0.7 && ssim < 1.0, "{point}");
    let markdown = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(markdown.contains("PSNR in dB · SSIM"), "{markdown}");
}
