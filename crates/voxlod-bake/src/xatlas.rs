//! xatlas (Ignacio Castaño's and Jonathan Young's atlas generator), as the `xatlas-rs` crate
//! vendors it, called through a safe interface: one mesh in, its charts parameterized and
//! packed, the unwelded mesh with texel-space coordinates out.
//!
//! **Workaround.** `xatlas-rs` 0.1.3 compiles and links xatlas's C++ source (`vendor/xatlas.cpp`
//! of 2019), but its Rust bindings name the functions by their MSVC-mangled symbols
//! (`?Create@xatlas@@…`), so a program that calls them does not link with GCC or Clang
//! (Itanium C++ ABI: Linux, macOS). This module is the one place that works around it: it
//! declares the functions itself under their Itanium names (on MSVC targets, the crate's own
//! MSVC names, which are not built or tested here), with the structures laid out as the
//! vendored `xatlas.h` declares them, and links the library `xatlas-rs` builds. Nothing else in voxlod calls xatlas. Diagnostics that xatlas
//! would print to standard output are switched off; [`Generated`] carries what is needed to
//! check its result instead.
//!
//! Cost: as xatlas: chart growing and least-squares conformal maps, near-linear in the
//! triangles; packing tries `attempts` random places per chart on a bit image of the atlas.

use std::os::raw::{c_char, c_int, c_void};

// The library itself: only its build script's static library is used (see above).
use xatlas_rs as _;

/// xatlas's `ChartOptions` (xatlas.h): how charts grow.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub(crate) struct ChartOptions {
    pub max_chart_area: f32,
    pub max_boundary_length: f32,
    pub proxy_fit_metric_weight: f32,
    pub roundness_metric_weight: f32,
    pub straightness_metric_weight: f32,
    /// Above 1000, normal seams are always chart borders.
    pub normal_seam_metric_weight: f32,
    pub texture_seam_metric_weight: f32,
    pub max_threshold: f32,
    pub grow_face_count: u32,
    pub max_iterations: u32,
}

impl Default for ChartOptions {
    /// xatlas's defaults.
    fn default() -> Self {
        ChartOptions {
            max_chart_area: 0.0,
            max_boundary_length: 0.0,
            proxy_fit_metric_weight: 2.0,
            roundness_metric_weight: 0.01,
            straightness_metric_weight: 6.0,
            normal_seam_metric_weight: 4.0,
            texture_seam_metric_weight: 0.5,
            max_threshold: 2.0,
            grow_face_count: 32,
            max_iterations: 1,
        }
    }
}

/// xatlas's `PackOptions` (xatlas.h): how charts are packed.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub(crate) struct PackOptions {
    pub attempts: c_int,
    pub texels_per_unit: f32,
    /// 0: one atlas as large as `texels_per_unit` needs; else atlases of exactly this size.
    pub resolution: u32,
    pub max_chart_size: u32,
    pub block_align: bool,
    /// Needed for `padding` to apply.
    pub conservative: bool,
    pub padding: u32,
}

#[repr(C)]
struct RawChart {
    atlas_index: u32,
    index_array: *mut u32,
    index_count: u32,
}

#[repr(C)]
#[derive(Clone, Copy)]
struct RawVertex {
    atlas_index: i32,
    uv: [f32; 2],
    xref: u32,
}

#[repr(C)]
struct RawMesh {
    chart_array: *mut RawChart,
    chart_count: u32,
    index_array: *mut u32,
    index_count: u32,
    vertex_array: *mut RawVertex,
    vertex_count: u32,
}

#[repr(C)]
struct RawAtlas {
    width: u32,
    height: u32,
    atlas_count: u32,
    chart_count: u32,
    mesh_count: u32,
    meshes: *mut RawMesh,
    utilization: *mut f32,
    texels_per_unit: f32,
}

#[repr(C)]
struct MeshDecl {
    vertex_count: u32,
    vertex_position_data: *const c_void,
    vertex_position_stride: u32,
    vertex_normal_data: *const c_void,
    vertex_normal_stride: u32,
    vertex_uv_data: *const c_void,
    vertex_uv_stride: u32,
    index_count: u32,
    index_data: *const c_void,
    index_offset: i32,
    /// 1: `u32` indices.
    index_format: c_int,
    face_ignore_data: *const bool,
}

