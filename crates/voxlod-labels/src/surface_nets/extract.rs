//! Each label's own mesh taken out of a [`SharedSurface`]: its triangles (turned to face out of
//! the label), its vertices compacted, and its non-manifold corners split into coincident
//! copies (the parent module's docs).
//!
//! The triangles come in order of their lowest corner plane, and a triangle whose lowest plane
//! is `k` has its corners in planes `k` and `k + 1` (the nets emit each plane's z faces, then
//! the x and y faces up to the next plane; a turned diagonal keeps both planes of its quad).
//! So a label's map from shared vertices to its own needs only two planes at a time: a
//! window of two planes' slots per thread, stamped per plane and label, which stays in cache
//! where a table over every shared vertex would miss on nearly every lookup.

use rayon::prelude::*;
use rustc_hash::FxHashMap;
use voxlod_core::{memory, TriangleMesh};

use super::{face_at, sheets, SharedSurface};
use crate::LabelsError;

/// Where labels stand in a sorted list, found in O(1): a table by label when the largest
/// label is small enough, else a hash map.
pub(crate) struct LabelSlots {
    table: Vec<u32>,
    map: FxHashMap<u32, u32>,
}

impl LabelSlots {
    /// Largest label served by the table (16 MiB of slots).
    const TABLE_LIMIT: u32 = 1 << 22;

    /// Slots of the sorted `labels`.
    pub(crate) fn new(labels: &[u32]) -> LabelSlots {
        let largest = labels.last().copied().unwrap_or(0);
        let dense = largest < Self::TABLE_LIMIT || (largest as usize) < 16 * labels.len();
        let mut slots = LabelSlots {
            table: Vec::new(),
            map: FxHashMap::default(),
        };
        if dense {
            slots.table = vec![u32::MAX; largest as usize + 1];
            for (n, &l) in labels.iter().enumerate() {
                slots.table[l as usize] = n as u32;
            }
        } else {
            slots.map = labels.iter().zip(0..).map(|(&l, n)| (l, n)).collect();
        }
        slots
    }

    /// The position of `label` in the list.
    #[inline]
    pub(crate) fn get(&self, label: u32) -> Option<usize> {
        if self.map.is_empty() {
            match self.table.get(label as usize) {
                Some(&s) if s != u32::MAX => Some(s as usize),
                _ => None,
            }
        } else {
            self.map.get(&label).map(|&s| s as usize)
        }
    }
}

impl SharedSurface {
    /// The labels other than 0 that have triangles, sorted. Cost: O(triangles), parallel.
    pub fn labels(&self) -> Vec<u32> {
        let mut labels: Vec<u32> = self
            .sides
            .par_chunks(1 << 16)
            .flat_map_iter(|chunk| {
                let mut acc: Vec<u32> = Vec::new();
                let mut last = [u32::MAX; 2];
                for s in chunk.iter().step_by(2) {
                    if *s != last {
                        acc.extend(s.iter().filter(|&&l| l != 0));
                        last = *s;
                    }
                }
                acc.sort_unstable();
                acc.dedup();
                acc
            })
            .collect();
        labels.par_sort_unstable();
        labels.dedup();
        labels
    }

    /// Whether the index-to-world transform reverses windings.
    fn flips(&self) -> bool {
        self.world.flips_handedness()
    }

    /// Per corner plane `k` (and two past the last), the first vertex in it.
    pub(crate) fn vertex_plane_starts(&self) -> Vec<usize> {
        (0..=self.dims[2] + 2)
            .map(|k| self.corners.partition_point(|c| (c[2] as usize) < k))
            .collect()
    }

    /// Per corner plane `k` (and one past the last), the first triangle whose lowest corner
    /// plane is at least `k` (module docs: triangles are in that order).
    pub(crate) fn triangle_plane_starts(&self) -> Vec<usize> {
        let low = |t: &[u32; 3]| t.iter().map(|&v| self.corners[v as usize][2]).min();
        (0..=self.dims[2] + 1)
            .into_par_iter()
            .map(|k| {
                self.triangles
                    .partition_point(|t| low(t).is_some_and(|z| (z as usize) < k))
            })
            .collect()
    }

    /// `label`'s closed, outward mesh: its triangles, wound counter-clockwise seen from outside
    /// the label, over its own compacted vertices (positions copied from the shared ones), with
    /// non-manifold corners split (module docs). Empty for a label without triangles.
    pub fn label_mesh(&self, label: u32) -> TriangleMesh {
        self.label_mesh_with_sources(label).0
    }

