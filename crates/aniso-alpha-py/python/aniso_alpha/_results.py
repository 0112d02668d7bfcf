"""The result of a detection: :class:`Detection`, with its parts as
:class:`Plane` and :class:`Segment` objects (re-exported by
:mod:`aniso_alpha`)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional

import numpy as np
from numpy.typing import NDArray

__all__ = ["Detection", "Plane", "RegionDetection", "RegionPart", "Segment"]


@dataclass(frozen=True, eq=False)
class Plane:
    """One plane found (a plane, or one facet of a polyhedral surface), as
    Open3D's ``segment_plane`` users read one.

    Attributes:
        equation: float64 ``[a, b, c, d]``: ``a·x + b·y + c·z + d = 0``,
            ``(a, b, c)`` the unit normal, least squares on the inliers.
        inliers: int64 indices of the input points on this plane,
            ascending (exact copies of a point included).
        polygon: float64 (k, 3): the outline, the boundary of the 2D
            alpha-shape of the inliers on the plane (outer loop,
            counter-clockwise seen from the normal).
        centroid: float64 (3,): the inliers' centroid, a point on the plane
            (with ``equation[:3]``, the plane without the large ``d`` of
            coordinates far from the origin).
        rms: root mean square distance of the inliers to the plane.
        id: the plane's id in ``Detection.part_labels``.
        structure: the id of its structure in ``Detection.labels``.
    """

    equation: NDArray[np.float64]
    inliers: NDArray[np.int64]
    polygon: NDArray[np.float64]
    centroid: NDArray[np.float64]
    rms: float
    id: int
    structure: int

    def __repr__(self) -> str:
        a, b, c, d = (float(x) for x in self.equation)
        return (
            f"Plane(id={self.id}, structure={self.structure}, {len(self.inliers)} inliers, "
            f"equation=[{a:.6f}, {b:.6f}, {c:.6f}, {d:.6g}], rms={self.rms:.3g})"
        )


@dataclass(frozen=True, eq=False)
class Segment:
    """One line found (a line, or one straight piece of a polyline).

    Attributes:
        endpoints: float64 (2, 3): the extreme projections of the inliers
            on the fitted line.
        direction: float64 (3,): the unit direction, least squares.
        inliers: int64 indices of the input points on this segment.
        length: the distance between the end points.
        rms: root mean square distance of the inliers to the line.
        id: the segment's id in ``Detection.part_labels``.
        structure: the id of its structure in ``Detection.labels``.
    """

    endpoints: NDArray[np.float64]
    direction: NDArray[np.float64]
    inliers: NDArray[np.int64]
    length: float
    rms: float
    id: int
    structure: int

    def __repr__(self) -> str:
        return (
            f"Segment(id={self.id}, structure={self.structure}, {len(self.inliers)} inliers, "
            f"length={self.length:.6g}, rms={self.rms:.3g})"
        )


def _float(x: Any) -> float:
    return float("nan") if x is None else float(x)


def _array(x: Any, shape: tuple[int, ...]) -> NDArray[np.float64]:
    a = np.array([np.nan if v is None else v for v in np.ravel(np.array(x, dtype=object))], dtype=np.float64)
    return a.reshape(shape)


@dataclass(frozen=True, eq=False)
class Detection:
    """The result of :func:`aniso_alpha.detect`.

    Attributes:
        labels: int64 array of shape (n,): for each input point, the id of
            the largest structure that holds it (an index into
            ``structures``), or -1 for background. An exact duplicate has
            its first occurrence's label.
        part_labels: int64 array of shape (n,): the id of the plane (a
            plane, or a facet of a polyhedral surface) or segment that
            holds the point, numbered structure by structure, or -1. These
            are the per-plane ids: a box of six walls is one structure of
            six planes.
        structures: one dict per structure, largest first, as in the
            ``"structures"`` list of the JSON report that
            ``aniso-alpha detect --report`` writes.
        parameters: the parameters used, as the report's ``"parameters"``.
        warnings: what the CLI would print as warnings (also issued with
            :func:`warnings.warn` as :class:`aniso_alpha.AnisoAlphaWarning`).
    """

    labels: NDArray[np.int64]
    part_labels: NDArray[np.int64]
    structures: List[Dict[str, Any]]
    parameters: Dict[str, Any]
    warnings: List[str] = field(default_factory=list)
    # The Rust detection, for the meshes `aniso_alpha.write` adds to a PLY.
    _native: Optional[Any] = field(default=None, repr=False)

    @property
    def kind(self) -> str:
        """``"planes"`` or ``"lines"``."""
        return str(self.parameters["structure"])

    @property
    def planes(self) -> List[Plane]:
        """Every plane found (each facet of a surface is one), in
        ``part_labels`` order; empty for lines.

        >>> import numpy as np, aniso_alpha as aa
        >>> g = np.arange(30.0)
        >>> x, y = (a.ravel() for a in np.meshgrid(g, g))
        >>> floor = np.c_[x, y, np.full(900, 2.0)] + np.random.default_rng(1).normal(0, 0.01, (900, 3))
        >>> plane = aa.detect(floor, "planes").planes[0]
        >>> [round(float(v), 2) for v in plane.equation], len(plane.inliers)
        ([0.0, 0.0, 1.0, -2.0], 900)
        """
        out: List[Plane] = []
        if self.kind != "planes":
            return out
        for s in self.structures:
            for p in s["parts"]:
                out.append(
                    Plane(
                        equation=_array(p.get("plane", [None] * 4), (4,)),
                        inliers=np.flatnonzero(self.part_labels == p["id"]).astype(np.int64),
                        polygon=_array(p.get("polygon", []), (-1, 3)),
                        centroid=_array(p.get("centroid", [None] * 3), (3,)),
                        rms=_float(p.get("rms")),
                        id=int(p["id"]),
                        structure=int(s["id"]),
                    )
                )
        return out

    @property
    def segments(self) -> List[Segment]:
        """Every straight segment found (each piece of a polyline is one),
        in ``part_labels`` order; empty for planes."""
        out: List[Segment] = []
        if self.kind != "lines":
            return out
        for s in self.structures:
            for p in s["parts"]:
                out.append(
                    Segment(
                        endpoints=_array(p.get("segment", [[None] * 3] * 2), (2, 3)),
                        direction=_array(p.get("direction", [None] * 3), (3,)),
                        inliers=np.flatnonzero(self.part_labels == p["id"]).astype(np.int64),
                        length=_float(p.get("length")),
                        rms=_float(p.get("rms")),
                        id=int(p["id"]),
                        structure=int(s["id"]),
                    )
                )
        return out

    def dimensions(self) -> Dict[str, NDArray[np.int32]]:
        """The per-point ids as PDAL dimensions, int32 arrays:
        ``StructureId`` (``labels``) and ``PlaneId`` for planes or
        ``LineId`` for lines (``part_labels``); -1 off the structures. In
        PDAL's ``filters.python``: ``outs.update(det.dimensions())``, with
        ``add_dimension`` declaring them.
        """
        return _dimensions(self.kind, self.labels, self.part_labels)

    def __repr__(self) -> str:
        background = int(np.count_nonzero(self.labels < 0))
        parts = int(self.part_labels.max()) + 1 if len(self.part_labels) else 0
        return (
            f"Detection({len(self.structures)} structure(s), {parts} "
            f"{'plane' if self.kind == 'planes' else 'segment'}(s), "
            f"{len(self.labels)} points of which {background} background)"
        )


@dataclass(frozen=True, eq=False)
class RegionPart:
    """One part of a region-by-region detection, joined across regions.

    Attributes:
        id: its id in ``RegionDetection.part_labels`` (0 = most points).
        structure: the id of its structure in ``RegionDetection.labels``.
        points: its number of points.
        pieces: how many regions' parts it joins.
        equation: a plane's float64 ``[a, b, c, d]`` (unit normal), least
            squares on its points; ``None`` for a line.
        direction: a line's float64 unit direction; ``None`` for a plane.
        point: a line's float64 point (its points' centroid); ``None`` for
            a plane.
        rms: root mean square distance of its points to the primitive.
    """

    id: int
    structure: int
    points: int
    pieces: int
    equation: Optional[NDArray[np.float64]]
    direction: Optional[NDArray[np.float64]]
    point: Optional[NDArray[np.float64]]
    rms: float


@dataclass(frozen=True, eq=False)
class RegionDetection:
    """What :func:`aniso_alpha.detect_regions` returns.

    Attributes:
        labels: int64 (n,): each point's structure id, or -1.
        part_labels: int64 (n,): each point's part id, or -1.
        parts: the joined parts, by id (:class:`RegionPart`).
        side: the region side used (input units); ``None`` when the cloud
            is about one region and ran whole.
        regions: the number of regions with points.
        widened: region estimates run again with a wider margin (their
            ellipsoids reached past the first one).
        joins: region parts joined across borders.
        skipped: regions whose points are all at one position (no spacing
            to estimate from), left as background.
        warnings: what the CLI prints as warnings (also raised as
            :class:`AnisoAlphaWarning`): regions that did not use the
            normals given with the points.
        kind: ``"planes"`` or ``"lines"``.
    """

    labels: NDArray[np.int64]
    part_labels: NDArray[np.int64]
    parts: List[RegionPart] = field(default_factory=list)
    side: Optional[float] = None
    regions: int = 1
    widened: int = 0
    joins: int = 0
    skipped: int = 0
    warnings: List[str] = field(default_factory=list)
    kind: str = "planes"

    def dimensions(self) -> Dict[str, NDArray[np.int32]]:
        """The per-point ids as PDAL dimensions, as
        :meth:`Detection.dimensions` gives them."""
        return _dimensions(self.kind, self.labels, self.part_labels)


@dataclass(frozen=True, eq=False)
class TileDetection:
    """What :func:`aniso_alpha.distributed.detect_tiles` returns: a region
    run over a cloud held as tiles, each point's labels written to a copy
    of its tile rather than returned.

    Attributes:
        outputs: the labelled tiles written, in the input's order (empty
            when no folder was given).
        points: the number of points over all tiles.
        parts: the joined parts, by id (:class:`RegionPart`): those of
            :func:`aniso_alpha.detect_regions` on the tiles' points stacked
            in list order.
        side, regions, widened, joins, skipped, warnings: as in
            :class:`RegionDetection`.
    """

    outputs: List[str]
    points: int
    parts: List[RegionPart] = field(default_factory=list)
    side: Optional[float] = None
    regions: int = 1
    widened: int = 0
    joins: int = 0
    skipped: int = 0
    warnings: List[str] = field(default_factory=list)


def _dimensions(
    kind: str, labels: NDArray[np.int64], part_labels: NDArray[np.int64]
) -> Dict[str, NDArray[np.int32]]:
    """``StructureId`` and ``PlaneId`` (planes) or ``LineId`` (lines), int32."""
    part = "PlaneId" if kind == "planes" else "LineId"
    return {"StructureId": labels.astype(np.int32), part: part_labels.astype(np.int32)}
