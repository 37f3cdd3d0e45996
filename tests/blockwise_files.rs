//! A raw, NRRD or MetaImage scan read blockwise (`voxlod::io::BlockwiseVolume` as a
//! `Source::BlockwiseThreshold`) gives exactly the levels of the same file read whole
//! (`Source::Threshold`) with the default chain (genus step and cleaning): the same triangle
//! counts, genus and bit-identical vertex sets, placed in the file's world (an oblique NRRD's
//! direction cosines included). On a generated scan of odd size, and on the CT head of
//! `../shared/data` when it is there.

use std::path::Path;

use voxlod::core::{Grid, Volume};
use voxlod::io::{open_volume_blockwise, read_volume, Endian, RawLayout, RawType};
use voxlod::sampling::Filter;
use voxlod::{Lod, LodOptions, Source};
use voxlod_testkit::compare::sorted_vertex_bits;
use voxlod_testkit::data::shared_data_or_skip;

/// Sorted bit patterns of a mesh's positions.
/// The levels of `path` read whole and read blockwise, compared level by level.
fn same_levels(path: &Path, raw: Option<&RawLayout>, threshold: f32, options: &LodOptions) -> Lod {
    let volume = read_volume(path, raw).unwrap();
    let scan = open_volume_blockwise(path, raw)
        .unwrap()
        .expect("read blockwise");
    let whole = voxlod::lod(
        &Source::Threshold {
            volume: &volume,
            threshold,
        },
        options,
    )
    .unwrap();
    let blockwise = Source::BlockwiseThreshold {
        scan: &scan,
        threshold,
    };
    let blockwise_levels = voxlod::lod(&blockwise, options).unwrap();
    assert_eq!(whole.levels.len(), blockwise_levels.levels.len());
    for (a, b) in whole.levels.iter().zip(&blockwise_levels.levels) {
        let r = a.resolution;
        assert!(a.mesh.triangle_count() > 0, "{r}");
        assert_eq!(a.mesh.triangle_count(), b.mesh.triangle_count(), "{r}");
        assert_eq!(a.topology.genus, b.topology.genus, "{r}");
        assert_eq!(a.topology.components, b.topology.components, "{r}");
        assert!(b.topology.is_closed_manifold(), "{r}");
        assert_eq!(
            sorted_vertex_bits(&a.mesh),
            sorted_vertex_bits(&b.mesh),
            "{r}"
        );
        assert!(b.band.is_some(), "the blockwise route samples bricks");
    }
    blockwise_levels
}

/// Two blobs and a tunnel, as int16 values around 0, on a 53 × 47 × 39 grid.
fn blobs() -> Vec<i16> {
    let [nx, ny, nz] = [53usize, 47, 39];
    let mut values = Vec::with_capacity(nx * ny * nz);
    for z in 0..nz {
        for y in 0..ny {
            for x in 0..nx {
                let p = [
                    x as f64 / nx as f64,
                    y as f64 / ny as f64,
                    z as f64 / nz as f64,
                ];
                let ball = |c: [f64; 3], r: f64| {
                    r - ((p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2) + (p[2] - c[2]).powi(2))
                        .sqrt()
                };
                let tunnel = 0.08 - ((p[1] - 0.5).powi(2) + (p[2] - 0.5).powi(2)).sqrt();
                let solid = ball([0.3, 0.5, 0.5], 0.25).max(ball([0.7, 0.45, 0.55], 0.2));
                values.push((1000.0 * solid.min(-tunnel)).round() as i16);
            }
        }
    }
    values
}

#[test]
fn an_oblique_nrrd_read_blockwise_gives_the_levels_read_whole() {
    let dir = tempfile::tempdir().unwrap();
    let bytes: Vec<u8> = blobs().iter().flat_map(|v| v.to_le_bytes()).collect();
    // Rotated about z by 30 degrees, in LPS, with uneven spacing.
    let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
    let header = format!(
        "NRRD0004\ntype: short\ndimension: 3\nsizes: 53 47 39\nendian: little\nencoding: raw\n\
         space: left-posterior-superior\n\
         space directions: ({},{},0) ({},{},0) (0,0,1.25)\nspace origin: (-20,5,30)\n\n",
        0.8 * c,
        0.8 * s,
        -0.9 * s,
        0.9 * c
    );
    let path = dir.path().join("blobs.nrrd");
    std::fs::write(&path, [header.as_bytes(), &bytes].concat()).unwrap();
    let options = LodOptions::halving(48, 3, Filter::Hypercone);
    let lod = same_levels(&path, None, 0.0, &options);
    // In the file's world: the mesh's box is rotated off the grid's box.
    let grid_box = Grid::new([53, 47, 39], [0.8, 0.9, 1.25], [-20.0, 5.0, 30.0])
        .unwrap()
        .bounds();
    let mesh_box = lod.levels[0].mesh.bounds();
    assert!(mesh_box.min.x < grid_box.min.x - 5.0, "{mesh_box:?}");
}

#[test]
fn a_raw_file_and_a_metaimage_read_blockwise_give_the_levels_read_whole() {
    let dir = tempfile::tempdir().unwrap();
    let values = blobs();
    let be: Vec<u8> = values.iter().flat_map(|v| v.to_be_bytes()).collect();
    let raw = dir.path().join("blobs.raw");
    std::fs::write(&raw, &be).unwrap();
    let mut layout = RawLayout::new([53, 47, 39], RawType::I16, Endian::Big);
    layout.spacing = [1.0, 1.0, 1.5];
    let options = LodOptions::halving(40, 2, Filter::GAUSSIAN);
    same_levels(&raw, Some(&layout), 40.0, &options);
    let grid = Grid::new([53, 47, 39], [1.0, 1.0, 1.5], [0.0; 3]).unwrap();
    let volume = Volume::from_vec(grid, values.iter().map(|&v| v as f32).collect()).unwrap();
    let mha = dir.path().join("blobs.mha");
    voxlod::io::write_volume(&mha, &volume).unwrap();
    same_levels(&mha, None, 40.0, &options);
}

#[test]
fn the_ct_head_read_blockwise_gives_the_levels_read_whole() {
    let head = "volumes/CThead_256x256x113_uint16be.raw";
    let Some(path) = shared_data_or_skip(head, "CT head read blockwise") else {
        return;
    };
    let mut layout = RawLayout::new([256, 256, 113], RawType::U16, Endian::Big);
    layout.spacing = [1.0, 1.0, 2.0];
    let options = LodOptions::halving(128, 3, Filter::Hypercone);
    for threshold in [500.0, 1500.0] {
        same_levels(&path, Some(&layout), threshold, &options);
    }
}
