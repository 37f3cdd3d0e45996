//! Textures as JPEG on request: base colour, occlusion-roughness-metallic and emissive are
//! JPEG (SOI marker, `image/jpeg`, `.jpg`), the normal map PNG; the JPEG base colour decodes
//! to the PNG bake's size and mean colour; a masked material keeps its base colour PNG with
//! a warning; a quality outside 1 to 100 is refused before any work.

use voxlod_asset::{AlphaMode, Asset, Material};
use voxlod_bake::{bake, BakeError, BakeOptions, Baked, ImageFormat};
use voxlod_testkit::assets::textured_sphere;
use voxlod_testkit::shapes::icosphere;

const SOI: [u8; 3] = [0xFF, 0xD8, 0xFF];
const PNG: &[u8] = b"\x89PNG\r\n\x1a\n";

/// The red and blue sphere in `alpha_mode` with alpha 0.5, glowing orange, its texture also
/// read as metallic-roughness (the blue half metallic), so that the bake has ORM and
/// emissive textures.
fn orm_emissive_sphere(alpha_mode: AlphaMode) -> Asset {
    let mut sphere = textured_sphere(3);
    let m = &mut sphere.materials[0];
    m.metallic_roughness_texture = m.base_color_texture.clone();
    m.metallic = 1.0;
    m.base_color[3] = 0.5;
    m.emissive = [0.5, 0.2, 0.0];
    m.alpha_mode = alpha_mode;
    sphere
}

/// `source` baked at 128² onto a slightly larger icosphere, its textures in `images`.
fn baked(source: &Asset, images: ImageFormat) -> Result<Baked, BakeError> {
    let mut level = icosphere(3);
    level.positions.iter_mut().for_each(|p| *p *= 1.01);
    let options = BakeOptions {
        images,
        ..BakeOptions::for_texture(128)
    };
    bake(source, &level, &options)
}

/// The image of a material slot: bytes, mime type, name.
fn slot(baked: &Baked, pick: impl Fn(&Material) -> Option<usize>) -> &voxlod_asset::Image {
    let image = pick(&baked.asset.materials[0]).expect("the slot has a texture");
    &baked.asset.images[image]
}

/// The mean of each channel of the decoded image, with its size.
fn mean_rgb(bytes: &[u8]) -> ((u32, u32), [f64; 3]) {
    let decoded = image::load_from_memory(bytes).unwrap().into_rgb8();
    let mut sum = [0.0; 3];
    for p in decoded.pixels() {
        (0..3).for_each(|k| sum[k] += p.0[k] as f64);
    }
    let n = (decoded.width() * decoded.height()) as f64;
    (decoded.dimensions(), sum.map(|s| s / n))
}

