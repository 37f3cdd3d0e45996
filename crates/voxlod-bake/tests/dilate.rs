//! Dilation into gutters: two charts facing each other across a gutter fill it each up to
//! the middle, with their own colours only; a limited dilation stops after its rings; point
//! charts fill the plane as their Voronoi regions.

use voxlod_bake::dilate::{apply, dilation_sources, NO_SOURCE};
use voxlod_bake::Dilation;

const RED: [u8; 4] = [255, 0, 0, 255];
const BLUE: [u8; 4] = [0, 0, 255, 255];
const EMPTY: [u8; 4] = [0; 4];

/// A 32 × 16 image: red chart on columns 0..10, blue on 22..32, a gutter between.
fn two_charts() -> (Vec<bool>, Vec<[u8; 4]>) {
    let (mut covered, mut values) = (Vec::new(), Vec::new());
    for _y in 0..16 {
        for x in 0..32 {
            covered.push(!(10..22).contains(&x));
            values.push(if x < 10 {
                RED
            } else if x >= 22 {
                BLUE
            } else {
                EMPTY
            });
        }
    }
    (covered, values)
}

#[test]
fn the_whole_gutter_takes_the_nearest_charts_colour_only() {
    let (covered, mut values) = two_charts();
    let sources = dilation_sources(&covered, 32, 16, Dilation::Whole);
    apply(&mut values, &sources);
    for (i, v) in values.iter().enumerate() {
        let x = i % 32;
        // Column 9 is red's edge, 22 blue's: up to column 15 red is nearer, from 16 blue.
        let expected = if x <= 15 { RED } else { BLUE };
        assert_eq!(*v, expected, "texel ({x}, {})", i / 32);
    }
    // Covered texels are their own sources.
    assert!(covered
        .iter()
        .enumerate()
        .all(|(i, &c)| !c || sources[i] == i as u32));
}

#[test]
fn a_limited_dilation_stops_after_its_rings() {
    let (covered, mut values) = two_charts();
    let sources = dilation_sources(&covered, 32, 16, Dilation::Texels(2));
    apply(&mut values, &sources);
    for (i, v) in values.iter().enumerate() {
        let x = i % 32;
        let expected = match x {
            0..=11 => RED,
            12..=19 => EMPTY,
            _ => BLUE,
        };
        assert_eq!(*v, expected, "texel ({x}, {})", i / 32);
        assert_eq!(sources[i] == NO_SOURCE, expected == EMPTY);
    }
    let none = dilation_sources(&covered, 32, 16, Dilation::None);
    assert_eq!(none.iter().filter(|&&s| s == NO_SOURCE).count(), 12 * 16);
}

#[test]
fn point_charts_fill_their_voronoi_regions() {
    let (w, h) = (40usize, 24usize);
    let sites = [(3usize, 4usize), (30, 20), (20, 2)];
    let mut covered = vec![false; w * h];
    for &(x, y) in &sites {
        covered[y * w + x] = true;
    }
    let sources = dilation_sources(&covered, w, h, Dilation::Whole);
    for (i, &s) in sources.iter().enumerate() {
        let (x, y) = ((i % w) as f64, (i / w) as f64);
        let d =
            |(sx, sy): (usize, usize)| ((sx as f64 - x).powi(2) + (sy as f64 - y).powi(2)).sqrt();
        let nearest = sites.iter().map(|&p| d(p)).fold(f64::INFINITY, f64::min);
        let site = sites
            .iter()
            .find(|&&(sx, sy)| sy * w + sx == s as usize)
            .unwrap_or_else(|| panic!("texel {i} copies {s}, not a chart"));
        // The sweep's choice is the nearest site, or one within a texel of as near.
        assert!(
            d(*site) <= nearest + 1.0,
            "texel ({x}, {y}) copies {site:?}"
        );
    }
}
