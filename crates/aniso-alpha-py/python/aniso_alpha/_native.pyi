# Type stubs of the Rust extension module `aniso_alpha._native`
# (crates/aniso-alpha-py/src/lib.rs). The public, documented API is the
# package `aniso_alpha`; these are its private building blocks.

from typing import Optional, Tuple

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

def detect(
    points: ArrayLike,
    structure: str,
    alpha: Optional[float] = None,
    lambda2: Optional[float] = None,
    lambda3: Optional[float] = None,
    min_size: Optional[int] = None,
    threads: Optional[int] = None,
) -> Tuple[NDArray[np.int64], NDArray[np.int64], str]:
    """(labels, part_labels, JSON text of {"structures": [...], "parameters": {...}})."""

def read(path: str) -> NDArray[np.float64]:
    """float64 (n, 3), the points of a point file in file order."""

def _points_address(points: ArrayLike) -> int:
    """Address of the float64 buffer the library reads (tests: no copy)."""

def _panic(on_worker: bool) -> None:
    """Panics inside a call; raises RuntimeError (tests: no crash)."""
