//! The two passes of [`super::clean_mesh`] (short edges collapsed, small triangles fixed), run
//! either one step at a time or speculatively on all threads with the same result.
//!
//! Which steps happen depends on their order (shortest edge first, then triangles in order):
//! a step is refused when an earlier one moved its vertices or put a triangle in its way. The
//! speculative run keeps that order. It takes the next batch of candidates, makes every
//! candidate's decision in parallel on the mesh as it stands (a decision only reads the mesh,
//! and notes the box of guard buckets it read: every triangle around the vertices it looks at
//! and every bucket the crossing guard searched), then applies the decisions one by one in
//! order. Each applied step marks the buckets of the triangles it changed, before and after;
//! a later candidate of the batch whose box holds a marked bucket is decided again, on the
//! mesh as it now stands, exactly as the one-at-a-time run would. A candidate whose box holds
//! none read nothing that changed, so its decision is the one the one-at-a-time run makes:
//! everything a decision reads (a vertex's triangles, their corners, whether a vertex moved in
//! this pass, the guard's triangles) belongs to a triangle in a bucket of its box, and every
//! step marks every triangle it changes. The tests compare both runs bit for bit.

use rayon::prelude::*;
use rustc_hash::FxHashSet;

use super::steps::{apply, changed_by, decide_collapse, decide_fix, Step};
use super::work::{KeyBox, Work};

/// How the passes run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Schedule {
    /// One candidate at a time: the reference.
    OneAtATime,
    /// Batches of decisions made in parallel, then applied in order; the batch's size, or 0
    /// for one in proportion to the guard's buckets.
    Speculative(usize),
}

impl Schedule {
    /// Speculative when there is more than one thread.
    pub(super) fn for_threads() -> Schedule {
        if rayon::current_num_threads() > 1 {
            Schedule::Speculative(0)
        } else {
            Schedule::OneAtATime
        }
    }
}

/// The candidates decided in parallel at once: few enough beside the buckets that most
/// decisions of a batch stay valid (a batch of `B` candidates spread over `N` buckets has about
/// `B² · 64 / N` pairs within reach of each other).
fn batch_size(work: &Work, schedule: Schedule) -> usize {
    match schedule {
        Schedule::Speculative(0) | Schedule::OneAtATime => {
            (work.buckets.count() / 256).clamp(32, 2048)
        }
        Schedule::Speculative(size) => size,
    }
}

/// Buckets changed by the steps applied in the current batch.
#[derive(Default)]
struct Marks {
    buckets: FxHashSet<[i64; 3]>,
}

impl Marks {
    fn hit(&self, reads: &KeyBox) -> bool {
        !self.buckets.is_empty() && reads.keys().any(|k| self.buckets.contains(&k))
    }

    /// Applies `step`, marking the buckets of what it changes before and after; returns the
    /// triangles changed.
    fn apply(&mut self, work: &mut Work, step: Step) -> Vec<u32> {
        let changed = changed_by(work, &step);
        for &t in &changed {
            self.buckets.insert(work.buckets.key_of_triangle(t));
        }
        apply(work, step);
        for &t in &changed {
            self.buckets.insert(work.buckets.key_of_triangle(t));
        }
        changed
    }
}

/// One pass of short-edge collapses over `edges` (`(length, a, b)`, shortest first, from
/// `defects.rs`); returns how many.
pub(super) fn collapse_short_edges(
    work: &mut Work,
    edges: &[(f64, u32, u32)],
    schedule: Schedule,
) -> usize {
    let decide = |work: &Work, a: u32, b: u32, reads: &mut KeyBox| {
        decide_collapse(work, a, b, reads).map(|to| Step::Collapse { a, b, to })
    };
    let mut count = 0;
    if schedule == Schedule::OneAtATime {
        for &(_, a, b) in edges {
            if let Some(step) = decide(work, a, b, &mut KeyBox::default()) {
                apply(work, step);
                count += 1;
            }
        }
        return count;
    }
    let batch = batch_size(work, schedule);
    let mut marks = Marks::default();
    for chunk in edges.chunks(batch) {
        let decisions: Vec<(Option<Step>, KeyBox)> = chunk
            .par_iter()
            .map(|&(_, a, b)| {
                let mut reads = KeyBox::default();
                let step = decide(work, a, b, &mut reads);
                work.note_fan(a, &mut reads);
                work.note_fan(b, &mut reads);
                (step, reads)
            })
            .collect();
        marks.buckets.clear();
        for (&(_, a, b), (step, reads)) in chunk.iter().zip(decisions) {
            let step = if marks.hit(&reads) {
                decide(work, a, b, &mut KeyBox::default())
            } else {
                step
            };
            if let Some(step) = step {
                marks.apply(work, step);
                count += 1;
            }
        }
    }
    count
}

