//! Each vertex's triangles while [`super::clean_mesh`] edits the mesh, in little memory: the
//! raw mesh's lists packed in one array (the triangles around each vertex in ascending order),
//! entries crossed out when a triangle leaves a vertex, and the few triangles a vertex gains
//! (by a collapse or a flip) in a side list. Dead triangles stay listed and are skipped by the
//! caller. About 14 bytes per triangle, against 28 for a vector per vertex.

use rustc_hash::FxHashMap;
use voxlod_core::topology::Incidence;

/// A crossed-out entry.
const GONE: u32 = u32::MAX;

/// The triangles around each vertex: the raw ones, then those gained, in the order gained.
pub(super) struct Fans {
    /// Where each vertex's raw list starts in `raw` (one more entry than vertices).
    start: Vec<u32>,
    /// The raw lists, one after another.
    raw: Vec<u32>,
    /// Triangles gained, per vertex that gained any.
    gained: FxHashMap<u32, Vec<u32>>,
}

impl Fans {
    /// The lists of `triangles` over `vertices` vertices, by a counting sort.
    pub(super) fn new(triangles: &[[u32; 3]], vertices: usize) -> Fans {
        let (start, raw) = Incidence::new(triangles, vertices).into_parts();
        Fans {
            start,
            raw,
            gained: FxHashMap::default(),
        }
    }

    /// The triangles listed at `v` (live or dead), raw ones first.
    pub(super) fn of(&self, v: u32) -> impl Iterator<Item = u32> + '_ {
        let (from, to) = (self.start[v as usize], self.start[v as usize + 1]);
        let gained = self.gained.get(&v).map(Vec::as_slice).unwrap_or(&[]);
        (self.raw[from as usize..to as usize].iter())
            .chain(gained)
            .copied()
            .filter(|&t| t != GONE)
    }

    /// `t` now has `v` as a corner.
    pub(super) fn push(&mut self, v: u32, t: u32) {
        self.gained.entry(v).or_default().push(t);
    }

    /// Appends `triangles` to `v`'s list.
    pub(super) fn extend(&mut self, v: u32, triangles: &[u32]) {
        if !triangles.is_empty() {
            self.gained
                .entry(v)
                .or_default()
                .extend_from_slice(triangles);
        }
    }

    /// `t` no longer has `v` as a corner.
    pub(super) fn remove(&mut self, v: u32, t: u32) {
        let (from, to) = (self.start[v as usize], self.start[v as usize + 1]);
        for slot in &mut self.raw[from as usize..to as usize] {
            if *slot == t {
                *slot = GONE;
            }
        }
        if let Some(list) = self.gained.get_mut(&v) {
            list.retain(|&x| x != t);
        }
    }

    /// `v` has no triangles any more.
    pub(super) fn clear(&mut self, v: u32) {
        let (from, to) = (self.start[v as usize], self.start[v as usize + 1]);
        self.raw[from as usize..to as usize].fill(GONE);
        self.gained.remove(&v);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// Random pushes, removals and clears give the lists that a vector per vertex gives, in
    /// the same order.
    #[test]
    fn fans_list_what_vectors_per_vertex_list() {
        let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(12);
        let vertices = 40u32;
        let triangles: Vec<[u32; 3]> = (0..100)
            .map(|_| {
                let a = rng.random_range(0..vertices - 2);
                [
                    a,
                    a + 1 + rng.random_range(0..1),
                    vertices - 1 - rng.random_range(0..a.min(3) + 1),
                ]
            })
            .collect();
        let mut fans = Fans::new(&triangles, vertices as usize);
        let mut model: Vec<Vec<u32>> = vec![Vec::new(); vertices as usize];
        for (t, tri) in triangles.iter().enumerate() {
            for &v in tri {
                model[v as usize].push(t as u32);
            }
        }
        for _ in 0..2000 {
            let v = rng.random_range(0..vertices);
            let t = rng.random_range(0..100u32);
            match rng.random_range(0..10) {
                0..=3 => {
                    fans.push(v, t);
                    model[v as usize].push(t);
                }
                4..=7 => {
                    fans.remove(v, t);
                    model[v as usize].retain(|&x| x != t);
                }
                8 => {
                    let more = [t, (t + 7) % 100];
                    fans.extend(v, &more);
                    model[v as usize].extend(more);
                }
                _ => {
                    fans.clear(v);
                    model[v as usize].clear();
                }
            }
            let w = rng.random_range(0..vertices);
            assert_eq!(fans.of(w).collect::<Vec<_>>(), model[w as usize]);
        }
        for v in 0..vertices {
            assert_eq!(fans.of(v).collect::<Vec<_>>(), model[v as usize]);
        }
    }
}
