//! The polygon that remains during ear clipping: a doubly linked ring over the corners, the
//! grid of its reflex corners, and the corners taken out for lying on a straight line.
//!
//! A corner whose neighbours are on a straight line through it (within a relative 1e-12) is
//! never an ear, blocks only the ears whose edges run along that line, and makes every ear
//! test near it look at it. Such corners are taken out of the ring as soon as they appear
//! (at the start, or when cutting an ear straightens a corner) and put back at the end by
//! splitting the triangle that holds their edge (`reinsert_collinear` in the parent module).
//! That keeps the count at n - 2 and every triangle of a simple polygon non-degenerate, and it
//! is what keeps a long straight run (a comb's back once its teeth are cut) from making each
//! later ear test scan it.

use glam::DVec2;

use super::reflex_grid::ReflexGrid;
use super::{turn, Rule};

/// Relative tolerance for a corner to count as lying on the line between its neighbours.
const STRAIGHT: f64 = 1e-12;

pub(super) struct Ring<'a> {
    p: &'a [DVec2],
    pub(super) prev: Vec<usize>,
    pub(super) next: Vec<usize>,
    in_ring: Vec<bool>,
    pub(super) remaining: usize,
    reflex: ReflexGrid,
    /// Corners taken out as `[u, v, w]`: `v` on the straight line from `u` to `w`.
    pub(super) collinear: Vec<[usize; 3]>,
    /// Corners, rows and cells looked at so far.
    pub(super) work: u64,
    /// The work allowed. A simple polygon of real data stays far below it; a self-intersecting
    /// or adversarial face that reaches it has the rest of its ring split as a fan, so that no
    /// face holds the reader up for long.
    pub(super) work_limit: u64,
}

impl<'a> Ring<'a> {
    pub(super) fn new(p: &'a [DVec2]) -> Ring<'a> {
        let n = p.len();
        let mut ring = Ring {
            p,
            prev: (0..n).map(|i| (i + n - 1) % n).collect(),
            next: (0..n).map(|i| (i + 1) % n).collect(),
            in_ring: vec![true; n],
            remaining: n,
            reflex: ReflexGrid::new(p, n / 2),
            collinear: Vec::new(),
            work: 0,
            work_limit: n as u64 * (32 + 2 * (n as f64).sqrt() as u64) + (1 << 22),
        };
        for b in 0..n {
            ring.settle(b);
        }
        ring
    }

    /// A corner still in the ring.
    pub(super) fn first(&self) -> usize {
        self.live(0)
    }

    /// `v`, or if it was taken out, the first corner after it that is still in the ring.
    pub(super) fn live(&self, mut v: usize) -> usize {
        while !self.in_ring[v] {
            v = self.next[v];
        }
        v
    }

    fn turn_at(&self, b: usize) -> f64 {
        turn(self.p[self.prev[b]], self.p[b], self.p[self.next[b]])
    }

    /// Whether `b` lies on the straight line between its neighbours, between them.
    fn is_straight(&self, b: usize) -> bool {
        let (a, c) = (self.p[self.prev[b]], self.p[self.next[b]]);
        let (ab, bc) = (self.p[b] - a, c - self.p[b]);
        self.turn_at(b).abs() <= STRAIGHT * ab.length() * bc.length() && ab.dot(bc) > 0.0
    }

    /// Takes `b` out if it is straight (then its neighbours in turn), else files it as reflex
    /// or not.
    fn settle(&mut self, b: usize) {
        let mut pending = vec![b];
        while let Some(b) = pending.pop() {
            if !self.in_ring[b] {
                continue;
            }
            if self.remaining > 3 && self.is_straight(b) {
                let (a, c) = (self.prev[b], self.next[b]);
                self.unlink(b);
                self.collinear.push([a, b, c]);
                pending.extend([a, c]);
            } else if self.turn_at(b) < 0.0 {
                self.reflex.insert(b, self.p[b]);
            } else {
                self.reflex.remove(b, self.p[b]);
            }
        }
    }

    fn unlink(&mut self, b: usize) {
        let (a, c) = (self.prev[b], self.next[b]);
        self.next[a] = c;
        self.prev[c] = a;
        self.in_ring[b] = false;
        self.reflex.remove(b, self.p[b]);
        self.remaining -= 1;
    }

    /// Whether `b` is an ear: convex, and no reflex corner in (`Strict`: or on) its triangle.
    pub(super) fn is_ear(&mut self, b: usize, rule: Rule) -> bool {
        let (a, c) = (self.prev[b], self.next[b]);
        let (pa, pb, pc) = (self.p[a], self.p[b], self.p[c]);
        if turn(pa, pb, pc) <= 0.0 {
            return false;
        }
        let p = self.p;
        let blocked = self
            .reflex
            .any_in_triangle([pa, pb, pc], &mut self.work, |r| {
                // A corner repeating one of the ear's corners does not block it.
                if r == a || r == b || r == c || p[r] == pa || p[r] == pb || p[r] == pc {
                    return false;
                }
                let q = p[r];
                let s = [turn(pa, pb, q), turn(pb, pc, q), turn(pc, pa, q)];
                match rule {
                    Rule::Strict => s.iter().all(|&x| x >= 0.0),
                    Rule::Relaxed => s.iter().all(|&x| x > 0.0),
                }
            });
        !blocked
    }

    /// Whether the triangle at `b` covers only a few cells of the grid.
    pub(super) fn is_small_ear(&self, b: usize) -> bool {
        let t = [self.p[self.prev[b]], self.p[b], self.p[self.next[b]]];
        self.reflex.cells_under_box(t) <= 64
    }

    /// Cuts the ear at `b`, returning its triangle.
    pub(super) fn cut(&mut self, b: usize) -> [usize; 3] {
        let (a, c) = (self.prev[b], self.next[b]);
        self.unlink(b);
        self.settle(a);
        self.settle(c);
        [a, b, c]
    }

    /// The corner to cut when no textbook ear exists: a relaxed ear if there is one, otherwise
    /// the corner that turns most to the left.
    pub(super) fn fallback_ear(&mut self, start: usize) -> usize {
        let mut b = start;
        for _ in 0..self.remaining {
            if self.is_ear(b, Rule::Relaxed) {
                return b;
            }
            b = self.next[b];
        }
        self.work += self.remaining as u64;
        let mut best = start;
        let mut best_turn = f64::NEG_INFINITY;
        for _ in 0..self.remaining {
            let t = self.turn_at(b);
            if t > best_turn {
                best_turn = t;
                best = b;
            }
            b = self.next[b];
        }
        best
    }

    /// Splits what remains of the ring as a fan from `from`, and empties it.
    pub(super) fn fan_rest(&mut self, from: usize, triangles: &mut Vec<[usize; 3]>) {
        let mut b = self.next[from];
        while self.next[b] != from {
            triangles.push([from, b, self.next[b]]);
            b = self.next[b];
        }
        self.remaining = 0;
    }
}
