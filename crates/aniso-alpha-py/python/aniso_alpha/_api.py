"""The functions of :mod:`aniso_alpha` (re-exported there): the
triangulation, the alpha intervals and the detection."""

from __future__ import annotations

import json
from dataclasses import dataclass
from typing import Any, Callable, Dict, List, Literal, Optional, Sequence, Tuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _native
from ._io import _warn, source_points
from ._results import Detection, RegionDetection, RegionPart

__all__ = ["AlphaIntervals", "Sampler", "Structure", "alpha_intervals", "delaunay", "detect"]

#: What :func:`detect` looks for.
Structure = Literal["planes", "lines"]
#: Where :func:`detect`'s orientations come from.
Sampler = Literal["data", "box", "fibonacci"]


@dataclass(frozen=True, eq=False)
class AlphaIntervals:
    """The alpha intervals of the Delaunay edges and triangles
    (the result of :func:`alpha_intervals`).

    A simplex is in the alpha-shape F_alpha when
    ``alpha_min <= alpha <= alpha_max``; ``alpha_max`` is ``inf`` on the
    convex hull.

    Attributes:
        edges: uint32 (m, 2), input indices, ascending in each row, rows
            sorted.
        edge_alpha: float64 (m, 2): ``[alpha_min, alpha_max]`` of each edge.
        triangles: uint32 (t, 3), input indices, ascending, rows sorted.
        triangle_alpha: float64 (t, 2): ``[alpha_min, alpha_max]`` of each
            triangle.
    """

    edges: NDArray[np.uint32]
    edge_alpha: NDArray[np.float64]
    triangles: NDArray[np.uint32]
    triangle_alpha: NDArray[np.float64]

    def at(self, alpha: float) -> Tuple[NDArray[np.uint32], NDArray[np.uint32]]:
        """The edges and triangles of the alpha-shape F_alpha:
        those with ``alpha_min <= alpha <= alpha_max``.

        >>> import numpy as np, aniso_alpha as aa
        >>> corners = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]
        >>> edges, triangles = aa.alpha_intervals(corners).at(0.75)
        >>> len(edges), len(triangles)
        (6, 3)
        """
        a = float(alpha)
        e = (self.edge_alpha[:, 0] <= a) & (a <= self.edge_alpha[:, 1])
        t = (self.triangle_alpha[:, 0] <= a) & (a <= self.triangle_alpha[:, 1])
        return self.edges[e], self.triangles[t]

    def __repr__(self) -> str:
        return f"AlphaIntervals({len(self.edges)} edges, {len(self.triangles)} triangles)"


def _triple(name: str, value: Optional[Sequence[float]]) -> Optional[Tuple[float, float, float]]:
    if value is None:
        return None
    v = np.asarray(value, dtype=np.float64)
    if v.shape != (3,):
        raise ValueError(f"{name} must be 3 numbers, got shape {v.shape}")
    return (float(v[0]), float(v[1]), float(v[2]))


def delaunay(points: ArrayLike, *, threads: Optional[int] = None) -> NDArray[np.uint32]:
    """The Delaunay tetrahedralization of ``points``.

    Exact predicates with CGAL's symbolic perturbation: on degenerate input
    (grids, cospherical points) the tetrahedra are CGAL's, tet for tet.

    Args:
        points: array-like of shape (n, 3); a C-contiguous float64 array is
            read in place, anything else is converted to one.
        threads: threads to build on (default: all cores). The tetrahedra
            are the same for any count; only the order of the rows may
            differ between counts (it is the same from run to run).

    Returns:
        uint32 array of shape (m, 4): one row per finite tetrahedron,
        indices into ``points`` (a duplicated point maps to its first
        occurrence), positively oriented (orient3d > 0). Points that span
        fewer than 3 dimensions give shape (0, 4).

    Raises:
        ValueError: wrong shape, no points, NaN or infinite coordinates.

    The GIL is released while the tetrahedralization is built.

    >>> import numpy as np, aniso_alpha as aa
    >>> cube = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], dtype=float)
    >>> tets = aa.delaunay(cube)
    >>> tets.shape, tets.dtype
    ((6, 4), dtype('uint32'))
    >>> aa.delaunay([[0, 0, 0], [1, 0, 0], [2, 0, 0]]).shape  # collinear
    (0, 4)
    """
    return _native.delaunay(points, threads)