type ProgressFunc = Option<unsafe extern "C" fn(c_int, c_int, *mut c_void)>;
type ParameterizeFunc =
    Option<unsafe extern "C" fn(*const f32, *mut f32, u32, *const u32, u32, bool)>;
type PrintFunc = Option<unsafe extern "C" fn(*const c_char, ...) -> c_int>;

extern "C" {
    #[cfg_attr(target_env = "msvc", link_name = "?Create@xatlas@@YAPEAUAtlas@1@XZ")]
    #[cfg_attr(not(target_env = "msvc"), link_name = "_ZN6xatlas6CreateEv")]
    fn xatlas_create() -> *mut RawAtlas;

    #[cfg_attr(target_env = "msvc", link_name = "?Destroy@xatlas@@YAXPEAUAtlas@1@@Z")]
    #[cfg_attr(not(target_env = "msvc"), link_name = "_ZN6xatlas7DestroyEPNS_5AtlasE")]
    fn xatlas_destroy(atlas: *mut RawAtlas);

    #[cfg_attr(
        target_env = "msvc",
        link_name = "?AddMesh@xatlas@@YA?AW4Enum@AddMeshError@1@PEAUAtlas@1@AEBUMeshDecl@1@@Z"
    )]
    #[cfg_attr(
        not(target_env = "msvc"),
        link_name = "_ZN6xatlas7AddMeshEPNS_5AtlasERKNS_8MeshDeclE"
    )]
    fn xatlas_add_mesh(atlas: *mut RawAtlas, decl: *const MeshDecl) -> c_int;

    #[cfg_attr(
        target_env = "msvc",
        link_name = "?ComputeCharts@xatlas@@YAXPEAUAtlas@1@UChartOptions@1@P6AXW4Enum@ProgressCategory@1@HPEAX@Z3@Z"
    )]
    #[cfg_attr(
        not(target_env = "msvc"),
        link_name = "_ZN6xatlas13ComputeChartsEPNS_5AtlasENS_12ChartOptionsEPFvNS_16ProgressCategory4EnumEiPvES5_"
    )]
    fn xatlas_compute_charts(
        atlas: *mut RawAtlas,
        options: ChartOptions,
        progress: ProgressFunc,
        user: *mut c_void,
    );

    #[cfg_attr(
        target_env = "msvc",
        link_name = "?ParameterizeCharts@xatlas@@YAXPEAUAtlas@1@P6AXPEBMPEAMIPEBII_N@ZP6AXW4Enum@ProgressCategory@1@HPEAX@Z7@Z"
    )]
    #[cfg_attr(
        not(target_env = "msvc"),
        link_name = "_ZN6xatlas18ParameterizeChartsEPNS_5AtlasEPFvPKfPfjPKjjbEPFvNS_16ProgressCategory4EnumEiPvESB_"
    )]
    fn xatlas_parameterize_charts(
        atlas: *mut RawAtlas,
        func: ParameterizeFunc,
        progress: ProgressFunc,
        user: *mut c_void,
    );

    #[cfg_attr(
        target_env = "msvc",
        link_name = "?PackCharts@xatlas@@YAXPEAUAtlas@1@UPackOptions@1@P6AXW4Enum@ProgressCategory@1@HPEAX@Z3@Z"
    )]
    #[cfg_attr(
        not(target_env = "msvc"),
        link_name = "_ZN6xatlas10PackChartsEPNS_5AtlasENS_11PackOptionsEPFvNS_16ProgressCategory4EnumEiPvES5_"
    )]
    fn xatlas_pack_charts(
        atlas: *mut RawAtlas,
        options: PackOptions,
        progress: ProgressFunc,
        user: *mut c_void,
    );

    #[cfg_attr(target_env = "msvc", link_name = "?SetPrint@xatlas@@YAXP6AHPEBDZZ_N@Z")]
    #[cfg_attr(not(target_env = "msvc"), link_name = "_ZN6xatlas8SetPrintEPFiPKczEb")]
    fn xatlas_set_print(print: PrintFunc, verbose: bool);
}

