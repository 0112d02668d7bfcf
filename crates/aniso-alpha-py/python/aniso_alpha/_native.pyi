# Type stubs of the Rust extension module `aniso_alpha._native`
# (crates/aniso-alpha-py/src/lib.rs). The public, documented API is the
# package `aniso_alpha`; these are its private building blocks.

from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

__version__: str

_Triple = Tuple[float, float, float]

def delaunay(points: ArrayLike, threads: Optional[int] = None) -> NDArray[np.uint32]:
    """Finite tets, uint32 (m, 4), input indices, positively oriented."""

def alpha_intervals(
    points: ArrayLike,
    elongation: Optional[_Triple] = None,
    euler: Optional[_Triple] = None,
    threads: Optional[int] = None,
) -> Tuple[NDArray[np.uint32], NDArray[np.float64], NDArray[np.uint32], NDArray[np.float64]]:
    """(edges, edge [alpha_min, alpha_max], triangles, triangle [alpha_min, alpha_max]), rows sorted."""

class NativeDetection:
    """A detection kept on the Rust side (for the meshes `write` adds)."""

class LasSource:
    """A LAS/LAZ file's header, VLRs and records (for `write`)."""

_DetectOut = Tuple[NDArray[np.int64], NDArray[np.int64], str, List[str], NativeDetection]

def detect(
    points: Any,
    structure: str,
    options: Optional[Dict[str, Any]] = None,
    threads: Optional[int] = None,
    normals: Optional[ArrayLike] = None,
    progress: Optional[Callable[[int, int], Optional[bool]]] = None,
    outlines: bool = True,
) -> _DetectOut:
    """(labels, part_labels, JSON text of {"structures": [...], "parameters": {...}},
    warnings, the detection)."""

_PartRow = Tuple[int, int, int, int, List[float], List[float], float]
# A region run: labels, part_labels, parts, regions, widened, joins, skipped, warnings.
_RunOut = Tuple[NDArray[np.int64], NDArray[np.int64], List[_PartRow], int, int, int, int, List[str]]

def detect_regions(
    points: Any,
    structure: str,
    side: Optional[float] = None,
    options: Optional[Dict[str, Any]] = None,
    threads: Optional[int] = None,
    normals: Optional[ArrayLike] = None,
    progress: Optional[Callable[[int, int], Optional[bool]]] = None,
    jobs: Optional[int] = None,
) -> Tuple[_RunOut, Optional[float]]:
    """(the run, the side used)."""

class RegionPlan:
    """The regions of a cloud (aniso_alpha.distributed.detect_regions)."""

    def __len__(self) -> int: ...
    @property
    def side(self) -> Optional[float]: ...
    @property
    def first_margin(self) -> float: ...
    def core(self, r: int) -> NDArray[np.uint32]: ...
    def points_within(self, points: ArrayLike, r: int, margin: float) -> NDArray[np.uint32]: ...

def region_plan(points: ArrayLike, side: Optional[float] = None) -> RegionPlan: ...

_StepArrays = Tuple[
    NDArray[np.int64], NDArray[np.int64], NDArray[np.uint32], NDArray[np.float64], int, float, bool, bool
]

def region_task(
    points: ArrayLike,
    structure: str,
    margin: float,
    options: Optional[Dict[str, Any]] = None,
    normals: Optional[ArrayLike] = None,
    threads: Optional[int] = None,
) -> Tuple[str, float, Optional[_StepArrays]]:
    """("skip" | "wider" | "step", margin, the step's arrays or None)."""

class RegionJoin:
    """The joining of region steps on the driver."""

    def __init__(self, n: int, scratch: Optional[str] = None) -> None: ...
    def widened(self) -> None: ...
    def add(
        self, ids: NDArray[np.uint32], core: NDArray[np.uint32], step: Optional[_StepArrays] = None
    ) -> None: ...
    def resolve(self) -> RegionJoined: ...
    def finish(self, points: ArrayLike) -> _RunOut: ...

class RegionJoined:
    """The joined parts of a region run, on a driver that streams the points
    (aniso_alpha.distributed.detect_tiles)."""

    def __len__(self) -> int: ...
    def labels(self, first: int, n: int) -> Tuple[NDArray[np.int64], NDArray[np.int64]]:
        """(structure labels, part labels) of points first..first + n."""
    def refit(self, first: int, points: ArrayLike) -> None: ...
    def end_pass(self) -> None: ...
    def finish(self) -> _RunOut:
        """The run, its labels empty."""

def region_grid(
    lo: Sequence[float], hi: Sequence[float], n: int, side: Optional[float] = None
) -> Tuple[Tuple[float, float], float, Optional[float], float]:
    """(origin, side run with, side reported, first margin)."""