    /// [`SharedSurface::label_mesh`] and, per vertex of that mesh, the shared vertex it copies.
    /// The surface's triangles must be in the order the nets give them (smoothing keeps it).
    pub fn label_mesh_with_sources(&self, label: u32) -> (TriangleMesh, Vec<u32>) {
        let entries: Vec<u32> = (0..self.triangles.len() as u32)
            .filter_map(|t| {
                let [inside, outside] = self.sides[t as usize];
                (inside == label || outside == label).then_some(t << 1 | (inside != label) as u32)
            })
            .collect();
        let places = Places::new(self);
        let mut window = Window::default();
        self.extract(label, entries.len(), [&entries[..]], &places, &mut window)
    }

    /// The meshes of `labels`, in that order: the triangles sorted by label in one parallel
    /// pass, then each label taken out in parallel. Fails only when the memory limit refuses
    /// the sorted triangles (a word per label triangle) or the threads' windows. The
    /// surface's triangles must be in the order the nets give them (smoothing keeps it).
    pub fn label_meshes(&self, labels: &[u32]) -> Result<Vec<TriangleMesh>, LabelsError> {
        let mut sorted: Vec<u32> = labels.to_vec();
        sorted.sort_unstable();
        sorted.dedup();
        let slots = LabelSlots::new(&sorted);
        let by_label = ByLabel::new(self, &slots, sorted.len())?;
        let places = Places::new(self);
        let threads = rayon::current_num_threads();
        memory::check_allocation(
            "the label meshes' windows",
            memory::bytes_of::<u64>(2 * places.width) * threads as u64,
        )?;
        // One window per thread, made once.
        let pool: Vec<std::sync::Mutex<Window>> =
            (0..threads).map(|_| Default::default()).collect();
        Ok(labels
            .par_iter()
            .map(|&label| {
                let Some(s) = slots.get(label) else {
                    return TriangleMesh::default();
                };
                let at = rayon::current_thread_index().unwrap_or(0) % threads;
                let mut window = pool[at].lock().unwrap_or_else(|e| e.into_inner());
                self.extract(
                    label,
                    by_label.count(s),
                    by_label.of(s),
                    &places,
                    &mut window,
                )
                .0
            })
            .collect())
    }

    /// One label's mesh from its triangles (`entries`: triangle `t` as `t << 1`, plus 1 where
    /// the label is the triangle's outside), in increasing order over the pieces, and each
    /// vertex's shared source.
    fn extract<'e>(
        &self,
        label: u32,
        size: usize,
        pieces: impl IntoIterator<Item = &'e [u32]>,
        places: &Places,
        window: &mut Window,
    ) -> (TriangleMesh, Vec<u32>) {
        window.begin_label(places.width);
        let mut sources = Vec::new();
        let mut triangles = Vec::with_capacity(size);
        let mut singular: Vec<(u32, u32, u8, u32)> = Vec::new();
        let mut k = usize::MAX;
        for piece in pieces {
            for (n, &entry) in piece.iter().enumerate() {
                // A label's triangles lie scattered among the others': fetch ahead.
                if let Some(&later) = piece.get(n + AHEAD) {
                    prefetch(&self.triangles[(later >> 1) as usize]);
                }
                let t = (entry >> 1) as usize;
                if k == usize::MAX || t >= places.triangles[k + 1] {
                    let next = places.triangles.partition_point(|&s| s <= t) - 1;
                    window.enter(k, next);
                    k = next;
                }
                let mut tri = self.triangles[t];
                if entry & 1 == 1 {
                    tri.swap(1, 2);
                }
                let out_t = triangles.len() as u32;
                let local = std::array::from_fn(|c| {
                    let v = tri[c];
                    let id = window.local(v, k, places, self, &mut sources);
                    if id == u32::MAX {
                        singular.push((v, out_t, c as u8, t as u32));
                    }
                    id
                });
                triangles.push(local);
            }
        }
        if !singular.is_empty() {
            self.split_singular(label, &mut singular, &mut triangles, &mut sources);
        }
        let mut positions = Vec::with_capacity(sources.len());
        for (n, &v) in sources.iter().enumerate() {
            if let Some(&later) = sources.get(n + AHEAD) {
                prefetch(&self.positions[later as usize]);
            }
            positions.push(self.positions[v as usize]);
        }
        (TriangleMesh::new(positions, triangles), sources)
    }

    /// Gives each corner of the label's triangles at a singular vertex the copy of that vertex
    /// for its sheet (`sheets`), appending the copies to `sources`. `singular` holds (shared
    /// vertex, output triangle, corner, shared triangle).
    fn split_singular(
        &self,
        label: u32,
        singular: &mut [(u32, u32, u8, u32)],
        triangles: &mut [[u32; 3]],
        sources: &mut Vec<u32>,
    ) {
        singular.sort_unstable();
        for group in singular.chunk_by(|a, b| a.0 == b.0) {
            let v = group[0].0;
            let faces: Vec<(u8, u8)> = group
                .iter()
                .map(|&(_, _, _, t)| {
                    let mut tri = self.triangles[t as usize];
                    if self.sides[t as usize][0] != label {
                        tri.swap(1, 2);
                    }
                    let corners = tri.map(|w| self.corners[w as usize]);
                    face_at(self.corners[v as usize], corners, self.flips())
                })
                .collect();
            let roots = sheets(&faces);
            let mut copies: Vec<(u8, u32)> = Vec::new();
            for (&(_, out, c, _), &(face, _)) in group.iter().zip(&faces) {
                let root = roots[face as usize];
                let id = match copies.iter().find(|p| p.0 == root) {
                    Some(p) => p.1,
                    None => {
                        sources.push(v);
                        let id = sources.len() as u32 - 1;
                        copies.push((root, id));
                        id
                    }
                };
                triangles[out as usize][c as usize] = id;
            }
        }
    }
}

