//! A mutation sweep of every reader: small seed files of every format (and Zarr stores, whose
//! metadata or one chunk file is mutated and whose folder is read), mutated with a fixed
//! random seed (bit flips; bytes replaced by 0xFF, 0x00, '9', '-' and other interesting
//! values; truncation; chunks duplicated or deleted; numbers in the text changed to huge,
//! negative, zero or off-by-one values; binary integers overwritten), each read in-process on
//! a worker thread. Any result is fine but a panic, a read that takes longer than the watchdog
//! allows, or an error that does not name the file in one plain line.
//!
//! `VOXLOD_SWEEP_ITERATIONS` (mutations per seed, default 400) and `VOXLOD_SWEEP_SEED`
//! (default fixed) make it longer or different: `scripts/mutation-sweep.sh` runs it for a
//! night. A failing file is kept under the target directory's temporary folder, and its path
//! is printed.

mod common;
mod zarr_fixtures;

use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use common::{cube, gzip, nifti, read_by_extension, small_volume};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use voxlod_core::{Attribute, PolyMesh};
use voxlod_io::{
    write_mesh, write_poly_mesh, write_volume, write_volume_with, IoError, VolumeWriteOptions,
};

/// How long one read may take before the sweep fails.
const WATCHDOG: Duration = Duration::from_secs(5);

/// Signs of a parser's internals; the message may quote the (mutated) file, so only signs that
/// no mutation of the seeds produces are looked for.
const DEBUG_SIGNS: [&str; 7] = [
    "Error(",
    "::",
    "Some(",
    "LineCol",
    "panicked",
    "ParseError",
    "Custom(",
];

/// One seed: its files (a detached header has a data file; a Zarr store's are paths inside its
/// folder), which of them is mutated, and which is read (or, for a Zarr store, its folder).
struct Seed {
    files: Vec<(String, Vec<u8>)>,
    mutate: usize,
    read: usize,
    folder: Option<String>,
}

fn single(name: &str, bytes: Vec<u8>) -> Seed {
    Seed {
        files: vec![(name.to_string(), bytes)],
        mutate: 0,
        read: 0,
        folder: None,
    }
}

fn fixture(name: &str) -> Seed {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/vtk")
        .join(name);
    single(name, std::fs::read(path).unwrap())
}

/// Writes with one of our writers and takes the bytes back.
fn written(name: &str, write: impl FnOnce(&Path)) -> Vec<(String, Vec<u8>)> {
    let dir = tempfile::tempdir().unwrap();
    write(&dir.path().join(name));
    let mut files: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| {
            let e = e.unwrap();
            (
                e.file_name().to_string_lossy().into_owned(),
                std::fs::read(e.path()).unwrap(),
            )
        })
        .collect();
    // The named file first, its data file (if any) after it.
    files.sort_by_key(|(n, _)| n != name);
    files
}

fn seed_written(name: &str, write: impl FnOnce(&Path)) -> Seed {
    Seed {
        files: written(name, write),
        mutate: 0,
        read: 0,
        folder: None,
    }
}

/// A Zarr store written into the folder `name` by `write`, with its file `mutated` (a path in
/// the folder) mutated and the folder read.
fn zarr_seed(name: &str, mutated: &str, write: impl FnOnce(&Path)) -> Seed {
    let dir = tempfile::tempdir().unwrap();
    write(&dir.path().join(name));
    let mut files = Vec::new();
    let mut folders = vec![dir.path().join(name)];
    while let Some(folder) = folders.pop() {
        for entry in std::fs::read_dir(folder).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                folders.push(path);
            } else {
                let relative = path.strip_prefix(dir.path()).unwrap();
                let relative = relative.to_string_lossy().into_owned();
                files.push((relative, std::fs::read(&path).unwrap()));
            }
        }
    }
    let wanted = format!("{name}/{mutated}");
    let mutate = files.iter().position(|(n, _)| *n == wanted).unwrap();
    Seed {
        files,
        mutate,
        read: 0,
        folder: Some(name.to_string()),
    }
}

