//! UV atlases by xatlas: a cube cut at its creases into its six faces, a sphere's charts at a
//! texel density, padding between charts, marching cubes' slivers kept from upsetting their
//! charts, and bad input named (sizes beyond the memory limit:
//! `atlas_limits.rs`, which sets the limit for its one test).

use voxlod_bake::atlas::NO_CHART;
use voxlod_bake::raster::UNCOVERED;
use voxlod_bake::{atlas, AtlasOptions};
use voxlod_core::glam::{DVec3, Vec3};
use voxlod_core::TriangleMesh;
use voxlod_testkit::shapes::{icosphere, subdivided, unit_cube};

/// The unit cube with each face split into 2·4^levels triangles.
fn fine_cube(levels: u32) -> TriangleMesh {
    let cube = unit_cube();
    subdivided(
        cube.positions.iter().map(|p| p.as_dvec3()).collect(),
        cube.triangles,
        levels,
        |p: DVec3| p,
    )
}

fn face_normal(atlas: &voxlod_bake::Atlas, t: usize) -> Vec3 {
    let [a, b, c] = atlas.triangles[t].map(|v| atlas.positions[v as usize]);
    (b - a).cross(c - a).normalize()
}

#[test]
fn a_cube_is_cut_at_its_creases_into_six_charts() {
    let level = fine_cube(2);
    let atlas = atlas(&level, &AtlasOptions::for_texture(256)).unwrap();
    assert_eq!(atlas.chart_count, 6);
    assert_eq!(atlas.triangles.len(), level.triangles.len());
    assert_eq!((atlas.width, atlas.height), (256, 256));
    // Each chart is one face: its triangles share one normal; each face's vertices are its own.
    for c in 0..6u32 {
        let members: Vec<usize> = (0..atlas.chart.len())
            .filter(|&t| atlas.chart[t] == c)
            .collect();
        assert_eq!(members.len(), level.triangles.len() / 6, "chart {c}");
        let n = face_normal(&atlas, members[0]);
        assert!(members
            .iter()
            .all(|&t| face_normal(&atlas, t).dot(n) > 0.999));
    }
    let mut chart_of_vertex = vec![NO_CHART; atlas.positions.len()];
    for (t, tri) in atlas.triangles.iter().enumerate() {
        for &v in tri {
            let c = &mut chart_of_vertex[v as usize];
            assert!(
                *c == NO_CHART || *c == atlas.chart[t],
                "vertex {v} in two charts"
            );
            *c = atlas.chart[t];
        }
    }
    // A face of 4^2 · 2 triangles has 5 × 5 vertices; the normals are the faces' own.
    assert_eq!(atlas.positions.len(), 6 * 25);
    for (t, tri) in atlas.triangles.iter().enumerate() {
        let n = face_normal(&atlas, t);
        for &v in tri {
            assert!(atlas.normals[v as usize].dot(n) > 0.999);
            assert_eq!(
                level.positions[atlas.level_vertex[v as usize] as usize],
                atlas.positions[v as usize]
            );
        }
    }
    assert!(atlas
        .uv
        .iter()
        .all(|uv| (0.0..=1.0).contains(&uv.x) && (0.0..=1.0).contains(&uv.y)));
    assert_eq!(atlas.flipped, 0);
}

#[test]
fn charts_keep_the_padding_apart() {
    // In one piece, and in sixteen pieces of 80 triangles (charted side by side, packed
    // together: each piece's border is a chart border).
    let level = icosphere(3);
    for (padding, piece_triangles) in [(2u32, 0u32), (6, 0), (4, 80)] {
        let options = AtlasOptions {
            padding,
            piece_triangles,
            ..AtlasOptions::for_texture(512)
        };
        let atlas = atlas(&level, &options).unwrap();
        assert!(atlas.chart_count >= if piece_triangles > 0 { 16 } else { 2 });
        let cover = atlas.coverage();
        let chart = |x: usize, y: usize| {
            let c = cover.texels[y * cover.width + x];
            (c.triangle != UNCOVERED).then(|| atlas.chart[c.triangle as usize])
        };
        // Two texels of different charts (inside or at their borders) are at least the
        // padding apart, less the conservative fringe of one texel on each side.
        let reach = padding.saturating_sub(2) as i64;
        for y in 0..cover.height {
            for x in 0..cover.width {
                let Some(a) = chart(x, y) else { continue };
                for dy in -reach..=reach {
                    for dx in -reach..=reach {
                        let (nx, ny) = (x as i64 + dx, y as i64 + dy);
                        if nx < 0 || ny < 0 || nx >= cover.width as i64 || ny >= cover.height as i64
                        {
                            continue;
                        }
                        if let Some(b) = chart(nx as usize, ny as usize) {
                            assert_eq!(
                                a, b,
                                "charts {a} and {b} meet at ({x}, {y}), padding {padding}"
                            );
                        }
                    }
                }
            }
        }
        let covered = cover.covered() as f64 / cover.texels.len() as f64;
        assert_eq!(atlas.utilisation, covered);
        assert!(
            atlas.utilisation > 0.2 && atlas.utilisation < 1.0,
            "{}",
            atlas.utilisation
        );
    }
}