def alpha_intervals(
    points: ArrayLike,
    elongation: Optional[Sequence[float]] = None,
    euler: Optional[Sequence[float]] = None,
    *,
    threads: Optional[int] = None,
) -> AlphaIntervals:
    """The alpha interval ``[alpha_min, alpha_max]`` of every Delaunay edge
    and triangle, Euclidean or anisotropic (as ``aniso-alpha alpha
    --intervals``, and CGAL's ``Alpha_shape_3`` in GENERAL mode).

    With ``elongation`` ``(e1, e2, e3)`` and/or ``euler`` ``(theta, psi,
    phi)`` (radians), the intervals are those of Del(Q·P), Q = diag(e)·R,
    R = Rz(theta)·Rx(psi)·Ry(phi): the anisotropic alpha-shape whose balls
    are ellipsoids with semi-axes alpha/e_i along the rows of R. Indices
    always refer to ``points``.

    Args:
        points: array-like of shape (n, 3).
        elongation: three positive factors (default 1, 1, 1).
        euler: three angles in radians (default 0, 0, 0).
        threads: threads to use (default: all cores); the result does not
            depend on it.

    Raises:
        ValueError: wrong shape, NaN or infinite coordinates, an elongation
            that is not finite and positive.

    The GIL is released during the computation.

    >>> import aniso_alpha as aa
    >>> iv = aa.alpha_intervals([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    >>> iv
    AlphaIntervals(6 edges, 4 triangles)
    >>> iv.edges[0].tolist(), iv.edge_alpha[0].tolist()
    ([0, 1], [0.5, inf])
    >>> aniso = aa.alpha_intervals([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], elongation=(1, 1, 0.125))
    >>> float(aniso.edge_alpha[2][0])  # edge 0-3, 8 times shorter along z
    0.0625
    """
    edges, edge_alpha, triangles, triangle_alpha = _native.alpha_intervals(
        points, _triple("elongation", elongation), _triple("euler", euler), threads
    )
    return AlphaIntervals(edges, edge_alpha, triangles, triangle_alpha)


def detect_options(
    *,
    alpha: Optional[float] = None,
    lambda2: Optional[float] = None,
    lambda3: Optional[float] = None,
    min_size: Optional[int] = None,
    sampler: Optional[Sampler] = None,
    m1: float = 0.3,
    m2: int = 12,
    step: float = 10.0,
    epsilon: Optional[float] = 1.0,
    tile: Optional[float] = None,
) -> Dict[str, Any]:
    """The options of :func:`detect` as the extension takes them."""
    return dict(
        alpha=alpha,
        lambda2=lambda2,
        lambda3=lambda3,
        min_size=min_size,
        sampler=sampler,
        m1=m1,
        m2=m2,
        step=step,
        epsilon=epsilon,
        tile=tile,
    )


def detect_input(
    source: Any, normals: Optional[ArrayLike], ignore_normals: bool
) -> Tuple[Any, Optional[ArrayLike]]:
    """The points of ``source`` and the normals to use."""
    points, own = source_points(source)
    if normals is not None and ignore_normals:
        raise ValueError("normals are given and ignore_normals=True: pass one or the other")
    if ignore_normals:
        return points, None
    return points, (normals if normals is not None else own)