#[test]
fn jpeg_bakes_colour_maps_as_jpeg_and_the_normal_map_as_png() {
    let source = orm_emissive_sphere(AlphaMode::Opaque);
    let jpeg = baked(&source, ImageFormat::Jpeg { quality: 90 }).unwrap();
    let png = baked(&source, ImageFormat::Png).unwrap();
    assert_eq!(
        jpeg.asset.images.len(),
        4,
        "base colour, normal, ORM, emissive"
    );
    let base = |m: &Material| m.base_color_texture.as_ref().map(|t| t.image);
    let orm = |m: &Material| m.metallic_roughness_texture.as_ref().map(|t| t.image);
    let emissive = |m: &Material| m.emissive_texture.as_ref().map(|t| t.image);
    let normal = |m: &Material| m.normal_texture.as_ref().map(|t| t.image);
    for image in [slot(&jpeg, base), slot(&jpeg, orm), slot(&jpeg, emissive)] {
        assert!(image.bytes.starts_with(&SOI), "{}", image.name);
        assert_eq!(image.mime, "image/jpeg", "{}", image.name);
        assert!(image.name.ends_with(".jpg"), "{}", image.name);
    }
    let n = slot(&jpeg, normal);
    assert!(n.bytes.starts_with(PNG));
    assert_eq!(
        (n.mime.as_str(), n.name.as_str()),
        ("image/png", "normal.png")
    );
    assert!(slot(&png, base).bytes.starts_with(PNG));
    assert!(
        jpeg.report.warnings.is_empty(),
        "{:?}",
        jpeg.report.warnings
    );
    // Same texels underneath: the JPEG decodes to the PNG's size and, per channel, to its
    // mean within 2 levels of 255.
    for pick in [base, orm, emissive] {
        let (size_j, mean_j) = mean_rgb(&slot(&jpeg, pick).bytes);
        let (size_p, mean_p) = mean_rgb(&slot(&png, pick).bytes);
        assert_eq!(size_j, (128, 128));
        assert_eq!(size_j, size_p);
        for k in 0..3 {
            assert!((mean_j[k] - mean_p[k]).abs() < 2.0, "{mean_j:?} {mean_p:?}");
        }
    }
    // The base colour is not flat: the red and the blue half both show, green nowhere.
    let (_, mean) = mean_rgb(&slot(&jpeg, base).bytes);
    assert!(
        mean[0] > 60.0 && mean[2] > 60.0 && mean[1] < 10.0,
        "{mean:?}"
    );
}

#[test]
fn a_masked_material_keeps_its_base_colour_png_with_a_warning() {
    let source = orm_emissive_sphere(AlphaMode::Mask);
    let jpeg = baked(&source, ImageFormat::Jpeg { quality: 80 }).unwrap();
    let m = &jpeg.asset.materials[0];
    // Its opacity measured by view rays, the level blends.
    assert_eq!(m.alpha_mode, AlphaMode::Blend);
    let base = &jpeg.asset.images[m.base_color_texture.as_ref().unwrap().image];
    assert!(base.bytes.starts_with(PNG));
    assert_eq!(
        (base.mime.as_str(), base.name.as_str()),
        ("image/png", "base_color.png")
    );
    let decoded = image::load_from_memory(&base.bytes).unwrap();
    assert!(
        decoded.color().has_alpha(),
        "the alpha the mask needs is kept"
    );
    let orm = &jpeg.asset.images[m.metallic_roughness_texture.as_ref().unwrap().image];
    assert!(orm.bytes.starts_with(&SOI), "ORM has no alpha: JPEG");
    let warned: Vec<_> = jpeg
        .report
        .warnings
        .iter()
        .filter(|w| w.contains("PNG"))
        .collect();
    assert_eq!(warned.len(), 1, "{:?}", jpeg.report.warnings);
    assert!(warned[0].contains("alpha"), "{}", warned[0]);
    // The same material bakes no such warning as PNG.
    let png = baked(&source, ImageFormat::Png).unwrap();
    assert!(png.report.warnings.iter().all(|w| !w.contains("PNG")));
}

#[test]
fn a_jpeg_quality_outside_1_to_100_is_refused() {
    let source = textured_sphere(2);
    for quality in [0, 101, 255] {
        let refused = baked(&source, ImageFormat::Jpeg { quality });
        match refused {
            Err(BakeError::Invalid(why)) => assert!(why.contains(&quality.to_string()), "{why}"),
            other => panic!("quality {quality}: {:?}", other.map(|b| b.report)),
        }
    }
    for quality in [1, 100] {
        let image = ImageFormat::Jpeg { quality };
        assert!(image.check().is_ok());
        let b = baked(&source, image).unwrap();
        let base = &b.asset.images[0];
        assert!(base.bytes.starts_with(&SOI), "quality {quality}");
    }
    // A lower quality is a smaller file of the same texels.
    let size = |quality| {
        let b = baked(&source, ImageFormat::Jpeg { quality }).unwrap();
        b.asset.images[0].bytes.len()
    };
    assert!(size(10) < size(95));
}
