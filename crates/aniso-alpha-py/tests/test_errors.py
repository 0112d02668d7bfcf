"""Bad input raises ValueError (OSError for a file that cannot be opened)
with the library's message; nothing crashes the interpreter."""

import numpy as np
import pytest

import aniso_alpha as aa
from conftest import FIXTURES

CUBE = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], dtype=float)
LINES = dict(alpha=1.0, lambda3=10.0, min_size=4)


def every_call():
    """Each public function that takes points, with valid other arguments."""
    return [
        ("delaunay", lambda p: aa.delaunay(p)),
        ("alpha_intervals", lambda p: aa.alpha_intervals(p)),
        ("detect", lambda p: aa.detect(p, "lines", **LINES)),
    ]


@pytest.mark.parametrize("name, call", every_call())
@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_non_finite(name, call, bad):
    pts = CUBE.copy()
    pts[5, 2] = bad
    with pytest.raises(ValueError, match="point 5 has a non-finite"):
        call(pts)


@pytest.mark.parametrize("name, call", every_call())
@pytest.mark.parametrize(
    "shape, text",
    [((8, 2), r"\(8, 2\)"), ((8, 4), r"\(8, 4\)"), ((24,), r"\(24,\)"), ((2, 4, 3), r"\(2, 4, 3\)")],
)
def test_wrong_shape(name, call, shape, text):
    with pytest.raises(ValueError, match=r"points must be an array of shape \(n, 3\), got shape " + text):
        call(np.zeros(shape))


@pytest.mark.parametrize("name, call", every_call())
def test_wrong_shape_list_and_scalar(name, call):
    with pytest.raises(ValueError, match="shape"):
        call([[0.0, 1.0], [2.0, 3.0]])
    with pytest.raises(ValueError, match="shape"):
        call(3.0)


@pytest.mark.parametrize("name, call", every_call())
def test_not_numbers(name, call):
    with pytest.raises(ValueError, match="real numbers"):
        call(CUBE.astype(np.complex128))
    with pytest.raises(ValueError):
        call([["a", "b", "c"]])
    with pytest.raises(ValueError):
        call([[0, 0, 0], [1, 2]])  # ragged


@pytest.mark.parametrize("name, call", every_call())
def test_empty(name, call):
    with pytest.raises(ValueError, match="no points"):
        call(np.zeros((0, 3)))


def test_out_of_range_coordinates():
    pts = CUBE.copy()
    pts[2, 0] = 1e300
    with pytest.raises(ValueError, match="point 2 has x coordinate 1e300, outside the range"):
        aa.delaunay(pts)


@pytest.mark.parametrize(
    "structure, params, text",
    [
        ("lines", dict(alpha=0.0, lambda3=10.0, min_size=4), "alpha must be positive and finite, got 0"),
        ("lines", dict(alpha=-1.0, lambda3=10.0, min_size=4), "alpha must be positive and finite, got -1"),
        ("lines", dict(alpha=np.nan, lambda3=10.0, min_size=4), "alpha must be positive and finite"),
        ("lines", dict(alpha=1.0, lambda3=-10.0, min_size=4), "lambda3 must be between 0.001 and 10000, got -10"),
        ("planes", dict(alpha=1.0, lambda2=0.0, lambda3=8.0, min_size=4), "lambda2 must be between 0.001 and 10000, got 0"),
        ("lines", dict(alpha=1.0, lambda3=10.0, min_size=0), r"^bad parameter: min_size must be between 1 and 4294967295, got 0$"),
        ("lines", dict(alpha=1.0, lambda3=10.0, min_size=-3), "min_size must be between 1 and"),
        ("lines", dict(alpha=1.0, lambda2=4.0, lambda3=10.0, min_size=4), "lambda2 is a parameter of planes"),
        ("circles", dict(alpha=1.0, lambda3=10.0, min_size=4), 'structure must be "lines" or "planes"'),
    ],
)
def test_parameter_out_of_range(structure, params, text):
    with pytest.raises(ValueError, match=text):
        aa.detect(CUBE, structure, **params)


