//! The appearance measure: identical renders, a level with and without its texture, a mesh
//! without looks.

use std::sync::Arc;

use glam::Vec2;
use image::ImageEncoder;
use voxlod_asset::{collapse, Asset, AssetMesh, Image, Material, Sampler, TextureRef};
use voxlod_eval::appearance::{appearance, AppearanceOptions, AppearanceReference};

fn png(w: u32, h: u32, rgb: impl Fn(u32, u32) -> [u8; 3]) -> Vec<u8> {
    let bytes: Vec<u8> = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .flat_map(|(x, y)| rgb(x, y))
        .collect();
    let mut out = Vec::new();
    image::codecs::png::PngEncoder::new(&mut out)
        .write_image(&bytes, w, h, image::ExtendedColorType::Rgb8)
        .unwrap();
    out
}

/// A unit icosphere of 5120 triangles without looks.
fn plain_sphere() -> Asset {
    let sphere = voxlod_testkit::shapes::icosphere(4);
    Asset {
        mesh: AssetMesh {
            normals: sphere.positions.iter().map(|p| p.normalize()).collect(),
            positions: sphere.positions,
            triangles: sphere.triangles,
            ..Default::default()
        },
        ..Default::default()
    }
}

/// The icosphere with planar texture coordinates (x, y) and a 64² checker of 4-texel squares,
/// orange and teal.
fn checkered_sphere() -> Asset {
    let mut asset = plain_sphere();
    let mesh = &mut asset.mesh;
    mesh.uv[0] = (mesh.positions.iter())
        .map(|p| Vec2::new(0.5 + 0.5 * p.x, 0.5 - 0.5 * p.y))
        .collect();
    mesh.material = vec![0; mesh.triangles.len()];
    asset.materials = vec![Material {
        base_color_texture: Some(TextureRef {
            image: 0,
            tex_coord: 0,
            transform: None,
            sampler: Sampler::default(),
        }),
        ..Material::default()
    }];
    let checker = png(64, 64, |x, y| {
        if (x / 4 + y / 4) % 2 == 0 {
            [240, 140, 30]
        } else {
            [20, 150, 160]
        }
    });
    asset.images = vec![Image {
        name: "checker".into(),
        mime: "image/png".into(),
        bytes: Arc::new(checker),
    }];
    asset
}

#[test]
fn identical_renders_score_infinite_psnr_and_ssim_one() {
    let input = checkered_sphere();
    let options = AppearanceOptions {
        views: 4,
        size: 128,
        supersample: 1,
    };
    let report = appearance(&input, &input, &options).unwrap();
    assert_eq!(report.psnr, f64::INFINITY);
    assert_eq!(report.ssim, 1.0);
    assert_eq!(report.per_view.len(), 4);
    assert!(report
        .per_view
        .iter()
        .all(|v| v.mse == 0.0 && v.ssim == 1.0));
    assert!(report.warnings.is_empty(), "{:?}", report.warnings);
}

#[test]
fn a_level_with_its_texture_replaced_by_grey_scores_clearly_lower() {
    let input = checkered_sphere();
    let level = collapse(&input, 600).unwrap();
    assert!(
        level.mesh.triangles.len() <= 700,
        "{}",
        level.mesh.triangles.len()
    );
    let mut grey = level.clone();
    grey.images[0].bytes = Arc::new(png(4, 4, |_, _| [130, 145, 95]));
    let reference = AppearanceReference::new(&input, &AppearanceOptions::default()).unwrap();
    let textured = reference.compare(&level).unwrap();
    let untextured = reference.compare(&grey).unwrap();
    eprintln!(
        "level of {} triangles: textured PSNR {:.2} dB SSIM {:.4}; grey PSNR {:.2} dB SSIM {:.4}",
        level.mesh.triangles.len(),
        textured.psnr,
        textured.ssim,
        untextured.psnr,
        untextured.ssim
    );
    assert_eq!(textured.per_view.len(), 14);
    assert!(textured.psnr.is_finite() && textured.ssim < 1.0);
    assert!(textured.psnr > untextured.psnr + 3.0);
    assert!(textured.ssim > untextured.ssim + 0.05);
    // View by view too.
    for (t, g) in textured.per_view.iter().zip(&untextured.per_view) {
        assert!(t.psnr > g.psnr && t.ssim > g.ssim, "{t:?} {g:?}");
    }
}

