//! What the budgets of a run share ([`BudgetContext`]): the source, the input mesh welded with
//! its topology and border, and the marching-cubes levels built so far, by resolution and
//! isodensity, each built once (module docs of [`crate::budget`], "Independence").

use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};
use voxlod_core::cpu_clock::CpuTimer;

use voxlod_core::components::triangle_components;
use voxlod_core::weld::weld_vertices;
use voxlod_core::{mesh_topology, Topology, TriangleMesh};
use voxlod_render::SilhouetteReference;
use voxlod_sampling::PyramidOptions;

use super::measure::{InputMeasure, Measured};
use super::parts::InputParts;
use super::silhouettes::input_silhouettes;
use super::{Then, DILATED_ISO_FRACTIONS};
use crate::caps::InputBorder;
use crate::error::PyramidError;
use crate::lod::{build_level, plan, LevelOptions, LodLevel, LodSource};

/// What the budgets share: the source, the input mesh and its border, levels built so far.
pub(crate) struct BudgetContext<'a> {
    pub(crate) source: &'a LodSource<'a>,
    pub(crate) level_options: LevelOptions,
    pub(crate) input: Option<&'a TriangleMesh>,
    /// The mesh the levels are sampled from (the input, or the input with its cavities filled),
    /// whose area predicts the resolution for a count.
    pub(super) sampled: Option<&'a TriangleMesh>,
    pub(crate) border: Option<Arc<InputBorder>>,
    /// The input mesh welded and its topology (with a mesh input; not in the context of the
    /// filled input, which leaves step 0 to the input's).
    pub(super) welded: Option<(TriangleMesh, Topology)>,
    pub(super) measure: Option<Arc<InputMeasure<'a>>>,
    pub(crate) input_genus: Option<i64>,
    pub(crate) then: Then,
    pub(crate) time_cap: f64,
    pub(crate) diagonal: f64,
    /// Whether the dilated levels are searched too (module docs, step 1): with a mesh input and
    /// the solid's default isodensity.
    pub(crate) dilated: bool,
    /// The triangles of each connected component of the welded input (found once, for the
    /// distance measure and the detached parts).
    pub(super) part_triangles: Vec<Vec<u32>>,
    /// The input's connected components as meshes, made on first use (module `detached`).
    pub(super) parts: InputParts,
    /// Levels by resolution and isodensity (its bits), with the seconds they took to build.
    levels: Mutex<HashMap<(usize, u32), (LodLevel, f64)>>,
    /// The input's silhouettes, rendered on first use (module `silhouettes`).
    silhouettes: Arc<OnceLock<Result<SilhouetteReference, String>>>,
}

impl<'a> BudgetContext<'a> {
    /// The context of a run; `closed` keeps the caps over an open input's holes.
    pub(crate) fn new(
        source: &'a LodSource<'a>,
        level_options: LevelOptions,
        input: Option<&'a TriangleMesh>,
        then: Then,
        closed: bool,
        time_cap: f64,
    ) -> Result<Self, PyramidError> {
        let border = match (input, closed) {
            (Some(mesh), false) => InputBorder::new(mesh)?,
            _ => None,
        };
        let welded = input.map(|m| {
            let mut mesh = m.clone();
            weld_vertices(&mut mesh);
            mesh.remove_unreferenced_vertices();
            let topology = mesh_topology(&mesh);
            (mesh, topology)
        });
        let input_genus = welded.as_ref().and_then(|w| w.1.genus);
        let part_triangles = (welded.as_ref())
            .map(|(mesh, _)| triangle_components(mesh))
            .unwrap_or_default();
        let measure = input
            .zip(welded.as_ref())
            .and_then(|(input, (welded, _))| InputMeasure::new(input, welded, &part_triangles));
        Ok(BudgetContext {
            source,
            level_options,
            input,
            sampled: input,
            border: border.map(Arc::new),
            welded,
            measure: measure.map(Arc::new),
            input_genus,
            then,
            time_cap,
            diagonal: source.bounds().diagonal(),
            dilated: false,
            part_triangles,
            parts: InputParts::default(),
            levels: Mutex::new(HashMap::new()),
            silhouettes: Arc::default(),
        })
    }
}

impl<'a> BudgetContext<'a> {
    /// The context of the same run over `sampled`, the input with its cavities filled, sampled
    /// as `source` ([`super::filled`]): the same options, border and distance measure against
    /// the input as given, its own levels, and no step 0 (the input's own collapse belongs to
    /// the input's context).
    pub(super) fn filled<'b>(
        &'b self,
        source: &'b LodSource<'b>,
        sampled: &'b TriangleMesh,
    ) -> BudgetContext<'b>
    where
        'a: 'b,
    {
        BudgetContext {
            source,
            level_options: self.level_options.clone(),
            input: self.input,
            sampled: Some(sampled),
            border: self.border.clone(),
            welded: None,
            measure: self.measure.clone(),
            input_genus: self.input_genus,
            then: self.then,
            time_cap: self.time_cap,
            diagonal: self.diagonal,
            dilated: self.dilated,
            part_triangles: Vec::new(),
            parts: {
                self.input_parts();
                self.parts.clone()
            },
            levels: Mutex::new(HashMap::new()),
            silhouettes: self.silhouettes.clone(),
        }
    }

    /// The input's silhouettes (module `silhouettes`), rendered once per run; `None` without an
    /// input mesh.
    pub(super) fn silhouettes(&self) -> Option<&Result<SilhouetteReference, String>> {
        let input = self.input?;
        Some(self.silhouettes.get_or_init(|| input_silhouettes(input)))
    }

    /// Two-sided distance from the input to `mesh`, when there is an input mesh.
    pub(super) fn measure(&self, mesh: &TriangleMesh) -> Option<Measured> {
        self.measure.as_ref()?.measure(mesh)
    }

    /// The isodensities each resolution is contoured at: the surface's, then the dilated one.
    pub(super) fn isos(&self) -> Vec<f32> {
        let surface = self.level_options.iso;
        let dilated = DILATED_ISO_FRACTIONS.map(|f| f * surface);
        std::iter::once(surface)
            .chain(dilated.into_iter().filter(|_| self.dilated))
            .collect()
    }

    /// The marching-cubes level at `resolution` and the seconds it took (built once), at the
    /// surface's isodensity.
    pub(super) fn level(&self, resolution: usize) -> Result<(LodLevel, f64), PyramidError> {
        self.level_at(resolution, self.level_options.iso)
    }

    /// The marching-cubes level at `resolution` and isodensity `iso`, and the CPU seconds it
    /// took (built once).
    pub(super) fn level_at(
        &self,
        resolution: usize,
        iso: f32,
    ) -> Result<(LodLevel, f64), PyramidError> {
        let key = (resolution, iso.to_bits());
        if let Some(found) = self.levels.lock().expect("not poisoned").get(&key) {
            return Ok(found.clone());
        }
        let timer = CpuTimer::start();
        let options = LevelOptions {
            pyramid: PyramidOptions {
                resolutions: vec![resolution],
                ..self.level_options.pyramid.clone()
            },
            iso,
            ..self.level_options.clone()
        };
        let plans = plan(self.source, &options)?;
        let level = build_level(self.source, &plans[0], &options)?;
        let built = (level, timer.seconds());
        self.levels
            .lock()
            .expect("not poisoned")
            .insert(key, built.clone());
        Ok(built)
    }
}
