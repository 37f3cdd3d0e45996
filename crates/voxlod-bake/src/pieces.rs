//! A level cut into compact pieces for xatlas ([`pieces`]): xatlas grows and parameterizes
//! the charts of separate meshes side by side on its threads, but those of one connected mesh
//! on one thread, in more than linear time in its size. A piece's border becomes a chart
//! border; with pieces of thousands of triangles that is a small share of the borders the
//! charts have anyway.
//!
//! Cost: O(T log T) for T triangles (a linear median selection per piece and depth).

use voxlod_core::glam::Vec3;

/// The triangles of `triangles` (corners in `positions`) in pieces of at most `most`
/// triangles each (0: one piece), cut at the median of the triangles' centroids across the
/// longest side of their box, again within each half until small enough. Every triangle is
/// in exactly one piece; the pieces are in order of the cuts.
pub fn pieces(positions: &[Vec3], triangles: &[[u32; 3]], most: usize) -> Vec<Vec<u32>> {
    let all: Vec<u32> = (0..triangles.len() as u32).collect();
    if most == 0 || triangles.len() <= most {
        return vec![all];
    }
    let centroids: Vec<Vec3> = (triangles.iter())
        .map(|t| t.iter().map(|&v| positions[v as usize]).sum::<Vec3>() / 3.0)
        .collect();
    let mut done = Vec::new();
    let mut open = vec![all];
    while let Some(mut piece) = open.pop() {
        if piece.len() <= most {
            done.push(piece);
            continue;
        }
        let (lo, hi) = (piece.iter()).fold((Vec3::MAX, Vec3::MIN), |(lo, hi), &t| {
            let c = centroids[t as usize];
            (lo.min(c), hi.max(c))
        });
        let axis = (hi - lo).max_position();
        let half = piece.len() / 2;
        piece.select_nth_unstable_by(half, |&a, &b| {
            let (a, b) = (centroids[a as usize][axis], centroids[b as usize][axis]);
            a.total_cmp(&b)
        });
        let upper = piece.split_off(half);
        open.push(upper);
        open.push(piece);
    }
    done
}