/// How many triangles ahead [`SharedSurface::extract`] fetches.
const AHEAD: usize = 16;

/// Asks the processor to bring `item`'s cache line in (a hint: nothing is read, nothing can
/// fault).
#[inline(always)]
fn prefetch<T>(item: &T) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: a prefetch neither reads into the program nor faults, and the pointer comes
    // from a live reference.
    unsafe {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        _mm_prefetch::<_MM_HINT_T0>(item as *const T as *const i8)
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = item;
}

/// Where the corner planes start among the vertices and the triangles.
struct Places {
    /// First vertex per corner plane (one past the last included).
    vertices: Vec<usize>,
    /// First triangle per lowest corner plane (one past the last included).
    triangles: Vec<usize>,
    /// Most vertices in one plane.
    width: usize,
}

impl Places {
    fn new(surface: &SharedSurface) -> Places {
        let vertices = surface.vertex_plane_starts();
        let width = vertices.windows(2).map(|w| w[1] - w[0]).max().unwrap_or(0);
        Places {
            vertices,
            triangles: surface.triangle_plane_starts(),
            width,
        }
    }
}

/// A label's map from shared vertices to its own over two corner planes (module docs): slot
/// `(k mod 2) · width + (v − first vertex of k)` holds the stamp of plane `k` for the current
/// label (high word) and the local index (`u32::MAX` for a singular vertex, whose copies are
/// made per sheet). Vertices outside the two planes (a surface not in the nets' order) go to
/// a hash map.
#[derive(Default)]
struct Window {
    slots: Vec<u64>,
    /// Stamp of the plane held by each half.
    held: [u32; 2],
    /// Last stamp given.
    stamp: u32,
    /// Vertices outside the window, for the current label.
    stray: FxHashMap<u32, u32>,
}

impl Window {
    fn begin_label(&mut self, width: usize) {
        if self.slots.len() != 2 * width {
            self.slots = vec![0; 2 * width];
            self.stamp = 0;
        }
        self.held = [0; 2];
        self.stray.clear();
    }

    fn fresh(&mut self) -> u32 {
        if self.stamp >= u32::MAX - 1 {
            self.slots.fill(0);
            self.stamp = 0;
            self.held = [0; 2];
        }
        self.stamp += 1;
        self.stamp
    }

    /// Moves the window from planes `from, from + 1` to `to, to + 1` (`from` is `usize::MAX`
    /// at a label's first triangle).
    fn enter(&mut self, from: usize, to: usize) {
        if from != usize::MAX && to == from + 1 {
            // Plane `to` keeps its half and stamp.
            self.held[(to + 1) % 2] = self.fresh();
        } else {
            self.held[to % 2] = self.fresh();
            self.held[(to + 1) % 2] = self.fresh();
        }
    }

