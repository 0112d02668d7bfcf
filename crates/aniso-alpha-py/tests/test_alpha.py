"""aa.alpha_intervals equals CGAL's Alpha_shape_3 intervals on the fixtures,
and the CLI's `alpha --intervals` exactly."""

import csv

import numpy as np
import pytest

import aniso_alpha as aa
from conftest import FIXTURES, run_cli

# grid_6_aniso.transform.txt: Q = diag(e)·R(euler).
ANISO = dict(elongation=(1.0, 0.25, 0.125), euler=(0.3, -0.2, 0.5))


def read_csv(path):
    """{(dim, v0, v1, v2): (alpha_min, alpha_max)} of an intervals CSV."""
    rows = {}
    with open(path) as f:
        r = csv.reader(f)
        assert next(r) == ["dim", "v0", "v1", "v2", "alpha_min", "alpha_max"]
        for dim, v0, v1, v2, lo, hi in r:
            key = (int(dim), int(v0), int(v1), int(v2) if v2 else -1)
            rows[key] = (float(lo), float(hi))
    return rows


def as_rows(iv):
    rows = {}
    for (a, b), (lo, hi) in zip(iv.edges.tolist(), iv.edge_alpha.tolist()):
        rows[(1, a, b, -1)] = (lo, hi)
    for (a, b, c), (lo, hi) in zip(iv.triangles.tolist(), iv.triangle_alpha.tolist()):
        rows[(2, a, b, c)] = (lo, hi)
    return rows


@pytest.mark.parametrize(
    "name, kwargs",
    [
        ("grid_6", {}),
        ("random_500", {}),
        ("sphere_100", {}),
        ("duplicates_50", {}),
        ("grid_6_aniso", ANISO),
    ],
)
def test_equals_cgal(name, kwargs):
    iv = aa.alpha_intervals(np.loadtxt(FIXTURES / f"{name}.xyz"), **kwargs)
    ours, theirs = as_rows(iv), read_csv(FIXTURES / f"{name}.intervals.csv")
    assert ours.keys() == theirs.keys()
    a = np.array([ours[k] for k in theirs])
    b = np.array([theirs[k] for k in theirs])
    assert (np.isinf(a) == np.isinf(b)).all()
    fin = np.isfinite(b)
    np.testing.assert_allclose(a[fin], b[fin], rtol=1e-9, atol=0)


def test_layout():
    iv = aa.alpha_intervals(np.loadtxt(FIXTURES / "grid_6.xyz"))
    assert iv.edges.dtype == np.uint32 and iv.edges.shape == (1115, 2)
    assert iv.triangles.dtype == np.uint32 and iv.triangles.shape == (1650, 3)
    assert iv.edge_alpha.shape == (1115, 2) and iv.triangle_alpha.shape == (1650, 2)
    assert (iv.edges[:, 0] < iv.edges[:, 1]).all()
    assert (np.diff(iv.triangles, axis=1) > 0).all()
    assert (iv.edge_alpha[:, 0] <= iv.edge_alpha[:, 1]).all()
    edges, triangles = iv.at(0.75)
    lo, hi = iv.edge_alpha.T
    assert len(edges) == np.count_nonzero((lo <= 0.75) & (0.75 <= hi))


@pytest.mark.parametrize("kwargs", [{}, ANISO])
def test_equals_cli(cli, tmp_path, kwargs):
    src = FIXTURES / "grid_6.xyz"
    out = tmp_path / "iv.csv"
    args = ["alpha", src, "--intervals", out]
    if kwargs:
        args += ["--elongation", "1,0.25,0.125", "--euler=0.3,-0.2,0.5"]
    run_cli(cli, *args)
    theirs = read_csv(out)
    ours = as_rows(aa.alpha_intervals(aa.read(src), **kwargs))
    # The CLI writes shortest round-trip decimals: the values are equal.
    assert ours == theirs
    assert list(ours) == list(theirs)  # and in the same order
    # The binary output: the same rows, as one NumPy structured array.
    npy = tmp_path / "iv.npy"
    run_cli(cli, *args[:3], npy, *args[4:])
    rows = np.load(npy)
    assert rows.dtype.names == ("dim", "v0", "v1", "v2", "alpha_min", "alpha_max")
    iv = aa.alpha_intervals(src_points(src), **kwargs)
    edges, tris = rows[rows["dim"] == 1], rows[rows["dim"] == 2]
    assert (rows["dim"][: len(edges)] == 1).all()  # edges first
    np.testing.assert_array_equal(np.c_[edges["v0"], edges["v1"]], iv.edges)
    assert (edges["v2"] == np.iinfo(np.uint32).max).all()
    np.testing.assert_array_equal(np.c_[edges["alpha_min"], edges["alpha_max"]], iv.edge_alpha)
    np.testing.assert_array_equal(np.c_[tris["v0"], tris["v1"], tris["v2"]], iv.triangles)
    np.testing.assert_array_equal(np.c_[tris["alpha_min"], tris["alpha_max"]], iv.triangle_alpha)


def src_points(path):
    return aa.read(path).points


def test_threads_do_not_change_the_result():
    pts = np.random.default_rng(5).random((20_000, 3))
    one = aa.alpha_intervals(pts, threads=1)
    two = aa.alpha_intervals(pts, threads=2)
    for f in ("edges", "edge_alpha", "triangles", "triangle_alpha"):
        np.testing.assert_array_equal(getattr(one, f), getattr(two, f))
