"""The functions and result types of :mod:`aniso_alpha` (re-exported there)."""

from __future__ import annotations

import json
import os
from dataclasses import dataclass
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _native

__all__ = [
    "AlphaIntervals",
    "Detection",
    "alpha_intervals",
    "delaunay",
    "detect",
    "read",
]

PathLike = Union[str, "os.PathLike[str]"]


@dataclass(frozen=True, eq=False)
class Detection:
    """The result of :func:`detect`.

    Attributes:
        labels: int64 array of shape (n,): for each input point, the id of the
            largest structure that holds it (an index into ``structures``),
            or -1 for background. An exact duplicate has its first
            occurrence's label.
        part_labels: int64 array of shape (n,): the id of the planar facet
            (planes) or straight segment (lines) that holds the point, parts
            numbered structure by structure, or -1.
        structures: one dict per structure, largest first, as in the
            ``"structures"`` list of the JSON report that
            ``aniso-alpha detect --report`` writes.
        parameters: the parameters used, as the report's ``"parameters"``.
    """

    labels: NDArray[np.int64]
    part_labels: NDArray[np.int64]
    structures: List[Dict[str, Any]]
    parameters: Dict[str, Any]

    def __repr__(self) -> str:
        background = int(np.count_nonzero(self.labels < 0))
        return (
            f"Detection({len(self.structures)} structure(s), "
            f"{len(self.labels)} points of which {background} background, "
            f"parameters={self.parameters!r})"
        )


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
        normals: optional array-like of shape (n, 3), the points' normals
            (e.g. a scan's ``nx ny nz``, or Open3D's ``pcd.normals``; the
            sign does not matter). For planes, a point then joins a plane
            only if its normal is within 36.9 degrees of the plane's (window
            frames and ledges stay out of a facade), and the data's
            orientations come from them. Rows of zeros or NaN are missing
            normals. Lines ignore them. As ``aniso-alpha detect`` does with
            a PLY or PCD file that has normals.

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


def detect(
    points: ArrayLike,
    structure: str,
    *,
    alpha: Optional[float] = None,
    lambda2: Optional[float] = None,
    lambda3: Optional[float] = None,
    min_size: Optional[int] = None,
    threads: Optional[int] = None,
    normals: Optional[ArrayLike] = None,
) -> Detection:
    """Finds lines or planes (and polyhedral surfaces) in ``points`` with
    anisotropic alpha-shapes (Bougleux, Melkemi & Elmoataz 2005), as
    ``aniso-alpha detect`` does.

    Args:
        points: array-like of shape (n, 3).
        structure: ``"lines"`` (k = 1, ellipsoids elongated by ``lambda3``)
            or ``"planes"`` (k = 2, flattened by ``lambda2`` and
            ``lambda3``).
        alpha: the ellipsoid's short semi-axis.
        lambda2: the elongation of the second axis (planes only; default
            ``lambda3`` when ``lambda3`` is given).
        lambda3: the elongation of the long axis.
        min_size: nb_c, the number of simplices a piece needs to count.
        threads: threads to use (default: all cores); the result does not
            depend on it.

    With ``alpha``, ``lambda3`` and ``min_size`` all given, this is the
    CLI's run with explicit parameters (the paper's box of orientations):
    the same labels as ``aniso-alpha detect --alpha ... --lambda3 ...
    --min-size ...``. With any of them left ``None``, the missing ones are
    estimated from the data (point spacing, noise, the modes of the local
    normals or directions, which also give the orientations scanned), and
    the given ones are kept. Each of ``Detection.parameters["alpha"]``,
    ``["lambda2"]``, ``["lambda3"]`` and ``["min_size"]`` is a dict with its
    ``"value"``, whether it was ``"estimated"``, and the ``"reason"`` for it.

    Returns:
        a :class:`Detection`: per-point ``labels`` and ``part_labels``, the
        ``structures`` and the ``parameters`` used.

    Raises:
        ValueError: wrong shape, no points, NaN or infinite coordinates, a
            parameter out of range, an unknown ``structure``.

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
    >>> len(det.structures), det.parameters["alpha"]["estimated"]
    (2, True)
    """
    labels, part_labels, report = _native.detect(
        points, structure, alpha, lambda2, lambda3, min_size, threads, normals
    )
    r = json.loads(report)
    return Detection(labels, part_labels, r["structures"], r["parameters"])


def read(path: PathLike) -> NDArray[np.float64]:
    """The points of a point file: float64 array of shape (n, 3), in file
    order, the format chosen by extension: ``.xyz`` ``.txt`` ``.csv``
    ``.pts`` (text: x y z in the first three columns), ``.ply`` (ascii and
    binary), ``.las`` ``.laz``, ``.pcd``, ``.e57``.

    Raises:
        OSError: the file cannot be opened (``FileNotFoundError``...).
        ValueError: an unknown extension, a malformed file (the message
            names the file and, for text, the line), NaN or infinite
            coordinates, no points.

    The GIL is released while the file is read.

    >>> import os, tempfile, aniso_alpha as aa
    >>> path = os.path.join(tempfile.mkdtemp(), "points.xyz")
    >>> with open(path, "w") as f:
    ...     _ = f.write("x y z\\n0 0 0\\n1 2 3\\n")
    >>> aa.read(path)
    array([[0., 0., 0.],
           [1., 2., 3.]])
    """
    return _native.read(os.fspath(path))
