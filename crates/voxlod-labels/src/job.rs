//! The segmentation stage's one call, [`label_surfaces`]: the map's labels found, the ones asked
//! for chosen, every one meshed in one pass over the map, moved into the frame asked for and
//! checked.
//!
//! Cost: that of the surface chosen (see `marching_cubes.rs` and `surface_nets.rs`) and of the
//! budget when one is asked for (`budget.rs`), plus one pass over the map to find the labels and
//! one over each mesh to check and move it.

use rayon::prelude::*;
use voxlod_core::validate::{find_defect, Requirements};
use voxlod_core::{Frame, LabelVolume, Placement, TriangleMesh};

use crate::budget::{budget_meshes, budget_shared, check_budget, BudgetReport};
use crate::find::{find_labels, select_labels, LabelInfo};
use crate::marching_cubes::marching_cubes_of;
use crate::smoothing::{smooth, SmoothingOptions, SmoothingReport};
use crate::surface_nets::{surface_nets, SharedSurface, SurfaceNetsOptions};
use crate::LabelsError;

/// Which surface every label gets.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum Surface {
    /// Marching cubes of each label's indicator at ½: every label closed and outward on its
    /// own (`marching_cubes.rs`).
    #[default]
    MarchingCubes,
    /// Surface nets over all labels at once, every interface meshed once and shared by its two
    /// labels (`surface_nets.rs`), then smoothed with the volumes kept (`smoothing.rs`;
    /// [`SmoothingOptions::none`] keeps the voxels' faces).
    Shared(SmoothingOptions),
}

/// How [`label_surfaces`] meshes a map.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SurfaceOptions {
    /// The surface.
    pub surface: Surface,
    /// Only these labels, in this order (every non-zero label, increasing, when `None`).
    pub labels: Option<Vec<u32>>,
    /// The frame of the meshes: the map's own when `None`.
    pub frame: Option<Frame>,
    /// Each label's mesh reduced to at most about this many triangles (`budget.rs`): for
    /// [`Surface::Shared`] the smoothed surface simplified patch by patch with the junctions
    /// between patches (and the vertices next to them) locked, so neighbours still share their
    /// triangles, and no patch moved by more than [`crate::budget::MEAN_SHIFT`] voxels on
    /// average; for marching cubes each label's mesh on its own. Labels whose locked vertices
    /// or unbreakable pieces hold more stay above it ([`LabelSurfaces::budget`] lists them).
    /// At least 4; `None` keeps every triangle. Cost: about one quadric simplification of every
    /// triangle, O(F log F), in parallel over patches or labels.
    pub triangles: Option<usize>,
    /// Where the map's first voxel lies in a larger map it is a block of, for
    /// [`Surface::Shared`] (the blockwise route; [`SurfaceNetsOptions::offset`]): the map's
    /// origin is then the larger map's, and the shared surface is placed and smoothed as
    /// there. Zero for a whole map.
    pub offset: [u32; 3],
}

/// One label with its mesh.
#[derive(Clone, Debug)]
pub struct LabelSurface {
    /// The label: its value, voxel count and index box.
    pub label: LabelInfo,
    /// Its voxels' volume: voxel count times the voxel's volume, in world units cubed.
    pub voxel_volume: f64,
    /// Its closed, outward mesh, in the frame of [`SurfaceOptions::frame`].
    pub mesh: TriangleMesh,
}

/// What [`label_surfaces`] returns.
#[derive(Clone, Debug)]
pub struct LabelSurfaces {
    /// Every label asked for with its mesh, in the order of [`SurfaceOptions::labels`].
    pub labels: Vec<LabelSurface>,
    /// What the smoothing of [`Surface::Shared`] did (`None` for marching cubes).
    pub smoothing: Option<SmoothingReport>,
    /// What the budget of [`SurfaceOptions::triangles`] did (`None` without a budget).
    pub budget: Option<BudgetReport>,
}

/// Every label asked for with its mesh: the labels found ([`find_labels`]), chosen
/// ([`select_labels`]: a label the map lacks, or a map of background alone, is an error), meshed
/// by the [`Surface`] asked for in one pass over the map, reduced to the budget of
/// [`SurfaceOptions::triangles`] when there is one, moved into [`SurfaceOptions::frame`] and
/// checked for coordinates beyond 32-bit floats. A budget under 4 is an error.
///
/// ```
/// use voxlod_core::{Grid, LabelVolume};
/// use voxlod_labels::{label_surfaces, SurfaceOptions};
///
/// // A 4 × 4 × 4 map holding one 2 × 2 × 2 block of label 7.
/// let grid = Grid::new([4, 4, 4], [1.0; 3], [0.0; 3]).unwrap();
/// let values = (0..64)
///     .map(|n: usize| [n % 4, n / 4 % 4, n / 16])
///     .map(|at| if at.iter().all(|&a| (1..3).contains(&a)) { 7 } else { 0 })
///     .collect();
/// let map = LabelVolume::from_vec(grid, values).unwrap();
/// let surfaces = label_surfaces(&map, &SurfaceOptions::default())?.labels;
/// assert_eq!(surfaces.len(), 1);
/// assert_eq!((surfaces[0].label.value, surfaces[0].label.voxels), (7, 8));
/// assert_eq!(surfaces[0].voxel_volume, 8.0);
/// assert!(!surfaces[0].mesh.is_empty());
/// # Ok::<(), voxlod_labels::LabelsError>(())
/// ```
pub fn label_surfaces(
    map: &LabelVolume,
    options: &SurfaceOptions,
) -> Result<LabelSurfaces, LabelsError> {
    let plan = Plan::of(map, options)?;
    let meshed = mesh(map, &plan, &options.surface)?;
    finish(plan, meshed)
}

