//! Medical volumes land where the anatomy is: oblique, non-diagonal and flipped index-to-world
//! transforms (NIfTI sform, NRRD space directions, MetaImage TransformMatrix), a DICOM series,
//! and label maps. Files are written here by hand; where the peers' Python is installed the
//! world centre is also computed by nibabel or SimpleITK, else (skip recorded) from the header.

use std::path::Path;

use voxlod::core::glam::{DMat3, DVec3};
use voxlod::core::{mesh_topology, Frame, TriangleMesh, Volume};
use voxlod::io::{read_dicom_series, read_volume, DicomOptions};
use voxlod::labels::{find_labels, label_levels, voxel_volume, LabelOptions};
use voxlod::lod::{build_level, plan, LevelOptions, LodSource};
use voxlod::sampling::{Filter, PyramidOptions, ThresholdSolid};
use voxlod_testkit::dicom::{ball_series, write_slice};
use voxlod_testkit::peers::run_python;

/// Volume-weighted centroid and enclosed volume of a closed mesh.
fn centroid_and_volume(mesh: &TriangleMesh) -> (DVec3, f64) {
    let (mut sum, mut volume) = (DVec3::ZERO, 0.0);
    for t in 0..mesh.triangles.len() {
        let [a, b, c] = mesh.corners(t);
        let v = a.dot(b.cross(c)) / 6.0;
        sum += (a + b + c) / 4.0 * v;
        volume += v;
    }
    (sum / volume, volume)
}

/// Level 0 of the thresholded volume at about `resolution` samples across, in world coordinates.
fn world_mesh(volume: &Volume, threshold: f32, resolution: usize) -> TriangleMesh {
    let options = LevelOptions {
        pyramid: PyramidOptions::for_resolutions(vec![resolution], Filter::Hypercone),
        ..LevelOptions::default()
    };
    let solid = ThresholdSolid::new(volume, threshold).unwrap();
    let source = LodSource::Solid(&solid);
    let plans = plan(&source, &options).unwrap();
    build_level(&source, &plans[0], &options).unwrap().mesh
}

/// A ball of `radius` mm about `centre` (world), sampled through `index_to_world`.
fn ball_samples(
    dims: [usize; 3],
    to_world: impl Fn(DVec3) -> DVec3,
    centre: DVec3,
    radius: f64,
) -> Vec<f32> {
    let mut out = Vec::with_capacity(dims.iter().product());
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                let p = to_world(DVec3::new(i as f64, j as f64, k as f64));
                out.push(if (p - centre).length() <= radius {
                    1.0
                } else {
                    0.0
                });
            }
        }
    }
    out
}

/// Asserts the mesh of the ball: centroid within one voxel of `centre`, positive volume within
/// 5 % of the ball's.
fn assert_ball(mesh: &TriangleMesh, centre: DVec3, radius: f64, voxel: f64, what: &str) {
    let t = mesh_topology(mesh);
    assert!(
        t.is_closed_manifold() && t.is_consistently_oriented(),
        "{what}: {t:?}"
    );
    let (c, v) = centroid_and_volume(mesh);
    let ball = 4.0 / 3.0 * std::f64::consts::PI * radius.powi(3);
    assert!(v > 0.0, "{what}: inside out ({v})");
    assert!(
        (v / ball - 1.0).abs() < 0.05,
        "{what}: volume {v} vs {ball}"
    );
    assert!(
        (c - centre).length() < voxel,
        "{what}: centroid {c} vs {centre}"
    );
}

/// The world point of a fractional index by an independent reader, when the peers' Python has it.
fn peer_point(script: &str, path: &Path, index: DVec3) -> Option<DVec3> {
    let args = [
        path.as_os_str().to_owned(),
        format!("{} {} {}", index.x, index.y, index.z).into(),
    ];
    let args: Vec<&std::ffi::OsStr> = args.iter().map(|a| a.as_os_str()).collect();
    let out = run_python(script, &args)?;
    let v: Vec<f64> = out.split_whitespace().map(|s| s.parse().unwrap()).collect();
    Some(DVec3::new(v[0], v[1], v[2]))
}

const DIMS: [usize; 3] = [40, 36, 32];
const BALL_INDEX: [f64; 3] = [23.0, 15.0, 17.0];

/// The NIfTI-1 header of an oblique sform (rows of a 3×4 matrix), float32 data.
fn nifti_header(srow: [[f32; 4]; 3]) -> Vec<u8> {
    let mut h = vec![0u8; 352];
    h[0..4].copy_from_slice(&348i32.to_le_bytes());
    let dim: [i16; 8] = [
        3,
        DIMS[0] as i16,
        DIMS[1] as i16,
        DIMS[2] as i16,
        1,
        1,
        1,
        1,
    ];
    for (i, d) in dim.iter().enumerate() {
        h[40 + 2 * i..42 + 2 * i].copy_from_slice(&d.to_le_bytes());
    }
    h[70..72].copy_from_slice(&16i16.to_le_bytes());
    h[72..74].copy_from_slice(&32i16.to_le_bytes());
    let pixdim: [f32; 8] = [1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0];
    for (i, p) in pixdim.iter().enumerate() {
        h[76 + 4 * i..80 + 4 * i].copy_from_slice(&p.to_le_bytes());
    }
    h[108..112].copy_from_slice(&352f32.to_le_bytes());
    h[123] = 2; // millimetres
    h[254..256].copy_from_slice(&1i16.to_le_bytes()); // sform_code: scanner
    for (r, row) in srow.iter().enumerate() {
        for (c, v) in row.iter().enumerate() {
            h[280 + 16 * r + 4 * c..284 + 16 * r + 4 * c].copy_from_slice(&v.to_le_bytes());
        }
    }
    h[344..348].copy_from_slice(b"n+1\0");
    h
}

