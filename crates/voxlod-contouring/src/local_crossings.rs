//! The guard of [`crate::clean_mesh`]: whether a proposed triangle would cross a triangle
//! nearby, so that no collapse, flip or move makes the mesh intersect itself (two sheets of a
//! thin part can lie closer than the distance a cleaning step moves a vertex).
//!
//! Beyond the paper. Triangles are bucketed by centroid on a grid of two cells (a
//! marching-cubes triangle lies in one cell, and cleaning moves vertices by a fraction of one),
//! and a proposed triangle is tested against the triangles of the 27 buckets around its own:
//! an edge of one that is not incident to a vertex the two share must not meet the other,
//! decided by the signs of `f64` orientation determinants, a zero counting as meeting (the
//! guard refuses what it cannot rule out; the pair test is
//! [`voxlod_core::crossings::triangles_meet`], shared with the whole-mesh count and the quadric
//! stage). Pairs whose bounding boxes lie apart (by more than
//! a millionth of a cell, far above the determinants' rounding) are ruled out first, which is
//! most pairs in the 27 buckets; a bucket whose triangles' boxes cannot reach the proposed
//! ones (the buckets keep how far any box they listed reached beyond its bucket's cell) is not
//! read at all. Bucket numbers come from a dense two-level table
//! (`bucket_index.rs`), and the lists of a search are gathered before they are scanned, so that
//! their cache misses overlap. Cost: O(1) per test on a marching-cubes mesh; the buckets are
//! made in O(F) on all threads (keys, then each bucket's list; only the numbering is serial).

use glam::DVec3;
use rayon::prelude::*;

use voxlod_core::crossings::{bounds, boxes_apart};

use crate::bucket_index::BucketIndex;

/// A bucketed triangle and its bounding box, rounded outwards to `f32`: a box that holds the
/// exact one, so that boxes apart here are apart exactly.
#[derive(Clone, Copy)]
struct Entry {
    triangle: u32,
    lo: [f32; 3],
    hi: [f32; 3],
}

impl Entry {
    fn new(triangle: u32, corners: [DVec3; 3]) -> Entry {
        let (lo, hi) = bounds(corners);
        Entry {
            triangle,
            lo: lo.to_array().map(f32_at_most),
            hi: hi.to_array().map(f32_at_least),
        }
    }

    fn bounds(&self) -> (DVec3, DVec3) {
        let widen = |a: [f32; 3]| DVec3::from_array(a.map(f64::from));
        (widen(self.lo), widen(self.hi))
    }

    /// How far the box reaches beyond the cell of bucket `key` (buckets of `size`), along the
    /// axis where it reaches farthest; 0 when it lies inside.
    fn beyond(&self, size: f64, key: [i64; 3]) -> f64 {
        let (lo, hi) = self.bounds();
        (0..3).fold(0.0, |far: f64, a| {
            let cell = key[a] as f64 * size;
            far.max(cell - lo[a]).max(hi[a] - (cell + size))
        })
    }
}

/// The largest `f32` not above `x`.
fn f32_at_most(x: f64) -> f32 {
    let y = x as f32;
    if f64::from(y) > x {
        y.next_down()
    } else {
        y
    }
}

/// The smallest `f32` not below `x`.
fn f32_at_least(x: f64) -> f32 {
    let y = x as f32;
    if f64::from(y) < x {
        y.next_up()
    } else {
        y
    }
}

/// Triangles bucketed by centroid, with their boxes: 28 bytes per triangle in the lists and 4
/// for its bucket's number, plus a few dozen per bucket and the index's few per block
/// (`bucket_index.rs`).
pub(crate) struct Buckets {
    size: f64,
    /// The number of every bucket that ever held a triangle.
    number: BucketIndex,
    /// The key of each bucket, by number.
    keys: Vec<[i64; 3]>,
    lists: Vec<Vec<Entry>>,
    /// The bucket of each triangle.
    bucket_of: Vec<u32>,
    /// How far any box listed ever reached beyond its bucket, along any axis (never lowered).
    reach: f64,
}

