"""aniso-alpha: lines, planes and polyhedral surfaces in 3D point clouds.

Anisotropic alpha-shapes (Bougleux, Melkemi & Elmoataz 2005) on an exact 3D
Delaunay and alpha-shape engine whose tetrahedra are CGAL's, tet for tet,
even on degenerate input. Points in and results out are numpy arrays.

>>> import numpy as np, aniso_alpha as aa
>>> grid = np.array([[x, y, z] for x in range(3) for y in range(3) for z in range(3)], dtype=float)
>>> aa.delaunay(grid).shape
(48, 4)

Functions: :func:`detect`, :func:`delaunay`, :func:`alpha_intervals`,
:func:`read`. Every long call releases the GIL and takes ``threads=``
(default: all cores); bad input raises ``ValueError`` with the library's
message.

:mod:`aniso_alpha.distributed` (with the optional ``dask[distributed]``,
the ``distributed`` extra) runs :func:`detect` tile by tile on a Dask
cluster, with the same result.
"""

from ._api import AlphaIntervals, Detection, alpha_intervals, delaunay, detect, read
from ._native import __version__

__all__ = [
    "AlphaIntervals",
    "Detection",
    "__version__",
    "alpha_intervals",
    "delaunay",
    "detect",
    "read",
]
