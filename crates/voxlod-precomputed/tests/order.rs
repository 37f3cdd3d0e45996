//! The layer's bytes depend on each label's set of triangles, not on the order of the mesh's
//! vertices, of its triangles or of their corners, nor on a vertex being given several times
//! (as when a label's triangles are gathered from blocks), nor on the number of threads.

mod common;

use std::collections::BTreeMap;
use std::path::Path;

use voxlod_core::TriangleMesh;
use voxlod_precomputed::{write_layer, PrecomputedOptions, Sharding};

/// A small deterministic generator (a linear congruential one).
struct Lcg(u64);

impl Lcg {
    fn below(&mut self, n: usize) -> usize {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 33) % n as u64) as usize
    }

    fn shuffle<T>(&mut self, items: &mut [T]) {
        for i in (1..items.len()).rev() {
            items.swap(i, self.below(i + 1));
        }
    }
}

/// The same triangles as `mesh`, written differently: every third triangle's corners get
/// copies of their vertices of their own and every seventh triangle is given twice (as block
/// boundaries would give), then the vertices are permuted, the triangles shuffled and each
/// triangle's corners rotated.
fn scrambled(mesh: &TriangleMesh, seed: u64) -> TriangleMesh {
    let mut rng = Lcg(seed);
    let mut positions = mesh.positions.clone();
    let mut triangles = mesh.triangles.clone();
    for t in triangles.iter_mut().step_by(3) {
        for v in t.iter_mut() {
            positions.push(positions[*v as usize]);
            *v = positions.len() as u32 - 1;
        }
    }
    let twice: Vec<[u32; 3]> = triangles.iter().step_by(7).copied().collect();
    triangles.extend(twice);
    let mut order: Vec<u32> = (0..positions.len() as u32).collect();
    rng.shuffle(&mut order);
    // Vertex `old` goes to place `place[old]`.
    let mut place = vec![0u32; positions.len()];
    for (new, &old) in order.iter().enumerate() {
        place[old as usize] = new as u32;
    }
    let moved = order.iter().map(|&old| positions[old as usize]).collect();
    let mut triangles: Vec<[u32; 3]> = triangles
        .iter()
        .map(|t| {
            let r = rng.below(3);
            [t[r], t[(r + 1) % 3], t[(r + 2) % 3]].map(|v| place[v as usize])
        })
        .collect();
    rng.shuffle(&mut triangles);
    TriangleMesh::new(moved, triangles)
}

/// Every file under `dir` by its path relative to `dir`, with its bytes.
fn files(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else {
                let name = path
                    .strip_prefix(dir)
                    .unwrap()
                    .to_string_lossy()
                    .into_owned();
                out.insert(name, std::fs::read(&path).unwrap());
            }
        }
    }
    out
}

/// Writes `meshes` into `dir` on a pool of `threads` threads.
fn write_on(
    dir: &Path,
    meshes: &[(u32, TriangleMesh)],
    options: &PrecomputedOptions,
    threads: usize,
) {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| write_layer(dir, &common::map(), meshes, options).unwrap());
}

#[test]
fn shuffled_vertices_and_triangles_give_the_same_bytes() {
    let meshes = common::meshes();
    let other: Vec<(u32, TriangleMesh)> = meshes
        .iter()
        .enumerate()
        .map(|(i, (label, mesh))| (*label, scrambled(mesh, 17 + i as u64)))
        .collect();
    // The scrambled meshes really are written differently.
    for ((_, a), (_, b)) in meshes.iter().zip(&other) {
        assert!(b.positions.len() > a.positions.len());
        assert!(b.triangles.len() > a.triangles.len());
        assert_ne!(a.triangles[..10], b.triangles[..10]);
    }
    let dir = tempfile::tempdir().unwrap();
    for sharding in [Sharding::Never, Sharding::Always] {
        let options = PrecomputedOptions {
            sharding,
            ..common::options()
        };
        let (first, second) = (dir.path().join("first"), dir.path().join("second"));
        write_on(&first, &meshes, &options, 1);
        write_on(&second, &other, &options, 3);
        let (a, b) = (files(&first), files(&second));
        let mesh_files = a.keys().filter(|k| k.starts_with("mesh")).count();
        assert!(mesh_files >= 2, "{:?}", a.keys().collect::<Vec<_>>());
        assert_eq!(
            a.keys().collect::<Vec<_>>(),
            b.keys().collect::<Vec<_>>(),
            "{sharding:?}"
        );
        for (name, bytes) in &a {
            assert!(bytes == &b[name], "{sharding:?}: {name} differs");
        }
    }
}

#[test]
fn a_different_mesh_gives_different_bytes() {
    // The comparison above can fail: moving one vertex changes the fragments.
    let meshes = common::meshes();
    let mut moved = meshes.clone();
    moved[0].1.positions[0].x += 0.25;
    let dir = tempfile::tempdir().unwrap();
    let (first, second) = (dir.path().join("first"), dir.path().join("second"));
    write_on(&first, &meshes, &common::options(), 2);
    write_on(&second, &moved, &common::options(), 2);
    let (a, b) = (files(&first), files(&second));
    assert_ne!(a["mesh/7"], b["mesh/7"]);
    assert_eq!(a["mesh/300"], b["mesh/300"]);
}