def detect(
    points: Any,
    structure: Structure,
    *,
    alpha: Optional[float] = None,
    lambda2: Optional[float] = None,
    lambda3: Optional[float] = None,
    min_size: Optional[int] = None,
    sampler: Optional[Sampler] = None,
    m1: float = 0.3,
    m2: int = 12,
    step: float = 10.0,
    epsilon: Optional[float] = 1.0,
    tile: Optional[float] = None,
    normals: Optional[ArrayLike] = None,
    ignore_normals: bool = False,
    threads: Optional[int] = None,
    progress: Optional[Callable[[int, int], Optional[bool]]] = None,
    outlines: bool = True,
) -> Detection:
    """Finds lines or planes (and polyhedral surfaces) in ``points`` with
    anisotropic alpha-shapes (Bougleux, Melkemi & Elmoataz 2005), as
    ``aniso-alpha detect`` does: the options are the CLI's, built into a
    detector by the same code, and the same file gives the same labels.

    Args:
        points: the cloud: a :class:`Cloud` from :func:`aniso_alpha.read`
            (its normals used for planes, as the CLI uses a file's), a PDAL
            structured array or mapping of dimensions (``X``, ``Y``, ``Z``,
            and ``NormalX``, ``NormalY``, ``NormalZ`` when present: what
            ``pipeline.arrays`` and ``filters.python``'s ``ins`` hold), an
            Open3D ``PointCloud`` (its ``points``, and ``normals`` when
            ``has_normals()``), or any array-like of shape (n, 3).
        structure: ``"lines"`` (k = 1, ellipsoids elongated by ``lambda3``)
            or ``"planes"`` (k = 2, flattened by ``lambda2`` and
            ``lambda3``).
        alpha: the ellipsoid's short semi-axis, a radius (``--alpha``).
        lambda2: the elongation of the second axis (planes only; default
            ``lambda3`` when the run is explicit) (``--lambda2``).
        lambda3: the elongation of the long axis (``--lambda3``).
        min_size: nb_c, the number of simplices a piece needs to count
            (``--min-size``).
        sampler: the orientations scanned: ``"data"`` (the modes of the
            local normals or directions), ``"box"`` (the paper's box
            sampler, ``m1``, ``m2``) or ``"fibonacci"`` (near-uniform,
            ``step``); default ``"box"`` when ``alpha``, ``lambda3`` and
            ``min_size`` are all given, else ``"data"`` (``--sampler``).
        m1: box sampler: the grid spacing on the box faces (``--m1``).
        m2: turns about a plane's normal when lambda2 != lambda3, box and
            data orientations (``--m2``).
        step: Fibonacci sampler: the angular step in degrees (``--step``).
        epsilon: the significance test's expected false alarms (``--epsilon``);
            ``None``: no test, min_size alone, as the paper
            (``--no-significance``).
        tile: triangulate in tiles of this side (input units) with halos:
            bounded memory, the same result (``--tile``).
        normals: the points' normals, array-like (n, 3) (the sign does not
            matter), overriding those of ``points``: for planes, a point
            joins a plane only if its normal is within 36.9 degrees of the
            plane's, and the data's orientations come from them unless
            their modes explain less of the cloud than those of normals
            estimated from the points (noisy or smoothed normals: then
            from the estimated ones, with an :class:`AnisoAlphaWarning`
            and ``parameters["normals"]["modes_from"] == "estimated"``).
            Normals that disagree with the points are not used at all.
            Rows of zeros or NaN are missing normals. Lines ignore them.
        ignore_normals: estimate every normal from its neighbourhood even
            when ``points`` has normals (``--ignore-normals``).
        threads: threads to use (default: all cores); the result does not
            depend on it (``--threads``).
        progress: called as ``progress(done, total)`` after each orientation
            scanned (the CLI's progress bar), from the worker threads; it
            returns ``False`` to cancel the run (``RuntimeError``), and an
            exception it raises cancels the run and is raised again. A tqdm
            bar: ``progress=lambda done, total: bar.update(1)`` with
            ``tqdm(total=...)``, or set ``bar.total = total`` on the first
            call.
        outlines: compute each plane's outline (``Plane.polygon``) and the
            parts' meshes that :func:`write` puts in a PLY; ``False``
            skips them, which is faster (4–13% of the CLI's time on depth
            frames, BENCHMARKS.md): every ``polygon`` is then empty
            (0, 3), a part's ``"triangles"`` 0 and a PLY gets no meshes,
            while the labels, equations, inliers and NFAs are the same.
            The CLI skips them when no output holds them.

    With ``alpha``, ``lambda3`` and ``min_size`` all given, this is the
    paper's run with explicit parameters (the box of orientations). With
    any of them left ``None``, the missing ones are estimated from the data
    (point spacing, noise, the modes of the local normals or directions,
    which also give the orientations scanned), and the given ones are kept.
    Each of ``Detection.parameters["alpha"]``, ``["lambda2"]``,
    ``["lambda3"]`` and ``["min_size"]`` is a dict with its ``"value"``,
    whether it was ``"estimated"``, and the ``"reason"`` for it.

    Returns:
        a :class:`Detection`: per-point ``labels`` (structures) and
        ``part_labels`` (planes or segments), the ``structures``, the
        ``planes`` or ``segments`` (equation, inliers, outline), the
        ``parameters`` used. What the CLI prints as a warning (normals
        given but not used, or used for the gate alone, a very large run)
        is issued as an
        :class:`AnisoAlphaWarning`.

    Raises:
        ValueError: wrong shape, no points, NaN or infinite coordinates, an
            option out of range (named as here: ``min_size``), an unknown
            ``structure`` or ``sampler``.
        TypeError: an option of the wrong type.

    The GIL is released during the detection.

    The paper's Fig. 12 parameters, on three lines of points:

    >>> import numpy as np, aniso_alpha as aa
    >>> t = np.arange(30, dtype=float) * 7.0
    >>> lines = [np.c_[t, np.full(30, 50.0 * i), np.zeros(30)] for i in range(3)]
    >>> det = aa.detect(np.vstack(lines), "lines", alpha=1.0, lambda3=10.0, min_size=4)
    >>> len(det.structures), sorted(set(det.labels.tolist()))
    (3, [0, 1, 2])
    >>> det.structures[0]["kind"], det.structures[0]["points"]
    ('line', 30)

    Parameters from the data, on two perpendicular planes of grid points:

    >>> g = np.arange(30.0)
    >>> x, y = (a.ravel() for a in np.meshgrid(g, g))
    >>> planes = np.vstack([np.c_[x, y, np.full(900, 10.0)], np.c_[x, np.full(900, 15.0), y]])
    >>> det = aa.detect(planes + np.random.default_rng(1).normal(0, 0.01, planes.shape), "planes")
    >>> len(det.planes), det.parameters["alpha"]["estimated"]
    (2, True)
    """
    pts, nrm = detect_input(points, normals, ignore_normals)
    options = detect_options(
        alpha=alpha,
        lambda2=lambda2,
        lambda3=lambda3,
        min_size=min_size,
        sampler=sampler,
        m1=m1,
        m2=m2,
        step=step,
        epsilon=epsilon,
        tile=tile,
    )
    labels, part_labels, report, messages, native = _native.detect(
        pts, structure, options, threads, nrm, progress, outlines
    )
    _warn(messages)
    r = json.loads(report)
    return Detection(labels, part_labels, r["structures"], r["parameters"], list(messages), native)


