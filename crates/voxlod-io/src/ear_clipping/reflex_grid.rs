//! A uniform grid over the corners of a polygon that are not convex, so that the test "does
//! any corner lie in this ear?" looks only at the few corners near the ear.
//!
//! Only non-convex corners can block an ear of a simple polygon (if a corner lies in a convex
//! ear triangle, a reflex one does), and cutting ears only ever turns reflex corners convex,
//! so the set shrinks as the clipping proceeds. The grid has about one cell per corner; a
//! query visits, row by row, the cells the triangle crosses (a long thin ear at 45 degrees
//! covers few of the cells of its bounding box), or, when that box covers more cells than
//! there are corners left, the list of corners itself. Insertion and removal are
//! O(1) (swap-remove with each corner's slot remembered).

use glam::DVec2;

const ABSENT: u32 = u32::MAX;

pub(super) struct ReflexGrid {
    min: DVec2,
    /// Cells per unit length along x and y.
    scale: DVec2,
    nx: usize,
    ny: usize,
    cells: Vec<Vec<u32>>,
    /// Each corner's position in its cell, or `ABSENT`.
    cell_slot: Vec<u32>,
    members: Vec<u32>,
    member_slot: Vec<u32>,
}

impl ReflexGrid {
    /// An empty grid sized for about `expected` members over the bounding box of `points`.
    pub(super) fn new(points: &[DVec2], expected: usize) -> ReflexGrid {
        let (min, max) = points.iter().fold(
            (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
            |(lo, hi), &p| (lo.min(p), hi.max(p)),
        );
        let size = (max - min).max(DVec2::splat(f64::MIN_POSITIVE));
        let target = expected.max(1) as f64;
        // Square-ish cells, about `target` of them, at most 4 per corner along either axis.
        let cell = (size.x * size.y / target)
            .sqrt()
            .max(size.max_element() / (4.0 * target));
        let cap = (4 * points.len()).max(1) as f64;
        let nx = (size.x / cell).ceil().clamp(1.0, cap) as usize;
        let ny = (size.y / cell).ceil().clamp(1.0, cap) as usize;
        ReflexGrid {
            min,
            scale: DVec2::new(nx as f64 / size.x, ny as f64 / size.y),
            nx,
            ny,
            cells: vec![Vec::new(); nx * ny],
            cell_slot: vec![ABSENT; points.len()],
            members: Vec::new(),
            member_slot: vec![ABSENT; points.len()],
        }
    }

    fn column_row(&self, p: DVec2) -> (usize, usize) {
        let q = (p - self.min) * self.scale;
        let clamp = |v: f64, n: usize| (v.max(0.0) as usize).min(n - 1);
        (clamp(q.x, self.nx), clamp(q.y, self.ny))
    }

    fn cell_of(&self, p: DVec2) -> usize {
        let (i, j) = self.column_row(p);
        j * self.nx + i
    }

    pub(super) fn contains(&self, v: usize) -> bool {
        self.cell_slot[v] != ABSENT
    }

    pub(super) fn insert(&mut self, v: usize, p: DVec2) {
        if self.contains(v) {
            return;
        }
        let cell = self.cell_of(p);
        self.cell_slot[v] = self.cells[cell].len() as u32;
        self.cells[cell].push(v as u32);
        self.member_slot[v] = self.members.len() as u32;
        self.members.push(v as u32);
    }

    pub(super) fn remove(&mut self, v: usize, p: DVec2) {
        if !self.contains(v) {
            return;
        }
        let cell = self.cell_of(p);
        let slot = self.cell_slot[v] as usize;
        self.cells[cell].swap_remove(slot);
        if let Some(&moved) = self.cells[cell].get(slot) {
            self.cell_slot[moved as usize] = slot as u32;
        }
        self.cell_slot[v] = ABSENT;
        let slot = self.member_slot[v] as usize;
        self.members.swap_remove(slot);
        if let Some(&moved) = self.members.get(slot) {
            self.member_slot[moved as usize] = slot as u32;
        }
        self.member_slot[v] = ABSENT;
    }

    /// The columns that the triangle `t` covers in row `j`, one more on each side for
    /// rounding: the triangle cut by the row's strip, projected on x.
    fn columns_in_row(&self, t: [DVec2; 3], j: usize) -> (usize, usize) {
        let lo = t[0].min(t[1]).min(t[2]);
        let hi = t[0].max(t[1]).max(t[2]);
        let y0 = (self.min.y + j as f64 / self.scale.y).max(lo.y);
        let y1 = (self.min.y + (j + 1) as f64 / self.scale.y).min(hi.y);
        let (mut x0, mut x1) = (f64::INFINITY, f64::NEG_INFINITY);
        let mut take = |x: f64| {
            x0 = x0.min(x);
            x1 = x1.max(x);
        };
        for k in 0..3 {
            let (p, q) = (t[k], t[(k + 1) % 3]);
            if (y0..=y1).contains(&p.y) {
                take(p.x);
            }
            if p.y != q.y {
                for y in [y0, y1] {
                    if (p.y.min(q.y)..=p.y.max(q.y)).contains(&y) {
                        take(p.x + (y - p.y) * (q.x - p.x) / (q.y - p.y));
                    }
                }
            }
        }
        if x0 > x1 {
            // The strip misses the triangle (rounding at its ends): the whole box row.
            (x0, x1) = (lo.x, hi.x);
        }
        let (i0, _) = self.column_row(DVec2::new(x0, y0));
        let (i1, _) = self.column_row(DVec2::new(x1, y0));
        (i0.saturating_sub(1), (i1 + 1).min(self.nx - 1))
    }

    /// The number of cells under the bounding box of `t`.
    pub(super) fn cells_under_box(&self, t: [DVec2; 3]) -> usize {
        let (i0, j0) = self.column_row(t[0].min(t[1]).min(t[2]));
        let (i1, j1) = self.column_row(t[0].max(t[1]).max(t[2]));
        (i1 - i0 + 1) * (j1 - j0 + 1)
    }

    /// Whether `blocks` holds for any member in the cells the triangle `t` crosses (or, when
    /// those are more than there are members, any member at all); `work` counts the rows,
    /// cells and members looked at.
    pub(super) fn any_in_triangle(
        &self,
        t: [DVec2; 3],
        work: &mut u64,
        mut blocks: impl FnMut(usize) -> bool,
    ) -> bool {
        let lo = t[0].min(t[1]).min(t[2]);
        let hi = t[0].max(t[1]).max(t[2]);
        let (_, j0) = self.column_row(lo);
        let (_, j1) = self.column_row(hi);
        if j1 - j0 + 1 >= self.members.len() {
            // Fewer members than rows to look at (often none at all: a convex remainder).
            *work += self.members.len() as u64 + 1;
            return self.members.iter().any(|&v| blocks(v as usize));
        }
        let mut rows = Vec::with_capacity(j1 - j0 + 1);
        let mut cells = 0;
        for j in j0..=j1 {
            let (c0, c1) = self.columns_in_row(t, j);
            cells += c1 - c0 + 1;
            rows.push((j, c0, c1));
        }
        *work += rows.len() as u64;
        if cells > self.members.len() {
            *work += self.members.len() as u64;
            return self.members.iter().any(|&v| blocks(v as usize));
        }
        *work += cells as u64;
        for (j, c0, c1) in rows {
            for cell in &self.cells[j * self.nx + c0..=j * self.nx + c1] {
                *work += cell.len() as u64;
                if cell.iter().any(|&v| blocks(v as usize)) {
                    return true;
                }
            }
        }
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn insert_remove_and_query() {
        let points: Vec<DVec2> = (0..100)
            .map(|i| DVec2::new((i % 10) as f64, (i / 10) as f64))
            .collect();
        let mut grid = ReflexGrid::new(&points, 100);
        for (v, &p) in points.iter().enumerate() {
            grid.insert(v, p);
        }
        grid.insert(5, points[5]);
        assert_eq!(grid.members.len(), 100);
        for v in (0..100).step_by(2) {
            grid.remove(v, points[v]);
        }
        assert_eq!(grid.members.len(), 50);
        let mut work = 0;
        let mut found = Vec::new();
        let triangle = [
            DVec2::new(2.0, 2.0),
            DVec2::new(6.0, 2.0),
            DVec2::new(2.0, 6.0),
        ];
        grid.any_in_triangle(triangle, &mut work, |v| {
            found.push(v);
            false
        });
        found.sort();
        // Odd indices inside the triangle; the cells may hold a few neighbours as well.
        for v in [23, 25, 33, 43, 35] {
            assert!(found.contains(&v), "{v} in {found:?}");
        }
        assert!(found.iter().all(|v| v % 2 == 1));
        assert!(!grid.contains(22) && grid.contains(23));
    }
}
