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
//! most pairs in the 27 buckets. Cost: O(1) per test on a marching-cubes mesh.

use rustc_hash::FxHashMap;

use glam::DVec3;

/// A bucketed triangle and its bounding box.
#[derive(Clone, Copy)]
pub(crate) struct Entry {
    /// The triangle.
    pub(crate) triangle: u32,
    lo: DVec3,
    hi: DVec3,
}

impl Entry {
    fn new(triangle: u32, corners: [DVec3; 3]) -> Entry {
        let (lo, hi) = bounds(corners);
        Entry { triangle, lo, hi }
    }
}

fn bounds(p: [DVec3; 3]) -> (DVec3, DVec3) {
    (p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]))
}

/// Triangles bucketed by centroid, with their boxes.
pub(crate) struct Buckets {
    size: f64,
    map: FxHashMap<[i64; 3], Vec<Entry>>,
    key_of: Vec<[i64; 3]>,
}

impl Buckets {
    /// Buckets of two cells holding triangles `0..corners.len()`, given by their corners.
    pub(crate) fn new(cell: f64, corners: impl Iterator<Item = [DVec3; 3]>) -> Buckets {
        let mut buckets = Buckets {
            size: 2.0 * cell,
            map: FxHashMap::default(),
            key_of: Vec::new(),
        };
        for (t, c) in corners.enumerate() {
            let key = buckets.key(centroid(c));
            buckets
                .map
                .entry(key)
                .or_default()
                .push(Entry::new(t as u32, c));
            buckets.key_of.push(key);
        }
        buckets
    }

    /// The distance below which two triangles' boxes count as touching for
    /// [`triangles_meet`]: a millionth of a cell.
    pub(crate) fn margin(&self) -> f64 {
        self.size * 0.5e-6
    }

    fn key(&self, p: DVec3) -> [i64; 3] {
        (p / self.size).floor().as_i64vec3().to_array()
    }

    /// Triangle `t` now has `corners`: its box is updated, and it moves to the bucket of its
    /// new centroid.
    pub(crate) fn update(&mut self, t: u32, corners: [DVec3; 3]) {
        let key = self.key(centroid(corners));
        let old = self.key_of[t as usize];
        let entry = Entry::new(t, corners);
        if let Some(list) = self.map.get_mut(&old) {
            if key == old {
                if let Some(slot) = list.iter_mut().find(|e| e.triangle == t) {
                    *slot = entry;
                }
                return;
            }
            list.retain(|e| e.triangle != t);
        }
        self.map.entry(key).or_default().push(entry);
        self.key_of[t as usize] = key;
    }

    /// Whether `meets(k, triangle)` holds for some triangle `k` of `proposed` and some bucketed
    /// triangle in the 27 buckets around the centroid of `k` whose box is not apart from
    /// `k`'s (by [`Buckets::margin`]). These are the pairs of a search bucket by bucket around
    /// each proposed triangle, but each bucket is read once for all the proposed triangles
    /// around it.
    pub(crate) fn any_near(
        &self,
        proposed: &[[DVec3; 3]],
        mut meets: impl FnMut(usize, u32) -> bool,
    ) -> bool {
        let margin = self.margin();
        let keys: Vec<[i64; 3]> = proposed.iter().map(|&p| self.key(centroid(p))).collect();
        let boxes: Vec<(DVec3, DVec3)> = proposed.iter().map(|&p| bounds(p)).collect();
        let mut seen: Vec<[i64; 3]> = Vec::with_capacity(64);
        let mut around: Vec<usize> = Vec::with_capacity(proposed.len());
        for k in &keys {
            for n in 0..27 {
                let key = [k[0] + n % 3 - 1, k[1] + (n / 3) % 3 - 1, k[2] + n / 9 - 1];
                if seen.contains(&key) {
                    continue;
                }
                seen.push(key);
                let Some(list) = self.map.get(&key) else {
                    continue;
                };
                around.clear();
                around.extend(
                    (0..keys.len()).filter(|&j| (0..3).all(|a| (keys[j][a] - key[a]).abs() <= 1)),
                );
                for entry in list {
                    for &j in &around {
                        let apart = boxes_apart((entry.lo, entry.hi), boxes[j], margin);
                        if !apart && meets(j, entry.triangle) {
                            return true;
                        }
                    }
                }
            }
        }
        false
    }
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
