//! The triangles that [`super::clean_mesh`]'s steps changed since each kind of scan for
//! candidates last ran (module `defects`): a step that renames or moves a triangle's corner
//! notes it as it re-buckets the triangle ([`super::work::Work::rebucket`]). Beyond the paper.
//! Cost: O(1) per note, O(K) per take for K noted triangles; one byte per triangle.

/// A note that a triangle changed since the last scan of short edges.
pub(super) const FOR_EDGES: u8 = 1;
/// A note that a triangle changed since the last scan of small triangles.
pub(super) const FOR_SMALL: u8 = 2;

/// The triangles changed since each kind of scan last ran.
pub(super) struct Changes {
    /// Per triangle: which scans have not seen its change yet.
    notes: Vec<u8>,
    /// The triangles with a note, each once.
    noted: Vec<u32>,
}

impl Changes {
    pub(super) fn new(triangles: usize) -> Changes {
        Changes {
            notes: vec![0; triangles],
            noted: Vec::new(),
        }
    }

    /// Triangle `t` changed (its corners were renamed or moved).
    pub(super) fn note(&mut self, t: u32) {
        let note = &mut self.notes[t as usize];
        if *note == 0 {
            self.noted.push(t);
        }
        *note = FOR_EDGES | FOR_SMALL;
    }

    /// The triangles changed since the last `take` of `kind`, whose notes of `kind` are cleared.
    pub(super) fn take(&mut self, kind: u8) -> Vec<u32> {
        let notes = &mut self.notes;
        let taken: Vec<u32> = (self.noted.iter().copied())
            .filter(|&t| notes[t as usize] & kind != 0)
            .collect();
        for &t in &taken {
            notes[t as usize] &= !kind;
        }
        self.noted.retain(|&t| notes[t as usize] != 0);
        taken
    }
}
