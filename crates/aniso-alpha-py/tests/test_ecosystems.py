"""PDAL's and Open3D's ways in and out: PDAL's structured arrays (what
`pipeline.arrays` gives) and `filters.python`'s dimension dicts, and an
Open3D PointCloud (duck-typed: its `points`, `normals`, `has_normals()`),
with the results as Open3D users read them (per plane: equation, inliers,
outline)."""

import numpy as np
import pytest

import aniso_alpha as aa
from conftest import FIXTURES

BALL = FIXTURES / "real" / "ball.ply"

# The dimensions and types of PDAL's readers.las (point format 3) and
# filters.normal, as `pdal.Pipeline(...).arrays[0].dtype` lists them.
PDAL_DTYPE = [
    ("X", "<f8"),
    ("Y", "<f8"),
    ("Z", "<f8"),
    ("Intensity", "<u2"),
    ("ReturnNumber", "u1"),
    ("NumberOfReturns", "u1"),
    ("Classification", "u1"),
    ("GpsTime", "<f8"),
    ("NormalX", "<f8"),
    ("NormalY", "<f8"),
    ("NormalZ", "<f8"),
    ("Curvature", "<f8"),
]


def pdal_array(cloud, normals=True):
    """The cloud as PDAL's structured array."""
    dtype = [d for d in PDAL_DTYPE if normals or not d[0].startswith("Normal")]
    a = np.zeros(len(cloud), dtype=dtype)
    for i, name in enumerate("XYZ"):
        a[name] = cloud.points[:, i]
    a["Intensity"] = np.arange(len(cloud)) % 65536
    a["Classification"] = 1
    if normals:
        for i, name in enumerate(("NormalX", "NormalY", "NormalZ")):
            a[name] = cloud.normals[:, i]
    return a


def test_pdal_structured_array_round_trip():
    cloud = aa.read(BALL)
    arr = pdal_array(cloud)
    det = aa.detect(arr, "planes")
    # The normals of the array are used: the labels of the cloud with its
    # normals, not those of the coordinates alone.
    ref = aa.detect(cloud, "planes")
    np.testing.assert_array_equal(det.labels, ref.labels)
    np.testing.assert_array_equal(det.part_labels, ref.part_labels)
    assert det.parameters["normals"]["source"] == "input"
    plain = aa.detect(pdal_array(cloud, normals=False), "planes")
    assert plain.parameters["normals"]["source"] == "estimated"

    out = aa.labelled_array(arr, det, classify=6)
    assert out.dtype.names == tuple(n for n, _ in PDAL_DTYPE) + ("StructureId", "PlaneId")
    assert out.dtype["StructureId"] == np.int32 and out.dtype["PlaneId"] == np.int32
    for name, _ in PDAL_DTYPE:
        if name != "Classification":
            np.testing.assert_array_equal(out[name], arr[name])
    np.testing.assert_array_equal(out["StructureId"], det.labels)
    np.testing.assert_array_equal(out["PlaneId"], det.part_labels)
    np.testing.assert_array_equal(out["Classification"], np.where(det.labels >= 0, 6, 1))
    # Back in: the labelled array reads as the same points and normals.
    again = aa.detect(out, "planes")
    np.testing.assert_array_equal(again.part_labels, det.part_labels)
    # Lines name their parts LineId.
    lines = aa.detect(arr, "lines")
    assert set(aa.labelled_array(arr, lines).dtype.names) >= {"StructureId", "LineId"}
    with pytest.raises(ValueError, match="fields X, Y and Z"):
        aa.detect(np.zeros(3, dtype=[("x", "<f8"), ("y", "<f8"), ("z", "<f8")]), "planes")
    with pytest.raises(ValueError, match="structured array"):
        aa.labelled_array(cloud.points, det)


def test_pdal_filters_python_function():
    """The README's filters.python function, called as PDAL calls it:
    `ins` a dict of the dimensions' arrays, `outs` a dict to fill."""
    cloud = aa.read(BALL)
    arr = pdal_array(cloud)
    ins = {name: arr[name] for name in arr.dtype.names}

    def detect_planes(ins, outs):
        det = aa.detect(ins, "planes")
        outs.update(det.dimensions())
        return True

    outs = {}
    assert detect_planes(ins, outs)
    ref = aa.detect(cloud, "planes")
    assert sorted(outs) == ["PlaneId", "StructureId"]
    np.testing.assert_array_equal(outs["PlaneId"], ref.part_labels)
    np.testing.assert_array_equal(outs["StructureId"], ref.labels)
    with pytest.raises(ValueError, match="needs X, Y and Z"):
        aa.detect({"X": arr["X"]}, "planes")


