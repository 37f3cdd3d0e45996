//! Surface nets over every label of a map at once, with boundaries shared between neighbours
//! (Frisken 2022, "SurfaceNets for multi-label segmentations with preservation of sharp
//! boundaries", JCGT 11(1); the layout of VTK's `vtkSurfaceNets3D`).
//!
//! Voxels are cubes. Every face between two face-adjacent voxels of different labels is one
//! quad, whose four corners are the voxel corners of that face; voxels outside the volume count
//! as background (label 0), so labels touching the border close there. Each voxel corner that
//! touches more than one label is one vertex, shared by every quad that uses it: the interface
//! between labels A and B is meshed once, and A's mesh and B's mesh use the same vertices and
//! the same triangles there, with opposite orientation ([`SharedSurface`]).
//!
//! Each quad is two triangles (consecutive in [`SharedSurface::triangles`], the first of them at
//! an even index) over the diagonal from its first corner; smoothing may turn the diagonal
//! ([`crate::smoothing`]), once for both labels since they share the triangles.
//!
//! Non-manifold corners (two voxels of a label touching only along an edge or at a corner) are
//! resolved, as far as splitting vertices can, when a label's mesh is taken out
//! ([`SharedSurface::label_mesh`]): the shared vertex is split, for that label, into one
//! coincident copy per sheet of the label's surface around the corner, voxels of the label
//! that meet only along an edge being kept apart (the label's voxels are 6-connected). A shared
//! vertex cannot be split for both labels of such an edge at once (the two labels pair the four
//! faces around the edge differently), so the copies keep the shared vertex's position bit for
//! bit instead of its index: the interface property holds on positions, and
//! [`SharedSurface::label_mesh_with_sources`] gives each copy's shared vertex.
//!
//! The contract: every label mesh is closed and consistently oriented (each directed edge is
//! matched by its reverse as often), and a 2-manifold except at one configuration: an edge
//! contact whose two voxels are also joined by other voxels of the label within the 2×2×2
//! block of an end of the edge. There the label's surface is one sheet at that end, so no
//! split of vertices can separate the edge (it would need new vertices); the label's mesh keeps
//! four triangles on that edge (VTK's surface nets leaves such neighbourhoods unresolved too).
//! Pinched corners and the other edge contacts are split.
//!
//! Cost: two passes over the volume (count, then fill into the final arrays), each in parallel
//! over slabs of z, each corner tested from the two padded voxel layers around it (a corner
//! inside a run of equal labels costs eight compares, a corner row whose four voxel rows are
//! equal costs a row comparison); the output is sized once from the
//! counts. Memory: the output plus, per slab task, three padded voxel layers and two planes of
//! corner indices.

use std::sync::OnceLock;

use rayon::prelude::*;
use voxlod_core::glam::{DMat3, DVec3, Vec3};
use voxlod_core::{memory, LabelVolume, WorldTransform};

use crate::LabelsError;

mod extract;
pub(crate) use extract::LabelSlots;

/// How [`surface_nets`] works (the surface itself has no parameter).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct SurfaceNetsOptions {
    /// Corner planes per parallel task; 0 picks from the volume's depth (at least 8 planes,
    /// about 32 tasks). The output does not depend on it.
    pub slab_planes: usize,
    /// Where the map's first voxel lies in a larger map it is a block of (the blockwise route):
    /// its vertices are placed, and smoothed, as that map's corners `corner + offset`, the
    /// map's origin being the larger map's. Zero for a whole map.
    pub offset: [u32; 3],
}

/// What the eight voxels around a vertex's corner say about it (bit set, see the methods).
///
/// Directions are numbered `2 * axis + (1 if positive)`: −x, +x, −y, +y, −z, +z.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct CornerFlags(pub u32);

/// How a vertex may move when smoothed (Frisken 2022, §3.2: nodes on a junction of three or
/// more labels follow their junction curve, nodes where junction curves meet stay).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VertexKind {
    /// On an interface of two labels: moves towards all its linked neighbours.
    Surface,
    /// On a junction curve (exactly two junction links): moves along the curve only.
    Curve,
    /// Where junction curves meet or end: stays.
    Fixed,
}

impl CornerFlags {
    const JUNCTION: u32 = 6;
    const BORDER: u32 = 12;
    const SINGULAR: u32 = 1 << 15;
    const TWO_LABELS: u32 = 1 << 16;

