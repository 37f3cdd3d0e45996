//! The topology of a level, read from its inside samples alone, exactly as marching cubes will
//! contour them: handles (genus), components and cavities, and the local topological numbers of
//! one sample (Bertrand and Malandain 1994) that say what flipping it can change.
//!
//! Beyond the paper (He et al. 1995 count triangles, not handles). voxlod's marching cubes
//! (`voxlod-contouring`, `tables.rs`) calls a sample inside when `value >= iso` and, on a cube
//! face with two diagonal inside corners, separates the inside corners: inside samples connect
//! only along grid edges (6-adjacency), outside samples also across face diagonals but not
//! across a cell's body diagonal (18-adjacency). The surface is therefore the boundary of the
//! (6, 18) digital object, and its topology follows from the samples:
//!
//! - surface components `s = b0(X, 6) + b0(X̄, 18) − 1` (a closed surface with `s` components
//!   cuts space into `s + 1` regions), the exterior counting as one background component, as if
//!   the grid were padded with outside samples;
//! - the surface's Euler characteristic `χ = Σ_cells loops − crossed grid edges`: the surface
//!   is the union of one disk per loop in each cell, glued along one segment per face per pair
//!   of crossed face edges, and every crossed edge lies on four faces;
//! - total genus `s − χ/2`, which is also `b1(X)`, the number of tunnels of the inside set.
//!
//! A cell's loops number `inside pieces + outside pieces − 1` of its corners, the pieces joined
//! by cube edges (inside) and by cube edges and face diagonals (outside). The tests check all of
//! this against the meshes marching cubes makes.
//!
//! **Local numbers** of a sample x: `T6` counts the 6-components of the inside samples among
//! x's 18 neighbours that touch x's 6 face neighbours; `T̄18` the 18-components of the outside
//! samples among its 26 neighbours that touch its 18 neighbours. By Mayer–Vietoris and Alexander
//! duality, adding x to the inside with `T6 <= 1` never adds a tunnel (it can only close one,
//! enclose a cavity or start a component), and removing x with `T̄18 <= 1` never adds one either.
//! `T6 = T̄18 = 1` is the classic simple point, whose flip changes nothing.
//!
//! Cost: [`digital_topology`] is two labellings by runs ([`crate::run_components`]) and one
//! pass over the cells a row at a time, run side by side on the threads: O(N) time, and memory
//! per run of equal samples rather than per sample; [`local_numbers`] is O(1) (a search over 26
//! neighbours).

use std::sync::OnceLock;

use rayon::prelude::*;
use serde::Serialize;
use voxlod_core::{memory, Volume};

use crate::run_components::{check_samples, RunComponents};
use crate::SamplingError;

/// The topology of the surface around a set of inside samples. See the module documentation.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct DigitalTopology {
    /// Total genus of the surface: handles, tunnels through the inside set.
    pub genus: u64,
    /// Connected pieces of the inside set (6-adjacency).
    pub components: u64,
    /// Pieces of the outside set enclosed by the inside (18-adjacency), not reaching the border.
    pub cavities: u64,
    /// Euler characteristic of the surface (twice the inside set's).
    pub euler_characteristic: i64,
}

impl DigitalTopology {
    /// Closed surfaces: one per component and one per cavity.
    pub fn surfaces(&self) -> u64 {
        self.components + self.cavities
    }
}

/// The samples `>= iso` of a volume (NaN is outside), x fastest, as marching cubes decides them.
pub fn inside_samples(volume: &Volume, iso: f32) -> Result<Vec<bool>, SamplingError> {
    memory::check_allocation("the inside samples of a level", volume.grid.len() as u64)?;
    Ok(volume.as_slice().par_iter().map(|&v| v >= iso).collect())
}

/// Index of the neighbour of `p` at `offset`, or `None` outside the grid.
#[inline]
pub(crate) fn step(dims: [usize; 3], p: [usize; 3], offset: [i64; 3]) -> Option<usize> {
    let mut q = [0usize; 3];
    for a in 0..3 {
        let c = p[a] as i64 + offset[a];
        if c < 0 || c >= dims[a] as i64 {
            return None;
        }
        q[a] = c as usize;
    }
    Some(q[0] + dims[0] * (q[1] + dims[1] * q[2]))
}

#[inline]
pub(crate) fn coordinates(dims: [usize; 3], index: usize) -> [usize; 3] {
    [
        index % dims[0],
        (index / dims[0]) % dims[1],
        index / (dims[0] * dims[1]),
    ]
}

