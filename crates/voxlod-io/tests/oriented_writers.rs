//! Written volumes keep their index-to-world transform: an oblique volume (rotated, and one with
//! a flipped axis) written as NRRD, NIfTI, MetaImage and VTK XML reads back with the same world
//! position of every sample, by our readers and, where the peers' Python is installed, by
//! nibabel (NIfTI's sform and qform), SimpleITK (NRRD, NIfTI, MetaImage) and VTK (VTI).

use std::path::Path;

use voxlod_core::glam::{DMat3, DVec3};
use voxlod_core::{Frame, Grid, Orientation, Volume, WorldTransform};
use voxlod_io::{read_volume, write_volume, write_volume_with, VolumeWriteOptions};
use voxlod_testkit::peers::run_python;

/// A 7×6×5 volume in LPS whose index axes are turned 30° about z and 20° about x, with the third
/// axis flipped when `flip`.
fn oblique_volume(flip: bool) -> Volume {
    let grid = Grid::new([7, 6, 5], [0.8, 1.1, 2.0], [-30.0, 12.5, 7.25]).unwrap();
    let values = (0..grid.len()).map(|i| (i * 7 % 23) as f32 - 3.5).collect();
    let turn =
        DMat3::from_rotation_x(20f64.to_radians()) * DMat3::from_rotation_z(30f64.to_radians());
    let flip = DMat3::from_diagonal(DVec3::new(1.0, 1.0, if flip { -1.0 } else { 1.0 }));
    Volume::from_vec(grid, values)
        .unwrap()
        .oriented(Orientation {
            direction: turn * flip,
            frame: Frame::Lps,
        })
}

/// Sample indices whose world positions are compared.
const PROBES: [[f64; 3]; 3] = [[0.0, 0.0, 0.0], [6.0, 0.0, 0.0], [1.0, 2.0, 3.0]];

/// The world position of `index` in `frame` (the volume's own numbers when its frame is
/// unknown).
fn world_point(world: &WorldTransform, frame: Frame, index: [f64; 3]) -> DVec3 {
    world.in_frame(frame).index_to_world(DVec3::from(index))
}

fn assert_near(a: DVec3, b: DVec3, what: &str) {
    assert!((a - b).length() < 1e-4, "{what}: {a} vs {b}");
}

#[test]
fn every_volume_format_with_a_header_keeps_an_oblique_transform() {
    let dir = tempfile::tempdir().unwrap();
    for flip in [false, true] {
        let volume = oblique_volume(flip);
        let world = volume.world();
        for name in [
            "v.nrrd", "v.nhdr", "v.nii", "v.nii.gz", "v.mha", "v.mhd", "v.vti",
        ] {
            for compress in [false, true] {
                let path = dir.path().join(name);
                write_volume_with(&path, &volume, &VolumeWriteOptions { compress }).unwrap();
                let back = read_volume(&path, None).unwrap_or_else(|e| panic!("{e}"));
                let what = format!("{name} flip={flip} compress={compress}");
                assert_eq!(back.grid.dims, volume.grid.dims, "{what}");
                assert_eq!(back.as_slice(), volume.as_slice(), "{what}");
                let expected_frame = match name {
                    "v.vti" => Frame::Unknown,
                    n if n.starts_with("v.nii") => Frame::Ras,
                    _ => Frame::Lps,
                };
                assert_eq!(back.orientation.frame, expected_frame, "{what}");
                assert_eq!(back.world().flips_handedness(), flip, "{what}");
                // VTK has no frame: the numbers are the volume's own (LPS).
                let frame = match expected_frame {
                    Frame::Unknown => Frame::Unknown,
                    _ => Frame::Lps,
                };
                for probe in PROBES {
                    assert_near(
                        world_point(&back.world(), frame, probe),
                        world_point(&world, Frame::Lps, probe),
                        &format!("{what} at {probe:?}"),
                    );
                }
            }
        }
    }
    // Legacy VTK has no place for a direction and says so.
    let err = write_volume(&dir.path().join("v.vtk"), &oblique_volume(false)).unwrap_err();
    assert!(err.message.contains("oblique"), "{err}");
}

