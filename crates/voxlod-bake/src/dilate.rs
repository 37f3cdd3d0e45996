//! Chart looks pushed into the gutters, so that bilinear filtering and mipmaps read a chart's
//! own looks beyond its border instead of the background: every gutter texel within reach
//! copies the covered texel nearest to it, found by propagating sources outward from the
//! charts (Danielsson's vector propagation, 1980, in sweeps over the texels that changed: a
//! texel takes the nearest of its own and its 8 neighbours' sources; exact but for rare
//! texels within a texel of a tie). A gutter texel therefore carries one chart's looks, never
//! a mix of two charts'.
//!
//! Cost: O(texels reached × sweeps), the sweeps about the gutter's width, each over the
//! texels that changed in the last one; in memory one source index per texel.

use serde::{Deserialize, Serialize};

/// The texel a texel copies: itself where covered, none where out of reach.
pub const NO_SOURCE: u32 = u32::MAX;

/// How far the charts' looks spread.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Dilation {
    /// Over the whole gutter: every texel takes the nearest chart's looks.
    #[default]
    Whole,
    /// This many rings of texels (8-neighbourhood) around each chart.
    Texels(u32),
    /// Not at all.
    None,
}

/// For each texel of a `width × height` image whose texels `covered` marks, the covered
/// texel it copies ([`NO_SOURCE`] beyond the reach of `dilation`).
pub fn dilation_sources(
    covered: &[bool],
    width: usize,
    height: usize,
    dilation: Dilation,
) -> Vec<u32> {
    assert_eq!(covered.len(), width * height, "one flag per texel");
    let mut source: Vec<u32> = covered
        .iter()
        .enumerate()
        .map(|(i, &c)| if c { i as u32 } else { NO_SOURCE })
        .collect();
    let reach = match dilation {
        Dilation::Whole => usize::MAX,
        Dilation::Texels(n) => n as usize,
        Dilation::None => return source,
    };
    let grid = Grid { width, height };
    let mut changed: Vec<u32> = (0..source.len() as u32)
        .filter(|&i| covered[i as usize])
        .collect();
    while !changed.is_empty() {
        let mut candidates: Vec<u32> = changed
            .iter()
            .flat_map(|&i| grid.neighbours(i as usize))
            .filter(|&n| !covered[n])
            .map(|n| n as u32)
            .collect();
        candidates.sort_unstable();
        candidates.dedup();
        let updates: Vec<(u32, u32)> = candidates
            .iter()
            .filter_map(|&i| {
                let best = grid.nearest_offered(&source, i as usize, reach);
                (best != source[i as usize]).then_some((i, best))
            })
            .collect();
        for &(i, s) in &updates {
            source[i as usize] = s;
        }
        changed = updates.into_iter().map(|u| u.0).collect();
    }
    source
}

/// Copies each texel's source value into it: `values[i] = values[source[i]]` where the
/// source is another texel.
pub fn apply<T: Copy>(values: &mut [T], source: &[u32]) {
    for (i, &s) in source.iter().enumerate() {
        if s != NO_SOURCE && s as usize != i {
            values[i] = values[s as usize];
        }
    }
}

/// The image's shape.
struct Grid {
    width: usize,
    height: usize,
}

impl Grid {
    fn at(&self, i: usize) -> (i64, i64) {
        ((i % self.width) as i64, (i / self.width) as i64)
    }

    /// The 8-neighbours of texel `i` inside the image.
    fn neighbours(&self, i: usize) -> impl Iterator<Item = usize> {
        let (x, y) = self.at(i);
        let (w, h) = (self.width as i64, self.height as i64);
        (-1i64..=1)
            .flat_map(move |dy| (-1i64..=1).map(move |dx| (x + dx, y + dy)))
            .filter(move |&(nx, ny)| (nx, ny) != (x, y) && nx >= 0 && ny >= 0 && nx < w && ny < h)
            .map(move |(nx, ny)| (ny * w + nx) as usize)
    }

    /// Of texel `i`'s own source and its neighbours' sources, the one nearest to it within
    /// `reach` texels along each axis (the lowest index among equally near ones).
    fn nearest_offered(&self, source: &[u32], i: usize, reach: usize) -> u32 {
        let (x, y) = self.at(i);
        let within = |s: u32| {
            let (sx, sy) = self.at(s as usize);
            ((sx - x).unsigned_abs().max((sy - y).unsigned_abs()) as usize) <= reach
        };
        let distance = |s: u32| {
            let (sx, sy) = self.at(s as usize);
            (sx - x).pow(2) + (sy - y).pow(2)
        };
        std::iter::once(source[i])
            .chain(self.neighbours(i).map(|n| source[n]))
            .filter(|&s| s != NO_SOURCE && within(s))
            .min_by_key(|&s| (distance(s), s))
            .unwrap_or(NO_SOURCE)
    }
}