/// Labels the components of the samples equal to `value`, with 6-adjacency for inside and
/// 18-adjacency for outside. For outside samples, every one on the grid's border belongs to the
/// exterior (label 0, always counted). Returns the labels (`u32::MAX` for the other value),
/// numbered in order of each component's first sample, and the number of components. The
/// labelling is by runs ([`RunComponents`]).
pub fn label_components(
    dims: [usize; 3],
    inside: &[bool],
    value: bool,
) -> Result<(Vec<u32>, u64), SamplingError> {
    memory::check_allocation("labelling a level", memory::bytes_of::<u32>(inside.len()))?;
    let components = RunComponents::new(dims, inside, value)?;
    Ok((components.labels(), components.count()))
}

/// Outside samples enclosed by the inside set (in no path of outside samples to the border).
pub fn cavity_samples(dims: [usize; 3], inside: &[bool]) -> Result<Vec<bool>, SamplingError> {
    memory::check_allocation("the cavities of a level", inside.len() as u64)?;
    Ok(RunComponents::new(dims, inside, false)?.enclosed())
}

/// Loops of marching cubes' surface in a cell of each of the 256 corner cases (corner `c` at
/// `(c & 1, c >> 1 & 1, c >> 2 & 1)`, bit `c` set when inside).
fn cell_loops() -> &'static [u8; 256] {
    static LOOPS: OnceLock<[u8; 256]> = OnceLock::new();
    LOOPS.get_or_init(|| {
        let mut loops = [0u8; 256];
        for (case, slot) in loops.iter_mut().enumerate().take(255).skip(1) {
            *slot = (corner_pieces(case as u8, true) + corner_pieces(case as u8, false) - 1) as u8;
        }
        loops
    })
}

/// Pieces of the corners that are inside (`true`) or outside: inside corners join along cube
/// edges, outside corners along cube edges and face diagonals.
fn corner_pieces(case: u8, inside: bool) -> usize {
    let member = |c: u8| ((case >> c) & 1 == 1) == inside;
    let mut parent: [u8; 8] = [0, 1, 2, 3, 4, 5, 6, 7];
    fn root(parent: &mut [u8; 8], mut c: u8) -> u8 {
        while parent[c as usize] != c {
            c = parent[c as usize];
        }
        c
    }
    for a in 0..8u8 {
        for b in (a + 1)..8u8 {
            let differing = (a ^ b).count_ones();
            let adjacent = differing == 1 || (!inside && differing == 2);
            if adjacent && member(a) && member(b) {
                let (ra, rb) = (root(&mut parent, a), root(&mut parent, b));
                parent[ra as usize] = rb;
            }
        }
    }
    (0..8u8)
        .filter(|&c| member(c) && root(&mut parent, c) == c)
        .count()
}

/// Row `(j, k)` of `inside`, or `None` beyond the grid (the padding's outside samples).
fn sample_row(dims: [usize; 3], inside: &[bool], j: i64, k: i64) -> Option<&[bool]> {
    if j < 0 || k < 0 || j >= dims[1] as i64 || k >= dims[2] as i64 {
        return None;
    }
    let start = dims[0] * (j as usize + dims[1] * k as usize);
    Some(&inside[start..start + dims[0]])
}

/// Σ over cells of the loops, with the grid padded by one layer of outside samples. Cells are
/// taken a row at a time (the four sample rows at their corners), z layers in parallel.
fn total_loops(dims: [usize; 3], inside: &[bool]) -> i64 {
    let loops = cell_loops();
    // Corners (dy, dz) of a column of a cell: bit 2 dy + 4 dz of the case for dx = 0.
    const SPREAD: [usize; 16] = {
        let mut spread = [0usize; 16];
        let mut column = 0;
        while column < 16 {
            let mut bit = 0;
            while bit < 4 {
                if column >> bit & 1 == 1 {
                    spread[column] |= 1 << (2 * bit);
                }
                bit += 1;
            }
            column += 1;
        }
        spread
    };
    (-1..dims[2] as i64)
        .into_par_iter()
        .map(|k| {
            let mut total = 0i64;
            for j in -1..dims[1] as i64 {
                let rows = [(j, k), (j + 1, k), (j, k + 1), (j + 1, k + 1)]
                    .map(|(j, k)| sample_row(dims, inside, j, k));
                if rows.iter().all(Option::is_none) {
                    continue;
                }
                let column = |i: i64| -> usize {
                    if i < 0 || i >= dims[0] as i64 {
                        return 0;
                    }
                    (rows.iter().enumerate())
                        .map(|(b, row)| (row.is_some_and(|r| r[i as usize]) as usize) << b)
                        .sum()
                };
                let mut left = 0usize;
                for i in -1..dims[0] as i64 {
                    let right = column(i + 1);
                    total += loops[SPREAD[left] | SPREAD[right] << 1] as i64;
                    left = right;
                }
            }
            total
        })
        .sum()
}