    /// Directions along which a quad edge leaves the vertex (the four voxels around that edge
    /// are not all one label).
    pub fn links(self) -> u8 {
        (self.0 & 0x3f) as u8
    }

    /// Links that are junction edges: the four voxels around the edge change label three or
    /// four times going round it (three or four labels, or two labels on diagonals), so three
    /// or four quads meet there.
    pub fn junctions(self) -> u8 {
        ((self.0 >> Self::JUNCTION) & 0x3f) as u8
    }

    /// Axes (bit 0 x, 1 y, 2 z) along which the corner lies on the volume's border.
    pub fn border_axes(self) -> u8 {
        ((self.0 >> Self::BORDER) & 7) as u8
    }

    /// Some label's surface has more than one sheet at this corner (an edge or corner contact).
    pub fn is_singular(self) -> bool {
        self.0 & Self::SINGULAR != 0
    }

    /// Exactly two labels (counting the background and the outside as 0) meet at the corner,
    /// so every quad at it separates the same two labels.
    pub fn has_two_labels(self) -> bool {
        self.0 & Self::TWO_LABELS != 0
    }

    /// How the vertex may move when smoothed.
    pub fn kind(self) -> VertexKind {
        match self.junctions().count_ones() {
            0 => VertexKind::Surface,
            2 => VertexKind::Curve,
            _ => VertexKind::Fixed,
        }
    }
}

/// The shared surface of every label of a map: one vertex per voxel corner where labels meet,
/// one quad (two triangles) per face between voxels of different labels.
#[derive(Clone, Debug, PartialEq)]
pub struct SharedSurface {
    /// Vertex positions in world units (the map's index-to-world transform applied; unsmoothed,
    /// corner `c` lies at index `c − ½`).
    pub positions: Vec<Vec3>,
    /// Three vertex indices per triangle, two triangles per quad (indices `2q`, `2q + 1`).
    pub triangles: Vec<[u32; 3]>,
    /// Per triangle `[inside, outside]`: the triangle winds counter-clockwise seen from the
    /// outside label, its normal pointing from inside to outside. The background (0, which
    /// includes the outside of the volume) is always outside; between two other labels the
    /// smaller is inside.
    pub sides: Vec<[u32; 2]>,
    /// Per vertex, the voxel corner it started at: corner `(i, j, k)` is shared by voxels
    /// `i−1..=i`, `j−1..=j`, `k−1..=k`. Vertices are numbered in raster order of their
    /// corners (x fastest, then y, then z).
    pub corners: Vec<[u32; 3]>,
    /// Per vertex, what the voxels around its corner say (links, junctions, border).
    pub flags: Vec<CornerFlags>,
    /// The map's voxels per axis.
    pub dims: [usize; 3],
    /// The map's index-to-world transform.
    pub world: WorldTransform,
    /// [`SurfaceNetsOptions::offset`]: corner `c` is the whole map's corner `c + offset`.
    pub offset: [u32; 3],
}

/// The shared surface of every label of `map` (the module's contract). Fails only when the
/// memory limit refuses the output or a task's layers, or when the map has more than 2³² − 1
/// vertices or 2³⁰ − 1 quads. A map of one label only gives an empty surface.
///
/// Cost: O(voxels) in two parallel passes plus O(output).
pub fn surface_nets(
    map: &LabelVolume,
    options: &SurfaceNetsOptions,
) -> Result<SharedSurface, LabelsError> {
    let net = Net::new(map, options.offset);
    let [nx, ny, nz] = map.grid.dims;
    let layer = memory::bytes_of::<u32>((nx + 2) * (ny + 2) * 3 + (nx + 1) * (ny + 1) * 2);
    memory::check_allocation(
        "surface nets' layers",
        layer * rayon::current_num_threads() as u64,
    )?;
    let slabs = slabs(nz + 1, options.slab_planes);
    let counts: Vec<(Vec<u32>, usize)> = slabs.par_iter().map(|&s| net.count(s)).collect();
    let plane_counts: Vec<u32> = counts.iter().flat_map(|c| c.0.iter().copied()).collect();
    let vertices: usize = plane_counts.iter().map(|&c| c as usize).sum();
    let quads: usize = counts.iter().map(|c| c.1).sum();
    // Label meshes list a triangle as `t << 1` plus its side: under 2³¹ triangles.
    if vertices > u32::MAX as usize || quads > (u32::MAX / 4) as usize {
        return Err(LabelsError::Core(voxlod_core::CoreError::InvalidGrid(
            format!("{vertices} vertices and {quads} quads are beyond 32-bit indices"),
        )));
    }
    memory::check_allocation(
        "the shared surface",
        memory::bytes_of::<[f32; 3]>(vertices) * 2
            + memory::bytes_of::<u32>(vertices)
            + memory::bytes_of::<[u32; 5]>(quads * 2),
    )?;
    let mut plane_offsets = Vec::with_capacity(plane_counts.len() + 1);
    plane_offsets.push(0u32);
    for &c in &plane_counts {
        plane_offsets.push(plane_offsets.last().unwrap() + c);
    }
    let mut out = Output::zeroed(vertices, quads);
    {
        let mut parts = out.split(&slabs, &plane_offsets, &counts);
        parts
            .par_iter_mut()
            .zip(slabs.par_iter())
            .for_each(|(part, &slab)| net.fill(slab, &plane_offsets, part));
    }
    Ok(SharedSurface {
        positions: out.positions,
        triangles: out.triangles,
        sides: out.sides,
        corners: out.corners,
        flags: out.flags,
        dims: map.grid.dims,
        world: map.world(),
        offset: options.offset,
    })
}

