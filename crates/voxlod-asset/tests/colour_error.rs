//! The colour error of a level against its input: zero for the input itself, and exactly the
//! colour difference where a level shows one plain colour over a two-coloured texture.

use voxlod_asset::{colour_error, Material};
use voxlod_core::glam::Vec3;
use voxlod_testkit::assets::textured_sphere;

#[test]
fn the_input_against_itself_has_no_colour_error() {
    // Smooth vertex colours instead of the two halves (whose border, sampled at the nearest
    // texel, flips with the last bit of a coordinate).
    let mut input = textured_sphere(3);
    input.materials = vec![Material::default()];
    input.images.clear();
    input.mesh.colors = (input.mesh.positions.iter())
        .map(|p| (*p * 0.5 + Vec3::splat(0.5)).extend(1.0))
        .collect();
    let e = colour_error(&input, &input).unwrap();
    assert!(e < 1e-5, "{e}");
    // Half the colour everywhere: off by half the mean colour's length.
    let mut dim = input.clone();
    dim.materials[0].base_color = [0.5, 0.5, 0.5, 1.0];
    let e = colour_error(&input, &dim).unwrap();
    assert!(e > 0.3 && e < 0.6, "{e}");
}

#[test]
fn a_plain_purple_level_of_a_red_and_blue_sphere_is_off_by_half_in_two_channels() {
    // Red (1, 0, 0) and blue (0, 0, 1) against purple (0.5, 0, 0.5): every sample is off by
    // (±0.5, 0, ∓0.5), whose length is √0.5.
    let input = textured_sphere(3);
    let mut level = input.clone();
    level.materials = vec![Material {
        name: "purple".into(),
        base_color: [0.5, 0.0, 0.5, 1.0],
        ..Material::default()
    }];
    level.images.clear();
    let e = colour_error(&input, &level).unwrap();
    assert!((e - 0.5f64.sqrt()).abs() < 1e-5, "{e}");
}

#[test]
fn a_level_without_triangles_is_refused() {
    let input = textured_sphere(2);
    let mut level = input.clone();
    level.mesh.triangles.clear();
    level.mesh.material.clear();
    let e = colour_error(&input, &level).unwrap_err().to_string();
    assert!(e.contains("no triangles"), "{e}");
}