/// Zarr stores: a format-3 array (zstd) written by zarrs, a format-2 array (gzip) written from
/// the specification, and an OME-Zarr 0.4 group; each with its metadata or one chunk mutated.
fn zarr_seeds() -> Vec<Seed> {
    let u8_v3 = |p: &Path| {
        let zstd = std::sync::Arc::new(zarrs::array::codec::ZstdCodec::new(3, false));
        let values = zarr_fixtures::samples(|v| v as u8);
        zarr_fixtures::v3_array(p, zarrs::array::DataType::UInt8, 0u8, &values, Some(zstd));
    };
    let u16_v2 = |p: &Path| {
        let le = |v: f64| (v as u16).to_le_bytes().to_vec();
        let compressor = serde_json::json!({"id": "gzip", "level": 1});
        zarr_fixtures::v2_array(p, "<u2", compressor, serde_json::json!(0), le, gzip);
    };
    let ome = |p: &Path| {
        zarr_fixtures::ome_04(p, [2.0, 1.0, 0.5], [1.0, 2.0, 3.0], "micrometer");
    };
    vec![
        zarr_seed("m3.zarr", "zarr.json", u8_v3),
        zarr_seed("c3.zarr", "c/1/0/1", u8_v3),
        zarr_seed("m2.zarr", ".zarray", u16_v2),
        zarr_seed("c2.zarr", "0.1.1", u16_v2),
        zarr_seed("ome.zarr", ".zattrs", ome),
        zarr_seed("ome-array.zarr", "0/.zarray", ome),
    ]
}

fn poly() -> PolyMesh {
    let mut poly = PolyMesh::from(cube());
    poly.lines = vec![[0, 6], [6, 5]];
    poly.points = vec![3];
    poly.vertex_attributes = vec![Attribute {
        name: "height".into(),
        values: poly.mesh.positions.iter().map(|p| p.z).collect(),
    }];
    poly.line_attributes = vec![Attribute {
        name: "width".into(),
        values: vec![2.0, 3.0],
    }];
    poly
}

fn mesh_seeds() -> Vec<Seed> {
    vec![
        seed_written("w.obj", |p| write_mesh(p, &cube()).unwrap()),
        single("h.obj", b"# polygons\nv 0 0 0\nv 2 0 0\nv 2 1 0\nv 1 1 0\nv 1 3 0\nv 0 3 0\nvn 0 0 1\nf 1//1 2//1 3//1 4//1 5//1 6//1\nf -6 -5 -4\nl 1 2 3\np 4\n".to_vec()),
        single("a.ply", b"ply\nformat ascii 1.0\ncomment seed\nelement vertex 5\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n0 0 0 1\n1 0 0 2\n1 1 0 3\n0 1 0 4\n0.5 2 0 5\n4 0 1 2 3\n3 3 2 4\n".to_vec()),
        seed_written("b.ply", |p| write_poly_mesh(p, &poly()).unwrap()),
        single("a.stl", b"solid seed\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nfacet normal 0 0 1\nouter loop\nvertex 1 0 0\nvertex 1 1 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid seed\n".to_vec()),
        seed_written("b.stl", |p| write_mesh(p, &cube()).unwrap()),
        seed_written("w.off", |p| write_mesh(p, &cube()).unwrap()),
        single("h.off", b"# seed\nCOFF 5 2 0\n0 0 0 255 0 0 255\n2 0 0 0 255 0 255\n2 1 0 0 0 255 255\n1 1 0 1 1 1 1\n0 1 0 1 1 1 1\n5 0 1 2 3 4 255 0 0\n3 0 2 4\n".to_vec()),
        seed_written("w.vtp", |p| write_poly_mesh(p, &poly()).unwrap()),
        seed_written("mesh-w.vtk", |p| write_poly_mesh(p, &poly()).unwrap()),
        fixture("cube-ascii.vtp"),
        fixture("cube-inline-plain.vtp"),
        fixture("cube-inline-zlib.vtp"),
        fixture("cube-raw-plain.vtp"),
        fixture("cube-raw-zlib.vtp"),
        fixture("cube-default.vtp"),
        fixture("cells-raw-lz4.vtp"),
        fixture("cells-raw-lzma.vtp"),
        fixture("cells-raw-zlib-big.vtp"),
        fixture("cube-legacy-ascii.vtk"),
        fixture("cube-legacy-binary.vtk"),
        fixture("grid-tets-default.vtu"),
        fixture("grid-tets-ascii.vtu"),
        fixture("grid-hexa-legacy-ascii.vtk"),
        textured_obj(0),
        textured_obj(1),
    ]
}