/// Corner planes `[start, end)` per task.
fn slabs(planes: usize, asked: usize) -> Vec<(usize, usize)> {
    let size = if asked > 0 {
        asked
    } else {
        planes.div_ceil(32).max(8)
    };
    (0..planes)
        .step_by(size)
        .map(|s| (s, (s + size).min(planes)))
        .collect()
}

/// The output arrays, allocated once at their final size.
struct Output {
    positions: Vec<Vec3>,
    corners: Vec<[u32; 3]>,
    flags: Vec<CornerFlags>,
    triangles: Vec<[u32; 3]>,
    sides: Vec<[u32; 2]>,
}

/// One task's share of the output: its planes' vertices and its quads.
struct Part<'a> {
    positions: &'a mut [Vec3],
    corners: &'a mut [[u32; 3]],
    flags: &'a mut [CornerFlags],
    triangles: &'a mut [[u32; 3]],
    sides: &'a mut [[u32; 2]],
    quads: usize,
}

impl Output {
    fn zeroed(vertices: usize, quads: usize) -> Output {
        Output {
            positions: vec![Vec3::ZERO; vertices],
            corners: vec![[0; 3]; vertices],
            flags: vec![CornerFlags(0); vertices],
            triangles: vec![[0; 3]; quads * 2],
            sides: vec![[0; 2]; quads * 2],
        }
    }

    fn split<'a>(
        &'a mut self,
        slabs: &[(usize, usize)],
        plane_offsets: &[u32],
        counts: &[(Vec<u32>, usize)],
    ) -> Vec<Part<'a>> {
        let (mut p, mut c, mut f) = (
            &mut self.positions[..],
            &mut self.corners[..],
            &mut self.flags[..],
        );
        let (mut t, mut s) = (&mut self.triangles[..], &mut self.sides[..]);
        let mut parts = Vec::with_capacity(slabs.len());
        for (&(start, end), count) in slabs.iter().zip(counts) {
            let n = (plane_offsets[end] - plane_offsets[start]) as usize;
            let (p0, p1) = std::mem::take(&mut p).split_at_mut(n);
            let (c0, c1) = std::mem::take(&mut c).split_at_mut(n);
            let (f0, f1) = std::mem::take(&mut f).split_at_mut(n);
            let (t0, t1) = std::mem::take(&mut t).split_at_mut(count.1 * 2);
            let (s0, s1) = std::mem::take(&mut s).split_at_mut(count.1 * 2);
            (p, c, f, t, s) = (p1, c1, f1, t1, s1);
            parts.push(Part {
                positions: p0,
                corners: c0,
                flags: f0,
                triangles: t0,
                sides: s0,
                quads: 0,
            });
        }
        parts
    }
}

/// The map seen as padded voxel layers, and the placement of corners in the world.
struct Net<'a> {
    values: &'a [u32],
    dims: [usize; 3],
    /// Index-to-world: `origin + linear · index`.
    linear: DMat3,
    origin: DVec3,
    /// The transform turns a right-handed index frame left-handed: windings are reversed.
    flip: bool,
    /// [`SurfaceNetsOptions::offset`], as a vector.
    offset: DVec3,
}

