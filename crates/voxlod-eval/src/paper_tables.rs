//! The voxel paper's three results tables (He, Hong, Kaufman, Varshney, Wang 1995, §4) as data,
//! the objects they were made from, and [`reproduce`], which runs our pipeline at the tables'
//! resolutions and returns our counts beside the paper's.
//!
//! - Table 1: the 820-sphere sphereflake, Gaussian filter ([`table1`], object
//!   [`voxlod::sampling::sphereflake()`]).
//! - Table 2: a mechanical part made by CSG, Gaussian filter ([`table2`], object
//!   [`mechanical_part`]: the paper does not give its part, so this is our own with the same
//!   5 : 5 : 3 box, holes of three sizes and a through-bore).
//! - Table 3: a CT-scanned head, hyper-cone filter ([`table3`]; the scan is thresholded at
//!   [`CT_HEAD_SKIN_THRESHOLD`], the skin, with trilinear interpolation, as §4 describes).
//!
//! Every row uses one voxel of its own level as the filter radius (the tables' radius column is
//! that voxel in units of the finest level's) and isodensity 0.5. A row's resolution is the
//! paper's largest dimension, which our pyramid puts across the object's longest side; the other
//! dimensions follow from the object's box (see [`TableRow::object_voxels`]).
//!
//! Cost: that of the levels (the finest dominates: seconds for a 200³ or 256³ level).

use std::path::{Path, PathBuf};
use std::time::Instant;

use glam::DVec3;
use serde::Serialize;
use voxlod::core::Axis;
use voxlod::lod::{build_level, plan, LevelOptions, LodError, LodLevel, LodSource};
use voxlod::sampling::{Filter, PyramidOptions, Shape};

/// One row of a paper's table.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct PaperRow {
    /// The row's letter (and figure panel).
    pub index: &'static str,
    /// The volume buffer's dimensions, x × y × z.
    pub dims: [usize; 3],
    /// Filter radius in voxels of the finest level.
    pub radius: f64,
    /// The paper's triangle count.
    pub triangles: usize,
}

/// One of the paper's tables.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PaperTable {
    /// The table's number in the paper.
    pub number: u8,
    /// The object, in words.
    pub object: &'static str,
    /// The filter of every row.
    pub filter: Filter,
    /// The rows, finest level first.
    pub rows: Vec<PaperRow>,
}

/// The paper's triangle counts (Table 1: sphereflake, Gaussian filter, isodensity 0.5).
pub const PAPER_TABLE1: [(&str, usize, f64, usize); 6] = [
    ("a", 200, 1.0, 322_214),
    ("b", 100, 2.0, 64_926),
    ("c", 50, 4.0, 13_576),
    ("d", 30, 6.7, 3_756),
    ("e", 15, 13.3, 636),
    ("f", 5, 40.0, 8),
];

const fn row(index: &'static str, dims: [usize; 3], radius: f64, triangles: usize) -> PaperRow {
    PaperRow {
        index,
        dims,
        radius,
        triangles,
    }
}

/// Table 1: the sphereflake (the rows of `voxlod demo`).
pub fn table1() -> PaperTable {
    PaperTable {
        number: 1,
        object: "fractal sphereflake, 820 spheres",
        filter: Filter::GAUSSIAN,
        rows: PAPER_TABLE1
            .iter()
            .map(|&(index, n, radius, triangles)| row(index, [n; 3], radius, triangles))
            .collect(),
    }
}

/// Table 2: the CSG mechanical part.
pub fn table2() -> PaperTable {
    PaperTable {
        number: 2,
        object: "CSG mechanical part",
        filter: Filter::GAUSSIAN,
        rows: vec![
            row("a", [200, 200, 120], 1.0, 271_504),
            row("b", [100, 100, 60], 2.0, 64_344),
            row("c", [50, 50, 30], 4.0, 13_292),
            row("d", [40, 40, 24], 5.0, 8_660),
            row("e", [20, 20, 12], 10.0, 1_508),
            row("f", [5, 5, 3], 40.0, 88),
        ],
    }
}

/// Table 3: the CT-scanned head (the paper's scan had 256 × 256 × 225 samples).
pub fn table3() -> PaperTable {
    PaperTable {
        number: 3,
        object: "CT-scanned human head",
        filter: Filter::Hypercone,
        rows: vec![
            row("a", [256, 256, 225], 1.0, 865_698),
            row("b", [128, 128, 113], 2.0, 193_790),
            row("c", [64, 64, 57], 4.0, 42_688),
            row("d", [32, 32, 29], 8.0, 9_246),
            row("e", [8, 8, 8], 32.0, 300),
            row("f", [4, 4, 4], 64.0, 52),
        ],
    }
}