impl Buckets {
    /// Buckets of two cells holding triangles `0..count`, whose corners are `corners(t)`; each
    /// list holds its triangles in ascending order and is allocated to size. The keys and the
    /// lists are made on all threads; the buckets are numbered in order of first use.
    pub(crate) fn new(
        cell: f64,
        count: usize,
        corners: impl Fn(usize) -> [DVec3; 3] + Sync,
    ) -> Buckets {
        let size = 2.0 * cell;
        let keys: Vec<[i64; 3]> = (0..count)
            .into_par_iter()
            .map(|t| key_of(size, centroid(corners(t))))
            .collect();
        let (lo, hi) = span(&keys);
        let mut number = BucketIndex::new(lo, hi);
        let mut sizes: Vec<u32> = Vec::new();
        let mut bucket_keys: Vec<[i64; 3]> = Vec::new();
        let bucket_of: Vec<u32> = (keys.iter())
            .map(|&key| {
                let fresh = bucket_keys.len() as u32;
                let b = number.get_or_insert(key, fresh);
                if b == fresh {
                    sizes.push(0);
                    bucket_keys.push(key);
                }
                sizes[b as usize] += 1;
                b
            })
            .collect();
        drop(keys);
        let (lists, reach) = fill_lists(size, &bucket_keys, &sizes, &bucket_of, corners);
        Buckets {
            size,
            number,
            keys: bucket_keys,
            lists,
            bucket_of,
            reach,
        }
    }

    /// The distance below which two triangles' boxes count as touching for
    /// [`voxlod_core::crossings::triangles_meet`]: a millionth of a cell.
    pub(crate) fn margin(&self) -> f64 {
        self.size * 0.5e-6
    }

    /// How many buckets there are.
    pub(crate) fn count(&self) -> usize {
        self.lists.len()
    }

    /// The key of the bucket around `p`.
    pub(crate) fn key(&self, p: DVec3) -> [i64; 3] {
        key_of(self.size, p)
    }

    /// The key of the bucket that holds triangle `t`.
    pub(crate) fn key_of_triangle(&self, t: u32) -> [i64; 3] {
        self.keys[self.bucket_of[t as usize] as usize]
    }

    /// Triangle `t` now has `corners`: its box is updated, and it moves to the bucket of its
    /// new centroid.
    pub(crate) fn update(&mut self, t: u32, corners: [DVec3; 3]) {
        let fresh = self.keys.len() as u32;
        let key = self.key(centroid(corners));
        let b = self.number.get_or_insert(key, fresh);
        if b == fresh {
            self.lists.push(Vec::new());
            self.keys.push(key);
        }
        let old = self.bucket_of[t as usize];
        let entry = Entry::new(t, corners);
        self.reach = self.reach.max(entry.beyond(self.size, key));
        let list = &mut self.lists[old as usize];
        if b == old {
            if let Some(slot) = list.iter_mut().find(|e| e.triangle == t) {
                *slot = entry;
            }
            return;
        }
        list.retain(|e| e.triangle != t);
        self.lists[b as usize].push(entry);
        self.bucket_of[t as usize] = b;
    }

    /// Whether `meets(k, triangle)` holds for some triangle `k` of `proposed` and some bucketed
    /// triangle in the 27 buckets around the centroid of `k` whose box is not apart from
    /// `k`'s (by [`Buckets::margin`]). These are the pairs of a search bucket by bucket around
    /// each proposed triangle, but each bucket is read once for all the proposed triangles
    /// around it: the buckets of the block that spans their neighbourhoods are visited in
    /// turn, leaving out those whose boxes cannot reach the proposed triangles' (the
    /// neighbourhood's reach is two cells beyond a centroid's bucket, a box's about one).
    /// `visit(key)` is told two opposite corners of the block of keys searched, so that the
    /// box of the keys it is told holds every bucket of the 27 around each proposed triangle
    /// that was searched.
    pub(crate) fn any_near(
        &self,
        proposed: &[[DVec3; 3]],
        mut visit: impl FnMut([i64; 3]),
        mut meets: impl FnMut(usize, u32) -> bool,
    ) -> bool {
        (proposed.chunks(BLOCK).enumerate())
            .any(|(c, block)| self.any_near_block(block, BLOCK * c, &mut visit, &mut meets))
    }

