"""Point clouds in and out: :func:`read` (a :class:`Cloud` with its
normals and attributes), :func:`write` (the labelled cloud, as
``aniso-alpha detect --output``), PDAL's structured arrays
(:func:`labelled_array`), and the inputs :func:`aniso_alpha.detect`
accepts (re-exported by :mod:`aniso_alpha`)."""

from __future__ import annotations

import os
import warnings
from dataclasses import dataclass, field
from typing import Any, Dict, Mapping, Optional, Tuple, Union

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _native
from ._results import Detection, RegionDetection

__all__ = ["AnisoAlphaWarning", "Cloud", "labelled_array", "read", "write"]

PathLike = Union[str, "os.PathLike[str]"]

# PDAL's names of the coordinates and of the normals (filters.normal).
_PDAL_XYZ = ("X", "Y", "Z")
_PDAL_NORMALS = ("NormalX", "NormalY", "NormalZ")


class AnisoAlphaWarning(UserWarning):
    """What the CLI prints as a warning: a text file's first line taken as
    a header, points skipped, normals given but not used, a very large
    run."""


def _warn(messages: Any, stacklevel: int = 3) -> None:
    for m in messages:
        warnings.warn(str(m), AnisoAlphaWarning, stacklevel=stacklevel)


@dataclass(frozen=True, eq=False)
class Cloud:
    """A point cloud read by :func:`read`: what :func:`aniso_alpha.detect`
    and :func:`write` take.

    Attributes:
        points: float64 (n, 3), in file order.
        normals: float64 (n, 3), the file's normals (a PLY's ``nx ny nz``
            or a PCD's ``normal_x normal_y normal_z``, as read: not
            normalised) or ``None``. :func:`aniso_alpha.detect` uses them
            for planes, as ``aniso-alpha detect`` does.
        attributes: every other per-point property of the file, by name in
            file order, each a 1-D array of the file's type (LAS fields
            under laspy's names: ``intensity``, ``classification``,
            ``gps_time``, ``red``...; the normals are among them too).
        path: the file read, or ``None``.
        format: ``"text"``, ``"ply"``, ``"las"`` (LAS or LAZ), ``"pcd"`` or
            ``"e57"``.
        rows: int64 (n,), each point's row in the file, when some rows
            were left out: an organized PCD cloud's (``HEIGHT`` > 1, a
            depth image's) pixels without a return, whose coordinates are
            NaN (as Open3D's reader leaves them out with
            ``remove_nan_points=True``); ``None`` otherwise.
            ``image = np.full(width * height, -1); image[cloud.rows] =
            det.labels`` gives the labels per pixel, as the CLI's
            ``--labels`` file holds them.

    A ``Cloud`` is array-like: ``np.asarray(cloud)`` is its points, so
    :func:`aniso_alpha.delaunay` and friends take it as they took the
    points.
    """

    points: NDArray[np.float64]
    normals: Optional[NDArray[np.float64]] = None
    attributes: Dict[str, NDArray[Any]] = field(default_factory=dict)
    path: Optional[str] = None
    format: Optional[str] = None
    # A LAS/LAZ file's header, VLRs and records: `write` copies every
    # record byte for byte while the point count is the file's.
    _las: Optional[Any] = field(default=None, repr=False)
    rows: Optional[NDArray[np.int64]] = None

    def __len__(self) -> int:
        return len(self.points)

    def __array__(self, dtype: Any = None, copy: Optional[bool] = None) -> NDArray[Any]:
        if dtype is None or np.dtype(dtype) == self.points.dtype:
            return self.points.copy() if copy else self.points
        return self.points.astype(dtype)

    def __repr__(self) -> str:
        names = ", ".join(self.attributes) or "none"
        return (
            f"Cloud({len(self.points)} points, normals {'yes' if self.normals is not None else 'no'}, "
            f"attributes: {names}{', from ' + self.path if self.path else ''})"
        )


