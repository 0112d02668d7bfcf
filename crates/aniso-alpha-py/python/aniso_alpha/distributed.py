"""Tiled detection on Dask: :func:`detect` spreads the triangulations of a
large cloud over the workers of a ``dask.distributed`` cluster (a
``LocalCluster`` on this machine by default, or any cluster a ``Client``
reaches) and returns the same :class:`~aniso_alpha.Detection` as
:func:`aniso_alpha.detect`.

Needs the optional dependency ``dask[distributed]``
(``pip install "crates/aniso-alpha-py[distributed]"``).

How a run goes (docs/method.md §8; ARCHITECTURE.md, "Distributed detection"):

1. The driver (this process) reads the cloud and makes a plan: the
   parameters, estimated once from the whole cloud when not given (so
   every tile uses the same ones), the orientations, and the tiles: cubes
   of side ``tile``, each with a halo of 2·alpha·lambda_max around it.
2. Each tile's points (float64 (m, 3)), their ids and which orientation
   group looks at which of them are scattered to a worker as numpy arrays;
   the worker triangulates them once per orientation and sends back the
   simplices of F_{k,alpha,Q} that the tile's core owns (uint32 arrays). A
   worker never sees more than one tile and its halo at a time.
3. The driver gathers the simplices and finishes: the per-orientation path
   filter, the union, the component filter and the structures. The
   simplices owned by the cores are exactly the whole cloud's, so the
   labels are those of :func:`aniso_alpha.detect`.

:func:`detect_regions` spreads :func:`aniso_alpha.detect_regions` instead
(docs/method.md §8, "Regions"): each region (its core and margin) is one
task that estimates its own parameters and runs the whole detection on
its points; the driver keeps the points, two labels a point and the
regions' part axes, and joins the parts across borders. It gives the
labels of :func:`aniso_alpha.detect_regions`.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import shutil
import tempfile
import time
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, Type, Union

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _native
from ._api import Structure, detect_input, detect_options
from ._io import Cloud, PathLike, _warn, read
from ._results import Detection, RegionDetection, TileDetection

__all__ = ["PIECE_POINTS", "RegionLost", "TileLost", "detect", "detect_regions", "detect_tiles", "load", "plan"]

Source = Union[PathLike, Sequence[PathLike], ArrayLike, Any]

# The tiles of the default side hold about this many points each (core):
# a triangulation of this size takes well under a second per orientation
# and a few hundred MB at most.
TILE_POINTS = 200_000

# The default side is at least this many halos, so that a tile's halo does
# not outweigh its core (with side = 2·halo a planar tile triangulates at
# most (1 + 2/2)² = 4 times its own points).
MIN_SIDE_HALOS = 2.0


def load(source: Source) -> np.ndarray:
    """The points of ``source`` as one float64 (n, 3) C-contiguous array:
    a path to a point file (any format :func:`aniso_alpha.read` reads), a
    list of paths (LAS/LAZ tiles or any point files, concatenated in list
    order), a Dask array of shape (n, 3) (computed), or any array-like of
    shape (n, 3).

    >>> import numpy as np
    >>> from aniso_alpha.distributed import load
    >>> load([[0, 0, 0], [1, 2, 3]]).dtype
    dtype('float64')
    """
    if isinstance(source, (str, os.PathLike)):
        return read(source, attributes=False).points
    if isinstance(source, Cloud):
        return source.points
    if isinstance(source, (list, tuple)) and source and all(
        isinstance(s, (str, os.PathLike)) for s in source
    ):
        # Each tile copied into one array and dropped as it goes: the
        # array's pages are touched as they are written, so the peak is
        # about the points once, not twice.
        tiles = [read(s, attributes=False).points for s in source]
        out = np.empty((sum(len(t) for t in tiles), 3), dtype=np.float64)
        at = 0
        tiles.reverse()
        while tiles:
            t = tiles.pop()
            out[at : at + len(t)] = t
            at += len(t)
            del t
        return out
    if hasattr(source, "compute") and hasattr(source, "chunks"):
        source = source.compute()
    a = np.ascontiguousarray(source, dtype=np.float64)
    if a.ndim != 2 or a.shape[1] != 3:
        raise ValueError(f"points must be an array of shape (n, 3), got shape {a.shape}")
    return a


def _default_tile(points: np.ndarray, halo: float, tiles_wanted: int) -> float:
    """The largest side (halving from the cloud's extent) that gives at
    least ``tiles_wanted`` occupied cells, but not below
    MIN_SIDE_HALOS·halo."""
    lo = points.min(axis=0)
    extent = float(np.max(points.max(axis=0) - lo))
    floor = MIN_SIDE_HALOS * halo
    side = max(extent, floor, 1e-300) * (1 + 1e-9)
    sample = points
    if len(points) > 100_000:
        sample = points[np.random.default_rng(0).choice(len(points), 100_000, replace=False)]
    scale = len(points) / len(sample)
    while side / 2 >= floor:
        cells = np.unique(np.floor(sample / side).astype(np.int64), axis=0)
        if len(cells) >= tiles_wanted and len(sample) * scale / len(cells) <= TILE_POINTS:
            break
        side /= 2
    return side


def _computed(a: Any) -> Any:
    """A Dask array computed; anything else as it is (the native side
    checks it)."""
    if hasattr(a, "compute") and hasattr(a, "chunks"):
        return a.compute()
    return a


def plan(
    points: ArrayLike,
    structure: Structure,
    *,
    tile: Optional[float] = None,
    workers: int = 1,
    threads: Optional[int] = None,
    normals: Optional[ArrayLike] = None,
    **options: Any,
) -> "_native.Plan":
    """The plan of a tiled run over ``points`` (the parameters as
    :func:`aniso_alpha.detect` chooses them, and the tiles): what
    :func:`detect` runs. ``tile`` is the side of the tiles (input units);
    by default, the largest side that gives at least 4 tiles per worker and
    at most about 200,000 points per tile, but not below 2 halos.

    The plan has ``tile``, ``halo`` (2·alpha·lambda_max), ``jobs`` (the
    number of orientations) and ``tiles(points)``: a list of (cell, ids).
    ``options`` are :func:`aniso_alpha.detect`'s (``alpha``, ``lambda2``,
    ``lambda3``, ``min_size``, ``sampler``, ``m1``, ``m2``, ``step``,
    ``epsilon``).
    """
    pts = load(points)
    if tile is not None and not (math.isfinite(tile) and tile > 0):
        raise ValueError(f"tile must be positive and finite, got {tile}")
    if "tile" in options:
        raise TypeError("plan's tile is the Dask tiles' side, given once")
    p = _native.plan(
        pts,
        structure,
        tile if tile is not None else 1.0,
        detect_options(**options),
        threads,
        _computed(normals),
    )
    if tile is None:
        p = p.with_tile(_default_tile(pts, p.halo, 4 * max(1, int(workers))))
    return p


def _run_tile(
    spec: Tuple[Any, ...], payload: Tuple[Any, ...], threads: int
) -> Tuple[NDArray[np.uint32], NDArray[np.uint64], int]:
    """The task a worker runs: every orientation of ``spec`` on one tile."""
    kind, side, rotations, elongations, alphas, groups = spec
    cell, points, ids, members = payload
    offsets, positions = members if members is not None else (None, None)
    # Arrays unpickled from one message frame may be unaligned: the
    # extension reads aligned, C-contiguous buffers (a copy if need be).
    def aligned(a: Any) -> Any:
        return None if a is None else np.require(a, requirements=("C", "A"))

    rotations, elongations, alphas, groups, ids, offsets, positions = (
        aligned(a) for a in (rotations, elongations, alphas, groups, ids, offsets, positions)
    )
    return _native.tile_step(
        kind, side, rotations, elongations, alphas, groups, cell, points, ids,
        offsets, positions, threads,
    )


def _workers(client: Any) -> int:
    try:
        return max(1, len(client.scheduler_info().get("workers", {})))
    except Exception:  # noqa: BLE001 - a count for the default tile size only
        return 1


def detect(
    source: Source,
    structure: Structure,
    *,
    tile: Optional[float] = None,
    client: Any = None,
    n_workers: Optional[int] = None,
    threads: Optional[int] = None,
    task_threads: int = 1,
    normals: Optional[ArrayLike] = None,
    ignore_normals: bool = False,
    **options: Any,
) -> Detection:
    """Finds lines or planes as :func:`aniso_alpha.detect` does, with the
    triangulations run as Dask tasks, tile by tile.

    Args:
        source: a path to a point file (its normals used, as
            :func:`aniso_alpha.detect` uses a :class:`~aniso_alpha.Cloud`'s),
            a :class:`~aniso_alpha.Cloud`, a list of paths (e.g. LAS/LAZ
            tiles, read and concatenated in order, coordinates only), a
            Dask array of shape (n, 3), or any array-like of shape (n, 3).
        structure: ``"lines"`` or ``"planes"``.
        tile: the side of the tiles, in input units (default: see
            :func:`plan`). Any side gives the same result; smaller tiles
            mean less memory per task and more halo work.
        client: a ``dask.distributed.Client``; ``None`` starts a
            ``LocalCluster`` of ``n_workers`` processes (default: one per
            core), one thread each, and closes it at the end.
        n_workers: the workers of the LocalCluster started without a client.
        options: :func:`aniso_alpha.detect`'s (``alpha``, ``lambda2``,
            ``lambda3``, ``min_size``, ``sampler``, ``m1``, ``m2``,
            ``step``, ``epsilon``); the missing parameters are estimated
            once, from the whole cloud, on this process.
        threads: threads of the estimate and of the final step, on this
            process (default: all cores).
        task_threads: threads of each tile task (default 1: Dask runs one
            task per worker thread).
        normals: the points' normals, shape (n, 3), as
            :func:`aniso_alpha.detect`'s ``normals`` (an array-like or a
            Dask array); used on this process, by the estimate and the
            final step (the tiles' triangulations do not need them).
        ignore_normals: as :func:`aniso_alpha.detect`'s.

    Returns:
        the :class:`~aniso_alpha.Detection` of :func:`aniso_alpha.detect`
        on the same points: the same labels, part labels, structures and
        parameters.

    Raises:
        ValueError: as :func:`aniso_alpha.detect`, and a bad ``tile``.
        ImportError: ``dask.distributed`` is not installed.
        TileLost: a tile's worker was lost :data:`TILE_ATTEMPTS` times
            (a tile lost fewer times is sent again: the result is the same).

    Two planes of a grid, cut into tiles of side 8 (smaller than the
    planes), on a LocalCluster of 2 processes:

    >>> import numpy as np, aniso_alpha as aa
    >>> from aniso_alpha import distributed
    >>> g = np.arange(30.0)
    >>> x, y = (a.ravel() for a in np.meshgrid(g, g))
    >>> pts = np.vstack([np.c_[x, y, np.full(900, 10.0)], np.c_[x, np.full(900, 15.0), y]])
    >>> pts += np.random.default_rng(1).normal(0, 0.01, pts.shape)
    >>> det = distributed.detect(pts, "planes", tile=8.0, n_workers=2)
    >>> len(det.structures), bool((det.labels == aa.detect(pts, "planes").labels).all())
    (2, True)

    On a cluster, pass its client (``Client("scheduler-address:8786")``).
    """
    points, normals = _source(source, normals, ignore_normals)
    client, own = _client(client, n_workers)
    try:
        p = plan(
            points,
            structure,
            tile=tile,
            workers=_workers(client),
            threads=threads,
            normals=normals,
            **options,
        )
        _warn(p.warnings)
        outputs = _run(client, p, points, task_threads)
        labels, part_labels, report, messages, native = p.finish(points, outputs, threads)
    finally:
        _close(own)
    r = json.loads(report)
    return Detection(labels, part_labels, r["structures"], r["parameters"], list(messages), native)


def _source(
    source: Source, normals: Optional[ArrayLike], ignore_normals: bool
) -> Tuple[NDArray[np.float64], Optional[ArrayLike]]:
    """The points of ``source`` (a path read, a Cloud's points, or an
    array, as :func:`load` takes them) and the normals to use."""
    if isinstance(source, (str, os.PathLike)):
        source = read(source)
    if isinstance(source, Cloud):
        _, normals = detect_input(source, normals, ignore_normals)
        source = source.points
    else:
        _, normals = detect_input(None, normals, ignore_normals)
    return load(source), normals


def _client(client: Any, n_workers: Optional[int]) -> Tuple[Any, Optional[Tuple[Any, Any]]]:
    """``client``, or a new one on a ``LocalCluster`` of ``n_workers``
    processes (default: one per core), one thread each, with that client
    and cluster to close (:func:`_close`)."""
    if client is not None:
        return client, None
    from dask.distributed import Client, LocalCluster

    n = int(n_workers) if n_workers else (os.cpu_count() or 1)
    cluster = LocalCluster(  # type: ignore[no-untyped-call]
        n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None
    )
    own = (Client(cluster), cluster)  # type: ignore[no-untyped-call]
    return own[0], own


def _close(own: Optional[Tuple[Any, Any]]) -> None:
    """Closes the client and cluster :func:`_client` started, if any."""
    if own is not None:
        own[0].close()
        own[1].close()


# A tile whose task is lost this many times (its worker died, its scattered
# points with it) ends the run with an error naming it.
TILE_ATTEMPTS = 3


class TileLost(RuntimeError):
    """A tile's task failed :data:`TILE_ATTEMPTS` times because its worker
    was lost (killed, out of memory, disconnected): the run stops, with the
    tile's cell and the last error."""


class RegionLost(TileLost):
    """A region's task of :func:`detect_regions` was lost with its worker
    as many times as the cluster allows (Dask's ``allowed-failures``): the
    run stops, naming the region."""


def _lost_worker_errors() -> Tuple[Type[BaseException], ...]:
    """The exceptions a task's result raises when its worker (or the data
    scattered to it) was lost, rather than when the task itself failed."""
    import asyncio
    import concurrent.futures

    from distributed.comm.core import CommClosedError
    from distributed.scheduler import KilledWorker

    return (
        KilledWorker,
        CommClosedError,
        asyncio.CancelledError,
        concurrent.futures.CancelledError,
        OSError,
    )


def _run(
    client: Any, p: "_native.Plan", points: NDArray[np.float64], task_threads: int
) -> List[Tuple[Any, ...]]:
    """Runs every tile of ``p`` on ``client``'s workers, at most a few tiles
    per worker in flight (the driver never holds every tile's copy of its
    points at once); returns the tiles' outputs in completion order.

    A tile whose worker is lost (its task and the points scattered to it
    go with it) is sent again from the driver's copy of the cloud, up to
    :data:`TILE_ATTEMPTS` times; the job spec is scattered again if every
    worker holding it is gone. A tile's output depends on its points only,
    so the labels are those of an undisturbed run. An error raised by the
    task itself (not a lost worker) is raised as it is."""
    from dask.distributed import as_completed

    lost_errors = _lost_worker_errors()
    tiles = iter(p.tiles(points))
    limit = 2 * _workers(client) + 2
    outputs: List[Tuple[Any, ...]] = []
    attempts: Dict[str, Tuple[Tuple[Any, ...], int]] = {}

    def scatter(data: Any, broadcast: bool = False) -> Any:
        """``client.scatter`` of one object, again (after a pause) when a
        worker it was sent to is lost on the way. Each scatter has a key of
        its own (``hash=False``): a tile sent again after its worker was
        lost does not reuse the key the scheduler is still forgetting."""
        for attempt in range(1, TILE_ATTEMPTS + 1):
            try:
                return client.scatter([data], broadcast=broadcast, hash=False)[0]
            except lost_errors:
                if attempt == TILE_ATTEMPTS:
                    raise
                time.sleep(0.5 * attempt)

    spec = scatter(p.step_spec(), broadcast=True)

    def submit(tile: Tuple[Any, ...], tried: int = 0) -> Any:
        nonlocal spec
        cell, ids = tile
        if spec.status != "finished":
            spec = scatter(p.step_spec(), broadcast=True)
        data = scatter((cell, np.ascontiguousarray(points[ids]), ids, p.members(ids)))
        future = client.submit(_run_tile, spec, data, task_threads, pure=False)
        attempts[future.key] = (tile, tried + 1)
        return future

    pending = as_completed([submit(t) for _, t in zip(range(limit), tiles)])  # type: ignore[no-untyped-call]
    for done in pending:
        tile, tried = attempts.pop(done.key)
        try:
            faces, offsets, triangulated = done.result()
        except lost_errors as e:
            done.release()
            if tried >= TILE_ATTEMPTS:
                raise TileLost(
                    f"tile {tuple(tile[0])} ({len(tile[1])} points) was lost {tried} times "
                    f"(its worker died or left the cluster); last error: {type(e).__name__}: {e}"
                ) from e
            pending.add(submit(tile, tried))  # type: ignore[no-untyped-call]
            continue
        # Unpickled from one frame, the arrays may be unaligned (see _run_tile).
        outputs.append(
            (
                np.require(faces, requirements=("C", "A")),
                np.require(offsets, requirements=("C", "A")),
                triangulated,
            )
        )
        done.release()
        nxt = next(tiles, None)
        if nxt is not None:
            pending.add(submit(nxt))  # type: ignore[no-untyped-call]
    return outputs


def _aligned_step(step: Optional[Tuple[Any, ...]]) -> Optional[Tuple[Any, ...]]:
    """A region step's arrays aligned (unpickled from one frame, they may
    not be; see :func:`_run_tile`)."""
    if step is None:
        return None
    return tuple(np.require(a, requirements=("C", "A")) if isinstance(a, np.ndarray) else a for a in step)


def _run_regions(
    client: Any,
    n_regions: int,
    first_margin: float,
    submit: Callable[[int, float], Any],
    size: Callable[[int], str],
    join: Any,
    add: Callable[[int, Optional[Tuple[Any, ...]], Tuple[Any, ...]], None],
    progress: Optional[Callable[[int, int], Optional[bool]]] = None,
) -> None:
    """Runs regions ``0..n_regions`` as tasks (``submit(r, margin)`` gives
    region r's future, whose result is ``(kind, margin, step, ...)``), at
    most a few per worker in flight, and adds each to ``join`` in the
    plan's order (``add(r, step or None, result)``; steps done ahead of
    their turn wait, joined ones are dropped). A region whose estimate
    reaches past its margin is sent again with the margin it asks for
    (each widening counted in ``join``, as the in-process run counts it). A
    region whose task was lost with its worker on every try Dask allows
    raises :class:`RegionLost` (``size(r)`` describes it). ``progress(done,
    total)`` is called after each region joined; ``False`` cancels
    (``RuntimeError``)."""
    from dask.distributed import as_completed

    waiting: Dict[int, Tuple[Optional[Tuple[Any, ...]], Tuple[Any, ...], int]] = {}
    joined = 0
    region_of: Dict[str, Tuple[int, int]] = {}

    def send(r: int, margin: float, widened: int) -> Any:
        future = submit(r, margin)
        region_of[future.key] = (r, widened)
        return future

    regions = iter(range(n_regions))
    limit = 2 * _workers(client) + 2
    pending = as_completed([send(r, first_margin, 0) for _, r in zip(range(limit), regions)])  # type: ignore[no-untyped-call]
    lost_errors = _lost_worker_errors()
    for done in pending:
        r, widened = region_of.pop(done.key)
        try:
            out = done.result()
        except lost_errors as e:
            # Dask ran the task again on other workers (its inputs travel
            # with it) until its allowed failures were spent.
            raise RegionLost(
                f"region {r} ({size(r)}) lost its worker on every try (its worker died "
                f"or left the cluster); last error: {type(e).__name__}: {e}"
            ) from e
        done.release()
        kind, margin = out[0], out[1]
        if kind == "wider":
            pending.add(send(r, margin, widened + 1))  # type: ignore[no-untyped-call]
            continue
        waiting[r] = (_aligned_step(out[2]) if kind == "step" else None, out, widened)
        while joined in waiting:
            step, res, times = waiting.pop(joined)
            for _ in range(times):
                join.widened()
            add(joined, step, res)
            joined += 1
            if progress is not None and progress(joined, n_regions) is False:
                for f in list(pending.futures):
                    f.cancel()
                raise RuntimeError("the region run was cancelled by the progress callback")
        nxt = next(regions, None)
        if nxt is not None:
            pending.add(send(nxt, first_margin, 0))  # type: ignore[no-untyped-call]


def _run_region(
    points: NDArray[np.float64],
    normals: Optional[NDArray[np.float64]],
    structure: str,
    margin: float,
    options: Dict[str, Any],
    task_threads: int,
) -> Tuple[Any, ...]:
    """A region's task on a worker (see :func:`detect_regions`)."""
    # Unpickled from one frame, the arrays may be unaligned (see _run_tile).
    pts = np.require(points, requirements=("C", "A"))
    nrm = None if normals is None else np.require(normals, requirements=("C", "A"))
    return _native.region_task(pts, structure, margin, options, nrm, task_threads)


def detect_regions(
    source: Source,
    structure: Structure,
    *,
    side: Optional[float] = None,
    client: Any = None,
    n_workers: Optional[int] = None,
    task_threads: int = 1,
    normals: Optional[ArrayLike] = None,
    ignore_normals: bool = False,
    progress: Optional[Callable[[int, int], Optional[bool]]] = None,
    **options: Any,
) -> RegionDetection:
    """:func:`aniso_alpha.detect_regions` with each region run as a Dask
    task: the same labels and parts.

    Args:
        source: as for :func:`detect`.
        structure: ``"lines"`` or ``"planes"``.
        side: the region side (input units); default: regions of about
            250,000 points (one region for a cloud of up to 1,000,000).
        client: a ``dask.distributed.Client``; ``None`` starts a
            ``LocalCluster`` of ``n_workers`` processes, one thread each.
        n_workers: the workers of that LocalCluster (default: one per core).
        task_threads: threads of each region task.
        progress: called as ``progress(done, total)`` on this process after
            each region joined (in the plan's order); ``False`` cancels
            (``RuntimeError``).
        normals, ignore_normals, options: as for
            :func:`aniso_alpha.detect_regions`; the parameters are
            estimated in each task, from its region's points.

    Returns:
        the :class:`~aniso_alpha.RegionDetection` of
        :func:`aniso_alpha.detect_regions` on the same points.

    The driver holds the points, two labels a point and, per region, its
    part axes; each task holds one region. A region's result depends on
    its own points only, so a task whose worker dies is run again (by
    Dask: its points travel with the task) with the same result. A region
    whose estimate reaches past its margin is sent again with the margin
    it asks for.

    >>> import numpy as np, aniso_alpha as aa
    >>> from aniso_alpha import distributed
    >>> x, y = (a.ravel() for a in np.meshgrid(np.arange(60.0), np.arange(30.0)))
    >>> sheet = np.c_[x, y, np.random.default_rng(2).normal(0, 0.01, x.size)]
    >>> r = distributed.detect_regions(sheet, "planes", side=30.0, n_workers=2)
    >>> bool((r.part_labels == aa.detect_regions(sheet, "planes", side=30.0).part_labels).all())
    True
    """
    points, normals = _source(source, normals, ignore_normals)
    nrm = None if normals is None else load(normals)
    if side is not None and not (math.isfinite(side) and side > 0):
        raise ValueError(f"region side {side}: must be positive and finite")
    opts = detect_options(**options)
    plan = _native.region_plan(points, side)
    client, own = _client(client, n_workers)
    try:
        join = _native.RegionJoin(len(points))
        ids_of: Dict[int, NDArray[np.uint32]] = {}

        def submit(r: int, margin: float) -> Any:
            ids = ids_of[r] = plan.points_within(points, r, margin)
            sub_n = None if nrm is None else np.ascontiguousarray(nrm[ids])
            return client.submit(
                _run_region,
                np.ascontiguousarray(points[ids]),
                sub_n,
                structure,
                margin,
                opts,
                task_threads,
                pure=False,
            )

        def size(r: int) -> str:
            return f"{len(ids_of[r])} points"

        def add(r: int, step: Optional[Tuple[Any, ...]], out: Tuple[Any, ...]) -> None:
            join.add(ids_of.pop(r), plan.core(r), step)

        _run_regions(client, len(plan), plan.first_margin, submit, size, join, add, progress)
        run = join.finish(points)
    finally:
        _close(own)
    from ._api import _region_detection

    return _region_detection(run, plan.side, structure)


# A piece of a tile: (path, first point, point count), or (path, 0, None)
# for the whole file of a format read only whole.
Piece = Tuple[str, int, Optional[int]]

# The most points read from a LAS/LAZ file at once by a task or the
# driver: 2^20, 25 MB of coordinates (and 35-70 MB of records of 34-67
# bytes in the driver's pass over the labelled copies). A region's task
# reads (and for LAZ decompresses) every piece whose bounding box meets
# its window: smaller pieces have tighter boxes, so a file in acquisition
# order costs less to read per region; each piece is one more small task
# for its bounds and cells.
PIECE_POINTS = 1 << 20


def _is_las(path: str) -> bool:
    return os.path.splitext(path)[1].lower() in (".las", ".laz")


def _pieces(paths: Sequence[str], piece: int) -> List[Piece]:
    """The pieces the tiles are read in, in input order: a LAS/LAZ tile in
    ranges of at most ``piece`` points (its count from its header), any
    other file whole."""
    out: List[Piece] = []
    for path in paths:
        if not _is_las(path):
            out.append((path, 0, None))
            continue
        n = int(_native.las_points(path))
        out.extend((path, s, min(piece, n - s)) for s in range(0, max(n, 1), piece))
    return out


def _piece_points(piece: Piece) -> NDArray[np.float64]:
    """A piece's points (coordinates only)."""
    path, start, count = piece
    if count is None:
        return read(path, attributes=False).points
    return read(path, attributes=False, start=start, count=count).points


def _tile_bounds(piece: Piece) -> Tuple[int, NDArray[np.float64], NDArray[np.float64]]:
    """A piece's task: its number of points and bounding box."""
    pts = _piece_points(piece)
    return len(pts), pts.min(axis=0), pts.max(axis=0)


def _tile_cells(piece: Piece, origin: Tuple[float, float], side: float) -> NDArray[np.int64]:
    """A piece's task: the region cells its points occupy."""
    return _native.region_cells(_piece_points(piece), origin, side)


def _tile_region(
    pieces: Sequence[Tuple[Piece, int]],
    origin: Tuple[float, float],
    side: float,
    cell: Tuple[int, int],
    margin: float,
    structure: str,
    options: Dict[str, Any],
    task_threads: int,
) -> Tuple[Any, ...]:
    """A region's task of :func:`detect_tiles`: its points cut from the
    pieces that meet its window (each piece with the input index of its
    first point), in input order, then :func:`_native.region_task`.
    Returns the task's ``(kind, margin, step)`` and, for a step, the
    region's input indices (uint32, ascending) and its core's."""
    points, ids, core = [], [], []
    for piece, first in pieces:
        pts = _piece_points(piece)
        idx, is_core = _native.region_select(pts, origin, side, cell, margin)
        points.append(pts[idx])
        glob = (idx.astype(np.uint64) + np.uint64(first)).astype(np.uint32)
        ids.append(glob)
        core.append(glob[is_core])
        del pts
    sub = np.ascontiguousarray(np.concatenate(points)) if points else np.empty((0, 3))
    kind, m, step = _native.region_task(sub, structure, margin, options, None, task_threads)
    if kind != "step":
        return kind, m, None, None, None
    return kind, m, step, np.concatenate(ids), np.concatenate(core)


def _output_names(tiles: Sequence[str], out: str) -> List[str]:
    """The labelled copy of each tile in ``out``: its name, a LAS, LAZ or
    PLY tile keeping its format and any other format written as PLY."""
    names = []
    for t in tiles:
        base = os.path.basename(t)
        stem, ext = os.path.splitext(base)
        names.append(os.path.join(out, base if ext.lower() in (".las", ".laz", ".ply") else stem + ".ply"))
    seen: Dict[str, str] = {}
    for t, n in zip(tiles, names):
        if n in seen:
            raise ValueError(f"tiles {seen[n]} and {t} would both be written as {n}")
        seen[n] = t
        if os.path.abspath(n) == os.path.abspath(t):
            raise ValueError(f"{n}: the output folder holds the tile itself")
    return names


def _labels_and_fits(
    joined: Any,
    pieces: Sequence[Piece],
    firsts: Sequence[int],
    counts: Sequence[int],
    staging: Optional[str],
    names: Dict[str, str],
    totals: Dict[str, int],
    classify: Optional[int],
) -> None:
    """The driver's three passes over the pieces in input order: the first
    writes each tile's labelled copy into ``staging`` (when given; a
    LAS/LAZ tile a piece at a time) and feeds the joined parts' refit, the
    two others finish it. ``totals``: each tile's points."""
    cls = None if classify is None else int(classify)
    for k in range(3):
        writer: Any = None
        for piece, first, n in zip(pieces, firsts, counts):
            path, start, count = piece
            label = k == 0 and staging is not None
            las = None
            if not label:
                points = _piece_points(piece)
            elif count is None:
                cloud = read(path, attributes=True)
                points = cloud.points
            else:
                points, las = _native.read_las_records(path, start, count)
            if len(points) != n:
                raise ValueError(f"{path}: {len(points)} points, {n} when the run began")
            joined.refit(first, points)
            if label:
                target = os.path.join(str(staging), os.path.basename(names[path]))
                labels, part_labels = joined.labels(first, n)
                if las is None:
                    _native.write(
                        target, points, list(cloud.attributes.items()), cloud._las, labels, part_labels, None, cls
                    )
                else:
                    # A LAS/LAZ tile's records are copied byte for byte, a
                    # piece at a time, with the two ids added.
                    if start == 0:
                        writer = _native.LasLabelWriter(target, las, totals[path], cls)
                    writer.append(las, labels, part_labels)
                    if start + n == totals[path]:
                        writer.finish()
                        writer = None
            del points, las
        joined.end_pass()


def detect_tiles(
    tiles: Sequence[PathLike],
    structure: Structure,
    out: Optional[PathLike] = None,
    *,
    side: Optional[float] = None,
    client: Any = None,
    n_workers: Optional[int] = None,
    task_threads: int = 1,
    classify: Optional[int] = None,
    progress: Optional[Callable[[int, int], Optional[bool]]] = None,
    piece: int = PIECE_POINTS,
    **options: Any,
) -> TileDetection:
    """:func:`detect_regions` over a cloud held as tiles (point files, such
    as LAS/LAZ tiles, or one LAS/LAZ file larger than memory), which no
    process reads whole: each point's labels are written to a copy of its
    tile instead of returned.

    Args:
        tiles: the tiles' paths (any format :func:`aniso_alpha.read`
            reads); the cloud is their points in list order. A LAS/LAZ
            tile is read in pieces of at most ``piece`` points (by
            offset, without the rest of the file: see
            :func:`aniso_alpha.read`'s ``start`` and ``count``), so one
            LAS/LAZ file of any size can be the whole cloud; another
            format is read whole by each task that needs it.
        structure: ``"lines"`` or ``"planes"``.
        out: a folder (made if missing) for the labelled tiles: each tile
            as :func:`aniso_alpha.write` writes it (a LAS/LAZ tile's header
            and records kept, the ids added as ``structure`` and ``part``),
            under its own name (a tile that is neither LAS, LAZ nor PLY as
            PLY); ``None`` writes nothing and returns the parts. The
            labelled tiles are written in a hidden folder inside ``out``
            and moved in together once all are complete: a run that fails
            leaves none.
        side, client, n_workers, task_threads, progress, options: as for
            :func:`detect_regions` (``progress`` counts the regions). The
            normals of the tiles are not read: each region estimates its
            own.
        classify: a LAS classification given to the structures' points in
            the outputs (as :func:`aniso_alpha.write`'s).
        piece: the most points a task or the driver reads from a LAS/LAZ
            tile at once (default :data:`PIECE_POINTS`, 2^20). A region's
            task reads every piece whose bounding box meets its window:
            a file in spatial order (tiles, COPC, or points sorted by
            PDAL's ``filters.mortonorder``) is read least; one in
            acquisition order (flight lines) may be read by many regions.

    Returns:
        a :class:`~aniso_alpha.TileDetection`: the parts, outputs and counts
        of :func:`detect_regions` on the tiles' points stacked in list
        order (the same labels, in the outputs).

    What each process holds: a worker, one region (the pieces that meet
    its window are read one at a time and cut); the driver, the pieces'
    bounds, the regions' cells, the margin labels still waiting for their
    core region, and one piece at a
    time while it writes the labels and refits the joined parts (three
    passes over the pieces in input order: the same fits as of the stacked
    points; a LAS/LAZ tile's labelled copy is written a piece at a time).
    The part ids are kept in a scratch file, in a hidden folder inside
    ``out`` (or the system's temporary folder without ``out``) with the
    labelled tiles until they are complete, removed at the end: the
    driver's memory does not grow with the cloud's points (the joined
    parts and the pair counts grow with the parts).
    Tasks read their tiles from the paths, so a task whose worker dies is
    run again by Dask with the same result; the paths must be readable
    from every worker.

    >>> import os, tempfile, numpy as np, aniso_alpha as aa
    >>> from aniso_alpha import distributed
    >>> d = tempfile.mkdtemp()
    >>> x, y = (a.ravel() for a in np.meshgrid(np.arange(60.0), np.arange(30.0)))
    >>> sheet = np.c_[x, y, np.random.default_rng(2).normal(0, 0.01, x.size)]
    >>> paths = [os.path.join(d, f"t{k}.xyz") for k in range(2)]
    >>> for k, p in enumerate(paths):
    ...     np.savetxt(p, sheet[k * 900 : (k + 1) * 900])
    >>> r = distributed.detect_tiles(paths, "planes", os.path.join(d, "out"), side=30.0, n_workers=2)
    >>> [os.path.basename(o) for o in r.outputs]
    ['t0.ply', 't1.ply']
    >>> ref = aa.detect_regions(distributed.load(paths), "planes", side=30.0)
    >>> labels = np.concatenate([aa.read(o).attributes["part"] for o in r.outputs])
    >>> bool((labels == ref.part_labels).all()), r.parts[0].points == ref.parts[0].points
    (True, True)
    """
    paths = [os.fspath(t) for t in tiles]
    if not paths:
        raise ValueError("no tiles")
    if side is not None and not (math.isfinite(side) and side > 0):
        raise ValueError(f"region side {side}: must be positive and finite")
    if classify is not None and not (isinstance(classify, (int, np.integer)) and 0 <= int(classify) <= 255):
        raise ValueError(f"classify must be a LAS class between 0 and 255, got {classify!r}")
    if not (isinstance(piece, (int, np.integer)) and piece >= 1):
        raise ValueError(f"piece must be a positive number of points, got {piece!r}")
    names = _output_names(paths, os.fspath(out)) if out is not None else []
    opts = detect_options(**options)
    pieces = _pieces(paths, int(piece))
    folder = None if out is None else os.fspath(out)
    made = folder is not None and not os.path.isdir(folder)
    if folder is not None:
        os.makedirs(folder, exist_ok=True)
    # The part ids (4 bytes a point) and the labelled tiles until all are
    # complete: a hidden folder inside `out`, removed at the end (and `out`
    # with it when this run made it and failed).
    scratch = tempfile.mkdtemp(prefix=".aniso-alpha-", dir=folder)
    done = False
    try:
        run = _tiles_run(pieces, paths, names, scratch, structure, side, client, n_workers, task_threads,
                         classify, progress, opts)
        done = True
    finally:
        shutil.rmtree(scratch, ignore_errors=True)
        if made and not done and folder is not None:
            with contextlib.suppress(OSError):
                os.rmdir(folder)
    return run


def _tiles_run(
    pieces: List[Piece],
    paths: List[str],
    names: List[str],
    scratch: str,
    structure: Structure,
    side: Optional[float],
    client: Any,
    n_workers: Optional[int],
    task_threads: int,
    classify: Optional[int],
    progress: Optional[Callable[[int, int], Optional[bool]]],
    opts: Dict[str, Any],
) -> TileDetection:
    """:func:`detect_tiles` once its input is checked: the regions, then
    the labelled tiles written into ``scratch`` and moved to their names."""
    client, own = _client(client, n_workers)
    try:
        bounds = client.gather(client.map(_tile_bounds, pieces, pure=False))
        counts = [int(b[0]) for b in bounds]
        firsts = np.concatenate([[0], np.cumsum(counts)[:-1]]).astype(int).tolist()
        lo = np.min([b[1] for b in bounds], axis=0)
        hi = np.max([b[2] for b in bounds], axis=0)
        origin, run_side, reported, first_margin = _native.region_grid(
            [float(v) for v in lo], [float(v) for v in hi], sum(counts), side
        )
        tile_cells = client.gather(client.map(_tile_cells, pieces, origin=origin, side=run_side, pure=False))
        cells = np.unique(np.concatenate(tile_cells), axis=0)
        join = _native.RegionJoin(sum(counts), scratch)

        def submit(r: int, margin: float) -> Any:
            cell = (int(cells[r][0]), int(cells[r][1]))
            x0, y0, x1, y1 = _native.region_window(origin, run_side, cell, margin)
            meets = [
                (p, f)
                for p, f, (_, tlo, thi) in zip(pieces, firsts, bounds)
                if tlo[0] <= x1 and thi[0] >= x0 and tlo[1] <= y1 and thi[1] >= y0
            ]
            return client.submit(
                _tile_region, meets, origin, run_side, cell, margin, structure, opts, task_threads, pure=False
            )

        def add(r: int, step: Optional[Tuple[Any, ...]], res: Tuple[Any, ...]) -> None:
            if step is None:
                join.add(np.empty(0, np.uint32), np.empty(0, np.uint32), None)
            else:
                join.add(np.require(res[3], requirements=("C", "A")), np.require(res[4], requirements=("C", "A")), step)

        _run_regions(
            client, len(cells), first_margin, submit, lambda r: f"cell {tuple(cells[r])}", join, add, progress
        )
    finally:
        _close(own)
    joined = join.resolve()
    del join
    totals: Dict[str, int] = {}
    for (path, _, _), n in zip(pieces, counts):
        totals[path] = totals.get(path, 0) + n
    staging = scratch if names else None
    _labels_and_fits(joined, pieces, firsts, counts, staging, dict(zip(paths, names)), totals, classify)
    # Every labelled tile is complete: they enter the folder together.
    for name in names:
        os.replace(os.path.join(scratch, os.path.basename(name)), name)
    _, _, rows, regions, widened, joins, skipped, messages = joined.finish()
    del joined  # its scratch file closed before the folder is removed
    _warn(messages)
    from ._api import _region_parts

    return TileDetection(
        names, sum(counts), _region_parts(rows, structure), reported, regions, widened, joins, skipped, messages
    )