/// One output vertex: texel-space coordinates (0..width, 0..height) and the input vertex it
/// copies; `chart` is `None` for a vertex of a triangle xatlas ignored (degenerate).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct OutVertex {
    pub uv: [f32; 2],
    pub input: u32,
    pub chart: Option<u32>,
}

/// What xatlas made of one mesh.
#[derive(Clone, Debug)]
pub(crate) struct Generated {
    pub width: u32,
    pub height: u32,
    /// How many atlases the charts needed (1 unless a fixed resolution was too small).
    pub atlas_count: u32,
    pub chart_count: u32,
    pub vertices: Vec<OutVertex>,
    /// Output triangles, in the input's triangle order.
    pub triangles: Vec<[u32; 3]>,
}

/// An xatlas atlas holding one mesh added as pieces (xatlas charts pieces side by side and
/// packs them together), destroyed on drop.
pub(crate) struct Xatlas {
    handle: *mut RawAtlas,
    pieces: Vec<Piece>,
}

/// One piece of the mesh as xatlas holds it: the mesh's vertex and triangle of each of its own.
struct Piece {
    vertices: Vec<u32>,
    triangles: Vec<u32>,
}

impl Xatlas {
    /// An atlas of the mesh with `positions` and `normals` (one per vertex; a normal seam,
    /// where the two sides of an edge have different vertices with different normals, is a
    /// crease) and `triangles`, added as `pieces` (lists of triangles that together name each
    /// triangle once; a piece's border is a chart border). Fails when xatlas refuses a piece.
    pub fn new(
        positions: &[[f32; 3]],
        normals: &[[f32; 3]],
        triangles: &[[u32; 3]],
        pieces: &[Vec<u32>],
    ) -> Result<Xatlas, String> {
        assert_eq!(positions.len(), normals.len());
        // SAFETY: Create returns a fresh atlas that only this value owns; SetPrint(null)
        // only stops xatlas from printing.
        let handle = unsafe {
            xatlas_set_print(None, false);
            xatlas_create()
        };
        if handle.is_null() {
            return Err("xatlas could not create an atlas".into());
        }
        let mut atlas = Xatlas {
            handle,
            pieces: Vec::with_capacity(pieces.len()),
        };
        let mut local = vec![u32::MAX; positions.len()];
        for piece in pieces {
            let mut vertices = Vec::new();
            let mut piece_triangles = Vec::with_capacity(piece.len());
            for &t in piece {
                let corners = triangles
                    .get(t as usize)
                    .ok_or("a piece names no triangle")?;
                piece_triangles.push(corners.map(|v| {
                    let slot = &mut local[v as usize];
                    if *slot == u32::MAX {
                        *slot = vertices.len() as u32;
                        vertices.push(v);
                    }
                    *slot
                }));
            }
            let at = |v: &u32| positions[*v as usize];
            let piece_positions: Vec<[f32; 3]> = vertices.iter().map(at).collect();
            let piece_normals: Vec<[f32; 3]> =
                vertices.iter().map(|v| normals[*v as usize]).collect();
            for &v in &vertices {
                local[v as usize] = u32::MAX;
            }
            atlas.add(&piece_positions, &piece_normals, &piece_triangles)?;
            atlas.pieces.push(Piece {
                vertices,
                triangles: piece.clone(),
            });
        }
        Ok(atlas)
    }

    /// Adds one piece as an xatlas mesh.
    fn add(
        &mut self,
        positions: &[[f32; 3]],
        normals: &[[f32; 3]],
        triangles: &[[u32; 3]],
    ) -> Result<(), String> {
        let decl = MeshDecl {
            vertex_count: positions.len() as u32,
            vertex_position_data: positions.as_ptr().cast(),
            vertex_position_stride: 12,
            vertex_normal_data: normals.as_ptr().cast(),
            vertex_normal_stride: 12,
            vertex_uv_data: std::ptr::null(),
            vertex_uv_stride: 0,
            index_count: (triangles.len() * 3) as u32,
            index_data: triangles.as_ptr().cast(),
            index_offset: 0,
            index_format: 1,
            face_ignore_data: std::ptr::null(),
        };
        // SAFETY: the declaration points at live slices of the lengths it states; xatlas
        // copies them before returning.
        let code = unsafe { xatlas_add_mesh(self.handle, &decl) };
        match code {
            0 => Ok(()),
            1 => Err("a triangle names a vertex out of range".into()),
            2 => Err("the index count is not a multiple of 3".into()),
            other => Err(format!("AddMesh returned {other}")),
        }
    }