    /// [`Buckets::any_near`] for at most [`BLOCK`] proposed triangles, numbered from `first`.
    fn any_near_block(
        &self,
        proposed: &[[DVec3; 3]],
        first: usize,
        visit: &mut impl FnMut([i64; 3]),
        meets: &mut impl FnMut(usize, u32) -> bool,
    ) -> bool {
        let margin = self.margin();
        let mut keys = [[0i64; 3]; BLOCK];
        let mut boxes = [(DVec3::ZERO, DVec3::ZERO); BLOCK];
        let (mut lo, mut hi) = ([i64::MAX; 3], [i64::MIN; 3]);
        for (j, &p) in proposed.iter().enumerate() {
            keys[j] = self.key(centroid(p));
            boxes[j] = bounds(p);
            for a in 0..3 {
                lo[a] = lo[a].min(keys[j][a] - 1);
                hi[a] = hi[a].max(keys[j][a] + 1);
            }
        }
        let keys = &keys[..proposed.len()];
        visit(lo);
        visit(hi);
        // The box around every proposed triangle: a bucketed triangle apart from it is apart
        // from each of them, so its pairs are ruled out at once (the pairs left, and the order
        // in which `meets` sees them, are those of the test against each box).
        let block_box = (boxes[..proposed.len()].iter())
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), b| {
                (lo.min(b.0), hi.max(b.1))
            });
        // Only the buckets whose triangles can reach the block's box: the others hold boxes
        // apart from it, whose pairs would be ruled out one by one.
        let Some((lo, hi)) = self.reaching(lo, hi, block_box, margin) else {
            return false;
        };
        // The buckets are gathered [`NEAR`] at a time, their lists' first entries loaded
        // together (so that their cache misses overlap), then scanned in the same order.
        let boxes = &boxes[..proposed.len()];
        let mut scan = |near: &[([i64; 3], u32, &[Entry])]| {
            near.iter().any(|&(_, around, list)| {
                list.iter().any(|entry| {
                    let there = entry.bounds();
                    !boxes_apart(there, block_box, margin)
                        && (boxes.iter().enumerate()).any(|(j, &b)| {
                            around & (1 << j) != 0
                                && !boxes_apart(there, b, margin)
                                && meets(first + j, entry.triangle)
                        })
                })
            })
        };
        let mut near = [([0i64; 3], 0u32, &[] as &[Entry]); NEAR];
        let mut count = 0;
        for z in lo[2]..=hi[2] {
            for y in lo[1]..=hi[1] {
                for x in lo[0]..=hi[0] {
                    let key = [x, y, z];
                    // The proposed triangles (bit j for the j-th) whose 27 buckets hold `key`.
                    let around = (keys.iter().enumerate()).fold(0u32, |m, (j, k)| {
                        m | ((0..3).all(|a| (k[a] - key[a]).abs() <= 1) as u32) << j
                    });
                    if around == 0 {
                        continue;
                    }
                    if count == NEAR {
                        if warm_and_scan(&near, &mut scan) {
                            return true;
                        }
                        count = 0;
                    }
                    let list = (self.number.get(key)).map_or(&[][..], |b| &self.lists[b as usize]);
                    near[count] = (key, around, list);
                    count += 1;
                }
            }
        }
        warm_and_scan(&near[..count], &mut scan)
    }

    /// The keys from `lo` to `hi` (inclusive) of the buckets whose listed boxes may come within
    /// `margin` of `block` (not farther than [`Buckets::reach`] beyond their cells, with a
    /// slack far above the rounding of these sums), or `None` when there are none.
    fn reaching(
        &self,
        lo: [i64; 3],
        hi: [i64; 3],
        (block_lo, block_hi): (DVec3, DVec3),
        margin: f64,
    ) -> Option<([i64; 3], [i64; 3])> {
        let reach = self.reach + margin;
        let near = |a: usize, k: i64| {
            let cell = k as f64 * self.size;
            let slack = 1e-6 * self.size + 1e-12 * cell.abs();
            cell + self.size + reach + slack >= block_lo[a] && cell - reach - slack <= block_hi[a]
        };
        let (mut from, mut to) = (lo, hi);
        for a in 0..3 {
            from[a] = (lo[a]..=hi[a]).find(|&k| near(a, k))?;
            to[a] = (from[a]..=hi[a]).rev().find(|&k| near(a, k))?;
        }
        Some((from, to))
    }
}

