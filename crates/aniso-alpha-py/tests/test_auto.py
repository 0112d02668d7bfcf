"""aa.detect without parameters: estimated from the data (Detector::auto),
the given ones kept."""

import numpy as np
import pytest

import aniso_alpha as aa


def two_planes():
    """Two perpendicular 40 x 40 grids (spacing 1, noise 0.02) and 300
    uniform background points; truth: 0, 1 or -1."""
    rng = np.random.default_rng(0)
    g = np.arange(40.0)
    x, y = (a.ravel() for a in np.meshgrid(g, g))
    a = np.c_[x, y, np.full(x.size, 10.0)]
    b = np.c_[x, np.full(x.size, 25.0), y]
    pts = np.vstack([a, b, rng.random((300, 3)) * 40])
    pts += rng.normal(0.0, 0.02, pts.shape)
    truth = np.r_[np.zeros(len(a)), np.ones(len(b)), -np.ones(300)]
    return pts, truth


def two_lines():
    """Two skew lines of 200 points (spacing 0.5) in 200 background points."""
    rng = np.random.default_rng(0)
    t = np.arange(200.0) * 0.5
    lines = np.vstack([np.c_[t, np.full(200, 5.0), np.full(200, 5.0)], np.c_[np.full(200, 20.0), t, np.full(200, 30.0)]])
    return np.vstack([lines, rng.random((200, 3)) * 100]), np.r_[np.zeros(200), np.ones(200), -np.ones(200)]


@pytest.fixture(scope="module")
def planes_auto():
    pts, truth = two_planes()
    return pts, truth, aa.detect(pts, "planes")


def test_planes_without_parameters(planes_auto):
    pts, truth, det = planes_auto
    assert det.labels.shape == (len(pts),) and det.labels.dtype == np.int64
    assert det.part_labels.shape == (len(pts),)
    p = det.parameters
    assert p["structure"] == "planes"
    names = ("alpha", "lambda2", "lambda3", "min_size")
    assert all(p[n]["estimated"] is True for n in names)
    assert all(isinstance(p[n]["reason"], str) and p[n]["reason"] for n in names)
    assert p["orientations"]["kind"] == "data" and len(p["orientations"]["modes"]) >= 2
    # The two planes are found, and little else.
    assert len(det.structures) == 2
    assert np.count_nonzero((det.labels >= 0) & (truth >= 0)) >= 0.95 * np.count_nonzero(truth >= 0)
    assert np.count_nonzero((det.labels >= 0) & (truth < 0)) <= 15
    for s in det.structures:
        assert s["kind"] == "plane" and s["points"] >= 1500


def test_lines_without_parameters():
    pts, truth = two_lines()
    det = aa.detect(pts, "lines")
    p = det.parameters
    assert all(p[n]["estimated"] is True for n in ("alpha", "lambda3", "min_size"))
    assert p["lambda2"] is None
    assert sorted(s["points"] for s in det.structures) == [200, 200]
    np.testing.assert_array_equal(det.labels >= 0, truth >= 0)


def test_given_values_are_kept():
    pts, _ = two_planes()
    det = aa.detect(pts, "planes", alpha=0.3, min_size=6)
    p = det.parameters
    assert p["alpha"]["value"] == 0.3 and p["min_size"]["value"] == 6
    assert {n: p[n]["estimated"] for n in ("alpha", "lambda2", "lambda3", "min_size")} == {
        "alpha": False,
        "lambda2": True,
        "lambda3": True,
        "min_size": False,
    }
    assert p["alpha"]["reason"] == "given"
    det = aa.detect(pts, "planes", lambda3=5.0)
    # lambda2 of planes follows a given lambda3.
    assert det.parameters["lambda3"]["value"] == 5.0 and det.parameters["lambda2"]["value"] == 5.0
    assert det.parameters["lambda3"]["estimated"] is False