/// [`label_surfaces`], taking the map and dropping it as soon as the labels' surface is made:
/// the shared surface's smoothing and the labels' meshes then run without it, so the peak is
/// the map and the surface, or the surface and the meshes, not all three.
pub fn label_surfaces_owned(
    map: LabelVolume,
    options: &SurfaceOptions,
) -> Result<LabelSurfaces, LabelsError> {
    let plan = Plan::of(&map, options)?;
    let meshed = mesh(&map, &plan, &options.surface)?;
    drop(map);
    finish(plan, meshed)
}

/// What the labels' meshes need from the map once it is gone: the labels chosen, the change of
/// frame, the voxel's volume.
struct Plan {
    chosen: Vec<LabelInfo>,
    to_frame: Placement,
    voxel: f64,
    triangles: Option<usize>,
    offset: [u32; 3],
}

impl Plan {
    fn of(map: &LabelVolume, options: &SurfaceOptions) -> Result<Plan, LabelsError> {
        if let Some(n) = options.triangles {
            check_budget(n)?;
        }
        let chosen = select_labels(find_labels(map), options.labels.as_deref())?;
        let to_frame = options.frame.map_or(Placement::IDENTITY, |target| {
            Placement::between_frames(map.orientation.frame, target)
        });
        let voxel = map.grid.spacing.iter().product::<f64>();
        Ok(Plan {
            chosen,
            to_frame,
            voxel,
            triangles: options.triangles,
            offset: options.offset,
        })
    }
}

/// The surface made from the map: the labels' meshes, or the shared surface to smooth.
enum Meshed<'a> {
    Meshes(Vec<TriangleMesh>),
    Shared(Box<SharedSurface>, &'a SmoothingOptions),
}

/// The pass over the map of the [`Surface`] asked for.
fn mesh<'a>(
    map: &LabelVolume,
    plan: &Plan,
    surface: &'a Surface,
) -> Result<Meshed<'a>, LabelsError> {
    Ok(match surface {
        Surface::MarchingCubes => Meshed::Meshes(marching_cubes_of(map, &plan.chosen)?),
        Surface::Shared(smoothing) => {
            let nets = SurfaceNetsOptions {
                offset: plan.offset,
                ..SurfaceNetsOptions::default()
            };
            let shared = surface_nets(map, &nets)?;
            Meshed::Shared(Box::new(shared), smoothing)
        }
    })
}

/// The labels' meshes (the shared surface smoothed, reduced to the budget and taken apart
/// first), moved into the frame and checked.
fn finish(plan: Plan, meshed: Meshed) -> Result<LabelSurfaces, LabelsError> {
    let values: Vec<u32> = plan.chosen.iter().map(|l| l.value).collect();
    let (meshes, smoothing, kept) = match (meshed, plan.triangles) {
        (Meshed::Shared(mut shared, options), budget) => {
            let report = smooth(&mut shared, options)?;
            let (meshes, kept) = match budget {
                Some(n) => budget_shared(&shared, &values, n)?,
                None => (shared.label_meshes(&values)?, 0),
            };
            (meshes, Some(report), kept)
        }
        (Meshed::Meshes(mut meshes), Some(n)) => {
            let kept = budget_meshes(&mut meshes, n)?;
            (meshes, None, kept)
        }
        (Meshed::Meshes(meshes), None) => (meshes, None, 0),
    };
    let budget = plan
        .triangles
        .map(|n| BudgetReport::of(n, &values, &meshes, kept));
    let Plan {
        chosen,
        to_frame,
        voxel,
        ..
    } = plan;
    let labels = chosen
        .into_par_iter()
        .zip(meshes)
        .map(|(label, mut mesh)| {
            to_frame.apply(&mut mesh);
            if let Some(defect) = find_defect(&mesh, &Requirements::computed()) {
                return Err(LabelsError::BeyondRange(label.value, defect.to_string()));
            }
            Ok(LabelSurface {
                voxel_volume: label.voxels as f64 * voxel,
                label,
                mesh,
            })
        })
        .collect::<Result<_, _>>()?;
    Ok(LabelSurfaces {
        labels,
        smoothing,
        budget,
    })
}