/// Grid edges (padded as in [`total_loops`]) whose two samples disagree: the surface's vertices.
fn crossed_edges(dims: [usize; 3], inside: &[bool]) -> i64 {
    (0..dims[2] as i64)
        .into_par_iter()
        .map(|k| {
            let mut total = 0i64;
            for j in 0..dims[1] as i64 {
                let Some(row) = sample_row(dims, inside, j, k) else {
                    continue;
                };
                let next_y = sample_row(dims, inside, j + 1, k);
                let next_z = sample_row(dims, inside, j, k + 1);
                for (i, &s) in row.iter().enumerate() {
                    let next_x = row.get(i + 1).copied().unwrap_or(false);
                    let y = next_y.is_some_and(|r| r[i]);
                    let z = next_z.is_some_and(|r| r[i]);
                    total += (s != next_x) as i64 + (s != y) as i64 + (s != z) as i64;
                    // The padding below: edges from outside into the first sample of a line.
                    let first = (i == 0) as i64 + (j == 0) as i64 + (k == 0) as i64;
                    total += first * s as i64;
                }
            }
            total
        })
        .sum()
}

/// The topology of the surface marching cubes would give for `inside` (x fastest on `dims`),
/// closed at the grid's border. See the module documentation.
pub fn digital_topology(
    dims: [usize; 3],
    inside: &[bool],
) -> Result<DigitalTopology, SamplingError> {
    Ok(topology_and_outside(dims, inside)?.0)
}

/// [`digital_topology`] and the labelled outside samples, whose components other than the
/// exterior are the cavities. The inside's labelling, the outside's and the count of loops and
/// crossed edges run side by side.
pub(crate) fn topology_and_outside(
    dims: [usize; 3],
    inside: &[bool],
) -> Result<(DigitalTopology, RunComponents), SamplingError> {
    check_samples(dims, inside)?;
    let (labelled, euler) = rayon::join(
        || {
            rayon::join(
                || RunComponents::new(dims, inside, true),
                || RunComponents::new(dims, inside, false),
            )
        },
        || total_loops(dims, inside) - crossed_edges(dims, inside),
    );
    let (components, outside) = (labelled.0?.count(), labelled.1?);
    let outside_count = outside.count();
    let surfaces = (components + outside_count - 1) as i64;
    let genus = surfaces - euler / 2;
    debug_assert!(
        euler % 2 == 0 && genus >= 0,
        "χ {euler}, surfaces {surfaces}"
    );
    let topology = DigitalTopology {
        genus: genus.max(0) as u64,
        components,
        cavities: outside_count - 1,
        euler_characteristic: euler,
    };
    Ok((topology, outside))
}

/// The local topological numbers of one sample. See the module documentation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LocalNumbers {
    /// 6-components of the inside among the 18 neighbours, touching a face neighbour.
    pub inside: u8,
    /// 18-components of the outside among the 26 neighbours, touching an 18-neighbour.
    pub outside: u8,
}

impl LocalNumbers {
    /// Flipping the sample changes no topology at all.
    pub fn is_simple(&self) -> bool {
        self.inside == 1 && self.outside == 1
    }
}

/// The 26 neighbours' positions in a 3×3×3 block (index `(di+1) + 3(dj+1) + 9(dk+1)`), with their
/// 6- and 18-adjacency among themselves.
struct Neighbourhood {
    cells: Vec<usize>,
    kind: [u8; 27],
    adjacent6: Vec<Vec<usize>>,
    adjacent18: Vec<Vec<usize>>,
}

fn neighbourhood() -> &'static Neighbourhood {
    static N: OnceLock<Neighbourhood> = OnceLock::new();
    N.get_or_init(|| {
        let pos = |c: usize| [c as i64 % 3 - 1, (c as i64 / 3) % 3 - 1, c as i64 / 9 - 1];
        let nonzero = |p: [i64; 3]| p.iter().filter(|d| **d != 0).count() as u8;
        let cells: Vec<usize> = (0..27).filter(|&c| c != 13).collect();
        let mut kind = [0u8; 27];
        for &c in &cells {
            kind[c] = nonzero(pos(c));
        }
        let adjacency = |max: u8| -> Vec<Vec<usize>> {
            (0..27)
                .map(|a| {
                    cells
                        .iter()
                        .copied()
                        .filter(|&b| {
                            let (pa, pb) = (pos(a), pos(b));
                            let d = [pa[0] - pb[0], pa[1] - pb[1], pa[2] - pb[2]];
                            b != a && d.iter().all(|x| x.abs() <= 1) && nonzero(d) <= max
                        })
                        .collect()
                })
                .collect()
        };
        let (adjacent6, adjacent18) = (adjacency(1), adjacency(2));
        Neighbourhood {
            cells,
            kind,
            adjacent6,
            adjacent18,
        }
    })
}

