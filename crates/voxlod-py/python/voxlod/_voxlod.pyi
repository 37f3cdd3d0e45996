"""Type stubs of the extension module ``voxlod._voxlod`` (the Rust half; call the functions of
:mod:`voxlod`, which check their arguments, instead)."""

from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple

import numpy as np
import numpy.typing as npt

__version__: str

F32 = npt.NDArray[np.float32]
I32 = npt.NDArray[np.int32]
U64 = npt.NDArray[np.uint64]

def memory_available() -> int: ...
def marching_cubes(
    volume: F32, level: float, descent: bool, mask: Optional[npt.NDArray[np.bool_]] = ...
) -> Tuple[F32, I32, F32, F32]: ...
def gaussian_filter(
    input: npt.NDArray[np.floating], sigma: Sequence[float], truncate: float, mode: str, cval: float
) -> npt.NDArray[np.floating]: ...
def contour_block(
    block: F32,
    level: float,
    offset: Sequence[int],
    own_start: Sequence[int],
    own_stop: Sequence[int],
    shape: Sequence[int],
) -> Tuple[F32, I32, F32, U64, U64]: ...
def stitch(pieces: List[Tuple[F32, I32, F32, U64, U64]]) -> Tuple[F32, I32, F32]: ...

Mesh = Tuple[F32, npt.NDArray[np.uint32]]
LevelArgs = Tuple[List[int], str, float, Optional[float], bool, bool]
Progress = Optional[Callable[[int, int, str], Optional[bool]]]

ScanArgs = Tuple[Sequence[int], Sequence[float], Sequence[float], float, LevelArgs]
BlockAnswer = Any  # float (the block's one value) or (crossings, indices u32, values f32, leaf positions u32, leaves f32)

def lod_threshold_blockwise(
    shape: Sequence[int],
    spacing: Sequence[float],
    origin: Sequence[float],
    threshold: float,
    levels: LevelArgs,
    run_level: Callable[[int, List[Tuple[Tuple[int, int, int], Tuple[int, int, int], Tuple[int, int, int]]]], List[BlockAnswer]],
    progress: Progress = ...,
) -> Tuple[List[Dict[str, Any]], List[str]]: ...
def fill_threshold_block(window: F32, scan: ScanArgs, level: int, block: Sequence[int]) -> BlockAnswer: ...

# shape, spacing, origin, (smallest, largest finite sample), window side, levels
DirectArgs = Tuple[Sequence[int], Sequence[float], Sequence[float], Tuple[float, float], int, LevelArgs]

def lod_direct_blockwise(
    shape: Sequence[int],
    spacing: Sequence[float],
    origin: Sequence[float],
    range: Tuple[float, float],
    window: int,
    levels: LevelArgs,
    run_level: Callable[[int, List[Tuple[Tuple[int, int, int], Tuple[int, int, int], Tuple[int, int, int]]]], List[F32]],
    progress: Progress = ...,
) -> Tuple[List[Dict[str, Any]], List[str]]: ...
def fill_direct_block(window: F32, scan: DirectArgs, level: int, block: Sequence[int]) -> F32: ...
def lod_mesh(mesh: Mesh, levels: LevelArgs, progress: Progress = ...) -> Tuple[List[Dict[str, Any]], List[str]]: ...
BudgetArgs = Tuple[Optional[List[int]], Optional[str], str, bool, float]
def lod_budgets(mesh: Mesh, levels: LevelArgs, budgets: BudgetArgs, progress: Progress = ...) -> Tuple[List[Dict[str, Any]], List[str]]: ...
def lod_volume(
    volume: F32,
    spacing: Sequence[float],
    origin: Sequence[float],
    threshold: Optional[float],
    levels: LevelArgs,
    progress: Progress = ...,
) -> Tuple[List[Dict[str, Any]], List[str]]: ...
def read_mesh(path: str) -> Tuple[F32, I32, F32]: ...
def write_mesh(path: str, mesh: Mesh) -> None: ...
def read_scene(path: str) -> Dict[str, Any]: ...
def write_scene(
    path: str,
    levels: List[Tuple[Any, ...]],
    layout: str,
    compress: bool = False,
    origin: Sequence[float] = ...,
) -> None: ...
def read_volume(
    path: str, raw: Optional[Tuple[Sequence[int], str, str, Sequence[float], Sequence[float]]] = ...
) -> Tuple[F32, Tuple[float, float, float], Tuple[float, float, float]]: ...
def write_volume(path: str, volume: F32, spacing: Sequence[float], origin: Sequence[float]) -> None: ...
def inspect(mesh: Mesh, welded: bool) -> Tuple[Dict[str, Any], List[str]]: ...
def compare(a: Mesh, b: Mesh, samples: int, seed: Optional[int] = ...) -> Dict[str, Any]: ...
def cluster(mesh: Mesh, method: str, cells: int, levels: int) -> List[Dict[str, Any]]: ...
def envelope(
    mesh: Mesh, epsilons: List[float], progress: Progress = ..., *, relative: bool = ..., tight: bool = ...
) -> List[Dict[str, Any]]: ...
def layers(mesh: Mesh, error: float, resolution: int, filter: str, progress: Progress = ...) -> List[Dict[str, Any]]: ...
def labels(
    map: np.ndarray,
    spacing: Sequence[float],
    origin: Sequence[float],
    labels: Optional[List[int]],
    options: Tuple[int, str, float, bool],
) -> List[Dict[str, Any]]: ...
def label_surfaces(
    map: np.ndarray,
    spacing: Tuple[float, float, float],
    origin: Tuple[float, float, float],
    labels: Optional[List[int]],
    shared: bool,
    smooth: Optional[int],
    normals: bool,
    triangles: Optional[int] = None,
    offset: Optional[Tuple[int, int, int]] = None,
    pressures: Optional[List[Tuple[List[int], List[float]]]] = None,
) -> Tuple[List[Dict[str, Any]], Optional[Dict[str, Any]]]: ...
RESTORE_ROUNDS: int
_Sums = Tuple[List[List[int]], List[int], float]
def shared_sums(
    block: np.ndarray,
    spacing: Tuple[float, float, float],
    origin: Tuple[float, float, float],
    offset: Tuple[int, int, int],
    owned_lo: Tuple[int, int, int],
    owned_hi: Tuple[int, int, int],
    smooth: Optional[int],
    pressures: List[Tuple[List[int], List[float]]],
) -> Tuple[_Sums, _Sums, _Sums]: ...
def shared_pressure(
    blocks: List[Tuple[_Sums, _Sums, _Sums]], smooth: Optional[int]
) -> Optional[Tuple[List[int], List[float]]]: ...
def write_precomputed(
    dir: str,
    map: np.ndarray,
    spacing: Tuple[float, float, float],
    origin: Tuple[float, float, float],
    meshes: List[Tuple[int, List[Tuple[np.ndarray, np.ndarray]]]],
    options: Tuple[int, int, float, str],
) -> Dict[str, Any]: ...
def chunk_labels(
    chunk: F32, offset: Sequence[int]
) -> Tuple[List[int], List[int], List[Tuple[int, int, int]], List[Tuple[int, int, int]]]: ...