#[test]
fn an_oblique_nifti_sform_puts_the_ball_where_nibabel_does() {
    let rot = DMat3::from_rotation_y(0.35) * DMat3::from_rotation_z(-0.6);
    let m = rot * DMat3::from_diagonal(DVec3::new(1.2, 0.9, 1.5));
    let origin = DVec3::new(-30.0, 12.0, 40.0);
    let srow: [[f32; 4]; 3] = std::array::from_fn(|r| {
        [
            m.row(r).x as f32,
            m.row(r).y as f32,
            m.row(r).z as f32,
            origin[r] as f32,
        ]
    });
    let to_world = |ijk: DVec3| {
        let row = |r: usize| DVec3::new(srow[r][0] as f64, srow[r][1] as f64, srow[r][2] as f64);
        DVec3::new(row(0).dot(ijk), row(1).dot(ijk), row(2).dot(ijk))
            + DVec3::new(srow[0][3] as f64, srow[1][3] as f64, srow[2][3] as f64)
    };
    let centre = to_world(DVec3::from(BALL_INDEX));
    let mut bytes = nifti_header(srow);
    for v in ball_samples(DIMS, to_world, centre, 9.0) {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("oblique.nii");
    std::fs::write(&path, bytes).unwrap();
    let script = "import sys, nibabel\nimport numpy as np\ni = nibabel.load(sys.argv[1])\np = i.affine @ np.array([float(x) for x in sys.argv[2].split()] + [1.0])\nprint(*p[:3])";
    let centre = peer_point(script, &path, DVec3::from(BALL_INDEX)).unwrap_or(centre);
    let volume = read_volume(&path, None).unwrap();
    assert_eq!(volume.orientation.frame, Frame::Ras);
    let mesh = world_mesh(&volume, 0.5, 60);
    assert_ball(&mesh, centre, 9.0, 1.5, "NIfTI sform");
}

#[test]
fn a_nrrd_with_non_diagonal_space_directions_in_lps_lands_on_the_ball() {
    let dirs = [
        DVec3::new(0.8, 0.3, 0.0),
        DVec3::new(-0.25, 0.9, 0.2),
        DVec3::new(0.1, -0.2, 1.1),
    ];
    let origin = DVec3::new(5.0, -7.0, 11.0);
    let to_world = |ijk: DVec3| origin + dirs[0] * ijk.x + dirs[1] * ijk.y + dirs[2] * ijk.z;
    let centre = to_world(DVec3::from(BALL_INDEX));
    let v = |d: DVec3| format!("({},{},{})", d.x, d.y, d.z);
    let header = format!(
        "NRRD0004\ntype: float\ndimension: 3\nsizes: {} {} {}\nspace: left-posterior-superior\nspace directions: {} {} {}\nspace origin: {}\nendian: little\nencoding: raw\n\n",
        DIMS[0], DIMS[1], DIMS[2], v(dirs[0]), v(dirs[1]), v(dirs[2]), v(origin)
    );
    let mut bytes = header.into_bytes();
    for s in ball_samples(DIMS, to_world, centre, 8.0) {
        bytes.extend_from_slice(&s.to_le_bytes());
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("sheared.nrrd");
    std::fs::write(&path, bytes).unwrap();
    let volume = read_volume(&path, None).unwrap();
    assert_eq!(volume.orientation.frame, Frame::Lps);
    let mesh = world_mesh(&volume, 0.5, 60);
    assert_ball(&mesh, centre, 8.0, 1.2, "NRRD space directions");
}

#[test]
fn a_metaimage_with_a_flipped_transform_matrix_keeps_outward_triangles() {
    let (c, s) = (0.5f64.cos(), 0.5f64.sin());
    // Columns: the world directions of the index axes; z is flipped (determinant -1).
    let cols = [
        DVec3::new(c, s, 0.0),
        DVec3::new(-s, c, 0.0),
        DVec3::new(0.0, 0.0, -1.0),
    ];
    let spacing = DVec3::new(1.1, 0.9, 1.3);
    let origin = DVec3::new(-20.0, 30.0, 15.0);
    let to_world = |ijk: DVec3| {
        origin
            + cols[0] * (ijk.x * spacing.x)
            + cols[1] * (ijk.y * spacing.y)
            + cols[2] * (ijk.z * spacing.z)
    };
    let centre = to_world(DVec3::from(BALL_INDEX));
    let matrix: Vec<String> = cols
        .iter()
        .flat_map(|d| d.to_array())
        .map(|x| x.to_string())
        .collect();
    let header = format!(
        "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\nCompressedData = False\nTransformMatrix = {}\nOffset = {} {} {}\nCenterOfRotation = 0 0 0\nAnatomicalOrientation = RAI\nElementSpacing = {} {} {}\nDimSize = {} {} {}\nElementType = MET_FLOAT\nElementDataFile = LOCAL\n",
        matrix.join(" "), origin.x, origin.y, origin.z, spacing.x, spacing.y, spacing.z, DIMS[0], DIMS[1], DIMS[2]
    );
    let mut bytes = header.into_bytes();
    for v in ball_samples(DIMS, to_world, centre, 9.0) {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("flipped.mha");
    std::fs::write(&path, bytes).unwrap();
    let script = "import sys, SimpleITK as sitk\ni = sitk.ReadImage(sys.argv[1])\nprint(*i.TransformContinuousIndexToPhysicalPoint([float(x) for x in sys.argv[2].split()]))";
    let centre = peer_point(script, &path, DVec3::from(BALL_INDEX)).unwrap_or(centre);
    let volume = read_volume(&path, None).unwrap();
    assert_eq!(volume.orientation.frame, Frame::Lps);
    assert!(volume.world().flips_handedness());
    let mesh = world_mesh(&volume, 0.5, 60);
    assert_ball(&mesh, centre, 9.0, 1.3, "MetaImage TransformMatrix");
}

#[test]
fn a_shuffled_dicom_series_with_a_second_series_gives_the_phantom_ball() {
    let centre = [-5.0, 3.0, 2.0];
    let radius = 12.0;
    let dir = tempfile::tempdir().unwrap();
    let ours = ball_series(
        "1.2.826.0.1.7",
        48,
        24,
        [1.5, 1.25, 2.0],
        0.4,
        centre,
        radius,
    );
    let other = ball_series("1.2.826.0.1.8", 16, 4, [1.0; 3], 0.0, [0.0; 3], 4.0);
    for (n, s) in ours.iter().chain(&other).enumerate() {
        write_slice(&dir.path().join(format!("IM{:04}", (n * 37) % 101)), s);
    }
    let volume = read_dicom_series(
        &[dir.path().to_path_buf()],
        &DicomOptions::series("1.2.826.0.1.7"),
    )
    .unwrap();
    let mesh = world_mesh(&volume, 0.0, 80);
    let t = mesh_topology(&mesh);
    assert!(
        t.is_closed_manifold() && t.is_consistently_oriented(),
        "{t:?}"
    );
    let (c, v) = centroid_and_volume(&mesh);
    let ball = 4.0 / 3.0 * std::f64::consts::PI * radius.powi(3);
    assert!((v / ball - 1.0).abs() < 0.03, "volume {v} vs {ball}");
    assert!((c - DVec3::from(centre)).length() < 1.25, "centroid {c}");
}

#[test]
fn three_labels_two_touching_give_three_closed_meshes_of_their_voxel_volume() {
    let dims = [40usize, 36, 30];
    let grid = voxlod::core::Grid::new(dims, [1.0, 1.2, 0.8], [10.0, -4.0, 2.0]).unwrap();
    let mut values = vec![0.0f32; grid.len()];
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                let p = grid.position(i as f64, j as f64, k as f64) - grid.origin_vec();
                let ball = |c: DVec3, r: f64| (p - c).length() <= r;
                let label = if ball(DVec3::new(12.0, 14.0, 12.0), 7.0) {
                    1.0
                } else if (19..=30).contains(&i) && (6..=22).contains(&j) && (5..=20).contains(&k) {
                    2.0 // a box flush against ball 1
                } else if ball(DVec3::new(30.0, 34.0, 15.0), 5.0) {
                    3.0
                } else {
                    0.0
                };
                values[grid.index(i, j, k)] = label;
            }
        }
    }
    let map = Volume::from_vec(grid, values).unwrap();
    let labels = find_labels(&map).unwrap();
    assert_eq!(
        labels.iter().map(|l| l.value).collect::<Vec<_>>(),
        vec![1, 2, 3]
    );
    for label in &labels {
        let levels = label_levels(&map, label, &LabelOptions::default()).unwrap();
        let mesh = &levels[0].mesh;
        let t = mesh_topology(mesh);
        assert!(
            t.is_closed_manifold() && t.is_consistently_oriented() && t.components == 1,
            "label {}: {t:?}",
            label.value
        );
        let expected = voxel_volume(&map, label.voxels);
        let v = mesh.signed_volume();
        // The filter (radius one voxel) pulls a convex surface in by about R²/r: within 3 % for
        // the two large structures; label 3, a ball of five voxels' radius, measured -4.7 %.
        let tolerance = if label.value == 3 { 0.06 } else { 0.03 };
        assert!(
            (v / expected - 1.0).abs() < tolerance,
            "label {}: {v} vs {expected}",
            label.value
        );
    }
}
