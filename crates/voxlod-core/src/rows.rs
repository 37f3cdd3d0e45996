//! Lists of values by row (a vertex's triangles, a triangle's neighbours), kept one after
//! another in one vector with where each row starts: compressed rows, made by a counting sort.
//! Cost: two passes over the entries, O(rows + entries) memory in two allocations.

/// Each row's values, one row after another (module docs).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Rows<T> {
    /// Where each row starts in `values` (one more entry than rows).
    starts: Vec<u32>,
    values: Vec<T>,
}

impl<T: Copy + Default> Rows<T> {
    /// `rows` rows holding the `(row, value)` pairs that `entries` gives, each row's values in
    /// the order given. `entries` is called twice (counting, then filling) and must give the
    /// same pairs both times, every row below `rows`.
    ///
    /// ```
    /// use voxlod_core::rows::Rows;
    ///
    /// let rows = Rows::new(3, || [(2, 'a'), (0, 'b'), (2, 'c')].into_iter());
    /// assert_eq!((rows.row(0), rows.row(1), rows.row(2)), (&['b'][..], &[][..], &['a', 'c'][..]));
    /// ```
    pub fn new<I: Iterator<Item = (u32, T)>>(rows: usize, entries: impl Fn() -> I) -> Rows<T> {
        // Internal iteration (`for_each`): a flattened iterator runs as nested loops.
        let mut starts = vec![0u32; rows + 1];
        entries().for_each(|(row, _)| starts[row as usize + 1] += 1);
        for r in 0..rows {
            starts[r + 1] += starts[r];
        }
        let mut next = starts.clone();
        let mut values = vec![T::default(); starts[rows] as usize];
        entries().for_each(|(row, value)| {
            let at = &mut next[row as usize];
            values[*at as usize] = value;
            *at += 1;
        });
        Rows { starts, values }
    }

    /// How many rows there are.
    pub fn rows(&self) -> usize {
        self.starts.len() - 1
    }

    /// The values of row `r`.
    #[inline]
    pub fn row(&self, r: usize) -> &[T] {
        &self.values[self.starts[r] as usize..self.starts[r + 1] as usize]
    }

    /// Where each row starts (one more entry than rows), and the rows one after another.
    pub fn into_parts(self) -> (Vec<u32>, Vec<T>) {
        (self.starts, self.values)
    }
}