/// Width of a padded voxel layer (one background voxel on each side of x and y).
fn padded_width(dims: [usize; 3]) -> usize {
    dims[0] + 2
}

impl<'a> Net<'a> {
    fn new(map: &'a LabelVolume, offset: [u32; 3]) -> Net<'a> {
        let world = map.world();
        Net {
            values: &map.values,
            dims: map.grid.dims,
            linear: world.direction * DMat3::from_diagonal(world.spacing),
            origin: world.origin,
            flip: world.flips_handedness(),
            offset: DVec3::from(offset.map(f64::from)),
        }
    }

    /// Voxel layer `k` (any integer; outside the volume all background) into `layer`, padded
    /// with background: padded `(i + 1, j + 1)` is voxel `(i, j)`.
    fn load_layer(&self, k: isize, layer: &mut [u32]) {
        let [nx, ny, nz] = self.dims;
        let w = padded_width(self.dims);
        layer.fill(0);
        if k < 0 || k as usize >= nz {
            return;
        }
        let base = k as usize * nx * ny;
        for j in 0..ny {
            let row = &self.values[base + j * nx..base + (j + 1) * nx];
            layer[(j + 1) * w + 1..(j + 1) * w + 1 + nx].copy_from_slice(row);
        }
    }

    /// Calls `found(i, j, octants)` for every vertex corner of the plane between voxel layers
    /// `below` and `above`, in raster order. Octant `dx + 2dy + 4dz` is voxel `(i−1+dx,
    /// j−1+dy, k−1+dz)`.
    fn plane_vertices(
        &self,
        below: &[u32],
        above: &[u32],
        mut found: impl FnMut(usize, usize, [u32; 8]),
    ) {
        let [nx, ny, _] = self.dims;
        let w = padded_width(self.dims);
        for j in 0..=ny {
            let (r0, r1) = (&below[j * w..(j + 2) * w], &above[j * w..(j + 2) * w]);
            let (a0, a1, b0, b1) = (&r0[..w], &r0[w..], &r1[..w], &r1[w..]);
            if a0 == a1 && a0 == b0 && a0 == b1 {
                // Four equal rows (a run of planes alike): vertices only where the row changes.
                for i in (0..=nx).filter(|&i| a0[i] != a0[i + 1]) {
                    let (l, r) = (a0[i], a0[i + 1]);
                    found(i, j, [l, r, l, r, l, r, l, r]);
                }
                continue;
            }
            for i in 0..=nx {
                let v = a0[i];
                if a0[i + 1] == v
                    && a1[i] == v
                    && a1[i + 1] == v
                    && b0[i] == v
                    && b0[i + 1] == v
                    && b1[i] == v
                    && b1[i + 1] == v
                {
                    continue;
                }
                let o = [
                    a0[i],
                    a0[i + 1],
                    a1[i],
                    a1[i + 1],
                    b0[i],
                    b0[i + 1],
                    b1[i],
                    b1[i + 1],
                ];
                found(i, j, o);
            }
        }
    }

    /// Vertices per plane of the slab and quads the slab emits.
    fn count(&self, (start, end): (usize, usize)) -> (Vec<u32>, usize) {
        let nz = self.dims[2];
        let w = padded_width(self.dims);
        let size = w * (self.dims[1] + 2);
        let (mut below, mut above) = (vec![0u32; size], vec![0u32; size]);
        self.load_layer(start as isize - 1, &mut below);
        let mut planes = Vec::with_capacity(end - start);
        let mut quads = 0usize;
        for k in start..end {
            self.load_layer(k as isize, &mut above);
            let mut n = 0u32;
            self.plane_vertices(&below, &above, |_, _, _| n += 1);
            planes.push(n);
            quads += self.count_z_faces(&below, &above);
            if k < nz {
                quads += self.count_xy_faces(&above);
            }
            std::mem::swap(&mut below, &mut above);
        }
        (planes, quads)
    }

    /// Faces between the two layers (z faces of the plane between them).
    fn count_z_faces(&self, below: &[u32], above: &[u32]) -> usize {
        let [nx, ny, _] = self.dims;
        let w = padded_width(self.dims);
        (1..=ny)
            .map(|j| {
                let (a, b) = (
                    &below[j * w + 1..j * w + 1 + nx],
                    &above[j * w + 1..j * w + 1 + nx],
                );
                a.iter().zip(b).filter(|(a, b)| a != b).count()
            })
            .sum()
    }

    /// Faces inside one layer: x faces (between voxels i−1 and i, borders included) and y faces.
    fn count_xy_faces(&self, layer: &[u32]) -> usize {
        let [nx, ny, _] = self.dims;
        let w = padded_width(self.dims);
        let x: usize = (1..=ny)
            .map(|j| {
                let row = &layer[j * w..j * w + nx + 2];
                row.windows(2).filter(|p| p[0] != p[1]).count()
            })
            .sum();
        let y: usize = (0..=ny)
            .map(|j| {
                let (a, b) = (
                    &layer[j * w + 1..j * w + 1 + nx],
                    &layer[(j + 1) * w + 1..(j + 1) * w + 1 + nx],
                );
                a.iter().zip(b).filter(|(a, b)| a != b).count()
            })
            .sum();
        x + y
    }
}

impl Net<'_> {
    /// Fills the slab's vertices and quads into `part` (the same order as [`Net::count`]).
    fn fill(&self, (start, end): (usize, usize), plane_offsets: &[u32], part: &mut Part) {
        let [nx, ny, nz] = self.dims;
        let w = padded_width(self.dims);
        let size = w * (ny + 2);
        let mut layers = [vec![0u32; size], vec![0u32; size], vec![0u32; size]];
        let plane = (nx + 1) * (ny + 1);
        let (mut ids, mut next_ids) = (vec![u32::MAX; plane], vec![u32::MAX; plane]);
        self.load_layer(start as isize - 1, &mut layers[0]);
        self.load_layer(start as isize, &mut layers[1]);
        let mut emitted = 0usize;
        self.number_plane(
            start,
            &layers[0],
            &layers[1],
            plane_offsets[start],
            &mut ids,
            Some((part, &mut emitted)),
        );
        for k in start..end {
            self.emit_z_faces(&layers[0], &layers[1], &ids, part);
            if k < nz {
                self.load_layer(k as isize + 1, &mut layers[2]);
                let sink = if k + 1 < end {
                    Some((&mut *part, &mut emitted))
                } else {
                    None
                };
                self.number_plane(
                    k + 1,
                    &layers[1],
                    &layers[2],
                    plane_offsets[k + 1],
                    &mut next_ids,
                    sink,
                );
                self.emit_xy_faces(&layers[1], &ids, &next_ids, part);
                layers.rotate_left(1);
                std::mem::swap(&mut ids, &mut next_ids);
            }
        }
    }