def detect_regions(
    points: Any,
    structure: Structure,
    *,
    side: Optional[float] = None,
    alpha: Optional[float] = None,
    lambda2: Optional[float] = None,
    lambda3: Optional[float] = None,
    min_size: Optional[int] = None,
    sampler: Optional[Sampler] = None,
    m1: float = 0.3,
    m2: int = 12,
    step: float = 10.0,
    epsilon: Optional[float] = 1.0,
    normals: Optional[ArrayLike] = None,
    ignore_normals: bool = False,
    threads: Optional[int] = None,
    progress: Optional[Callable[[int, int], Optional[bool]]] = None,
    jobs: Optional[int] = None,
) -> RegionDetection:
    """:func:`detect` region by region, for clouds of millions of points
    (what ``aniso-alpha detect`` does by default above 1,000,000 points,
    docs/method.md §8 "Regions"): the x-y extent is cut into square
    regions, each detected on its points and a margin with its own
    parameters from its data, and the parts that cross a border are joined
    through the points both regions labelled. The peak memory is that of
    ``jobs`` regions' runs, not the whole cloud's.

    Args:
        points: as for :func:`detect`.
        structure: ``"lines"`` or ``"planes"``.
        side: the region side (input units); default: regions of about
            250,000 points, and one whole run for a cloud of up to
            1,000,000 points (``--regions``).
        alpha, lambda2, lambda3, min_size, sampler, m1, m2, step, epsilon,
            normals, ignore_normals, threads: as for :func:`detect`, for
            every region.
        progress: called as ``progress(done, total)`` after each region;
            ``False`` cancels (``RuntimeError``).
        jobs: regions detected at once (default: ``threads``); each holds
            one region's run in memory and runs on all the threads. The
            result is the same for any value.

    Returns:
        a :class:`RegionDetection`: per-point ``labels`` and
        ``part_labels``, the joined ``parts`` (plane equations or line
        directions), the ``side`` used and the counts of regions,
        widened margins and joins.

    Two regions of 30 units across a plane of 60 x 30 points give one part:

    >>> import numpy as np, aniso_alpha as aa
    >>> x, y = (a.ravel() for a in np.meshgrid(np.arange(60.0), np.arange(30.0)))
    >>> sheet = np.c_[x, y, np.random.default_rng(2).normal(0, 0.01, x.size)]
    >>> r = aa.detect_regions(sheet, "planes", side=30.0)
    >>> r.regions, len(r.parts), r.parts[0].pieces, r.parts[0].points > 1600
    (2, 1, 2, True)
    """
    pts, nrm = detect_input(points, normals, ignore_normals)
    options = detect_options(
        alpha=alpha,
        lambda2=lambda2,
        lambda3=lambda3,
        min_size=min_size,
        sampler=sampler,
        m1=m1,
        m2=m2,
        step=step,
        epsilon=epsilon,
    )
    run, used = _native.detect_regions(pts, structure, side, options, threads, nrm, progress, jobs)
    return _region_detection(run, used, structure)


def _region_detection(run: Tuple[Any, ...], side: Optional[float], structure: str) -> RegionDetection:
    """The :class:`RegionDetection` of the extension's region run (its
    warnings raised as :class:`AnisoAlphaWarning`)."""
    labels, part_labels, rows, regions, widened, joins, skipped, messages = run
    _warn(messages, stacklevel=4)
    return RegionDetection(
        labels, part_labels, _region_parts(rows, structure), side, regions, widened, joins, skipped, messages,
        structure,
    )


def _region_parts(rows: Sequence[Tuple[Any, ...]], structure: str) -> List[RegionPart]:
    """The joined parts of a region run from the extension's rows."""
    parts = []
    line = structure == "lines"
    for pid, st, n, pieces, a, b, rms in rows:
        parts.append(
            RegionPart(
                id=pid,
                structure=st,
                points=n,
                pieces=pieces,
                equation=None if line or not a else np.asarray(a, dtype=np.float64),
                direction=np.asarray(a, dtype=np.float64) if line and a else None,
                point=np.asarray(b, dtype=np.float64) if line and b else None,
                rms=rms,
            )
        )
    return parts
