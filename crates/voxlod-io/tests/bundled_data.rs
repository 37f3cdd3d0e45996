//! The samples in `data/` (made by `data/generate.py`, on which the README's examples run) read
//! as `data/README.md` describes them: grids, tissues at hand-checked voxels, the phantom's
//! integral against the ellipsoids' closed form, and the meshes' topology.

use std::f64::consts::PI;
use std::path::PathBuf;

use voxlod_core::mesh_topology;
use voxlod_io::{read_mesh, read_volume, Endian, RawLayout, RawType};
use voxlod_testkit::data::workspace_root;

fn data(name: &str) -> PathBuf {
    workspace_root().join("data").join(name)
}

/// ∫ intensity dV of the phantom in sample units × mm³: each ellipsoid's intensity × 1000 × its
/// volume (4/3 π abc, semi-axes in units of the 100 mm half-side), as in data/generate.py.
fn phantom_integral() -> f64 {
    let ellipsoids: [(f64, [f64; 3]); 10] = [
        (1.0, [0.69, 0.92, 0.81]),
        (-0.8, [0.6624, 0.874, 0.78]),
        (-0.2, [0.11, 0.31, 0.22]),
        (-0.2, [0.16, 0.41, 0.28]),
        (0.1, [0.21, 0.25, 0.41]),
        (0.1, [0.046, 0.046, 0.05]),
        (0.1, [0.046, 0.046, 0.05]),
        (0.1, [0.046, 0.023, 0.05]),
        (0.1, [0.023, 0.023, 0.02]),
        (0.1, [0.023, 0.046, 0.02]),
    ];
    let unit_volume: f64 = ellipsoids
        .iter()
        .map(|(a, [x, y, z])| a * 4.0 / 3.0 * PI * x * y * z)
        .sum();
    unit_volume * 100f64.powi(3) * 1000.0
}

fn integral(volume: &voxlod_core::Volume) -> f64 {
    let cell: f64 = volume.grid.spacing.iter().product();
    volume.as_slice().iter().map(|&v| v as f64).sum::<f64>() * cell
}

#[test]
fn the_head_phantom_nrrd_has_its_grid_tissues_and_integral() {
    let v = read_volume(&data("head-phantom.nrrd"), None).unwrap();
    assert_eq!(v.grid.dims, [128; 3]);
    assert_eq!(v.grid.spacing, [1.5625; 3]);
    assert_eq!(v.grid.origin, [-99.21875; 3]);
    // Voxel centres at -99.21875 + 1.5625 i mm; the phantom's unit is 100 mm.
    assert_eq!(v.get(0, 0, 0), 0.0, "air in the corner");
    assert_eq!(v.get(64, 64, 64), 200.0, "brain at (0.8, 0.8, 0.8) mm");
    // (22.66, 0.78, 0.78) mm: the right ventricle's centre is at x = 22 mm.
    assert_eq!(v.get(78, 64, 64), 0.0, "ventricle");
    // z = 78.9 mm, voxel [78.1, 79.7] mm: between the brain (top at 78 mm) and the skull's
    // outer surface (81 mm).
    assert_eq!(v.get(64, 64, 114), 1000.0, "skull");
    let ratio = integral(&v) / phantom_integral();
    assert!((ratio - 1.0).abs() < 1e-3, "integral off by {ratio}");
}

#[test]
fn the_headerless_phantom_reads_with_the_readme_flags() {
    let mut layout = RawLayout::new([64, 64, 32], RawType::I16, Endian::Big);
    layout.spacing = [3.125, 3.125, 6.25];
    let v = read_volume(&data("head-phantom-64x64x32-i16be.raw"), Some(&layout)).unwrap();
    assert_eq!(v.range(), Some((0.0, 1000.0)));
    assert_eq!(v.get(32, 32, 16), 200.0, "brain");
    let ratio = integral(&v) / phantom_integral();
    assert!((ratio - 1.0).abs() < 1e-3, "integral off by {ratio}");
    // Read little-endian by mistake, the samples would be nonsense.
    let wrong = RawLayout::new([64, 64, 32], RawType::I16, Endian::Little);
    let wrong = read_volume(&data("head-phantom-64x64x32-i16be.raw"), Some(&wrong)).unwrap();
    assert!(wrong.range().unwrap().1 > 10_000.0);
}

#[test]
fn the_bundled_meshes_are_closed_with_their_documented_topology() {
    // (file, vertices, triangles, components, genus)
    let meshes = [
        ("trefoil-knot.obj", 2_880, 5_760, 1, 1),
        ("chain.obj", 2_304, 4_608, 3, 3),
        ("holed-block.obj", 16, 32, 1, 1),
    ];
    for (name, vertices, triangles, components, genus) in meshes {
        let mesh = read_mesh(&data(name)).unwrap().mesh;
        let t = mesh_topology(&mesh);
        assert_eq!((t.vertices, t.triangles), (vertices, triangles), "{name}");
        assert!(
            t.is_closed_manifold() && t.is_consistently_oriented(),
            "{name}: {t:?}"
        );
        assert_eq!((t.components, t.genus), (components, Some(genus)), "{name}");
        assert!(mesh.signed_volume() > 0.0, "{name} is inside out");
    }
}