    /// Numbers the vertices of corner plane `k` from `first` into `ids` (index `j(nx+1) + i`,
    /// `u32::MAX` where no vertex), writing them into the sink when the slab owns the plane.
    fn number_plane(
        &self,
        k: usize,
        below: &[u32],
        above: &[u32],
        first: u32,
        ids: &mut [u32],
        mut sink: Option<(&mut Part, &mut usize)>,
    ) {
        let [nx, ny, nz] = self.dims;
        ids.fill(u32::MAX);
        let mut next = first;
        let k_border = (k == 0 || k == nz) as u32;
        self.plane_vertices(below, above, |i, j, octants| {
            ids[j * (nx + 1) + i] = next;
            next += 1;
            if let Some((part, at)) = sink.as_mut() {
                let border =
                    (i == 0 || i == nx) as u32 | ((j == 0 || j == ny) as u32) << 1 | k_border << 2;
                let c = DVec3::new(i as f64, j as f64, k as f64) + self.offset - 0.5;
                part.positions[**at] = (self.origin + self.linear * c).as_vec3();
                part.corners[**at] = [i as u32, j as u32, k as u32];
                part.flags[**at] = corner_flags(&octants, border);
                **at += 1;
            }
        });
    }

    /// One quad between voxels labelled `below` (on the axis's negative side) and `above`;
    /// `ring` is its corners counter-clockwise seen from the positive side.
    #[inline]
    fn quad(&self, part: &mut Part, ring: [u32; 4], below: u32, above: u32) {
        let inside = if above == 0 || (below != 0 && below < above) {
            below
        } else {
            above
        };
        let outside = if inside == below { above } else { below };
        // Normal from inside to outside: +axis when the inside voxel is below.
        let forward = (inside == below) != self.flip;
        let [a, b, c, d] = if forward {
            ring
        } else {
            [ring[0], ring[3], ring[2], ring[1]]
        };
        let t = part.quads * 2;
        part.triangles[t] = [a, b, c];
        part.triangles[t + 1] = [a, c, d];
        part.sides[t] = [inside, outside];
        part.sides[t + 1] = [inside, outside];
        part.quads += 1;
    }