    /// Grows and parameterizes the charts.
    pub fn charts(&mut self, options: ChartOptions) {
        // SAFETY: the handle is live and holds a mesh; no callbacks are passed.
        unsafe {
            xatlas_compute_charts(self.handle, options, None, std::ptr::null_mut());
            xatlas_parameterize_charts(self.handle, None, None, std::ptr::null_mut());
        }
    }

    /// Packs the charts (after [`charts`](Self::charts)) and reads the result. Fails where
    /// xatlas returns another number of triangles than a piece holds.
    pub fn pack(&mut self, options: PackOptions) -> Result<Generated, String> {
        // SAFETY: the handle is live with its charts parameterized; PackCharts replaces the
        // output meshes, which are read below before any other call.
        unsafe {
            xatlas_pack_charts(self.handle, options, None, std::ptr::null_mut());
            self.read()
        }
    }

    /// Copies the output of the last packing: the pieces' vertices one after another, their
    /// charts numbered on, the triangles back in the mesh's order.
    ///
    /// # Safety
    /// The atlas must have been packed.
    unsafe fn read(&self) -> Result<Generated, String> {
        let atlas = &*self.handle;
        let mut generated = Generated {
            width: atlas.width,
            height: atlas.height,
            atlas_count: atlas.atlas_count,
            chart_count: 0,
            vertices: Vec::new(),
            triangles: Vec::new(),
        };
        let meshes = slice(atlas.meshes, atlas.mesh_count);
        if meshes.len() != self.pieces.len() {
            return Err(format!(
                "xatlas returned {} meshes for {} pieces",
                meshes.len(),
                self.pieces.len()
            ));
        }
        let total = self.pieces.iter().map(|p| p.triangles.len()).sum();
        generated.triangles = vec![[0; 3]; total];
        for (mesh, piece) in meshes.iter().zip(&self.pieces) {
            let first_vertex = generated.vertices.len() as u32;
            let vertices = slice(mesh.vertex_array, mesh.vertex_count);
            let mut chart_of = vec![None; vertices.len()];
            for (c, chart) in slice(mesh.chart_array, mesh.chart_count).iter().enumerate() {
                for &v in slice(chart.index_array, chart.index_count) {
                    chart_of[v as usize] = Some(generated.chart_count + c as u32);
                }
            }
            generated.chart_count += mesh.chart_count;
            generated
                .vertices
                .extend(vertices.iter().zip(chart_of).map(|(v, chart)| OutVertex {
                    uv: v.uv,
                    input: piece.vertices[v.xref as usize],
                    chart,
                }));
            let indices = slice(mesh.index_array, mesh.index_count);
            if indices.len() != 3 * piece.triangles.len() {
                let (got, held) = (indices.len() / 3, piece.triangles.len());
                return Err(format!(
                    "xatlas returned {got} triangles for a piece of {held}"
                ));
            }
            for (t, corners) in piece.triangles.iter().zip(indices.chunks_exact(3)) {
                generated.triangles[*t as usize] =
                    [corners[0], corners[1], corners[2]].map(|v| first_vertex + v);
            }
        }
        Ok(generated)
    }
}

/// The `n` values at `p` (none where `n` is 0, whatever `p` is).
///
/// # Safety
/// Where `n` > 0, `p` must point at `n` live values.
unsafe fn slice<'a, T>(p: *const T, n: u32) -> &'a [T] {
    if n == 0 || p.is_null() {
        &[]
    } else {
        std::slice::from_raw_parts(p, n as usize)
    }
}

impl Drop for Xatlas {
    fn drop(&mut self) {
        // SAFETY: the handle came from Create and is destroyed once.
        unsafe { xatlas_destroy(self.handle) }
    }
}