def test_estimation_does_not_depend_on_threads(planes_auto):
    pts, _, ref = planes_auto
    det = aa.detect(pts, "planes", threads=1)
    np.testing.assert_array_equal(det.labels, ref.labels)
    np.testing.assert_array_equal(det.part_labels, ref.part_labels)
    assert det.parameters == ref.parameters and det.structures == ref.structures


def wall_with_frame():
    """A wall z = 0 (6 m, a 0.1 m grid, 5 mm of noise) with normals (0, 0, 1)
    and, on it, 100 points of a window frame's sides within 1 cm of the
    wall, facing along x; the wall's points come first."""
    rng = np.random.default_rng(5)
    g = np.arange(60) * 0.1
    x, y = (a.ravel() for a in np.meshgrid(g, g))
    wall = np.c_[x + rng.uniform(-0.01, 0.01, x.size), y + rng.uniform(-0.01, 0.01, x.size), rng.uniform(-0.005, 0.005, x.size)]
    frame = np.c_[3.0 + np.where(np.arange(100) % 2 == 0, -0.01, 0.01), rng.uniform(1, 5, 100), rng.uniform(-0.0075, 0.0075, 100)]
    normals = np.r_[np.tile([0.0, 0.0, 1.0], (len(wall), 1)), np.tile([1.0, 0.0, 0.0], (100, 1))]
    return np.vstack([wall, frame]), normals


def test_normals_keep_a_frame_out_of_its_wall():
    pts, normals = wall_with_frame()
    n_wall = len(pts) - 100

    def frame_in_wall(det):
        wall = np.bincount(det.part_labels[:n_wall][det.part_labels[:n_wall] >= 0]).argmax()
        assert np.sum(det.part_labels[:n_wall] == wall) >= n_wall - 50
        return int(np.sum(det.part_labels[n_wall:] == wall))

    assert frame_in_wall(aa.detect(pts, "planes", normals=normals)) == 0
    # Without them, the frame's points are within the wall's claim radius.
    assert frame_in_wall(aa.detect(pts, "planes")) >= 80
    # A list of lists works too; the sign of a normal does not matter.
    det = aa.detect(pts, "planes", normals=(-normals).tolist())
    assert frame_in_wall(det) == 0


def test_normals_of_another_shape_are_a_value_error():
    pts, normals = wall_with_frame()
    with pytest.raises(ValueError, match="normals"):
        aa.detect(pts, "planes", normals=normals[:10])
    with pytest.raises(ValueError, match="normals"):
        aa.detect(pts, "planes", normals=normals[:, :2])


def test_outlines_off_changes_nothing_but_the_polygons(planes_auto, tmp_path):
    """outlines=False: the same labels, equations, inliers and report, every
    polygon empty (0, 3), and a PLY written from it without meshes."""
    pts, _, det = planes_auto
    bare = aa.detect(pts, "planes", outlines=False)
    np.testing.assert_array_equal(bare.labels, det.labels)
    np.testing.assert_array_equal(bare.part_labels, det.part_labels)
    assert bare.parameters == det.parameters
    assert len(bare.planes) == len(det.planes) >= 2
    for a, b in zip(bare.planes, det.planes):
        np.testing.assert_array_equal(a.equation, b.equation)
        np.testing.assert_array_equal(a.inliers, b.inliers)
        assert a.rms == b.rms
        assert a.polygon.shape == (0, 3) and len(b.polygon) >= 3
    strip = ("polygon", "triangles")

    def without_outlines(structures):
        return [
            {**s, "parts": [{k: v for k, v in p.items() if k not in strip} for p in s["parts"]]}
            for s in structures
        ]

    assert without_outlines(bare.structures) == without_outlines(det.structures)
    with_meshes, bare_ply = tmp_path / "full.ply", tmp_path / "bare.ply"
    aa.write(with_meshes, pts, det)
    aa.write(bare_ply, pts, bare)
    assert b"element face" in with_meshes.read_bytes()[:2000]
    assert b"element face" not in bare_ply.read_bytes()[:2000]
