//! A scaffold of struts as one closed manifold of high genus: the boundary faces of a set of
//! voxels (a cuberille), every voxel face two triangles, vertices shared at the voxel corners.
//!
//! Along each axis the voxels are sorted into runs "in" and gaps; a voxel is solid when at
//! least two of its three coordinates are in a run (and all three lie between the first and the
//! last run). The solid is then a thickened graph: a node where three runs meet, a strut along
//! the axis whose coordinate lies in a gap. With n_x, n_y, n_z runs it has
//! V = n_x·n_y·n_z nodes and E = (n_x − 1)·n_y·n_z + n_x·(n_y − 1)·n_z + n_x·n_y·(n_z − 1)
//! struts, so its surface has genus E − V + 1.
//!
//! Solidity is a threshold on a sum of one value per axis, so within any 2×2×2 block of voxels
//! it is monotone along each axis: two solid voxels never meet at an edge or corner only, and
//! the surface is a manifold.

use glam::DVec3;

use voxlod_core::TriangleMesh;

/// One axis of the scaffold: the widths of its runs and of the gaps between them, alternating
/// (run, gap, run, …, run), in voxels.
pub(super) struct Axis {
    pub(super) runs: Vec<u32>,
    pub(super) gaps: Vec<u32>,
}

impl Axis {
    /// Per voxel along the axis, with one empty voxel of margin at each end: 1 in a run, 0 in a
    /// gap, -3 in the margin (so that no voxel with a margin coordinate is solid).
    fn values(&self) -> Vec<i32> {
        let mut values = vec![-3];
        for (r, &width) in self.runs.iter().enumerate() {
            values.extend(std::iter::repeat_n(1, width as usize));
            if let Some(&gap) = self.gaps.get(r) {
                values.extend(std::iter::repeat_n(0, gap as usize));
            }
        }
        values.push(-3);
        values
    }
}

/// The scaffold over `axes` (module docs), its voxel corner (i, j, k) placed at `place`:
/// closed, manifold, outward when `place` preserves orientation.
pub(super) fn scaffold(axes: [&Axis; 3], place: impl Fn(DVec3) -> DVec3) -> TriangleMesh {
    let values = axes.map(Axis::values);
    let dims = values.each_ref().map(Vec::len);
    let solid = |c: [i64; 3]| {
        (0..3).all(|a| c[a] >= 0 && (c[a] as usize) < dims[a])
            && (0..3).map(|a| values[a][c[a] as usize]).sum::<i32>() >= 2
    };
    let corners = [dims[0] + 1, dims[1] + 1, dims[2] + 1];
    let mut index = vec![u32::MAX; corners[0] * corners[1] * corners[2]];
    let mut mesh = TriangleMesh::default();
    let mut vertex = |c: [usize; 3], mesh: &mut TriangleMesh| {
        let slot = &mut index[(c[2] * corners[1] + c[1]) * corners[0] + c[0]];
        if *slot == u32::MAX {
            *slot = mesh.positions.len() as u32;
            let p = DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64);
            mesh.positions.push(place(p).as_vec3());
        }
        *slot
    };
    for z in 0..dims[2] {
        for y in 0..dims[1] {
            for x in 0..dims[0] {
                let voxel = [x as i64, y as i64, z as i64];
                if !solid(voxel) {
                    continue;
                }
                for (axis, side) in (0..3).flat_map(|a| [(a, -1i64), (a, 1)]) {
                    let mut neighbour = voxel;
                    neighbour[axis] += side;
                    if solid(neighbour) {
                        continue;
                    }
                    let quad = face_corners([x, y, z], axis, side > 0);
                    let ids = quad.map(|c| vertex(c, &mut mesh));
                    mesh.triangles.push([ids[0], ids[1], ids[2]]);
                    mesh.triangles.push([ids[0], ids[2], ids[3]]);
                }
            }
        }
    }
    mesh
}

/// The four corners of the face of `voxel` across `axis` (on its high side when `high`),
/// counter-clockwise seen from outside the voxel.
fn face_corners(voxel: [usize; 3], axis: usize, high: bool) -> [[usize; 3]; 4] {
    let (u, w) = ((axis + 1) % 3, (axis + 2) % 3);
    let corner = |du: usize, dw: usize| {
        let mut c = voxel;
        c[axis] += high as usize;
        c[u] += du;
        c[w] += dw;
        c
    };
    let quad = [corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1)];
    if high {
        quad
    } else {
        [quad[0], quad[3], quad[2], quad[1]]
    }
}
