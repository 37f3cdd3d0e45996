//! The shared real data (see `../shared/data/README.md`): every mesh with its documented
//! counts, every volume with its documented dimensions, spacing and value range. Each test
//! skips, saying why, when the data is not beside the checkout.

use voxlod_core::mesh_topology;
use voxlod_io::{read_mesh, read_volume, Endian, MeshFormat, RawLayout, RawType};
use voxlod_testkit::data::shared_data_or_skip;

/// (file, vertices, triangles) as documented; STL vertex counts are after welding.
const MESHES: [(&str, usize, usize); 11] = [
    ("stanford-bunny.obj", 35_947, 69_451),
    ("fandisk.obj", 6_475, 12_946),
    ("rocker-arm.obj", 10_044, 20_088),
    ("wingnut.obj", 3_047, 6_090),
    ("utah-teapot.obj", 3_644, 6_320),
    ("cgal-pinion-gear.off", 650, 1_300),
    ("cgal-blade.off", 8_231, 16_222),
    ("cgal-elephant-with-holes.off", 2_798, 4_463),
    ("thingi10k-68247.stl", 39, 78),
    ("thingi10k-138207.stl", 26, 156),
    ("thingi10k-42722.stl", 195, 402),
];

#[test]
fn every_shared_mesh_has_its_documented_counts() {
    for (name, vertices, triangles) in MESHES {
        let Some(path) = shared_data_or_skip(&format!("meshes/{name}"), "real mesh counts") else {
            continue;
        };
        let loaded = read_mesh(&path).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(loaded.mesh.vertex_count(), vertices, "{name} vertices");
        assert_eq!(loaded.mesh.triangle_count(), triangles, "{name} triangles");
        assert_eq!(loaded.polygons_triangulated, 0, "{name}");
        if loaded.format == MeshFormat::Stl {
            let report = loaded.welded.expect("STL is welded");
            assert_eq!(report.vertices_before, 3 * triangles, "{name}");
            assert_eq!(report.vertices_after, vertices, "{name}");
        } else {
            assert!(loaded.welded.is_none());
        }
    }
}

#[test]
fn documented_mesh_defects_survive_reading() {
    if let Some(path) = shared_data_or_skip("meshes/stanford-bunny.obj", "bunny defects") {
        let t = mesh_topology(&read_mesh(&path).unwrap().mesh);
        assert_eq!(t.unreferenced_vertices, 1_113);
        assert_eq!(t.boundary_loops, 5);
    }
    if let Some(path) = shared_data_or_skip("meshes/thingi10k-68247.stl", "inside-out STL") {
        let mesh = read_mesh(&path).unwrap().mesh;
        let t = mesh_topology(&mesh);
        assert!(t.is_closed_manifold(), "{t:?}");
        assert!(
            mesh.signed_volume() < 0.0,
            "the shell is documented as inside out"
        );
    }
    if let Some(path) = shared_data_or_skip("meshes/cgal-blade.off", "open blade") {
        let t = mesh_topology(&read_mesh(&path).unwrap().mesh);
        assert_eq!(t.boundary_loops, 2);
    }
}

#[test]
fn ct_head_raw() {
    let Some(path) = shared_data_or_skip("volumes/CThead_256x256x113_uint16be.raw", "CT head")
    else {
        return;
    };
    let mut layout = RawLayout::new([256, 256, 113], RawType::U16, Endian::Big);
    layout.spacing = [1.0, 1.0, 2.0];
    let v = read_volume(&path, Some(&layout)).unwrap();
    assert_eq!(v.grid.dims, [256, 256, 113]);
    assert_eq!(v.grid.spacing, [1.0, 1.0, 2.0]);
    assert_eq!(v.range(), Some((0.0, 3272.0)));
    // Read little-endian by mistake, the values would exceed 3272 wildly.
    let wrong = RawLayout::new([256, 256, 113], RawType::U16, Endian::Little);
    assert!(read_volume(&path, Some(&wrong)).unwrap().range().unwrap().1 > 60000.0);
    // And a wrong depth is refused with the one that fits.
    let short = RawLayout::new([256, 256, 100], RawType::U16, Endian::Big);
    let err = read_volume(&path, Some(&short)).unwrap_err();
    assert!(err.message.contains("dims 256 256 113"), "{err}");
}

#[test]
fn engine_raw() {
    let Some(path) = shared_data_or_skip("volumes/engine_256x256x128_uint8.raw", "engine") else {
        return;
    };
    let v = read_volume(
        &path,
        Some(&RawLayout::new(
            [256, 256, 128],
            RawType::U8,
            Endian::Little,
        )),
    )
    .unwrap();
    let (lo, hi) = v.range().unwrap();
    assert!(lo >= 0.0 && hi <= 255.0 && hi > lo);
}

#[test]
fn tooth_nrrd() {
    let Some(path) = shared_data_or_skip("volumes/tooth_103x94x161_uint8.nrrd", "tooth") else {
        return;
    };
    let v = read_volume(&path, None).unwrap();
    assert_eq!(v.grid.dims, [103, 94, 161]);
    assert_eq!(v.grid.spacing, [1.0, 1.0, 1.0]);
    assert_eq!(v.grid.origin, [0.0, 0.0, 0.0]);
    let (lo, hi) = v.range().unwrap();
    assert!(lo >= 0.0 && hi <= 255.0 && hi > 200.0, "{lo}..{hi}");
}

#[test]
fn colin27_nifti() {
    let Some(path) = shared_data_or_skip("volumes/ch2_colin27_T1.nii.gz", "Colin27") else {
        return;
    };
    let v = read_volume(&path, None).unwrap();
    assert_eq!(v.grid.dims, [181, 217, 181]);
    assert_eq!(v.grid.spacing, [1.0, 1.0, 1.0]);
    // The sform places voxel (0,0,0) at (-90, -125, -71) mm.
    assert_eq!(v.grid.origin, [-90.0, -125.0, -71.0]);
    assert_eq!(v.range(), Some((0.0, 254.0)));
}

#[test]
fn lung_metaimage() {
    let Some(path) = shared_data_or_skip("volumes/LIDC2_lung_ct_256x256x133_uint8.mha", "lung")
    else {
        return;
    };
    let v = read_volume(&path, None).unwrap();
    assert_eq!(v.grid.dims, [256, 256, 133]);
    for (got, want) in v.grid.spacing.iter().zip([1.40625, 1.40625, 2.5]) {
        assert!((got - want).abs() < 1e-9, "{:?}", v.grid.spacing);
    }
    assert!((v.grid.origin[1] - 360.0).abs() < 1e-9 && (v.grid.origin[2] - 332.5).abs() < 1e-9);
    let (lo, hi) = v.range().unwrap();
    assert!(lo >= 0.0 && hi <= 255.0 && hi > lo);
}