#[test]
fn a_density_sizes_the_texture() {
    // The unit sphere's area is 4π; at 64 texels a unit, its charts need about 64²·4π texels.
    let level = icosphere(3);
    let atlas = atlas(&level, &AtlasOptions::for_density(64.0)).unwrap();
    let texels = (atlas.width * atlas.height) as f64;
    let chart_texels = 64.0f64.powi(2) * 4.0 * std::f64::consts::PI;
    assert!(
        texels > chart_texels && texels < 4.0 * chart_texels,
        "{}×{}",
        atlas.width,
        atlas.height
    );
    let denser = voxlod_bake::atlas(&level, &AtlasOptions::for_density(128.0)).unwrap();
    assert!(denser.width > atlas.width * 3 / 2);
}

#[test]
fn bad_levels_and_options_are_named() {
    let empty = TriangleMesh::default();
    let err = atlas(&empty, &AtlasOptions::default()).unwrap_err();
    assert!(err.to_string().contains("no triangles"), "{err}");
    let mut broken = unit_cube();
    broken.triangles[3][1] = 99;
    let err = atlas(&broken, &AtlasOptions::default()).unwrap_err();
    assert!(err.to_string().contains("triangle 3"), "{err}");
    let err = atlas(&unit_cube(), &AtlasOptions::for_density(-1.0)).unwrap_err();
    assert!(err.to_string().contains("density"), "{err}");
    for bad in [-0.1, f32::NAN] {
        let options = AtlasOptions {
            sliver_edge: Some(bad),
            ..AtlasOptions::default()
        };
        let err = atlas(&unit_cube(), &options).unwrap_err();
        assert!(err.to_string().contains("sliver edge"), "{err}");
    }
}

#[test]
fn a_fixed_texture_is_filled_as_densely_as_its_charts_pack() {
    // A sphere's smooth charts pack into a 512² texture with about half of its texels covered
    // or more: the density is scaled until the packing reaches nearly the texture's side, not
    // left where a first guess happened to fit.
    let atlas = voxlod_bake::atlas(&icosphere(4), &AtlasOptions::for_texture(512)).unwrap();
    assert!(atlas.utilisation >= 0.45, "{}", atlas.utilisation);
}

#[test]
fn a_level_in_pieces_keeps_its_triangles_in_order() {
    // 5 120 triangles in pieces of at most 700 (eight pieces): every triangle keeps its place
    // and its corners, every one is in a chart, and the pieces pack about as densely as one.
    let level = icosphere(4);
    let whole = atlas(&level, &AtlasOptions::for_texture(1024)).unwrap();
    let options = AtlasOptions {
        piece_triangles: 700,
        ..AtlasOptions::for_texture(1024)
    };
    let cut = atlas(&level, &options).unwrap();
    assert_eq!(cut.triangles.len(), level.triangles.len());
    for (t, corners) in cut.triangles.iter().enumerate() {
        let copied = corners.map(|v| cut.level_vertex[v as usize]);
        assert_eq!(copied, level.triangles[t], "triangle {t}");
        assert_ne!(cut.chart[t], NO_CHART, "triangle {t}");
    }
    // A piece's border is a chart border: each of the eight pieces holds a chart or more.
    assert!(cut.chart_count >= 8, "{} charts", cut.chart_count);
    assert_eq!(cut.flipped, 0);
    assert!(
        cut.utilisation > 0.8 * whole.utilisation,
        "{} against {}",
        cut.utilisation,
        whole.utilisation
    );
}

#[test]
fn many_small_charts_narrow_the_padding_rather_than_fail() {
    // 300 cubes apart, 1 800 charts (a cube's faces), into a 256² texture: at 4 texels of
    // padding a side the gutters alone would need more texels than the texture has, so the
    // charts are packed with less, said in the atlas; a 1024² texture keeps the 4 asked.
    let cube = unit_cube();
    let mut level = TriangleMesh::default();
    for k in 0..300u32 {
        let offset = Vec3::new((k % 20) as f32, (k / 20) as f32, 0.0) * 2.0;
        let first = level.positions.len() as u32;
        level
            .positions
            .extend(cube.positions.iter().map(|&p| p + offset));
        level
            .triangles
            .extend(cube.triangles.iter().map(|t| t.map(|v| v + first)));
    }
    let small = atlas(&level, &AtlasOptions::for_texture(256)).unwrap();
    assert_eq!(small.chart_count, 1800);
    assert!(small.padding < 4, "{}", small.padding);
    assert_eq!((small.width, small.height), (256, 256));
    let large = atlas(&level, &AtlasOptions::for_texture(1024)).unwrap();
    assert_eq!(large.padding, 4);
}

