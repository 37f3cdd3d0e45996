//! Where a volume sits in the world: its index-to-world transform and its anatomical frame.
//!
//! The paper (§2, §4) works in one axis-aligned lattice; medical scans are not axis-aligned. A
//! scan's sample `(i, j, k)` lies at `origin + D · diag(spacing) · (i, j, k)`, where the columns
//! of `D` are the world directions of the three index axes (NRRD's `space directions`, NIfTI's
//! sform, MetaImage's `TransformMatrix`, DICOM's ImageOrientationPatient), in the patient frame
//! the file uses: LPS (DICOM, ITK, Slicer's files) or RAS (NIfTI, Slicer's screen).
//!
//! voxlod filters and contours in the axis-aligned *grid space* of [`Grid`] (`origin + spacing
//! · index`, the lattice the samplers and marching cubes know), and only the finished mesh is
//! turned into the world by a [`Placement`]: one affine map of the vertices,
//! normals by the inverse transpose, and the winding reversed when the map flips handedness so
//! the triangles still face outwards. With an identity direction the map is the identity and
//! nothing changes. Beyond the paper; the cost is one pass over the vertices.

use glam::{DMat3, DMat4, DVec3};
use serde::Serialize;

use crate::{CoreError, Grid, TriangleMesh};

/// The anatomical meaning of the world axes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Frame {
    /// x to the patient's left, y to posterior, z to superior (DICOM, ITK, Slicer's files).
    Lps,
    /// x to the patient's right, y to anterior, z to superior (NIfTI, nibabel, Slicer's
    /// display): the point `(x, y, z)` in LPS is `(-x, -y, z)` in RAS.
    Ras,
    /// The file does not say.
    #[default]
    Unknown,
}

impl Frame {
    /// The lower-case name used in reports and flags (`lps`, `ras`, `unknown`).
    pub fn name(self) -> &'static str {
        match self {
            Frame::Lps => "lps",
            Frame::Ras => "ras",
            Frame::Unknown => "unknown",
        }
    }

    /// The world matrix that takes coordinates in `self` to coordinates in `target`: LPS and
    /// RAS differ by the sign of x and y; with an unknown frame on either side nothing changes.
    pub fn conversion_to(self, target: Frame) -> DMat3 {
        match (self, target) {
            (Frame::Lps, Frame::Ras) | (Frame::Ras, Frame::Lps) => {
                DMat3::from_diagonal(DVec3::new(-1.0, -1.0, 1.0))
            }
            _ => DMat3::IDENTITY,
        }
    }
}

/// The direction cosines and frame a volume carries beside its [`Grid`] (which holds the
/// origin and spacing). The identity direction in an unknown frame is what formats without
/// orientation give.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Orientation {
    /// Column `c` is the unit world direction of index axis `c`.
    pub direction: DMat3,
    /// The anatomical meaning of the world axes.
    pub frame: Frame,
}

impl Default for Orientation {
    fn default() -> Self {
        Orientation {
            direction: DMat3::IDENTITY,
            frame: Frame::Unknown,
        }
    }
}

impl Orientation {
    /// Whether the direction is the identity (the grid space is the world).
    pub fn is_axis_aligned(&self) -> bool {
        self.direction == DMat3::IDENTITY
    }
}

/// The full index-to-world transform of a volume: `world = origin + direction · (spacing ∘
/// index)`, in `frame`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WorldTransform {
    /// World position of sample (0, 0, 0).
    pub origin: DVec3,
    /// Distance between neighbouring samples along each index axis.
    pub spacing: DVec3,
    /// Columns: unit world directions of the index axes.
    pub direction: DMat3,
    /// The anatomical meaning of the world axes.
    pub frame: Frame,
}

impl WorldTransform {
    /// The transform of a grid with an orientation.
    pub fn of(grid: &Grid, orientation: &Orientation) -> WorldTransform {
        WorldTransform {
            origin: grid.origin_vec(),
            spacing: grid.spacing_vec(),
            direction: orientation.direction,
            frame: orientation.frame,
        }
    }