def read(
    path: PathLike,
    *,
    attributes: bool = True,
    start: Optional[int] = None,
    count: Optional[int] = None,
) -> Cloud:
    """Reads a point file: its points, normals and attributes, in file
    order, the format chosen by extension: ``.xyz`` ``.txt`` ``.csv``
    ``.pts`` (text: x y z in the first three columns), ``.ply`` (ascii and
    binary), ``.las`` ``.laz``, ``.pcd``, ``.e57``.

    Args:
        path: the file.
        attributes: read every per-point attribute (default); ``False``
            reads the coordinates alone, faster (no normals then).
        start, count: a LAS/LAZ file's points ``start`` to ``start +
            count`` alone (``count`` cut at the end of the file; either
            may be left out), read without the file's other points or
            bytes: a file larger than memory is read a range at a time
            (:func:`aniso_alpha.distributed.detect_tiles` does). Other
            formats raise ``ValueError``.

    Returns:
        a :class:`Cloud`. What the reader guessed (a text file's first
        line taken as a header, E57 points skipped, an organized PCD
        cloud's points without a return left out: :attr:`Cloud.rows`) is
        issued as an :class:`AnisoAlphaWarning`, as the CLI prints it.

    Raises:
        OSError: the file cannot be opened (``FileNotFoundError``...).
        ValueError: an unknown extension, a malformed file (the message
            names the file and, for text, the line), NaN or infinite
            coordinates, no points.

    The GIL is released while the file is read.

    >>> import os, tempfile, aniso_alpha as aa
    >>> path = os.path.join(tempfile.mkdtemp(), "points.xyz")
    >>> with open(path, "w") as f:
    ...     _ = f.write("0 0 0\\n1 2 3\\n")
    >>> cloud = aa.read(path)
    >>> cloud.points
    array([[0., 0., 0.],
           [1., 2., 3.]])
    >>> cloud.normals is None
    True
    """
    p = os.fspath(path)
    for name, v in (("start", start), ("count", count)):
        if v is not None and not (isinstance(v, (int, np.integer)) and v >= 0):
            raise ValueError(f"{name} must be a non-negative integer, got {v!r}")
    points, attrs, normals, messages, las, fmt, rows = _native.read(
        p, attributes, None if start is None else int(start), None if count is None else int(count)
    )
    _warn([f"{p}: {m}" for m in messages])
    return Cloud(points, normals, dict(attrs), p, fmt, las, rows)


def _labels_of(
    detection: Union[Detection, RegionDetection], n: int
) -> Tuple[NDArray[np.int64], NDArray[np.int64]]:
    if len(detection.labels) != n:
        raise ValueError(f"the detection has {len(detection.labels)} labels for a cloud of {n} points")
    return detection.labels, detection.part_labels


def write(
    path: PathLike,
    cloud: Union[Cloud, ArrayLike],
    detection: Union[Detection, RegionDetection],
    *,
    classify: Optional[int] = None,
) -> None:
    """Writes the cloud with each point's structure and part ids, as
    ``aniso-alpha detect --output`` does: ``.las``/``.laz`` (a LAS/LAZ
    input's header, VLRs and records kept byte for byte, the ids added as
    two int32 extra-bytes fields ``structure`` and ``part``; another input
    becomes LAS 1.2 point format 0 with its attributes as extra bytes) or
    ``.ply`` (every attribute as a vertex property, and the parts' meshes).

    Args:
        path: the output, written atomically (complete or absent).
        cloud: a :class:`Cloud` (its attributes are written), or points
            (n, 3).
        detection: the :class:`Detection` of these points, or their
            :class:`RegionDetection` (its parts have no meshes: a PLY
            gets the points and ids alone).
        classify: a LAS classification (0-255) given to the structures'
            points (``--classify planes=6``).

    >>> import os, tempfile, numpy as np, aniso_alpha as aa
    >>> g = np.arange(20.0)
    >>> x, y = (a.ravel() for a in np.meshgrid(g, g))
    >>> pts = np.c_[x, y, np.zeros(400)] + np.random.default_rng(2).normal(0, 0.01, (400, 3))
    >>> out = os.path.join(tempfile.mkdtemp(), "labelled.ply")
    >>> aa.write(out, pts, aa.detect(pts, "planes"), classify=6)
    >>> back = aa.read(out)
    >>> int((back.attributes["part"] == 0).sum()), int(back.attributes["classification"][0])
    (400, 6)
    """
    if not isinstance(cloud, Cloud):
        cloud = Cloud(np.ascontiguousarray(np.asarray(cloud, dtype=np.float64)))
    labels, parts = _labels_of(detection, len(cloud.points))
    if classify is not None and not (isinstance(classify, (int, np.integer)) and 0 <= int(classify) <= 255):
        raise ValueError(f"classify must be a LAS class between 0 and 255, got {classify!r}")
    _native.write(
        os.fspath(path),
        cloud.points,
        list(cloud.attributes.items()),
        cloud._las,
        labels,
        parts,
        detection._native if isinstance(detection, Detection) else None,
        None if classify is None else int(classify),
    )