/// A textured square as OBJ with its MTL and a 1×1 PNG; `mutated` 0 mutates the OBJ, 1 the MTL
/// (the OBJ is read either way).
fn textured_obj(mutated: usize) -> Seed {
    let obj = b"mtllib t.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl tex\nf 1/1 2/2 3/3 4/4\n";
    let mtl =
        b"newmtl tex\nKd 1 0.5 0.25\nNs 50\nd 0.75\nmap_Kd -clamp on t.png\nmap_Bump -bm 2 t.png\n";
    let png = b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR\0\0\0\x01\0\0\0\x01\x08\x02\0\0\0\x90wS\xde\0\0\0\x0cIDATx\x9cc\xf8\xcf\xc0\0\0\x03\x01\x01\0\xc9\xfe\x92\xef\0\0\0\0IEND\xaeB`\x82";
    Seed {
        files: vec![
            ("t.obj".into(), obj.to_vec()),
            ("t.mtl".into(), mtl.to_vec()),
            ("t.png".into(), png.to_vec()),
        ],
        mutate: mutated,
        read: 0,
        folder: None,
    }
}

fn volume_seeds() -> Vec<Seed> {
    let compress = VolumeWriteOptions { compress: true };
    let v = small_volume();
    let mut nii = nifti([3, 2, 3, 2, 1, 1, 1, 1], 4, 16);
    nii.extend((0..12i16).flat_map(|x| (x * 100 - 300).to_le_bytes()));
    let mut nhdr_data = written("d.nhdr", |p| write_volume(p, &v).unwrap());
    let data_seed = Seed {
        files: std::mem::take(&mut nhdr_data),
        mutate: 1,
        read: 0,
        folder: None,
    };
    let mut mhd = written("d.mhd", |p| write_volume(p, &v).unwrap());
    let mhd_data = Seed {
        files: std::mem::take(&mut mhd),
        mutate: 1,
        read: 0,
        folder: None,
    };
    vec![
        seed_written("w.nrrd", |p| write_volume(p, &v).unwrap()),
        seed_written("z.nrrd", |p| write_volume_with(p, &v, &compress).unwrap()),
        single("h.nrrd", b"NRRD0005\n# seed\ntype: short\ndimension: 3\nsizes: 2 2 2\nspace directions: (1,0,0) (0,2,0) (0,0,0.5)\nspace origin: (10,20,30)\nspace units: \"mm\" \"mm\" \"mm\"\nendian: big\nencoding: ascii\nline skip: 1\n\nskipped\n1 2 3 4 5 6 7 -8\n".to_vec()),
        single("s.nrrd", b"NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nspacings: 1 1 1\nencoding: raw\nbyte skip: 2\n\nxx\x01\x02\x03\x04\x05\x06\x07\x08".to_vec()),
        seed_written("h.nhdr", |p| write_volume(p, &v).unwrap()),
        data_seed,
        seed_written("w.mha", |p| write_volume(p, &v).unwrap()),
        seed_written("z.mha", |p| write_volume_with(p, &v, &compress).unwrap()),
        seed_written("w.mhd", |p| write_volume(p, &v).unwrap()),
        mhd_data,
        seed_written("w.vti", |p| write_volume(p, &v).unwrap()),
        seed_written("z.vti", |p| write_volume_with(p, &v, &compress).unwrap()),
        seed_written("w.vtk", |p| write_volume(p, &v).unwrap()),
        fixture("image-default.vti"),
        fixture("image-raw-zlib.vti"),
        fixture("image-raw-plain-u64.vti"),
        fixture("image-raw-zlib-blocks.vti"),
        fixture("image-ascii.vti"),
        fixture("image-legacy-ascii.vtk"),
        fixture("image-legacy-binary.vtk"),
        single("n.nii", nii.clone()),
        single("n.nii.gz", gzip(&nii)),
        single("r.raw", (0..16u8).collect()),
        dicom_seed(),
        dicom_seg_seed(),
        single("s.seg.nrrd", SEG_NRRD.to_vec()),
        seed_written("w.nii", |p| write_volume(p, &v).unwrap()),
        seed_written("z.nii.gz", |p| write_volume(p, &v).unwrap()),
    ]
}

/// A Slicer segmentation: a 2x2x2 label map with two named, coloured segments.
const SEG_NRRD: &[u8] = b"NRRD0004\ntype: uint8\ndimension: 3\nspace: left-posterior-superior\nsizes: 2 2 2\nspace directions: (0.5,0,0) (0,0.5,0) (0,0,1)\nspace origin: (-1,2,3)\nencoding: raw\nSegment0_Name:=Left Lung\nSegment0_LabelValue:=1\nSegment0_Color:=0.9 0.2 0.1\nSegment0_Layer:=0\nSegment1_Name:=heart\nSegment1_LabelValue:=2\nSegment1_Color:=0.1 0.3 0.9\nSegment1_Layer:=0\n\n\x00\x01\x01\x02\x00\x02\x01\x00";

/// One CT slice (4x4, slope 2, intercept -1024) written with dicom-object.
fn dicom_seed() -> Seed {
    let slices = voxlod_testkit::dicom::ball_series("1.2.3", 4, 1, [1.0; 3], 0.3, [0.0; 3], 30.0);
    seed_written("c.dcm", |p| {
        voxlod_testkit::dicom::write_slice(p, &slices[0])
    })
}

/// A DICOM Segmentation written with dicom-object: 5x3 frames (15 bits, so frames straddle
/// bytes), two segments, four frames on two planes of an oblique grid.
fn dicom_seg_seed() -> Seed {
    use voxlod_testkit::dicom_seg::{phantom_seg, write_seg, Frame, Kind};
    let mut seg = phantom_seg(Kind::Binary);
    (seg.rows, seg.columns) = (3, 5);
    let normal = voxlod_testkit::dicom_seg::oblique_axes()[2];
    seg.frames = (0..4u8)
        .map(|k| Frame {
            segment: 1 + u16::from(k % 2),
            position: [0, 1, 2].map(|a| 10.0 + normal[a] * 1.5 * f64::from(k / 2)),
            pixels: (0..15u8).map(|i| (i + k) % 3 / 2).collect(),
        })
        .collect();
    seed_written("s.seg.dcm", |p| write_seg(p, &seg))
}

/// Interesting byte values: the ends of the ranges, digits and signs, separators.
const BYTES: [u8; 12] = [
    0xff, 0x00, b'9', b'-', 0x7f, 0x80, b' ', b'\n', b'<', b'"', b'_', b'.',
];

/// Replacements for a number in the text.
const NUMBERS: [&str; 9] = [
    "4294967295",
    "18446744073709551615",
    "99999999999",
    "2147483648",
    "-1",
    "-2147483648",
    "0",
    "1e308",
    "nan",
];

/// One random change to `bytes`, described.
fn mutate_once(rng: &mut Pcg64, bytes: &mut Vec<u8>) -> String {
    if bytes.is_empty() {
        bytes.push(b'0');
        return "empty made one byte".into();
    }
    let at = rng.random_range(0..bytes.len());
    match rng.random_range(0..8) {
        0 => {
            bytes[at] ^= 1 << rng.random_range(0..8);
            format!("bit flip at {at}")
        }
        1 => {
            bytes[at] = BYTES[rng.random_range(0..BYTES.len())];
            format!("byte {at} = {}", bytes[at])
        }
        2 => {
            bytes.truncate(at);
            format!("truncated to {at}")
        }
        3 => {
            let len = rng.random_range(1..=64.min(bytes.len() - at));
            let chunk = bytes[at..at + len].to_vec();
            let to = rng.random_range(0..=bytes.len());
            bytes.splice(to..to, chunk);
            format!("{len} bytes from {at} copied to {to}")
        }
        4 => {
            let len = rng.random_range(1..=64.min(bytes.len() - at));
            bytes.drain(at..at + len);
            format!("{len} bytes deleted at {at}")
        }
        5 | 6 => change_number(rng, bytes),
        _ => {
            let at = at - at % 4;
            let value =
                [u32::MAX, 0, i32::MIN as u32, 0x7fff_ffff, 1 << 20][rng.random_range(0..5)];
            let end = (at + 4).min(bytes.len());
            let le = value.to_le_bytes();
            bytes[at..end].copy_from_slice(&le[..end - at]);
            format!("u32 {value} at {at}")
        }
    }
}

/// Replaces one run of ASCII digits (a count, a size, an offset) by a huge, negative, zero or
/// neighbouring value.
fn change_number(rng: &mut Pcg64, bytes: &mut Vec<u8>) -> String {
    let runs: Vec<(usize, usize)> = {
        let mut runs = Vec::new();
        let mut i = 0;
        while i < bytes.len() {
            if bytes[i].is_ascii_digit() {
                let start = i;
                while i < bytes.len() && bytes[i].is_ascii_digit() {
                    i += 1;
                }
                runs.push((start, i));
            } else {
                i += 1;
            }
        }
        runs
    };
    if runs.is_empty() {
        return "no number to change".into();
    }
    let (start, end) = runs[rng.random_range(0..runs.len())];
    let old: u128 = std::str::from_utf8(&bytes[start..end])
        .unwrap()
        .parse()
        .unwrap_or(0);
    let new = match rng.random_range(0..NUMBERS.len() + 2) {
        k if k < NUMBERS.len() => NUMBERS[k].to_string(),
        k if k == NUMBERS.len() => (old + 1).to_string(),
        _ => old.saturating_sub(1).to_string(),
    };
    bytes.splice(start..end, new.bytes());
    format!("number at {start} = {new}")
}

/// What a read did.
enum Outcome {
    Read,
    Refused(IoError),
}

/// Reads on a worker thread, so that a hang is caught by the watchdog.
struct Worker {
    jobs: mpsc::Sender<PathBuf>,
    results: mpsc::Receiver<std::thread::Result<Outcome>>,
}

impl Worker {
    fn start() -> Worker {
        let (jobs, inbox) = mpsc::channel::<PathBuf>();
        let (outbox, results) = mpsc::channel();
        std::thread::spawn(move || {
            for path in inbox {
                let outcome = std::panic::catch_unwind(|| match read_by_extension(&path) {
                    Ok(()) => Outcome::Read,
                    Err(e) => Outcome::Refused(e),
                });
                if outbox.send(outcome).is_err() {
                    return;
                }
            }
        });
        Worker { jobs, results }
    }

    fn read(&self, path: &Path) -> Result<Outcome, String> {
        self.jobs.send(path.to_path_buf()).unwrap();
        match self.results.recv_timeout(WATCHDOG) {
            Ok(Ok(outcome)) => Ok(outcome),
            Ok(Err(_)) => Err("the reader panicked".into()),
            Err(_) => Err(format!("the read took longer than {WATCHDOG:?}")),
        }
    }
}

/// Keeps a failing file for reproduction and fails with its path.
fn fail(path: &Path, what: &str, mutations: &[String]) -> ! {
    let keep = Path::new(env!("CARGO_TARGET_TMPDIR")).join("mutation-sweep-failures");
    std::fs::create_dir_all(&keep).unwrap();
    let kept = keep.join(path.file_name().unwrap());
    std::fs::copy(path, &kept).unwrap();
    panic!(
        "{}: {what}\n  mutations: {}\n  file kept at {}",
        path.display(),
        mutations.join("; "),
        kept.display()
    );
}

fn check_error(path: &Path, seed: &Seed, e: &IoError, mutations: &[String]) {
    let text = e.to_string();
    let names_a_file = seed.files.iter().any(|(n, _)| text.contains(n.as_str()))
        || seed
            .folder
            .as_ref()
            .is_some_and(|f| text.contains(f.as_str()));
    if !names_a_file || text.contains('\n') {
        fail(
            path,
            &format!("error does not name the file in one line: {text}"),
            mutations,
        );
    }
    if let Some(sign) = DEBUG_SIGNS.iter().find(|s| e.message.contains(*s)) {
        fail(path, &format!("'{sign}' in the message: {text}"), mutations);
    }
}

#[test]
fn mutated_files_never_panic_hang_or_leak_internals() {
    let iterations: usize = std::env::var("VOXLOD_SWEEP_ITERATIONS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(400);
    let base_seed: u64 = std::env::var("VOXLOD_SWEEP_SEED")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(0x5eed_f11e);
    let dir = tempfile::tempdir().unwrap();
    let worker = Worker::start();
    let started = Instant::now();
    let (mut files, mut refused) = (0usize, 0usize);
    let seeds: Vec<Seed> = mesh_seeds()
        .into_iter()
        .chain(volume_seeds())
        .chain(zarr_seeds())
        .collect();
    for (s, seed) in seeds.iter().enumerate() {
        for (name, bytes) in &seed.files {
            let path = dir.path().join(name);
            std::fs::create_dir_all(path.parent().unwrap()).unwrap();
            std::fs::write(path, bytes).unwrap();
        }
        let (target_name, original) = &seed.files[seed.mutate];
        let target = dir.path().join(target_name);
        let read_path = match &seed.folder {
            Some(folder) => dir.path().join(folder),
            None => dir.path().join(&seed.files[seed.read].0),
        };
        // The seed itself must read.
        match worker.read(&read_path) {
            Ok(Outcome::Read) => {}
            Ok(Outcome::Refused(e)) => panic!("seed {target_name} is refused: {e}"),
            Err(what) => fail(&read_path, &what, &[]),
        }
        let mut rng =
            Pcg64::seed_from_u64(base_seed ^ (s as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15));
        for _ in 0..iterations {
            let mut bytes = original.clone();
            let mutations: Vec<String> = (0..rng.random_range(1..=3))
                .map(|_| mutate_once(&mut rng, &mut bytes))
                .collect();
            std::fs::write(&target, &bytes).unwrap();
            files += 1;
            match worker.read(&read_path) {
                Ok(Outcome::Read) => {}
                Ok(Outcome::Refused(e)) => {
                    refused += 1;
                    check_error(&read_path, seed, &e, &mutations);
                }
                Err(what) => fail(&target, &what, &mutations),
            }
        }
        std::fs::write(&target, original).unwrap();
    }
    println!(
        "mutation sweep: {} seeds, {files} mutated files ({refused} refused, {} read) in {:.1} s",
        seeds.len(),
        files - refused,
        started.elapsed().as_secs_f64()
    );
}