    /// Splits a 4×4 index-to-world matrix (row-major, last row `0 0 0 1`) into origin, spacing
    /// (the column lengths) and unit directions. Fails on a non-finite matrix or a zero or
    /// degenerate (coplanar) column set.
    pub fn from_matrix(rows: [[f64; 4]; 4], frame: Frame) -> Result<WorldTransform, CoreError> {
        let columns: [DVec3; 3] =
            std::array::from_fn(|c| DVec3::new(rows[0][c], rows[1][c], rows[2][c]));
        let origin = DVec3::new(rows[0][3], rows[1][3], rows[2][3]);
        WorldTransform::from_columns(origin, columns, frame)
    }

    /// A transform from the world vectors of one index step along each axis.
    pub fn from_columns(
        origin: DVec3,
        steps: [DVec3; 3],
        frame: Frame,
    ) -> Result<WorldTransform, CoreError> {
        let bad = |why: &str| CoreError::InvalidGrid(format!("index-to-world transform: {why}"));
        if !origin.is_finite() || steps.iter().any(|s| !s.is_finite()) {
            return Err(bad("not finite"));
        }
        let spacing = DVec3::new(steps[0].length(), steps[1].length(), steps[2].length());
        if spacing.min_element() <= 0.0 {
            return Err(bad("an index axis has zero length"));
        }
        let direction = DMat3::from_cols(
            steps[0] / spacing.x,
            steps[1] / spacing.y,
            steps[2] / spacing.z,
        );
        if direction.determinant().abs() < 1e-6 {
            return Err(bad("the index axes are coplanar"));
        }
        Ok(WorldTransform {
            origin,
            spacing,
            direction: snap_to_identity(direction),
            frame,
        })
    }

    /// The grid (origin and spacing) and the orientation (direction and frame) to store.
    pub fn split(&self, dims: [usize; 3]) -> Result<(Grid, Orientation), CoreError> {
        let grid = Grid::new(dims, self.spacing.to_array(), self.origin.to_array())?;
        Ok((
            grid,
            Orientation {
                direction: self.direction,
                frame: self.frame,
            },
        ))
    }

    /// The same placement expressed in `target` (unchanged when either frame is unknown).
    pub fn in_frame(&self, target: Frame) -> WorldTransform {
        if self.frame == Frame::Unknown || target == Frame::Unknown {
            return *self;
        }
        let f = self.frame.conversion_to(target);
        WorldTransform {
            origin: f * self.origin,
            spacing: self.spacing,
            direction: f * self.direction,
            frame: target,
        }
    }

    /// The 4×4 index-to-world matrix, row-major.
    pub fn matrix(&self) -> [[f64; 4]; 4] {
        let m = self.direction * DMat3::from_diagonal(self.spacing);
        let c = DMat4::from_cols(
            m.x_axis.extend(0.0),
            m.y_axis.extend(0.0),
            m.z_axis.extend(0.0),
            self.origin.extend(1.0),
        );
        std::array::from_fn(|r| c.row(r).to_array())
    }

    /// World position of a (fractional) index.
    pub fn index_to_world(&self, index: DVec3) -> DVec3 {
        self.origin + self.direction * (self.spacing * index)
    }

    /// Whether the transform turns a right-handed index frame into a left-handed world.
    pub fn flips_handedness(&self) -> bool {
        self.direction.determinant() < 0.0
    }

    /// The map from grid space (`origin + spacing · index`, where the samplers and marching
    /// cubes work) to this transform's world, for a volume whose grid starts at `grid_origin`
    /// (its own origin, before any change of frame).
    pub fn placement(&self, grid_origin: DVec3) -> Placement {
        Placement {
            linear: self.direction,
            translation: self.origin - self.direction * grid_origin,
        }
    }

