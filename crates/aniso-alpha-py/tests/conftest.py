"""Shared fixtures: the `aniso-alpha` CLI the package is compared with, the
CGAL fixtures of the library's tests, and the benchmark scenes."""

from __future__ import annotations

import json
import os
import pathlib
import subprocess
from typing import Dict

import numpy as np
import pytest

CRATE = pathlib.Path(__file__).resolve().parents[1]
REPO = CRATE.parents[1]
FIXTURES = REPO / "crates" / "aniso-alpha" / "tests" / "fixtures"


@pytest.fixture(scope="session")
def cli() -> pathlib.Path:
    """The CLI binary: $ANISO_ALPHA_CLI (set by .ci/run), else built here
    with `cargo build --release -p aniso-alpha-cli`."""
    given = os.environ.get("ANISO_ALPHA_CLI")
    if given:
        path = pathlib.Path(given)
        assert path.is_file(), f"ANISO_ALPHA_CLI={given} is not a file"
        return path
    subprocess.run(
        ["cargo", "build", "--release", "--quiet", "-p", "aniso-alpha-cli"], cwd=REPO, check=True
    )
    meta = subprocess.run(
        ["cargo", "metadata", "--format-version", "1", "--no-deps"],
        cwd=REPO,
        check=True,
        capture_output=True,
        text=True,
    )
    path = pathlib.Path(json.loads(meta.stdout)["target_directory"]) / "release" / "aniso-alpha"
    assert path.is_file(), path
    return path


def run_cli(cli: pathlib.Path, *args: object) -> subprocess.CompletedProcess:
    """Runs the CLI (quiet), failing the test with its stderr if it fails."""
    cmd = [str(cli), *map(str, args), "--quiet"]
    p = subprocess.run(cmd, capture_output=True, text=True)
    assert p.returncode == 0, f"{' '.join(cmd)} failed: {p.stderr}"
    return p


def read_ints(path: pathlib.Path) -> np.ndarray:
    return np.loadtxt(path, dtype=np.int64, ndmin=1)


def read_tets(path: pathlib.Path) -> np.ndarray:
    rows = [line.split() for line in path.read_text().splitlines() if line.strip()]
    return np.array(rows, dtype=np.uint32).reshape(-1, 4)


# Even permutations of a tet's 4 vertices that bring vertex m first.
_FIRST = np.array([[0, 1, 2, 3], [1, 0, 3, 2], [2, 3, 0, 1], [3, 2, 1, 0]])
# Rotations of the last three.
_ROT = np.array([[0, 1, 2], [1, 2, 0], [2, 0, 1]])


def canonical(tets: np.ndarray) -> np.ndarray:
    """The fixtures' canonical form of positively oriented tets (rotated by an
    even permutation: smallest index first, then the smallest of the other
    three), rows sorted. Equal arrays mean the same tets with the same
    orientation."""
    t = np.asarray(tets, dtype=np.int64).reshape(-1, 4)
    rows = np.arange(len(t))[:, None]
    s = t[rows, _FIRST[t.argmin(axis=1)]]
    rest = s[:, 1:]
    rest = rest[rows, _ROT[rest.argmin(axis=1)]]
    out = np.concatenate([s[:, :1], rest], axis=1)
    return out[np.lexsort(out.T[::-1])]


# The paper's parameters: Fig. 12 (lines) and Fig. 10 (polyhedron).
PAPER = {
    "lines": ("lines", dict(alpha=1.0, lambda3=10.0, min_size=4)),
    "polyhedron": ("planes", dict(alpha=1.0, lambda2=4.0, lambda3=8.0, min_size=20)),
}


@pytest.fixture(scope="session")
def detections(scenes):
    """aa.detect on each scene with the paper's parameters (default threads),
    computed once: {scene: (points, Detection)}."""
    import aniso_alpha as aa

    out = {}
    for scene, (structure, params) in PAPER.items():
        pts = aa.read(scenes[scene]).points
        out[scene] = (pts, aa.detect(pts, structure, **params))
    return out


@pytest.fixture(scope="session")
def scenes(cli, tmp_path_factory) -> Dict[str, pathlib.Path]:
    """The paper's benchmark scenes, written by `aniso-alpha synth`."""
    d = tmp_path_factory.mktemp("scenes")
    out = {}
    for kind in ("lines", "polyhedron"):
        out[kind] = d / f"{kind}.xyz"
        run_cli(cli, "synth", kind, "--seed", 1, "--output", out[kind])
    return out


def need(module: str, why: str):
    """Imports `module` for a test that needs it: a skip saying so when it
    is missing, a failure under ANISO_ALPHA_CI=1 (set by .ci/run, which
    installs it), as the Rust tests' `tool_missing` rule."""
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError as e:
        msg = f"{module} is not installed ({e}): {why}"
        if os.environ.get("ANISO_ALPHA_CI", "") not in ("", "0"):
            pytest.fail(msg + " (ANISO_ALPHA_CI is set: a test whose tool is missing fails)")
        pytest.skip(msg)


def ground_and_roof_scene():
    """A 90 x 60 ground at z = 0 (spacing 1, jittered) with a pitched roof
    face over 25..55 x 20..35, across the border x = 30 of 30-unit
    regions; the points and the roof's mask."""
    rng = np.random.default_rng(5)
    x, y = (a.ravel() for a in np.meshgrid(np.arange(90.0), np.arange(60.0)))
    x = x + rng.uniform(-0.1, 0.1, x.size)
    y = y + rng.uniform(-0.1, 0.1, y.size)
    roof = (x >= 25) & (x < 55) & (y >= 20) & (y < 35)
    z = np.where(roof, 6.0 + 0.4 * (y - 20.0), 0.0) + rng.uniform(-0.01, 0.01, x.size)
    return np.c_[x, y, z], roof