/// The smallest and the largest of `keys` along each axis.
fn span(keys: &[[i64; 3]]) -> ([i64; 3], [i64; 3]) {
    let empty = || ([i64::MAX; 3], [i64::MIN; 3]);
    let join = |(lo, hi): ([i64; 3], [i64; 3]), (l, h): ([i64; 3], [i64; 3])| {
        let lo = [0, 1, 2].map(|a| lo[a].min(l[a]));
        (lo, [0, 1, 2].map(|a| hi[a].max(h[a])))
    };
    (keys.par_iter())
        .fold(empty, |span, &key| join(span, (key, key)))
        .reduce(empty, join)
}

/// The lists of the buckets numbered `0..sizes.len()` (keys `keys`, `sizes[b]` triangles
/// each), every triangle `t` in bucket `bucket_of[t]` in ascending order, and how far their
/// boxes reach beyond their buckets' cells (buckets of `size`): the triangles sorted by bucket
/// by a counting sort, then each list made on its own, on all threads.
fn fill_lists(
    size: f64,
    keys: &[[i64; 3]],
    sizes: &[u32],
    bucket_of: &[u32],
    corners: impl Fn(usize) -> [DVec3; 3] + Sync,
) -> (Vec<Vec<Entry>>, f64) {
    let mut start = Vec::with_capacity(sizes.len() + 1);
    start.push(0usize);
    for &n in sizes {
        start.push(start[start.len() - 1] + n as usize);
    }
    let mut next = start[..sizes.len()].to_vec();
    let mut order = vec![0u32; bucket_of.len()];
    for (t, &b) in bucket_of.iter().enumerate() {
        order[next[b as usize]] = t as u32;
        next[b as usize] += 1;
    }
    drop(next);
    let filled: Vec<(Vec<Entry>, f64)> = (0..sizes.len())
        .into_par_iter()
        .map(|b| {
            let list: Vec<Entry> = (order[start[b]..start[b + 1]].iter())
                .map(|&t| Entry::new(t, corners(t as usize)))
                .collect();
            let reach = (list.iter()).fold(0.0f64, |far, e| far.max(e.beyond(size, keys[b])));
            (list, reach)
        })
        .collect();
    let reach = filled.iter().fold(0.0f64, |far, f| far.max(f.1));
    (filled.into_iter().map(|f| f.0).collect(), reach)
}

/// Buckets whose lists [`Buckets::any_near`] loads together.
const NEAR: usize = 64;

