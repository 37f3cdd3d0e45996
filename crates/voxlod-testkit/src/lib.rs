//! Fixtures for voxlod's tests, benchmarks and examples: a dev-dependency only, never a normal
//! dependency of any crate (it is not published).
//!
//! - [`data`]: where the shared real data lives (`../shared/data` or `VOXLOD_SHARED_DATA`), with
//!   the skip-with-a-printed-reason lookup that tests must use when it is absent.
//! - [`skips`]: every skip (no shared data, a missing tool) recorded, for the count and reasons
//!   that `scripts/test` prints at the end.
//! - [`shapes`]: closed meshes made in code (cubes, icospheres, tori, a holed block, prisms).
//! - [`corpus`]: hard meshes made in code (open sheets, many parts, overlapping shells, CAD
//!   plates, a holed scan, an inside-out surface, a soup, high genus, thin tubes), by name.
//! - [`fields`]: the sphereflake and gyroid fields of the peers' benchmark kit.
//! - [`volumes`]: small volumes made in code.
//! - [`dicom`]: DICOM slices and series of a ball phantom, written with dicom-object.
//! - [`dicom_seg`]: DICOM Segmentation objects of a ball and a box, written with dicom-object.
//! - [`intersections`]: an independent triangle–triangle intersection test of a mesh.
//! - [`files`]: writing and listing files, gzip and zlib streams.
//! - [`compare`]: meshes compared bit for bit.
//! - [`peers`]: the peers' Python (nibabel, pydicom, SimpleITK, zmesh), or a recorded skip.
//! - [`readers`]: minimal OBJ and ASCII STL readers independent of `voxlod-io`.
//! - [`scenes`]: scenes with materials and generated textures (a room, a machine, a tree, a
//!   building, instanced props, a million-triangle machine), for scene proxies.
//!
//! It depends on `voxlod-core`, and on `voxlod-sampling` for the sphereflake's spheres: every
//! other crate can use it without a dependency loop. Those two keep small private helpers in
//! their unit tests, and tests that need more run from the workspace root's `tests/`.

pub mod assets;
pub mod browser;
pub mod compare;
pub mod corpus;
pub mod data;
pub mod dicom;
pub mod dicom_seg;
pub mod fields;
pub mod files;
pub mod gltf_validator;
pub mod intersections;
pub mod peers;
pub mod readers;
pub mod scenes;
pub mod shapes;
pub mod skips;
pub mod volumes;