class Vector3dVector:
    """Open3D's Vector3dVector as numpy sees it: the buffer protocol of an
    (n, 3) float64 array (np.asarray gives a view)."""

    def __init__(self, rows):
        self._rows = np.ascontiguousarray(rows, dtype=np.float64)

    def __array__(self, dtype=None, copy=None):
        return self._rows

    def __len__(self):
        return len(self._rows)


class PointCloud:
    """The part of open3d.geometry.PointCloud that aniso_alpha reads."""

    def __init__(self, points, normals=None):
        self.points = Vector3dVector(points)
        self.normals = Vector3dVector(normals if normals is not None else np.zeros((0, 3)))

    def has_normals(self):
        return len(self.normals) > 0


def test_open3d_point_cloud_and_planes_as_open3d_reads_them():
    cloud = aa.read(BALL)
    pcd = PointCloud(cloud.points, cloud.normals)
    det = aa.detect(pcd, "planes")
    ref = aa.detect(cloud, "planes")
    np.testing.assert_array_equal(det.part_labels, ref.part_labels)
    no_normals = aa.detect(PointCloud(cloud.points), "planes")
    assert no_normals.parameters["normals"]["source"] == "estimated"

    planes = det.planes
    assert len(planes) == det.part_labels.max() + 1 and det.segments == []
    for p in planes:
        a, b, c, d = p.equation
        assert abs(np.hypot(np.hypot(a, b), c) - 1) < 1e-9
        np.testing.assert_array_equal(p.inliers, np.flatnonzero(det.part_labels == p.id))
        # The inliers lie on the plane within a few RMS; the outline on it.
        dist = cloud.points[p.inliers] @ p.equation[:3] + d
        assert np.sqrt(np.mean(dist**2)) == pytest.approx(p.rms, rel=1e-6)
        assert p.polygon.ndim == 2 and p.polygon.shape[1] == 3 and len(p.polygon) >= 3
        assert np.abs(p.polygon @ p.equation[:3] + d).max() < 1e-6
        assert abs(p.centroid @ p.equation[:3] + d) < 1e-9
        assert set(det.labels[p.inliers]) == {p.structure}


def test_segments_of_lines(detections):
    pts, det = detections["lines"]
    segs = det.segments
    assert segs and det.planes == []
    for s in segs:
        assert s.endpoints.shape == (2, 3)
        assert s.length == pytest.approx(np.linalg.norm(s.endpoints[1] - s.endpoints[0]))
        np.testing.assert_array_equal(s.inliers, np.flatnonzero(det.part_labels == s.id))


def test_open3d_itself():
    """The real open3d.geometry.PointCloud (.ci/run installs Open3D from
    PyPI): its points and normals are what aa.detect reads, and the largest
    plane agrees with Open3D's own segment_plane on its inliers."""
    from conftest import need

    o3d = need("open3d", "pip install open3d")
    cloud = aa.read(BALL)
    pcd = o3d.geometry.PointCloud()
    pcd.points = o3d.utility.Vector3dVector(cloud.points)
    pcd.normals = o3d.utility.Vector3dVector(cloud.normals)
    det = aa.detect(pcd, "planes")
    np.testing.assert_array_equal(det.part_labels, aa.detect(cloud, "planes").part_labels)
    plane = det.planes[0]
    sub = pcd.select_by_index(plane.inliers.tolist())
    eq, inliers = sub.segment_plane(distance_threshold=3 * plane.rms, ransac_n=3, num_iterations=200)
    eq = np.asarray(eq)
    assert abs(abs(eq[:3] @ plane.equation[:3]) - 1) < 1e-3
    assert len(inliers) > 0.9 * len(plane.inliers)
    # Normals estimated by Open3D itself are used as given normals.
    pcd.estimate_normals(o3d.geometry.KDTreeSearchParamHybrid(radius=2.0, max_nn=30))
    det = aa.detect(pcd, "planes")
    assert det.parameters["normals"]["source"] == "input" and len(det.planes) >= 15
