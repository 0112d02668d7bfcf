"""Points: any array-like of shape (n, 3); a C-contiguous float64 array is
read in place, anything else converted once."""

import numpy as np
import pytest

import aniso_alpha as aa
from conftest import FIXTURES

GRID = np.loadtxt(FIXTURES / "grid_6.xyz")


def test_c_contiguous_float64_is_not_copied():
    pts = np.ascontiguousarray(GRID)
    assert aa._native._points_address(pts) == pts.ctypes.data
    # A C-contiguous slice of rows is a view: still no copy.
    rows = pts[10:50]
    assert aa._native._points_address(rows) == rows.ctypes.data
    # Read-only arrays too.
    ro = pts.copy()
    ro.setflags(write=False)
    assert aa._native._points_address(ro) == ro.ctypes.data


@pytest.mark.parametrize(
    "convert",
    [
        np.asfortranarray,
        lambda a: a.astype(np.float32),
        lambda a: a.astype(np.int64),
        lambda a: a.astype(">f8"),
        lambda a: np.repeat(a, 2, axis=0)[::2],  # strided view
    ],
)
def test_other_arrays_are_converted(convert):
    arr = convert(GRID)
    assert aa._native._points_address(arr) != arr.ctypes.data
    np.testing.assert_array_equal(aa.delaunay(arr), aa.delaunay(GRID))


def test_lists_and_tuples():
    ref = aa.delaunay(GRID)
    np.testing.assert_array_equal(aa.delaunay(GRID.tolist()), ref)
    np.testing.assert_array_equal(aa.delaunay(tuple(map(tuple, GRID.tolist()))), ref)


def test_array_like_objects():
    class Cloud:
        def __array__(self, dtype=None, copy=None):
            return GRID

    np.testing.assert_array_equal(aa.delaunay(Cloud()), aa.delaunay(GRID))


def test_caller_array_is_left_alone():
    pts = np.ascontiguousarray(GRID)
    before = pts.copy()
    aa.detect(pts, "lines", alpha=0.4, lambda3=2.0, min_size=4)
    np.testing.assert_array_equal(pts, before)
    assert pts.flags.writeable


def test_read_formats(tmp_path):
    pts = np.random.default_rng(1).random((50, 3))
    xyz = tmp_path / "p.xyz"
    np.savetxt(xyz, pts, fmt="%.17g", header="x y z")
    csv = tmp_path / "p.csv"
    np.savetxt(csv, pts, fmt="%.17g", delimiter=",")
    ply = tmp_path / "p.ply"
    header = "ply\nformat binary_little_endian 1.0\nelement vertex 50\n" + "".join(
        f"property double {c}\n" for c in "xyz"
    ) + "end_header\n"
    ply.write_bytes(header.encode() + pts.astype("<f8").tobytes())
    for path in (xyz, csv, ply):
        got = aa.read(path).points
        assert got.dtype == np.float64 and got.shape == (50, 3) and got.flags.c_contiguous
        np.testing.assert_array_equal(got, pts)
    # str and os.PathLike both work.
    np.testing.assert_array_equal(aa.read(str(ply)).points, pts)


def test_read_a_range_of_a_las_file(tmp_path):
    """start/count read a LAS/LAZ file's rows alone (every attribute and
    the records of those rows); other formats refuse them."""
    las = FIXTURES / "las" / "simple.copc.laz"
    whole = aa.read(las)
    n = len(whole.points)
    for start, count in ((0, n), (0, 1), (n - 1, 5), (517, 300), (1000, None)):
        part = aa.read(las, start=start, count=count)
        stop = n if count is None else min(n, start + count)
        np.testing.assert_array_equal(part.points, whole.points[start:stop])
        for name, values in whole.attributes.items():
            np.testing.assert_array_equal(part.attributes[name], values[start:stop], err_msg=name)
    np.testing.assert_array_equal(aa.read(las, count=3, attributes=False).points, whole.points[:3])
    with pytest.raises(ValueError, match=f"the file has {n} points"):
        aa.read(las, start=n)
    with pytest.raises(ValueError, match="start must be a non-negative integer"):
        aa.read(las, start=-1)
    xyz = tmp_path / "p.xyz"
    np.savetxt(xyz, whole.points[:10])
    with pytest.raises(ValueError, match="read from LAS/LAZ files only"):
        aa.read(xyz, start=2)