def region_cells(points: ArrayLike, origin: Tuple[float, float], side: float) -> NDArray[np.int64]: ...
def region_window(
    origin: Tuple[float, float], side: float, cell: Tuple[int, int], margin: float
) -> Tuple[float, float, float, float]: ...
def region_select(
    points: ArrayLike, origin: Tuple[float, float], side: float, cell: Tuple[int, int], margin: float
) -> Tuple[NDArray[np.uint32], NDArray[np.bool_]]: ...

class Plan:
    """A split detection run (aniso_alpha.distributed); made by `plan`."""

    @property
    def halo(self) -> float:
        """The halo width: the largest 2·alpha·lambda_max of the jobs."""
    @property
    def tile(self) -> float:
        """The tile side."""
    @property
    def jobs(self) -> int:
        """The number of jobs (orientations)."""
    @property
    def warnings(self) -> List[str]:
        """The warnings the CLI would print for this run."""
    def with_tile(self, tile: float) -> "Plan":
        """The same plan with tiles of another side."""
    def tiles(self, points: ArrayLike) -> List[Tuple[Tuple[int, int, int], NDArray[np.uint32]]]:
        """(cell, ids ascending) per tile."""
    def members(
        self, ids: NDArray[np.uint32]
    ) -> Optional[Tuple[NDArray[np.uint64], NDArray[np.uint32]]]:
        """(offsets, positions) of each group's members among ids, or None (every point)."""
    def step_spec(
        self,
    ) -> Tuple[str, float, NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.uint32]]:
        """(kind, side, rotations (j, 3, 3), elongations (j, 3), alphas (j,), groups (j,))."""
    def finish(
        self,
        points: ArrayLike,
        outputs: List[Tuple[NDArray[np.uint32], NDArray[np.uint64], int]],
        threads: Optional[int] = None,
    ) -> _DetectOut:
        """(labels, part_labels, JSON report, warnings, detection) from the tiles' outputs."""

def plan(
    points: ArrayLike,
    structure: str,
    tile: float,
    options: Optional[Dict[str, Any]] = None,
    threads: Optional[int] = None,
    normals: Optional[ArrayLike] = None,
) -> Plan:
    """The plan of a split run with tiles of side `tile`."""

def tile_step(
    kind: str,
    side: float,
    rotations: NDArray[np.float64],
    elongations: NDArray[np.float64],
    alphas: NDArray[np.float64],
    groups: NDArray[np.uint32],
    cell: Tuple[int, int, int],
    points: ArrayLike,
    ids: NDArray[np.uint32],
    member_offsets: Optional[NDArray[np.uint64]] = None,
    member_ids: Optional[NDArray[np.uint32]] = None,
    threads: Optional[int] = None,
) -> Tuple[NDArray[np.uint32], NDArray[np.uint64], int]:
    """(faces flat, offsets per job, points triangulated) of one tile."""

def read(
    path: str, attributes: bool = True, start: Optional[int] = None, count: Optional[int] = None
) -> Tuple[
    NDArray[np.float64],
    List[Tuple[str, NDArray[Any]]],
    Optional[NDArray[np.float64]],
    List[str],
    Optional[LasSource],
    str,
    Optional[NDArray[np.int64]],
]:
    """(points, attributes, normals, warnings, LAS source, format name, the
    file row of each point when an organized cloud's points without a
    return were left out)."""

def read_las_records(path: str, start: int, count: int) -> Tuple[NDArray[np.float64], LasSource]:
    """The points start..start + count of a LAS/LAZ file and their records."""

def las_points(path: str) -> int:
    """The number of points a LAS/LAZ file declares."""

class LasLabelWriter:
    """A labelled copy of a LAS/LAZ file written a range at a time."""

    def __init__(self, path: str, las: LasSource, points: int, classify: Optional[int] = None) -> None: ...
    def append(self, las: LasSource, labels: NDArray[np.int64], part_labels: NDArray[np.int64]) -> None: ...
    def finish(self) -> None: ...

def write(
    path: str,
    points: ArrayLike,
    attributes: List[Tuple[str, NDArray[Any]]],
    las: Optional[LasSource],
    labels: NDArray[np.int64],
    part_labels: NDArray[np.int64],
    detection: Optional[NativeDetection] = None,
    classify: Optional[int] = None,
) -> None:
    """Writes the labelled cloud (LAS/LAZ/PLY), as `detect --output`."""

def _points_address(points: ArrayLike) -> int:
    """Address of the float64 buffer the library reads (tests: no copy)."""

def _panic(on_worker: bool) -> None:
    """Panics inside a call; raises RuntimeError (tests: no crash)."""
