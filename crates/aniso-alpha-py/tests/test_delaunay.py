"""aa.delaunay equals CGAL's tets on the library's fixtures (degenerate grids,
cospherical, coplanar, collinear, duplicated points) and the CLI's output."""

import numpy as np
import pytest

import aniso_alpha as aa
from conftest import FIXTURES, canonical, read_tets, run_cli

CGAL_FIXTURES = [
    "grid_6",  # integer grid {0..5}^3: cospherical everywhere
    "random_500",
    "sphere_100",
    "cocircular_plane",
    "duplicates_50",
    "coplanar_30",
    "collinear_10",
]


def orient3d(p: np.ndarray, tets: np.ndarray) -> np.ndarray:
    a, b, c, d = (p[tets[:, i].astype(np.int64)] for i in range(4))
    return np.einsum("ij,ij->i", np.cross(b - a, c - a), d - a)


@pytest.mark.parametrize("name", CGAL_FIXTURES)
@pytest.mark.parametrize("threads", [1, 2])
def test_equals_cgal(name, threads):
    pts = np.loadtxt(FIXTURES / f"{name}.xyz", ndmin=2)
    tets = aa.delaunay(pts, threads=threads)
    assert tets.dtype == np.uint32 and tets.ndim == 2 and tets.shape[1] == 4
    theirs = read_tets(FIXTURES / f"{name}.tets")
    assert len(tets) == len(theirs)
    np.testing.assert_array_equal(canonical(tets), canonical(theirs))


def test_grid_is_degenerate_and_positively_oriented():
    pts = np.loadtxt(FIXTURES / "grid_6.xyz")
    tets = aa.delaunay(pts)
    assert len(tets) == 750
    # Integer coordinates: the determinants are exact in float64.
    assert (orient3d(pts, tets) > 0).all()


def test_lower_dimensions_have_no_tets():
    for name in ("collinear_10", "coplanar_30"):
        tets = aa.delaunay(np.loadtxt(FIXTURES / f"{name}.xyz"))
        assert tets.shape == (0, 4) and tets.dtype == np.uint32


def test_duplicates_map_to_first_occurrence():
    pts = np.loadtxt(FIXTURES / "duplicates_50.xyz")
    used = np.unique(aa.delaunay(pts))
    first = {tuple(p): i for i, p in reversed(list(enumerate(pts.tolist())))}
    assert set(used.tolist()) <= set(first.values())


@pytest.mark.parametrize("threads", [1, 2])
def test_equals_cli(cli, tmp_path, threads):
    # A cloud large enough for the parallel build, in a file both read.
    rng = np.random.default_rng(7)
    pts = rng.random((40_000, 3))
    path = tmp_path / "cloud.xyz"
    np.savetxt(path, pts, fmt="%.17g")
    out = tmp_path / "cloud.tets"
    run_cli(cli, "delaunay", path, "--tets", out, "--threads", threads)
    theirs = read_tets(out)
    ours = aa.delaunay(aa.read(path), threads=threads)
    # Same thread count: the same rows in the same order.
    np.testing.assert_array_equal(ours, theirs)


def test_canonical_can_fail():
    # The comparison sees an odd permutation (the other orientation) and a
    # changed vertex.
    t = np.array([[0, 1, 2, 3], [4, 5, 6, 7]])
    assert (canonical(t) == canonical(t[::-1, [2, 3, 0, 1]])).all()
    assert not (canonical(t) == canonical(t[:, [1, 0, 2, 3]])).all()
    assert not (canonical(t) == canonical(t + [0, 0, 0, 1])).all()


def test_thread_counts_give_the_same_tets():
    rng = np.random.default_rng(3)
    pts = rng.random((40_000, 3))
    one = aa.delaunay(pts, threads=1)
    two = aa.delaunay(pts, threads=2)
    np.testing.assert_array_equal(canonical(one), canonical(two))