    /// A volume sampled in this scan's axis-aligned grid space, placed in its world: the
    /// scan's direction and frame, and a grid whose first sample is where this transform puts
    /// that point. Cost: none beyond moving the volume.
    pub fn place(&self, volume: crate::Volume) -> Result<crate::Volume, CoreError> {
        let g = volume.grid;
        let to_world = self.placement(self.origin);
        let origin = to_world.linear * g.origin_vec() + to_world.translation;
        let grid = Grid::new(g.dims, g.spacing, origin.to_array())?;
        let orientation = Orientation {
            direction: self.direction,
            frame: self.frame,
        };
        Ok(crate::Volume { grid, ..volume }.oriented(orientation))
    }
}

/// An affine map of finished meshes from grid space to the world: `p ↦ linear · p +
/// translation`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placement {
    /// The linear part.
    pub linear: DMat3,
    /// Where grid-space zero lands.
    pub translation: DVec3,
}

impl Placement {
    /// The map that changes nothing.
    pub const IDENTITY: Placement = Placement {
        linear: DMat3::IDENTITY,
        translation: DVec3::ZERO,
    };

    /// The placement of a volume in its own frame, or converted to `frame`.
    pub fn of(world: &WorldTransform, frame: Option<Frame>) -> Placement {
        match frame {
            Some(target) => world.in_frame(target).placement(world.origin),
            None => world.placement(world.origin),
        }
    }

    /// The change of frame of finished world meshes (a half turn about z between LPS and RAS;
    /// nothing when either frame is unknown).
    pub fn between_frames(from: Frame, to: Frame) -> Placement {
        let known = from != Frame::Unknown && to != Frame::Unknown;
        Placement {
            linear: if known {
                from.conversion_to(to)
            } else {
                DMat3::IDENTITY
            },
            translation: DVec3::ZERO,
        }
    }

    /// Whether the map changes nothing.
    pub fn is_identity(&self) -> bool {
        self.linear == DMat3::IDENTITY && self.translation == DVec3::ZERO
    }

    /// Moves a mesh: positions by the affine map, normals by the inverse transpose of its
    /// linear part, and the winding of every triangle reversed when the map flips handedness,
    /// so outward triangles stay outward.
    pub fn apply(&self, mesh: &mut TriangleMesh) {
        if self.is_identity() {
            return;
        }
        for p in &mut mesh.positions {
            *p = (self.linear * p.as_dvec3() + self.translation).as_vec3();
        }
        let normal_map = self.linear.inverse().transpose();
        for n in &mut mesh.normals {
            *n = (normal_map * n.as_dvec3()).normalize_or_zero().as_vec3();
        }
        if self.linear.determinant() < 0.0 {
            for t in &mut mesh.triangles {
                t.swap(1, 2);
            }
        }
    }
}

