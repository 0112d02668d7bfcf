"""aniso-alpha: lines, planes and polyhedral surfaces in 3D point clouds.

Anisotropic alpha-shapes (Bougleux, Melkemi & Elmoataz 2005) on an exact 3D
Delaunay and alpha-shape engine whose tetrahedra are CGAL's, tet for tet,
even on degenerate input. Points in and results out are numpy arrays.

>>> import numpy as np, aniso_alpha as aa
>>> grid = np.array([[x, y, z] for x in range(3) for y in range(3) for z in range(3)], dtype=float)
>>> aa.delaunay(grid).shape
(48, 4)

Functions: :func:`detect` (the CLI's ``detect``, the same options and
labels), :func:`detect_regions` (region by region, for clouds of millions
of points: the CLI's default above 1,000,000), :func:`read` (a :class:`Cloud`: points, normals, attributes),
:func:`write` (the labelled cloud, as ``detect --output``),
:func:`labelled_array` (PDAL's structured arrays), :func:`delaunay`,
:func:`alpha_intervals`. :func:`detect` takes a :class:`Cloud`, PDAL's
arrays, an Open3D ``PointCloud`` or any (n, 3) array-like; its
:class:`Detection` lists each :class:`Plane` (equation, inliers, outline)
or :class:`Segment`. Every long call releases the GIL and takes
``threads=`` (default: all cores); bad input raises ``ValueError`` with
the library's message; what the CLI prints as a warning is an
:class:`AnisoAlphaWarning`.

:mod:`aniso_alpha.distributed` (with the optional ``dask[distributed]``,
the ``distributed`` extra) runs :func:`detect` tile by tile on a Dask
cluster, with the same result.
"""

from ._api import (
    AlphaIntervals,
    Sampler,
    Structure,
    alpha_intervals,
    delaunay,
    detect,
    detect_regions,
)
from ._io import AnisoAlphaWarning, Cloud, labelled_array, read, write
from ._native import __version__
from ._results import Detection, Plane, RegionDetection, RegionPart, Segment, TileDetection

__all__ = [
    "AlphaIntervals",
    "AnisoAlphaWarning",
    "Cloud",
    "Detection",
    "Plane",
    "RegionDetection",
    "RegionPart",
    "Sampler",
    "Segment",
    "Structure",
    "TileDetection",
    "__version__",
    "alpha_intervals",
    "delaunay",
    "detect",
    "detect_regions",
    "labelled_array",
    "read",
    "write",
]
