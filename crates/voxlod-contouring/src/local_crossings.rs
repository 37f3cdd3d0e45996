//! The guard of [`crate::clean_mesh`]: whether a proposed triangle would cross a triangle
//! nearby, so that no collapse, flip or move makes the mesh intersect itself (two sheets of a
//! thin part can lie closer than the distance a cleaning step moves a vertex).
//!
//! Beyond the paper. Triangles are bucketed by centroid on a grid of two cells (a
//! marching-cubes triangle lies in one cell, and cleaning moves vertices by a fraction of one),
//! and a proposed triangle is tested against the triangles of the 27 buckets around its own:
//! an edge of one that is not incident to a vertex the two share must not meet the other,
//! decided by the signs of `f64` orientation determinants, a zero counting as meeting (the
//! guard refuses what it cannot rule out). Pairs whose bounding boxes lie apart (by more than
//! a millionth of a cell, far above the determinants' rounding) are ruled out first, which is
//! most pairs in the 27 buckets. Bucket numbers come from a dense two-level table
//! (`bucket_index.rs`), and the lists of a search are gathered before they are scanned, so that
//! their cache misses overlap. Cost: O(1) per test on a marching-cubes mesh.

use glam::DVec3;

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

fn bounds(p: [DVec3; 3]) -> (DVec3, DVec3) {
    (p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]))
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
}

impl Buckets {
    /// Buckets of two cells holding triangles `0..count`, whose corners are `corners(t)`; each
    /// list holds its triangles in ascending order and is allocated to size.
    pub(crate) fn new(cell: f64, count: usize, corners: impl Fn(usize) -> [DVec3; 3]) -> Buckets {
        let size = 2.0 * cell;
        let (mut lo, mut hi) = ([i64::MAX; 3], [i64::MIN; 3]);
        for t in 0..count {
            let key = key_of(size, centroid(corners(t)));
            lo = [0, 1, 2].map(|a| lo[a].min(key[a]));
            hi = [0, 1, 2].map(|a| hi[a].max(key[a]));
        }
        let mut number = BucketIndex::new(lo, hi);
        let mut sizes: Vec<u32> = Vec::new();
        let mut keys: Vec<[i64; 3]> = Vec::new();
        let bucket_of: Vec<u32> = (0..count)
            .map(|t| {
                let fresh = keys.len() as u32;
                let key = key_of(size, centroid(corners(t)));
                let b = number.get_or_insert(key, fresh);
                if b == fresh {
                    sizes.push(0);
                    keys.push(key);
                }
                sizes[b as usize] += 1;
                b
            })
            .collect();
        let mut lists: Vec<Vec<Entry>> = (sizes.iter())
            .map(|&n| Vec::with_capacity(n as usize))
            .collect();
        for (t, &b) in bucket_of.iter().enumerate() {
            lists[b as usize].push(Entry::new(t as u32, corners(t)));
        }
        Buckets {
            size,
            number,
            keys,
            lists,
            bucket_of,
        }
    }

    /// The distance below which two triangles' boxes count as touching for
    /// [`triangles_meet`]: a millionth of a cell.
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
    /// turn. `visit(key)` is told every bucket read.
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
        // The box around every proposed triangle: a bucketed triangle apart from it is apart
        // from each of them, so its pairs are ruled out at once (the pairs left, and the order
        // in which `meets` sees them, are those of the test against each box).
        let block_box = (boxes[..proposed.len()].iter())
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), b| {
                (lo.min(b.0), hi.max(b.1))
            });
        // The buckets are gathered [`NEAR`] at a time, their lists' first entries loaded
        // together (so that their cache misses overlap), then scanned in the same order.
        let boxes = &boxes[..proposed.len()];
        let mut scan = |near: &[([i64; 3], u32, &[Entry])]| {
            near.iter().any(|&(key, around, list)| {
                visit(key);
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

/// Sign of the volume of the tetrahedron `a b c d` (+1, -1 or 0).
fn side(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
    let volume = (b - a).cross(c - a).dot(d - a);
    if volume > 0.0 {
        1.0
    } else if volume < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// Segment `p q` meets triangle `t` (touching counts).
fn segment_meets(p: DVec3, q: DVec3, t: [DVec3; 3]) -> bool {
    let (sp, sq) = (side(t[0], t[1], t[2], p), side(t[0], t[1], t[2], q));
    if sp * sq > 0.0 {
        return false;
    }
    if sp == 0.0 && sq == 0.0 {
        // Coplanar: leave it to the turn-over test around the change.
        return false;
    }
    let e = [
        side(p, q, t[0], t[1]),
        side(p, q, t[1], t[2]),
        side(p, q, t[2], t[0]),
    ];
    !(e.iter().any(|&s| s > 0.0) && e.iter().any(|&s| s < 0.0))
}

/// Two boxes lie apart along some axis by more than `margin`.
fn boxes_apart((a_lo, a_hi): (DVec3, DVec3), (b_lo, b_hi): (DVec3, DVec3), margin: f64) -> bool {
    (a_hi + margin).cmplt(b_lo).any() || (b_hi + margin).cmplt(a_lo).any()
}

/// Triangle `a` (vertex ids `ia`) and triangle `b` (ids `ib`) meet other than at what they
/// share: an edge of either, not incident to a shared vertex, meets the other. Triangles whose
/// boxes lie apart by more than `margin` cannot meet, and are not tested further: the margin
/// (a millionth of a cell, from [`Buckets::margin`]) is far above the rounding of the
/// orientation determinants, so the answer is the full test's.
pub(crate) fn triangles_meet(
    a: [DVec3; 3],
    ia: [u32; 3],
    b: [DVec3; 3],
    ib: [u32; 3],
    margin: f64,
) -> bool {
    if boxes_apart(bounds(a), bounds(b), margin) {
        return false;
    }
    let edges_of = |p: [DVec3; 3], ip: [u32; 3], other: [u32; 3]| {
        (0..3).filter_map(move |k| {
            let (u, v) = (ip[k], ip[(k + 1) % 3]);
            (!other.contains(&u) && !other.contains(&v)).then_some((p[k], p[(k + 1) % 3]))
        })
    };
    edges_of(a, ia, ib).any(|(p, q)| segment_meets(p, q, b))
        || edges_of(b, ib, ia).any(|(p, q)| segment_meets(p, q, a))
}
