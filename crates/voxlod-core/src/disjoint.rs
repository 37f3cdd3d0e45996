//! A slice written by several threads at once, each at indices no other thread touches: the
//! shape of strided parallel passes over a volume (a column of z samples, a strip of every
//! slice) that `chunks_mut` cannot express. Used by the separable Gaussian and the direct filter
//! of scanned volumes (paper §2 and §4). Cost: O(1) per access, with a bounds check.

use std::marker::PhantomData;

/// See the module documentation. Each index must be accessed by at most one thread while the
/// slice is shared; `get` and `set` check bounds and are `unsafe` for that rule alone.
pub struct DisjointSlice<'a, T> {
    ptr: *mut T,
    len: usize,
    _borrow: PhantomData<&'a mut [T]>,
}

// SAFETY: the only access is through `get` and `set`, whose callers guarantee that no index is
// used by two threads.
unsafe impl<T: Send> Sync for DisjointSlice<'_, T> {}

impl<'a, T: Copy> DisjointSlice<'a, T> {
    /// Shares `slice` for disjoint writes; the borrow lasts as long as the wrapper.
    pub fn new(slice: &'a mut [T]) -> Self {
        DisjointSlice {
            ptr: slice.as_mut_ptr(),
            len: slice.len(),
            _borrow: PhantomData,
        }
    }

    /// Number of elements.
    pub fn len(&self) -> usize {
        self.len
    }

    /// No elements.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// # Safety
    /// No other thread may access index `i` during this call.
    #[inline]
    pub unsafe fn get(&self, i: usize) -> T {
        assert!(i < self.len);
        unsafe { *self.ptr.add(i) }
    }

    /// # Safety
    /// No other thread may access index `i` during this call.
    #[inline]
    pub unsafe fn set(&self, i: usize, value: T) {
        assert!(i < self.len);
        unsafe { *self.ptr.add(i) = value }
    }

    /// The run `i..i + n` as a mutable slice.
    ///
    /// # Safety
    /// No other thread may access any index of the run while the returned slice lives.
    #[inline]
    #[allow(clippy::mut_from_ref)]
    pub unsafe fn run_mut(&self, i: usize, n: usize) -> &mut [T] {
        assert!(i.checked_add(n).is_some_and(|end| end <= self.len));
        unsafe { std::slice::from_raw_parts_mut(self.ptr.add(i), n) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rayon::prelude::*;

    #[test]
    fn threads_write_their_own_columns() {
        let (rows, cols) = (64, 37);
        let mut data = vec![0u32; rows * cols];
        let shared = DisjointSlice::new(&mut data);
        (0..cols).into_par_iter().for_each(|c| {
            for r in 0..rows {
                // SAFETY: column c belongs to this task alone.
                unsafe { shared.set(r * cols + c, (r * 1000 + c) as u32) };
            }
        });
        assert!(data
            .iter()
            .enumerate()
            .all(|(i, &v)| v == ((i / cols) * 1000 + i % cols) as u32));
    }
}