/// Loads the first entry of each list in `near` (independent loads, whose misses overlap),
/// then `scan(near)`.
fn warm_and_scan<'a>(
    near: &[([i64; 3], u32, &'a [Entry])],
    scan: &mut impl FnMut(&[([i64; 3], u32, &'a [Entry])]) -> bool,
) -> bool {
    let firsts = (near.iter()).fold(0u32, |sum, n| {
        sum.wrapping_add(n.2.first().map_or(0, |e| e.triangle))
    });
    std::hint::black_box(firsts);
    scan(near)
}

/// Proposed triangles searched around at once by [`Buckets::any_near`].
const BLOCK: usize = 32;

fn key_of(size: f64, p: DVec3) -> [i64; 3] {
    (p / size).floor().as_i64vec3().to_array()
}

/// The centroid of a triangle.
pub(crate) fn centroid(p: [DVec3; 3]) -> DVec3 {
    (p[0] + p[1] + p[2]) / 3.0
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64;

    /// A triangle of about `size` around `centre`.
    fn triangle(rng: &mut Pcg64, centre: DVec3, size: f64) -> [DVec3; 3] {
        let mut corner = || {
            let d = DVec3::new(rng.random(), rng.random(), rng.random()) - DVec3::splat(0.5);
            centre + d * size
        };
        [corner(), corner(), corner()]
    }

    /// Triangles of a cell or less scattered over twelve cells, a tenth of them moved by up to
    /// two cells after bucketing (as cleaning moves them, and farther): every search of up to
    /// 40 proposed triangles tests exactly the pairs of the search bucket by bucket (every
    /// listed triangle in the 27 buckets around a proposed triangle whose box is not apart from
    /// the block's and its own), and the keys it is told span those 27 buckets.
    #[test]
    fn a_search_tests_the_pairs_of_its_27_buckets() {
        let mut rng = Pcg64::seed_from_u64(7);
        let cell = 0.5;
        let mut corners: Vec<[DVec3; 3]> = (0..4000)
            .map(|_| {
                let c = DVec3::new(rng.random(), rng.random(), rng.random()) * 6.0;
                triangle(&mut rng, c, cell)
            })
            .collect();
        let mut buckets = Buckets::new(cell, corners.len(), |t| corners[t]);
        for (t, at) in corners.iter_mut().enumerate().take(400) {
            let shift = (DVec3::new(rng.random(), rng.random(), rng.random()) - 0.5) * 4.0 * cell;
            *at = triangle(&mut rng, centroid(*at) + shift, 1.5 * cell);
            buckets.update(t as u32, *at);
        }
        let margin = buckets.margin();
        let mut pairs = 0;
        for _ in 0..400 {
            let centre = DVec3::new(rng.random(), rng.random(), rng.random()) * 6.0;
            let count = rng.random_range(1..40);
            let proposed: Vec<[DVec3; 3]> = (0..count)
                .map(|_| triangle(&mut rng, centre, 2.0 * cell))
                .collect();
            let (mut lo, mut hi) = ([i64::MAX; 3], [i64::MIN; 3]);
            let mut seen = Vec::new();
            let visit = |key: [i64; 3]| {
                lo = [0, 1, 2].map(|a| lo[a].min(key[a]));
                hi = [0, 1, 2].map(|a| hi[a].max(key[a]));
            };
            let found = buckets.any_near(&proposed, visit, |k, t| {
                seen.push((k, t));
                false
            });
            assert!(!found);
            let mut expected = Vec::new();
            for (c, block) in proposed.chunks(BLOCK).enumerate() {
                let block_box = (block.iter().map(|&p| bounds(p)))
                    .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(l, h), b| {
                        (l.min(b.0), h.max(b.1))
                    });
                for (j, &p) in block.iter().enumerate() {
                    let key = buckets.key(centroid(p));
                    assert!((0..3).all(|a| lo[a] < key[a] && key[a] < hi[a]));
                    for d in 0..27i64 {
                        let near = [
                            key[0] + d % 3 - 1,
                            key[1] + d / 3 % 3 - 1,
                            key[2] + d / 9 - 1,
                        ];
                        let Some(b) = buckets.number.get(near) else {
                            continue;
                        };
                        for e in &buckets.lists[b as usize] {
                            let there = e.bounds();
                            if !boxes_apart(there, block_box, margin)
                                && !boxes_apart(there, bounds(p), margin)
                            {
                                expected.push((BLOCK * c + j, e.triangle));
                            }
                        }
                    }
                }
            }
            seen.sort_unstable();
            expected.sort_unstable();
            assert_eq!(seen, expected);
            pairs += seen.len();
        }
        assert!(pairs > 10_000, "{pairs}");
    }
}