/// Direction cosines read from text carry rounding (`0.99999999`): a matrix within 1e-9 of the
/// identity is taken as the identity, so axis-aligned files keep the axis-aligned fast path.
fn snap_to_identity(direction: DMat3) -> DMat3 {
    if direction.abs_diff_eq(DMat3::IDENTITY, 1e-9) {
        DMat3::IDENTITY
    } else {
        direction
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn oblique() -> WorldTransform {
        let rot = DMat3::from_rotation_z(0.5) * DMat3::from_rotation_x(0.3);
        let steps = [
            rot.x_axis * 2.0,
            rot.y_axis * 1.5,
            -rot.z_axis * 3.0, // flipped: left-handed
        ];
        WorldTransform::from_columns(DVec3::new(10.0, -20.0, 5.0), steps, Frame::Lps).unwrap()
    }

    #[test]
    fn matrix_round_trips_and_maps_indices() {
        let t = oblique();
        assert!((t.spacing - DVec3::new(2.0, 1.5, 3.0)).abs().max_element() < 1e-12);
        assert!(t.flips_handedness());
        let back = WorldTransform::from_matrix(t.matrix(), Frame::Lps).unwrap();
        assert!(back.direction.abs_diff_eq(t.direction, 1e-12));
        let m = t.matrix();
        let ijk = DVec3::new(1.0, 2.0, 3.0);
        let by_matrix = DVec3::new(
            m[0][0] + 2.0 * m[0][1] + 3.0 * m[0][2] + m[0][3],
            m[1][0] + 2.0 * m[1][1] + 3.0 * m[1][2] + m[1][3],
            m[2][0] + 2.0 * m[2][1] + 3.0 * m[2][2] + m[2][3],
        );
        assert!((t.index_to_world(ijk) - by_matrix).length() < 1e-9);
    }

    #[test]
    fn frame_conversion_negates_x_and_y() {
        let t = oblique();
        let ras = t.in_frame(Frame::Ras);
        let p = t.index_to_world(DVec3::new(3.0, 1.0, 2.0));
        let q = ras.index_to_world(DVec3::new(3.0, 1.0, 2.0));
        assert!((q - DVec3::new(-p.x, -p.y, p.z)).length() < 1e-9);
        assert_eq!(ras.frame, Frame::Ras);
        assert_eq!(t.in_frame(Frame::Unknown), t);
    }

    #[test]
    fn rejects_degenerate_axes() {
        let z = DVec3::ZERO;
        assert!(
            WorldTransform::from_columns(z, [DVec3::X, DVec3::X, DVec3::Z], Frame::Lps).is_err()
        );
        assert!(WorldTransform::from_columns(z, [DVec3::X, z, DVec3::Z], Frame::Lps).is_err());
        let nan = DVec3::splat(f64::NAN);
        assert!(
            WorldTransform::from_columns(nan, [DVec3::X, DVec3::Y, DVec3::Z], Frame::Lps).is_err()
        );
    }

    #[test]
    fn a_flipping_transform_keeps_triangles_outward() {
        // One triangle of a tetrahedron facing +z in grid space, normal +z.
        let mut mesh = TriangleMesh::new(vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 2]]);
        mesh.normals = vec![Vec3::Z; 3];
        let t = WorldTransform::from_columns(
            DVec3::ZERO,
            [DVec3::X, DVec3::Y, -DVec3::Z],
            Frame::Unknown,
        )
        .unwrap();
        t.placement(DVec3::ZERO).apply(&mut mesh);
        assert_eq!(mesh.triangles, vec![[0, 2, 1]]);
        assert_eq!(mesh.normals[0], -Vec3::Z);
        // The geometric normal of the rewound triangle agrees with the transformed normal.
        let [a, b, c] = mesh.triangles[0].map(|i| mesh.positions[i as usize]);
        assert!((b - a).cross(c - a).dot(mesh.normals[0]) > 0.0);
    }

    #[test]
    fn identity_direction_leaves_the_mesh_alone() {
        let mut mesh = TriangleMesh::new(vec![Vec3::ONE, Vec3::X, Vec3::Y], vec![[0, 1, 2]]);
        let before = mesh.clone();
        let g = Grid::new([2, 2, 2], [0.5, 1.0, 2.0], [3.0, 4.0, 5.0]).unwrap();
        let world = WorldTransform::of(&g, &Orientation::default());
        Placement::of(&world, None).apply(&mut mesh);
        assert_eq!(mesh, before);
        // An unknown frame is not converted; a known one is, about the world's origin.
        Placement::of(&world, Some(Frame::Ras)).apply(&mut mesh);
        assert_eq!(mesh, before);
        let lps = WorldTransform {
            frame: Frame::Lps,
            ..world
        };
        Placement::of(&lps, Some(Frame::Ras)).apply(&mut mesh);
        assert_eq!(mesh.positions[0], Vec3::new(-1.0, -1.0, 1.0));
        assert_eq!(mesh.triangles, before.triangles);
    }
}