    fn emit_z_faces(&self, below: &[u32], above: &[u32], ids: &[u32], part: &mut Part) {
        let [nx, ny, _] = self.dims;
        let (w, s) = (padded_width(self.dims), nx + 1);
        for j in 0..ny {
            let (a, b) = (
                &below[(j + 1) * w + 1..(j + 1) * w + 1 + nx],
                &above[(j + 1) * w + 1..(j + 1) * w + 1 + nx],
            );
            for i in 0..nx {
                if a[i] != b[i] {
                    let ring = [
                        ids[j * s + i],
                        ids[j * s + i + 1],
                        ids[(j + 1) * s + i + 1],
                        ids[(j + 1) * s + i],
                    ];
                    self.quad(part, ring, a[i], b[i]);
                }
            }
        }
    }

    /// x and y faces of the voxel layer between corner planes `ids` (k) and `next` (k + 1).
    fn emit_xy_faces(&self, layer: &[u32], ids: &[u32], next: &[u32], part: &mut Part) {
        let [nx, ny, _] = self.dims;
        let (w, s) = (padded_width(self.dims), nx + 1);
        for j in 0..=ny {
            if j < ny {
                let row = &layer[(j + 1) * w..(j + 2) * w];
                for i in 0..=nx {
                    if row[i] != row[i + 1] {
                        let ring = [
                            ids[j * s + i],
                            ids[(j + 1) * s + i],
                            next[(j + 1) * s + i],
                            next[j * s + i],
                        ];
                        self.quad(part, ring, row[i], row[i + 1]);
                    }
                }
            }
            let (a, b) = (
                &layer[j * w + 1..j * w + 1 + nx],
                &layer[(j + 1) * w + 1..(j + 1) * w + 1 + nx],
            );
            for i in 0..nx {
                if a[i] != b[i] {
                    let ring = [
                        ids[j * s + i],
                        next[j * s + i],
                        next[j * s + i + 1],
                        ids[j * s + i + 1],
                    ];
                    self.quad(part, ring, a[i], b[i]);
                }
            }
        }
    }
}

/// The four octants around the edge leaving the corner in direction `2 * axis + side`, in
/// cyclic order round the edge.
fn ring(direction: usize) -> [usize; 4] {
    let (axis, side) = (direction / 2, direction % 2);
    let (e, f) = others(axis);
    [(0, 0), (1, 0), (1, 1), (0, 1)].map(|(a, b)| side << axis | a << e | b << f)
}

/// The two axes other than `axis`, in increasing order.
fn others(axis: usize) -> (usize, usize) {
    match axis {
        0 => (1, 2),
        1 => (0, 2),
        _ => (0, 1),
    }
}

/// The flags of a vertex from its octants' labels and its border axes.
fn corner_flags(octants: &[u32; 8], border: u32) -> CornerFlags {
    let mut bits = border << CornerFlags::BORDER;
    for direction in 0..6 {
        let r = ring(direction).map(|o| octants[o]);
        let changes = (0..4).filter(|&n| r[n] != r[(n + 1) % 4]).count();
        if changes > 0 {
            bits |= 1 << direction;
        }
        if changes >= 3 {
            bits |= 1 << (direction as u32 + CornerFlags::JUNCTION);
        }
    }
    let mut distinct = [0u32; 8];
    let mut n = 0;
    for &label in octants {
        if !distinct[..n].contains(&label) {
            distinct[n] = label;
            n += 1;
        }
    }
    if n == 2 {
        bits |= CornerFlags::TWO_LABELS;
    }
    let loops = sheet_counts();
    for &label in distinct[..n].iter().filter(|&&l| l != 0) {
        let mask = (0..8).fold(0u8, |m, o| m | ((octants[o] == label) as u8) << o);
        if loops[mask as usize] > 1 {
            bits |= CornerFlags::SINGULAR;
            break;
        }
    }
    CornerFlags(bits)
}

