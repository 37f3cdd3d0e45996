//! Budget levels of a textured asset keep its looks: a sphere textured red on its −x half and
//! blue on its +x half (texture coordinates projected along z). The large budget is the
//! input's collapse with its texture coordinates and texture; every level, whatever made it,
//! shows red where the input is red and blue where it is blue, never grey.

use voxlod_testkit::assets::{textured_sphere, two_halves_png};

use voxlod_budget::{asset_levels, Looks, PortfolioOptions};
use voxlod_core::glam::Vec4;

#[test]
fn every_level_of_a_textured_asset_shows_its_texture() {
    let input = textured_sphere(4);
    let run = asset_levels(&input, &PortfolioOptions::for_triangles(&[2000, 200, 40])).unwrap();
    assert_eq!(run.levels.len(), 3);
    let red = Vec4::new(1.0, 0.0, 0.0, 1.0);
    let blue = Vec4::new(0.0, 0.0, 1.0, 1.0);
    for level in &run.levels {
        let a = &level.asset;
        a.validate().unwrap();
        let t = a.mesh.triangles.len();
        assert!(
            t as f64 <= level.report.budget as f64 * 1.1,
            "{t} for {}",
            level.report.budget
        );
        match level.looks {
            Looks::Kept => {
                // The input's texture coordinates and its texture: u < 0.5 exactly where x < 0.
                assert!(a.materials[0].base_color_texture.is_some());
                assert_eq!(*a.images[0].bytes, two_halves_png());
                for (p, uv) in a.mesh.positions.iter().zip(&a.mesh.uv[0]) {
                    assert!(((p.x + 1.0) / 2.0 - uv.x).abs() < 1e-6, "{p}: {uv}");
                }
            }
            Looks::Transferred => {
                for (p, c) in a.mesh.positions.iter().zip(&a.mesh.colors) {
                    if p.x < -0.2 {
                        assert!((*c - red).abs().max_element() < 1e-5, "{p}: {c}");
                    } else if p.x > 0.2 {
                        assert!((*c - blue).abs().max_element() < 1e-5, "{p}: {c}");
                    }
                }
            }
            Looks::Baked => panic!("asset_levels never bakes (voxlod-pyramid's asset_lod does)"),
        }
    }
    assert_eq!(
        run.levels[0].looks,
        Looks::Kept,
        "the large budget is the input's own collapse"
    );
}