    /// The local index of shared vertex `v` (a triangle of lowest plane `k`), made (and its
    /// source recorded) on first use; `u32::MAX` for a singular vertex.
    #[inline]
    fn local(
        &mut self,
        v: u32,
        k: usize,
        places: &Places,
        surface: &SharedSurface,
        sources: &mut Vec<u32>,
    ) -> u32 {
        let at = v as usize;
        let plane = if at < places.vertices[k + 1] {
            k
        } else {
            k + 1
        };
        let first = places.vertices[plane];
        if at < first || at >= places.vertices[plane + 1] {
            return self.stray(v, surface, sources);
        }
        let index = (plane % 2) * (self.slots.len() / 2) + (at - first);
        let stamp = self.held[plane % 2];
        let slot = &mut self.slots[index];
        if (*slot >> 32) as u32 == stamp {
            return *slot as u32;
        }
        let id = if surface.flags[at].is_singular() {
            u32::MAX
        } else {
            sources.push(v);
            sources.len() as u32 - 1
        };
        *slot = (stamp as u64) << 32 | id as u64;
        id
    }

    fn stray(&mut self, v: u32, surface: &SharedSurface, sources: &mut Vec<u32>) -> u32 {
        *self.stray.entry(v).or_insert_with(|| {
            if surface.flags[v as usize].is_singular() {
                u32::MAX
            } else {
                sources.push(v);
                sources.len() as u32 - 1
            }
        })
    }
}

/// Every asked label's triangles, as `t << 1` plus 1 where the label is the outside, sorted
/// by label within each of a few chunks of the triangles (a counting sort per chunk, the
/// chunks in parallel). A label's list is its pieces in chunk order.
struct ByLabel {
    /// Per chunk: per label slot (and one past), the start of its piece in `entries`.
    offsets: Vec<Vec<u32>>,
    entries: Vec<Vec<u32>>,
}

impl ByLabel {
    fn new(
        surface: &SharedSurface,
        slots: &LabelSlots,
        labels: usize,
    ) -> Result<ByLabel, LabelsError> {
        let n = surface.triangles.len();
        let chunks = (4 * rayon::current_num_threads())
            .min(n.div_ceil(1 << 16))
            .max(1);
        let size = n.div_ceil(chunks).max(1);
        memory::check_allocation(
            "the label meshes' triangle lists",
            memory::bytes_of::<u32>(n * 2) + memory::bytes_of::<u32>((labels + 1) * chunks),
        )?;
        let pieces: Vec<(Vec<u32>, Vec<u32>)> = (0..chunks)
            .into_par_iter()
            .map(|c| {
                let range = (c * size).min(n)..((c + 1) * size).min(n);
                let sides = &surface.sides[range.clone()];
                let mut offsets = vec![0u32; labels + 1];
                let mut last = ([u32::MAX; 2], [None, None]);
                for s in sides {
                    if *s != last.0 {
                        last = (*s, s.map(|l| slots.get(l)));
                    }
                    last.1.iter().flatten().for_each(|&i| offsets[i + 1] += 1);
                }
                for i in 0..labels {
                    offsets[i + 1] += offsets[i];
                }
                let mut cursor = offsets.clone();
                let mut entries = vec![0u32; offsets[labels] as usize];
                last = ([u32::MAX; 2], [None, None]);
                for (t, s) in range.zip(sides) {
                    if *s != last.0 {
                        last = (*s, s.map(|l| slots.get(l)));
                    }
                    for (side, i) in last.1.iter().enumerate() {
                        if let Some(&i) = i.as_ref() {
                            entries[cursor[i] as usize] = (t as u32) << 1 | side as u32;
                            cursor[i] += 1;
                        }
                    }
                }
                (offsets, entries)
            })
            .collect();
        let (offsets, entries) = pieces.into_iter().unzip();
        Ok(ByLabel { offsets, entries })
    }

    /// The number of triangles of the label in slot `s`.
    fn count(&self, s: usize) -> usize {
        self.offsets
            .iter()
            .map(|o| (o[s + 1] - o[s]) as usize)
            .sum()
    }

    /// The pieces of the label in slot `s`, in order.
    fn of(&self, s: usize) -> impl Iterator<Item = &[u32]> + '_ {
        self.offsets
            .iter()
            .zip(&self.entries)
            .map(move |(o, e)| &e[o[s] as usize..o[s + 1] as usize])
    }
}
