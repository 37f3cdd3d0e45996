//! Textures beyond the memory limit or beyond what GPUs take are refused before anything of
//! their size is allocated, xatlas's packing bitmap included. One test, since it sets the
//! memory limit of the process.

use voxlod_bake::atlas::MAX_TEXTURE;
use voxlod_bake::{atlas, bake, AtlasOptions, BakeError, BakeOptions, TextureSize};
use voxlod_core::memory::MAX_MEMORY_VARIABLE;
use voxlod_core::CoreError;
use voxlod_testkit::assets::textured_sphere;
use voxlod_testkit::shapes::icosphere;

fn out_of_memory(result: Result<impl std::fmt::Debug, BakeError>, case: &str) {
    match result {
        Err(BakeError::Core(CoreError::OutOfMemory { what, .. })) => {
            assert!(what.contains("texture"), "{case}: {what}")
        }
        other => panic!("{case}: {other:?}"),
    }
}

#[test]
fn textures_beyond_the_limits_are_refused() {
    let level = icosphere(1);
    for texture in [TextureSize::Texels(1 << 22), TextureSize::Density(1e9)] {
        let options = AtlasOptions {
            texture,
            ..AtlasOptions::default()
        };
        out_of_memory(atlas(&level, &options), &format!("{texture:?}"));
    }
    // A bake asks before its textures: a 4096² bake needs far more than 64 MiB.
    std::env::set_var(MAX_MEMORY_VARIABLE, "64M");
    out_of_memory(
        bake(&textured_sphere(2), &level, &BakeOptions::for_texture(4096)),
        "bake",
    );
    // Within memory but beyond what GPUs take.
    std::env::set_var(MAX_MEMORY_VARIABLE, "1T");
    let err = atlas(&level, &AtlasOptions::for_texture(MAX_TEXTURE * 2)).unwrap_err();
    std::env::remove_var(MAX_MEMORY_VARIABLE);
    assert!(err.to_string().contains("16384"), "{err}");
}
