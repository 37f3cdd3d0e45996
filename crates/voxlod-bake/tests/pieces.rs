//! A level cut into compact pieces for xatlas: every triangle in one piece, none larger than
//! asked, cut across the longest side.

use voxlod_bake::pieces::pieces;
use voxlod_core::glam::Vec3;

/// `n` triangles in a row along x, each one unit wide, their corners their own.
fn strip(n: usize) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for i in 0..n {
        let x = i as f32;
        let first = positions.len() as u32;
        positions.extend([
            Vec3::new(x, 0.0, 0.0),
            Vec3::new(x + 1.0, 0.0, 0.0),
            Vec3::new(x, 0.5, 0.0),
        ]);
        triangles.push([first, first + 1, first + 2]);
    }
    (positions, triangles)
}

#[test]
fn a_strip_is_cut_into_runs_along_its_length() {
    // 1 000 triangles in pieces of at most 128: halves of halves, eight runs of 125.
    let (positions, triangles) = strip(1000);
    let cut = pieces(&positions, &triangles, 128);
    assert_eq!(cut.len(), 8);
    let mut seen = vec![0; triangles.len()];
    for piece in &cut {
        assert_eq!(piece.len(), 125);
        let mut members = piece.clone();
        members.sort_unstable();
        // A run: consecutive triangles of the strip.
        assert_eq!(members.last().unwrap() - members[0], 124, "{members:?}");
        members.iter().for_each(|&t| seen[t as usize] += 1);
    }
    assert!(seen.iter().all(|&n| n == 1));
}

#[test]
fn small_levels_and_no_limit_are_one_piece() {
    let (positions, triangles) = strip(10);
    for most in [0, 10, 11] {
        let cut = pieces(&positions, &triangles, most);
        assert_eq!(cut, vec![(0..10).collect::<Vec<u32>>()], "at most {most}");
    }
    assert_eq!(pieces(&positions, &triangles, 9).len(), 2);
    assert_eq!(pieces(&positions, &[], 4), vec![Vec::<u32>::new()]);
}