@pytest.mark.parametrize(
    "params, text",
    [
        (dict(alpha=-1.0), "alpha must be positive and finite, got -1"),
        (dict(lambda2=4.0, lambda3=1e9), "lambda3 must be between 0.001 and 10000, got 1000000000"),
        (dict(min_size=0), r"^bad parameter: min_size must be between 1 and 4294967295, got 0$"),
    ],
)
def test_given_parameter_out_of_range_with_estimation(params, text):
    # Some parameters given, the others estimated: the given ones are checked.
    with pytest.raises(ValueError, match=text):
        aa.detect(CUBE, "planes", **params)


def test_bad_points_with_estimation():
    pts = CUBE.copy()
    pts[3, 1] = np.nan
    with pytest.raises(ValueError, match="point 3 has a non-finite"):
        aa.detect(pts, "planes")
    with pytest.raises(ValueError, match="no points"):
        aa.detect(np.zeros((0, 3)), "lines")


@pytest.mark.parametrize(
    "kwargs, text",
    [
        (dict(elongation=(1, 0, 1)), "elongation e2 = 0 must be finite and > 0"),
        (dict(elongation=(1, -2, 1)), "elongation e2 = -2 must be finite and > 0"),
        (dict(elongation=(1, 1)), r"elongation must be 3 numbers, got shape \(2,\)"),
        (dict(euler=(0, np.nan, 0)), "Euler angles must be finite"),
    ],
)
def test_alpha_parameters(kwargs, text):
    with pytest.raises(ValueError, match=text):
        aa.alpha_intervals(CUBE, **kwargs)


@pytest.mark.parametrize("threads", [0, -1])
def test_threads_out_of_range(threads):
    with pytest.raises(ValueError, match=f"threads must be at least 1, got {threads}"):
        aa.delaunay(CUBE, threads=threads)
    with pytest.raises(ValueError, match="threads must be at least 1"):
        aa.detect(CUBE, "lines", threads=threads, **LINES)


def test_read_errors(tmp_path):
    with pytest.raises(FileNotFoundError) as e:
        aa.read(tmp_path / "missing.xyz")
    assert e.value.filename == str(tmp_path / "missing.xyz")
    folder = tmp_path / "folder.xyz"
    folder.mkdir()
    with pytest.raises(IsADirectoryError, match=r"folder\.xyz"):
        aa.read(folder)
    bad = tmp_path / "bad.xyz"
    bad.write_text("0 0 0\n1 2\n")
    with pytest.raises(ValueError, match=r"bad\.xyz:2: expected 3 numeric columns, found 2"):
        aa.read(bad)
    nan = tmp_path / "nan.xyz"
    nan.write_text("0 0 0\n1 nan 2\n")
    with pytest.raises(ValueError, match=r"nan\.xyz"):
        aa.read(nan)
    with pytest.raises(ValueError, match=r"scan\.e58"):
        aa.read(tmp_path / "scan.e58")
    ply = tmp_path / "cut.ply"
    ply.write_bytes(b"ply\nformat binary_little_endian 1.0\nelement vertex 5\nproperty double x\nproperty double y\nproperty double z\nend_header\n" + b"\0" * 20)
    with pytest.raises(ValueError, match=r"cut\.ply"):
        aa.read(ply)


@pytest.mark.parametrize("on_worker", [False, True])
def test_panic_is_an_exception_not_a_crash(on_worker):
    # A panic in the library (a bug) surfaces as RuntimeError, from the
    # calling thread of the pool or from one of its workers.
    with pytest.raises(RuntimeError, match="internal error in aniso-alpha"):
        aa._native._panic(on_worker)
    # And the module still works afterwards.
    assert aa.delaunay(CUBE).shape == (6, 4)


def test_fixture_files_read():
    # The reader on the CGAL fixtures: the same numbers as numpy's.
    for name in ("grid_6", "random_500", "sphere_100"):
        path = FIXTURES / f"{name}.xyz"
        np.testing.assert_array_equal(aa.read(path).points, np.loadtxt(path))


def test_read_e57():
    # The E57 reader is compiled into the package: a colour scan from the
    # e57 crate's test data (see the fixtures' README) reads as finite points.
    pts = aa.read(FIXTURES / "e57" / "tinyCartesianFloatRgb.e57").points
    assert pts.dtype == np.float64 and pts.ndim == 2 and pts.shape[1] == 3
    assert len(pts) > 0 and np.isfinite(pts).all()