/// `T6` of the inside and `T̄18` of the outside at sample `index` (outside the grid is outside).
pub fn local_numbers(dims: [usize; 3], inside: &[bool], index: usize) -> LocalNumbers {
    let n = neighbourhood();
    let p = coordinates(dims, index);
    let mut block = [false; 27];
    for &c in &n.cells {
        let o = [c as i64 % 3 - 1, (c as i64 / 3) % 3 - 1, c as i64 / 9 - 1];
        block[c] = step(dims, p, o).map(|q| inside[q]).unwrap_or(false);
    }
    // Inside: within the 18-neighbourhood, 6-adjacency, seeds at the face neighbours.
    let inside_count = count_pieces(n, &n.adjacent6, |c| block[c] && n.kind[c] <= 2, 1);
    let outside_count = count_pieces(n, &n.adjacent18, |c| !block[c], 2);
    LocalNumbers {
        inside: inside_count,
        outside: outside_count,
    }
}

/// Components of the member cells reachable from a member seed of kind `<= seed_kind`.
fn count_pieces(
    n: &Neighbourhood,
    adjacency: &[Vec<usize>],
    member: impl Fn(usize) -> bool,
    seed_kind: u8,
) -> u8 {
    let mut seen = [false; 27];
    let mut stack = Vec::with_capacity(26);
    let mut count = 0u8;
    for &seed in &n.cells {
        if n.kind[seed] > seed_kind || seen[seed] || !member(seed) {
            continue;
        }
        count += 1;
        seen[seed] = true;
        stack.push(seed);
        while let Some(c) = stack.pop() {
            for &d in &adjacency[c] {
                if !seen[d] && member(d) {
                    seen[d] = true;
                    stack.push(d);
                }
            }
        }
    }
    count
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ball(dims: [usize; 3], centre: [f64; 3], r: f64) -> Vec<bool> {
        let mut v = vec![false; dims.iter().product()];
        for (i, s) in v.iter_mut().enumerate() {
            let p = coordinates(dims, i);
            let d2: f64 = (0..3).map(|a| (p[a] as f64 - centre[a]).powi(2)).sum();
            *s = d2 <= r * r;
        }
        v
    }

    #[test]
    fn a_single_sample_is_a_sphere_and_a_ring_has_one_handle() {
        let dims = [5, 5, 5];
        let mut one = vec![false; 125];
        one[62] = true;
        let t = digital_topology(dims, &one).unwrap();
        assert_eq!(
            (t.genus, t.components, t.cavities, t.euler_characteristic),
            (0, 1, 0, 2)
        );
        // A square ring of 8 samples in the plane k = 2 around (2, 2, 2).
        let mut ring = vec![false; 125];
        for (i, j) in [
            (1, 1),
            (2, 1),
            (3, 1),
            (3, 2),
            (3, 3),
            (2, 3),
            (1, 3),
            (1, 2),
        ] {
            ring[i + 5 * (j + 5 * 2)] = true;
        }
        let t = digital_topology(dims, &ring).unwrap();
        assert_eq!((t.genus, t.components, t.cavities), (1, 1, 0));
        // Its centre is not simple: the inside around it is one piece (the face neighbours join
        // through the edge neighbours), the outside two (above and below), so adding it closes
        // the tunnel.
        let centre = 2 + 5 * (2 + 5 * 2);
        let n = local_numbers(dims, &ring, centre);
        assert_eq!((n.inside, n.outside), (1, 2));
    }

    #[test]
    fn a_hollow_ball_has_a_cavity() {
        let dims = [13, 13, 13];
        let outer = ball(dims, [6.0; 3], 5.0);
        let inner = ball(dims, [6.0; 3], 3.0);
        let shell: Vec<bool> = outer.iter().zip(&inner).map(|(&o, &i)| o && !i).collect();
        let t = digital_topology(dims, &shell).unwrap();
        assert_eq!((t.genus, t.components, t.cavities), (0, 1, 1));
        let cav = cavity_samples(dims, &shell).unwrap();
        assert_eq!(cav, inner);
    }

    #[test]
    fn loops_of_the_classic_cases() {
        let loops = cell_loops();
        assert_eq!(loops[0], 0);
        assert_eq!(loops[255], 0);
        assert_eq!(loops[1], 1);
        // Two inside corners on a body diagonal: two loops; their complement too.
        assert_eq!(loops[0b1000_0001], 2);
        assert_eq!(loops[0b0111_1110], 2);
        // Two inside corners on a face diagonal are separated; two outside ones are joined.
        assert_eq!(loops[0b0000_1001], 2);
        assert_eq!(loops[0b1111_0110], 1);
    }
}