/// The CT head's skin: halfway between air (0–100) and soft tissue (about 1050) in the shared
/// scan's units. The paper does not give its threshold; its Table 3 counts follow the skin (a
/// bone threshold leaves nothing at 8³, where the paper has 300 triangles).
pub const CT_HEAD_SKIN_THRESHOLD: f32 = 500.0;

/// Our mechanical part for Table 2, in millimetres, with the paper's 5 : 5 : 3 box
/// (100 × 100 × 60):
///
/// - a square plate 100 × 100 × 24 with a cylindrical boss of radius 30 on it, 60 high in all;
/// - a through-bore of radius 14 along the boss's axis, widened to radius 20 (a counterbore) in
///   its top 10 mm;
/// - a cross hole of radius 4 through the boss, crossing the bore;
/// - four bolt holes of radius 2.2 through the plate's corners, four pin holes of radius 1
///   between them, and a notch 7 × 20 × 12 in one edge.
///
/// Genus 11 (bore 1, cross hole 2, bolt holes 4, pin holes 4). The holes come in sizes that the
/// filter closes at different levels of Table 2 (a hole survives about as long as its radius
/// exceeds half a voxel): the pin holes at 40 × 40 × 24, the bolt holes at 20 × 20 × 12, the
/// bore and cross hole at 5 × 5 × 3. Hole axes sit 0.37 mm off the round millimetres, so no
/// level's grid happens to have samples on them (a sample on a hole's axis keeps it open a level
/// longer).
pub fn mechanical_part() -> Shape {
    const OFF: f64 = 0.37;
    let body = Shape::Union(vec![
        Shape::cuboid(DVec3::new(-50.0, -50.0, 0.0), DVec3::new(50.0, 50.0, 24.0)),
        Shape::cylinder(DVec3::new(0.0, 0.0, 30.0), Axis::Z, 30.0, 30.0),
    ]);
    // Along z through everything, from z = -1 to 61.
    let through =
        |x: f64, y: f64, r: f64| Shape::cylinder(DVec3::new(x, y, 30.0), Axis::Z, r, 31.0);
    let mut cuts = vec![
        through(0.0, 0.0, 14.0),
        Shape::cylinder(DVec3::new(0.0, 0.0, 55.5), Axis::Z, 20.0, 5.5),
        Shape::cylinder(DVec3::new(0.0, 0.0, 38.0 + OFF), Axis::X, 4.0, 31.0),
        Shape::cuboid(DVec3::new(44.0, -10.0, -1.0), DVec3::new(51.0, 10.0, 12.0)),
    ];
    let b = 36.0 + OFF;
    for (x, y) in [(b, b), (-b, b), (-b, -b), (b, -b)] {
        cuts.push(through(x, y, 2.2));
    }
    let p = 40.0 + OFF;
    for (x, y) in [(OFF, p), (-p, OFF), (OFF, -p), (p, 20.0 + OFF)] {
        cuts.push(through(x, y, 1.0));
    }
    body.minus(Shape::Union(cuts))
}

/// One row of ours beside the paper's.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TableRow {
    /// The paper's row.
    pub paper: PaperRow,
    /// Samples across the object's longest side.
    pub resolution: usize,
    /// Voxels across the object's box along x, y, z, `ceil(size / voxel)`: our counterpart of
    /// the paper's dimensions (the grid itself is padded by the radius and two voxels on each
    /// side).
    pub object_voxels: [usize; 3],
    /// Samples of the level's grid along x, y, z.
    pub grid: [usize; 3],
    /// The level's voxel side, in world units.
    pub voxel_size: f64,
    /// Filter radius in world units.
    pub radius: f64,
    /// Filter radius in voxels of the finest level (the paper's radius column).
    pub radius_in_finest_voxels: f64,
    /// Our triangles.
    pub triangles: usize,
    /// Our vertices.
    pub vertices: usize,
    /// Connected components of our level.
    pub components: usize,
    /// Genus of our level, when it is a closed manifold.
    pub genus: Option<i64>,
    /// Whether our level is a closed, consistently oriented manifold.
    pub closed_manifold: bool,
    /// Time to sample and contour the level.
    pub seconds: f64,
}

impl TableRow {
    /// Our triangles over the paper's.
    pub fn ratio(&self) -> f64 {
        self.triangles as f64 / self.paper.triangles as f64
    }
}