/// Plain marching cubes of a ball of radius `r` sample spacings sampled on `n` samples a side
/// over [-1, 1]³ (0.5 plus the signed distance, positive inside): slivers wherever the sphere passes
/// through or near a sample (through every sample at a whole distance `r` from the centre).
fn marching_cubes_ball(n: usize, r: f64) -> TriangleMesh {
    use voxlod::contouring::{marching_cubes, ContourOptions};
    use voxlod::core::{Grid, Volume};
    let h = 2.0 / (n - 1) as f64;
    let grid = Grid::new([n; 3], [h; 3], [-1.0; 3]).unwrap();
    let at = |i: usize| -1.0 + i as f64 * h;
    let mut values = Vec::with_capacity(n * n * n);
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let p = DVec3::new(at(i), at(j), at(k));
                values.push((0.5 + r * h - p.length()) as f32);
            }
        }
    }
    let volume = Volume::from_vec(grid, values).unwrap();
    marching_cubes(&volume, &ContourOptions::default()).unwrap()
}

/// Texels per unit of surface of each chart (its texel area over its surface area, rooted).
fn chart_densities(atlas: &voxlod_bake::Atlas) -> Vec<f64> {
    let mut areas = vec![(0.0f64, 0.0f64); atlas.chart_count];
    let scale = voxlod_core::glam::Vec2::new(atlas.width as f32, atlas.height as f32);
    for (t, &c) in atlas.triangles.iter().zip(&atlas.chart) {
        let [a, b, e] = t.map(|v| atlas.positions[v as usize]);
        let [u, v, w] = t.map(|v| atlas.uv[v as usize] * scale);
        if let Some(area) = areas.get_mut(c as usize) {
            area.0 += (v - u).perp_dot(w - u).abs() as f64 / 2.0;
            area.1 += (b - a).cross(e - a).length() as f64 / 2.0;
        }
    }
    areas.iter().map(|&(t, s)| (t / s).sqrt()).collect()
}

/// Marching cubes' slivers upset their charts (xatlas parameterizes a sliver's tiny area as any
/// other): with them snapped shut while the charts are made, every chart of a ball's level is
/// packed within 20 times the median density either way, the triangles in no chart have almost
/// no area (and their corners are copies of charted vertices), and the atlas keeps the level's own positions. Without the snap, the balls through samples
/// have charts of slivers alone (texels and no surface).
#[test]
fn slivers_do_not_upset_their_charts() {
    let within = |(low, high): (f64, f64)| low > 0.05 && high < 20.0;
    for (n, r) in [(21, 5.0), (21, 7.0), (65, 25.0)] {
        let level = marching_cubes_ball(n, r);
        let check = |sliver_edge| {
            let options = AtlasOptions {
                sliver_edge,
                ..AtlasOptions::for_texture(512)
            };
            let atlas = atlas(&level, &options).unwrap();
            let mut d = chart_densities(&atlas);
            d.sort_by(f64::total_cmp);
            let median = d[d.len() / 2];
            ((d[0] / median, d[d.len() - 1] / median), atlas)
        };
        let (range, atlas) = check(None);
        assert!(
            within(range),
            "{n} samples, r {r}: charts at {range:?} of the median"
        );
        let loose: Vec<usize> = (0..atlas.chart.len())
            .filter(|&t| atlas.chart[t] == NO_CHART)
            .collect();
        let area = |t: &[u32; 3]| {
            let [a, b, c] = t.map(|v| atlas.positions[v as usize]);
            (b - a).cross(c - a).length() as f64
        };
        let loose_area: f64 = loose.iter().map(|&t| area(&atlas.triangles[t])).sum();
        let all_area: f64 = atlas.triangles.iter().map(area).sum();
        assert!(
            loose_area < 1e-4 * all_area,
            "{n}: {loose_area} of {all_area}"
        );
        let mut charted = vec![false; atlas.positions.len()];
        for (t, &c) in atlas.triangles.iter().zip(&atlas.chart) {
            t.iter().for_each(|&v| charted[v as usize] |= c != NO_CHART);
        }
        // Every corner of a loose triangle is charted or maps to a charted corner's point.
        let charted_uv: Vec<_> = (0..charted.len())
            .filter(|&v| charted[v])
            .map(|v| atlas.uv[v])
            .collect();
        let mapped = |v: u32| charted[v as usize] || charted_uv.contains(&atlas.uv[v as usize]);
        for t in &loose {
            assert!(atlas.triangles[*t].iter().all(|&v| mapped(v)), "{t}");
        }
        for (v, &l) in atlas.level_vertex.iter().enumerate() {
            assert_eq!(atlas.positions[v], level.positions[l as usize]);
        }
        if n == 21 {
            let (unsnapped, _) = check(Some(0.0));
            assert!(
                !within(unsnapped),
                "{n} samples, r {r}: {unsnapped:?} unsnapped"
            );
        }
    }
}