/// A step decided on (or none), and the box of buckets the decision read.
type Decision = (Option<Step>, KeyBox);

/// How many small triangles were fixed in each way: flips, collapses, relaxed corners.
pub(super) type FixCounts = [usize; 3];

fn count(counts: &mut FixCounts, step: &Step) {
    match step {
        Step::Flip { .. } => counts[0] += 1,
        Step::Collapse { .. } => counts[1] += 1,
        Step::Relax { .. } => counts[2] += 1,
    }
}

/// One pass over the triangles below `limit` area, in order (a triangle that an earlier step
/// of the pass made small is fixed in its turn too). `candidates` are those below `limit` when
/// the pass starts, ascending (from `defects.rs`); with none given, one at a time looks at
/// every triangle in its turn (the reference).
pub(super) fn fix_small_triangles(
    work: &mut Work,
    limit: f64,
    schedule: Schedule,
    candidates: Option<Vec<u32>>,
) -> FixCounts {
    let mut counts = [0usize; 3];
    let small = |work: &Work, t: u32| work.surface.alive[t as usize] && work.area(t) < limit;
    let Some(candidates) = candidates else {
        for t in 0..work.surface.triangles.len() as u32 {
            if small(work, t) {
                if let Some(step) = decide_fix(work, t, &mut KeyBox::default()) {
                    count(&mut counts, &step);
                    apply(work, step);
                }
            }
        }
        return counts;
    };
    // Triangles changed in this pass after their turn came, or before it: the latter must be
    // looked at again in their turn.
    let mut changed: std::collections::BTreeSet<u32> = Default::default();
    let batch = batch_size(work, schedule);
    let mut marks = Marks::default();
    let mut start = 0;
    while start < candidates.len() || !changed.is_empty() {
        let chunk = &candidates[start..(start + batch).min(candidates.len())];
        let end = candidates.get(start + batch).copied().unwrap_or(u32::MAX);
        // `None`: not small when the batch was decided, so decided in its turn if it is then.
        let decisions: Vec<(u32, Option<Decision>)> = chunk
            .par_iter()
            .map(|&t| {
                if !small(work, t) {
                    return (t, None);
                }
                let mut reads = KeyBox::default();
                let step = decide_fix(work, t, &mut reads);
                for v in work.surface.triangles[t as usize] {
                    work.note_fan(v, &mut reads);
                }
                (t, Some((step, reads)))
            })
            .collect();
        marks.buckets.clear();
        let mut decided = decisions.into_iter().peekable();
        loop {
            // The next triangle in order: a candidate of the batch or a changed one.
            let next_changed = changed.first().copied().filter(|&t| t < end);
            let next_decided = decided.peek().map(|d| d.0);
            let t = match (next_changed, next_decided) {
                (None, None) => break,
                (Some(c), Some(d)) => c.min(d),
                (c, d) => c.or(d).unwrap_or(u32::MAX),
            };
            changed.remove(&t);
            let cached = decided.next_if(|d| d.0 == t).and_then(|d| d.1);
            if !small(work, t) {
                continue;
            }
            let step = match cached {
                Some((step, reads)) if !marks.hit(&reads) => step,
                _ => decide_fix(work, t, &mut KeyBox::default()),
            };
            if let Some(step) = step {
                count(&mut counts, &step);
                for u in marks.apply(work, step) {
                    if u > t {
                        changed.insert(u);
                    }
                }
            }
        }
        start = (start + batch).min(candidates.len());
    }
    counts
}