/// Runs `table`'s rows on `source` (with the table's filter, radius one voxel per level and
/// isodensity `iso`), handing each level to `each` as it is made (to write it, say).
pub fn reproduce(
    source: &LodSource,
    table: &PaperTable,
    iso: f32,
    mut each: impl FnMut(&TableRow, &LodLevel),
) -> Result<Vec<TableRow>, LodError> {
    let resolutions = table
        .rows
        .iter()
        .map(|r| r.dims.into_iter().max().unwrap_or(1))
        .collect();
    let options = LevelOptions {
        pyramid: PyramidOptions::for_resolutions(resolutions, table.filter),
        iso,
        normals: true,
        // The paper's counts are of plain marching cubes.
        clean: None,
        snap: false,
    };
    let plans = plan(source, &options)?;
    let size = source.bounds().size();
    let finest = plans[0].voxel_size;
    let mut rows = Vec::new();
    for (p, paper) in plans.iter().zip(&table.rows) {
        let start = Instant::now();
        let level = build_level(source, p, &options)?;
        let t = &level.topology;
        let row = TableRow {
            paper: *paper,
            resolution: p.resolution,
            object_voxels: [0, 1, 2]
                .map(|a| ((size[a] / p.voxel_size) - 1e-9).ceil().max(1.0) as usize),
            grid: p.grid.dims,
            voxel_size: p.voxel_size,
            radius: p.radius,
            radius_in_finest_voxels: p.radius / finest,
            triangles: level.mesh.triangles.len(),
            vertices: level.mesh.positions.len(),
            components: t.components,
            genus: t.genus,
            closed_manifold: t.is_closed_manifold() && t.is_consistently_oriented(),
            seconds: start.elapsed().as_secs_f64(),
        };
        each(&row, &level);
        rows.push(row);
    }
    Ok(rows)
}

/// The rows as a fixed-width text table, ours beside the paper's.
pub fn format_rows(rows: &[TableRow]) -> String {
    let mut out = format!(
        "{:<6}{:>14}{:>14}{:>8}{:>12}{:>12}{:>7}{:>7}{:>6}{:>9}\n",
        "index",
        "paper dims",
        "our voxels",
        "radius",
        "paper tris",
        "our tris",
        "ratio",
        "genus",
        "comp",
        "seconds"
    );
    for r in rows {
        let dims = |d: [usize; 3]| format!("{}x{}x{}", d[0], d[1], d[2]);
        out.push_str(&format!(
            "{:<6}{:>14}{:>14}{:>8.1}{:>12}{:>12}{:>7.2}{:>7}{:>6}{:>9.2}\n",
            r.paper.index,
            dims(r.paper.dims),
            dims(r.object_voxels),
            r.radius_in_finest_voxels,
            r.paper.triangles,
            r.triangles,
            r.ratio(),
            r.genus.map_or("-".to_string(), |g| g.to_string()),
            r.components,
            r.seconds
        ));
    }
    out
}

/// The examples' runner: [`reproduce`] at isodensity 0.5, each level written to `output` when
/// given ([`write_level`]), then the table printed ours beside the paper's. The first write
/// that fails is returned after the table is printed.
pub fn reproduce_and_print(
    source: &LodSource,
    table: &PaperTable,
    output: Option<&Path>,
) -> Result<Vec<TableRow>, Box<dyn std::error::Error>> {
    let mut failure = None;
    let rows = reproduce(source, table, 0.5, |row, level| {
        if let Some(dir) = output {
            if let Err(e) = write_level(dir, table, row, level) {
                failure.get_or_insert(e);
            }
        }
    })?;
    print!("{}", format_rows(&rows));
    match failure {
        Some(e) => Err(e.into()),
        None => Ok(rows),
    }
}

/// The examples' optional output folder: `None` when absent, empty or `-`.
pub fn output_folder(arg: Option<String>) -> Option<PathBuf> {
    arg.filter(|d| !d.is_empty() && d != "-").map(PathBuf::from)
}

/// Writes a row's level as `DIR/tableN-INDEX.ply` (creating DIR); `None` for an empty level.
pub fn write_level(
    dir: &Path,
    table: &PaperTable,
    row: &TableRow,
    level: &LodLevel,
) -> Result<Option<PathBuf>, voxlod::io::IoError> {
    if level.mesh.is_empty() {
        return Ok(None);
    }
    std::fs::create_dir_all(dir).map_err(|e| {
        voxlod::io::IoError::new(
            dir,
            voxlod::io::IoErrorKind::Access,
            format!("cannot create the folder: {e}"),
        )
    })?;
    let path = dir.join(format!("table{}-{}.ply", table.number, row.paper.index));
    voxlod::io::write_mesh(&path, &level.mesh)?;
    Ok(Some(path))
}
