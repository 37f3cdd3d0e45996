//! Meshes for the tests and the benchmark: generated shapes and minimal readers of the shared
//! data's OBJ and ASCII STL files (the io crate is not a dependency of this one), all from
//! voxlod-testkit.

#![allow(dead_code, unused_imports)]

use voxlod_core::TriangleMesh;

pub use voxlod_testkit::readers::{read_ascii_stl, read_obj};
pub use voxlod_testkit::shapes::{icosphere, torus_with, unit_cube};

/// A round torus, major radius 2 and tube radius 1.
pub fn torus(n: u32, m: u32) -> TriangleMesh {
    voxlod_testkit::shapes::torus(n, m, 2.0, 1.0)
}