/// Face `4a + q` of a corner's 2×2×2 block lies in the plane through the corner normal to axis
/// `a`, in quadrant `q` (bit 0: the first other axis positive, bit 1: the second). Its two
/// octants (towards −a and +a).
fn face_octants(face: usize) -> (usize, usize) {
    let (a, q) = (face / 4, face % 4);
    let (e, f) = others(a);
    let low = (q & 1) << e | (q >> 1) << f;
    (low, low | 1 << a)
}

/// Groups a label's boundary faces at one corner into sheets: `faces` lists `(face, the
/// label's octant of it)`; two faces are joined across an edge leaving the corner when they
/// are the only two of the label there, or when they bound the same voxel of the label (at an
/// edge where the label holds two diagonal voxels, its voxels are kept apart). Returns each
/// face's sheet (a representative face index), by face. A face may be listed more than once
/// (both triangles of a quad).
fn sheets(faces: &[(u8, u8)]) -> [u8; 12] {
    let mut parent: [u8; 12] = std::array::from_fn(|f| f as u8);
    fn root(parent: &mut [u8; 12], mut f: u8) -> u8 {
        while parent[f as usize] != f {
            parent[f as usize] = parent[parent[f as usize] as usize];
            f = parent[f as usize];
        }
        f
    }
    for direction in 0..6 {
        let (axis, side) = (direction / 2, direction % 2);
        let mut at = [(0u8, 0u8); 4];
        let mut n = 0;
        for &(face, octant) in faces {
            let (a, q) = (face as usize / 4, face as usize % 4);
            if a == axis {
                continue;
            }
            let (e, f) = others(a);
            let bit = if e == axis {
                q & 1
            } else if f == axis {
                q >> 1
            } else {
                2
            };
            if bit == side && n < 4 && !at[..n].iter().any(|p| p.0 == face) {
                at[n] = (face, octant);
                n += 1;
            }
        }
        let mut join = |x: u8, y: u8| {
            let (rx, ry) = (root(&mut parent, x), root(&mut parent, y));
            parent[rx as usize] = ry;
        };
        match n {
            2 => join(at[0].0, at[1].0),
            4 => {
                for p in 0..4 {
                    for q in p + 1..4 {
                        if at[p].1 == at[q].1 {
                            join(at[p].0, at[q].0);
                        }
                    }
                }
            }
            _ => {}
        }
    }
    std::array::from_fn(|f| root(&mut parent, f as u8))
}

/// Sheets of a label's surface at a corner, by the mask of its octants (0 for an empty or full
/// block).
fn sheet_counts() -> &'static [u8; 256] {
    static TABLE: OnceLock<[u8; 256]> = OnceLock::new();
    TABLE.get_or_init(|| {
        std::array::from_fn(|mask| {
            let faces: Vec<(u8, u8)> = (0..12)
                .filter_map(|face| {
                    let (lo, hi) = face_octants(face);
                    let (l, h) = (mask >> lo & 1 == 1, mask >> hi & 1 == 1);
                    (l != h).then_some((face as u8, if l { lo } else { hi } as u8))
                })
                .collect();
            let roots = sheets(&faces);
            let mut seen: Vec<u8> = faces.iter().map(|&(f, _)| roots[f as usize]).collect();
            seen.sort_unstable();
            seen.dedup();
            seen.len() as u8
        })
    })
}

/// The face of `corner`'s block that a label's outward triangle at that corner lies on, and the
/// label's octant of it. `tri` holds the triangle's corners, `flip` whether the world reverses
/// windings.
fn face_at(corner: [u32; 3], tri: [[u32; 3]; 3], flip: bool) -> (u8, u8) {
    let d = |p: [u32; 3], q: [u32; 3]| -> [i64; 3] {
        std::array::from_fn(|a| p[a] as i64 - q[a] as i64)
    };
    let (u, v) = (d(tri[1], tri[0]), d(tri[2], tri[0]));
    let n = [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ];
    let axis = (0..3).max_by_key(|&a| n[a].abs()).unwrap_or(0);
    let outward = if flip { -n[axis] } else { n[axis] };
    let (e, f) = others(axis);
    let positive = |a: usize| tri.iter().any(|p| p[a] > corner[a]) as usize;
    let (qe, qf) = (positive(e), positive(f));
    let octant = ((outward < 0) as usize) << axis | qe << e | qf << f;
    ((axis * 4 + qe + 2 * qf) as u8, octant as u8)
}