#[test]
fn a_mesh_without_looks_is_measured_on_its_shaded_renders() {
    let input = plain_sphere();
    let level = collapse(&input, 300).unwrap();
    let options = AppearanceOptions {
        size: 256,
        ..AppearanceOptions::default()
    };
    let report = appearance(&input, &level, &options).unwrap();
    eprintln!(
        "plain sphere at {} triangles: PSNR {:.2} dB, SSIM {:.4}",
        level.mesh.triangles.len(),
        report.psnr,
        report.ssim
    );
    assert!(report.psnr.is_finite() && report.psnr > 25.0, "{report:?}");
    assert!(report.ssim < 1.0 && report.ssim > 0.8, "{report:?}");
}

#[test]
fn evaluate_asset_measures_each_level_s_appearance() {
    use voxlod::metrics::DistanceOptions;
    use voxlod_eval::evaluate::{evaluate_asset, report, Budgets, EvaluateOptions, ImageOptions};

    let input = checkered_sphere();
    let options = EvaluateOptions {
        methods: vec![
            "rossignac-borrel".parse().unwrap(),
            "voxel-gaussian".parse().unwrap(),
        ],
        budgets: Budgets::Explicit(vec![2000, 300]),
        distance: DistanceOptions::for_samples(2_000),
        images: ImageOptions::off(),
        ..EvaluateOptions::quick()
    };
    let evaluation = evaluate_asset(&input, &options, |_, _| {}).unwrap();
    assert_eq!(evaluation.appearance_views, 14);
    for curve in &evaluation.curves {
        for p in &curve.points {
            let a = p.appearance.expect("measured");
            eprintln!(
                "{} at {} triangles: PSNR {:.2} dB, SSIM {:.4}",
                curve.method, p.triangles, a.psnr, a.ssim
            );
            assert!(a.psnr.is_finite() && a.psnr > 12.0, "{a:?}");
            assert!(a.ssim > 0.5 && a.ssim < 1.0, "{a:?}");
        }
        // More triangles look closer to the input.
        if let [fine, coarse] = &curve.points[..] {
            let (f, c) = (fine.appearance.unwrap(), coarse.appearance.unwrap());
            assert!(f.ssim > c.ssim, "{}: {f:?} {c:?}", curve.method);
        }
    }
    let markdown = report::markdown(&evaluation, &report::ReportContext::default());
    assert!(markdown.contains("PSNR in dB · SSIM"), "{markdown}");
    assert!(markdown.contains(" dB · 0."), "{markdown}");
}

#[test]
fn spot_s_collapsed_levels_keep_its_looks_better_than_grey() {
    let test = "spot_s_collapsed_levels_keep_its_looks_better_than_grey";
    let Some(path) = voxlod_testkit::data::shared_data_or_skip("assets/spot/spot.obj", test) else {
        return;
    };
    let input = voxlod::io::read_asset(&path).unwrap().asset;
    let reference = AppearanceReference::new(&input, &AppearanceOptions::default()).unwrap();
    let mut last = f64::INFINITY;
    for triangles in [2000, 500] {
        let level = collapse(&input, triangles).unwrap();
        let kept = reference.compare(&level).unwrap();
        let mut grey = level.clone();
        grey.images[0].bytes = Arc::new(png(4, 4, |_, _| [150, 140, 130]));
        let grey = reference.compare(&grey).unwrap();
        eprintln!(
            "spot at {} triangles: textured {:.2} dB / SSIM {:.4}, grey {:.2} dB / {:.4}",
            level.mesh.triangles.len(),
            kept.psnr,
            kept.ssim,
            grey.psnr,
            grey.ssim
        );
        assert!(kept.psnr > grey.psnr && kept.ssim > grey.ssim);
        assert!(kept.ssim < last);
        last = kept.ssim;
    }
}