def labelled_array(
    array: NDArray[Any], detection: Union[Detection, RegionDetection], *, classify: Optional[int] = None
) -> NDArray[Any]:
    """A PDAL point array (a numpy structured array, as
    ``pdal.Pipeline.arrays`` gives it) with the ids of ``detection`` (a
    :class:`Detection` or a :class:`RegionDetection`) added as
    dimensions: ``StructureId`` and ``PlaneId`` (planes) or ``LineId``
    (lines), int32, -1 off the structures (:meth:`Detection.dimensions`);
    with ``classify``, ``Classification`` (uint8, added if missing) set to
    that class on the structures' points. Fields of those names are
    replaced where they are; the others are copied as they are.

    >>> import numpy as np, aniso_alpha as aa
    >>> g = np.arange(20.0)
    >>> x, y = (a.ravel() for a in np.meshgrid(g, g))
    >>> arr = np.zeros(400, dtype=[("X", "<f8"), ("Y", "<f8"), ("Z", "<f8"), ("Intensity", "<u2")])
    >>> arr["X"], arr["Y"] = x, y
    >>> arr["Z"] = np.random.default_rng(3).normal(0, 0.01, 400)
    >>> out = aa.labelled_array(arr, aa.detect(arr, "planes"), classify=6)
    >>> out.dtype.names
    ('X', 'Y', 'Z', 'Intensity', 'StructureId', 'PlaneId', 'Classification')
    >>> int((out["PlaneId"] == 0).sum()), int(out["Classification"][0])
    (400, 6)
    """
    names = array.dtype.names
    if names is None:
        raise ValueError("labelled_array takes a structured array (PDAL's), with fields X, Y, Z")
    dims: Dict[str, NDArray[Any]] = dict(detection.dimensions())
    _labels_of(detection, len(array))
    if classify is not None:
        if not (isinstance(classify, (int, np.integer)) and 0 <= int(classify) <= 255):
            raise ValueError(f"classify must be a LAS class between 0 and 255, got {classify!r}")
        old = array["Classification"] if "Classification" in names else np.zeros(len(array), np.uint8)
        dims["Classification"] = np.where(detection.labels >= 0, np.uint8(classify), old).astype(
            old.dtype
        )
    fields = [(n, dims[n].dtype if n in dims else array.dtype[n]) for n in names]
    fields += [(n, v.dtype) for n, v in dims.items() if n not in names]
    out = np.empty(len(array), dtype=np.dtype(fields))
    for n, _ in fields:
        out[n] = dims[n] if n in dims else array[n]
    return out


def _columns(source: Any) -> Optional[Tuple[NDArray[np.float64], Optional[NDArray[np.float64]]]]:
    """Points and normals of PDAL's layouts: a structured array or a
    mapping of dimension arrays (``filters.python``'s ``ins``) with ``X``,
    ``Y``, ``Z`` (and ``NormalX``, ``NormalY``, ``NormalZ``)."""
    if isinstance(source, np.ndarray) and source.dtype.names is not None:
        names = source.dtype.names
        if not all(n in names for n in _PDAL_XYZ):
            raise ValueError(
                f"a structured array needs fields X, Y and Z (PDAL's), got {', '.join(names)}"
            )
        get = source.__getitem__
        has_normals = all(n in names for n in _PDAL_NORMALS)
    elif isinstance(source, Mapping):
        if not all(n in source for n in _PDAL_XYZ):
            raise ValueError(
                f"a mapping of dimensions needs X, Y and Z (PDAL's), got {', '.join(map(str, source))}"
            )
        get = source.__getitem__
        has_normals = all(n in source for n in _PDAL_NORMALS)
    else:
        return None
    points = np.column_stack([np.asarray(get(n), dtype=np.float64) for n in _PDAL_XYZ])
    normals = (
        np.column_stack([np.asarray(get(n), dtype=np.float64) for n in _PDAL_NORMALS])
        if has_normals
        else None
    )
    return points, normals


def source_points(source: Any) -> Tuple[Any, Optional[ArrayLike]]:
    """The points and normals of what :func:`aniso_alpha.detect` takes: a
    :class:`Cloud`, a PDAL structured array or mapping of dimensions, an
    Open3D ``PointCloud`` (anything with ``points`` and ``has_normals()``:
    its ``normals`` when it has them), or an array-like of shape (n, 3)
    (no normals)."""
    if isinstance(source, Cloud):
        return source.points, source.normals
    cols = _columns(source)
    if cols is not None:
        return cols
    if hasattr(source, "points") and callable(getattr(source, "has_normals", None)):
        points = np.asarray(source.points, dtype=np.float64)
        normals = np.asarray(source.normals, dtype=np.float64) if source.has_normals() else None
        return points, normals
    return source, None