#[test]
fn the_nifti_qform_alone_gives_the_same_transform_as_the_sform() {
    let dir = tempfile::tempdir().unwrap();
    for flip in [false, true] {
        let volume = oblique_volume(flip);
        let path = dir.path().join("q.nii");
        write_volume(&path, &volume).unwrap();
        let mut bytes = std::fs::read(&path).unwrap();
        assert_eq!(
            i16::from_le_bytes([bytes[252], bytes[253]]),
            1,
            "qform_code"
        );
        let qfac = f32::from_le_bytes(bytes[76..80].try_into().unwrap());
        assert_eq!(qfac, if flip { -1.0 } else { 1.0 });
        bytes[254..256].copy_from_slice(&0i16.to_le_bytes()); // sform_code: unknown
        std::fs::write(&path, bytes).unwrap();
        let back = read_volume(&path, None).unwrap();
        for probe in PROBES {
            assert_near(
                world_point(&back.world(), Frame::Lps, probe),
                world_point(&volume.world(), Frame::Lps, probe),
                &format!("qform flip={flip} at {probe:?}"),
            );
        }
    }
}

/// Prints, for each file, the world point of every probe as the peer tools compute it, in LPS:
/// nibabel's sform and qform (RAS, turned to LPS), SimpleITK's physical point, VTK's.
const PEERS: &str = r#"
import sys
import numpy as np
kind, path = sys.argv[1], sys.argv[2]
probes = [[float(v) for v in p.split(",")] for p in sys.argv[3:]]
lps = np.diag([-1.0, -1.0, 1.0, 1.0])
if kind == "nibabel":
    import nibabel as nib
    h = nib.load(path).header
    for affine in (h.get_sform(), h.get_qform()):
        for p in probes:
            print(*(lps @ affine @ np.array(p + [1.0]))[:3])
elif kind == "sitk":
    import SimpleITK as sitk
    image = sitk.ReadImage(path)
    for p in probes:
        print(*image.TransformContinuousIndexToPhysicalPoint(p))
else:
    import vtk
    reader = vtk.vtkXMLImageDataReader()
    reader.SetFileName(path)
    reader.Update()
    image = reader.GetOutput()
    for p in probes:
        out = [0.0, 0.0, 0.0]
        image.TransformContinuousIndexToPhysicalPoint(p, out)
        print(*out)
"#;

fn peer_points(kind: &str, path: &Path) -> Option<Vec<DVec3>> {
    let mut args: Vec<std::ffi::OsString> = vec![kind.into(), path.as_os_str().to_owned()];
    args.extend(
        PROBES
            .iter()
            .map(|p| format!("{},{},{}", p[0], p[1], p[2]).into()),
    );
    let args: Vec<&std::ffi::OsStr> = args.iter().map(|a| a.as_os_str()).collect();
    let out = run_python(PEERS, &args)?;
    Some(
        out.lines()
            .map(|l| {
                let v: Vec<f64> = l.split_whitespace().map(|s| s.parse().unwrap()).collect();
                DVec3::new(v[0], v[1], v[2])
            })
            .collect(),
    )
}

#[test]
fn nibabel_simpleitk_and_vtk_read_the_written_transform() {
    let dir = tempfile::tempdir().unwrap();
    for flip in [false, true] {
        let volume = oblique_volume(flip);
        let expected: Vec<DVec3> = PROBES
            .iter()
            .map(|&p| world_point(&volume.world(), Frame::Lps, p))
            .collect();
        for (name, kind, copies) in [
            ("p.nii.gz", "nibabel", 2),
            ("p.nii", "sitk", 1),
            ("p.nrrd", "sitk", 1),
            ("p.mha", "sitk", 1),
            ("p.vti", "vtk", 1),
        ] {
            let path = dir.path().join(name);
            write_volume(&path, &volume).unwrap();
            let Some(points) = peer_points(kind, &path) else {
                return;
            };
            assert_eq!(points.len(), PROBES.len() * copies, "{name}: {points:?}");
            for (i, point) in points.iter().enumerate() {
                // f32 in the NIfTI header and VTK's attributes: well under a micrometre here.
                let e = expected[i % PROBES.len()];
                assert!(
                    (*point - e).length() < 1e-3,
                    "{kind} on {name} (flip={flip}), probe {}: {point} vs {e}",
                    i % PROBES.len()
                );
            }
        }
    }
}
