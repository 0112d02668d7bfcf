"""aa.detect with the paper's parameters gives the CLI's labels, part labels
and report on the paper's scenes."""

import json

import numpy as np
import pytest

import aniso_alpha as aa
from conftest import PAPER, read_ints, run_cli


def cli_args(structure, params):
    args = ["--structure", structure]
    for k, v in params.items():
        args += ["--" + k.replace("_", "-"), v]
    return args


@pytest.fixture(scope="module", params=sorted(PAPER))
def compared(request, cli, scenes, detections, tmp_path_factory):
    """(scene name, the CLI's labels, part labels and report, aa.detect's Detection)."""
    scene = request.param
    structure, params = PAPER[scene]
    d = tmp_path_factory.mktemp(scene)
    run_cli(
        cli,
        "detect",
        scenes[scene],
        *cli_args(structure, params),
        "--labels",
        d / "labels.txt",
        "--part-labels",
        d / "parts.txt",
        "--report",
        d / "report.json",
    )
    report = json.loads((d / "report.json").read_text())
    det = detections[scene][1]
    return scene, read_ints(d / "labels.txt"), read_ints(d / "parts.txt"), report, det


def test_labels_equal_cli(compared):
    scene, labels, _, _, det = compared
    assert det.labels.dtype == np.int64 and det.labels.shape == labels.shape
    np.testing.assert_array_equal(det.labels, labels)
    # Not vacuous: the scene's structures are found.
    assert len(det.structures) >= (4 if scene == "lines" else 1)
    assert np.count_nonzero(det.labels >= 0) >= (40 if scene == "lines" else 180)


def test_part_labels_equal_cli(compared):
    _, _, parts, _, det = compared
    assert det.part_labels.dtype == np.int64
    np.testing.assert_array_equal(det.part_labels, parts)


def test_structures_and_parameters_equal_report(compared):
    _, _, _, report, det = compared
    assert det.structures == report["structures"]
    assert det.parameters == report["parameters"]
    assert [s["id"] for s in det.structures] == list(range(len(det.structures)))
    assert set(det.labels.tolist()) <= {-1, *range(len(det.structures))}


def test_against_ground_truth(scenes, detections):
    # Labels are -1 where the scene has background, up to a few points.
    scene = np.loadtxt(scenes["polyhedron"])
    pts, det = detections["polyhedron"]
    np.testing.assert_array_equal(pts, scene[:, :3])
    truth = scene[:, 3] >= 0
    found = det.labels >= 0
    assert np.count_nonzero(truth & found) >= 0.95 * np.count_nonzero(truth)
    assert np.count_nonzero(found & ~truth) <= 0.05 * np.count_nonzero(truth)


def test_input_forms_give_the_same_result(detections):
    pts, ref = detections["lines"]
    structure, params = PAPER["lines"]
    for other in (pts.tolist(), np.asfortranarray(pts), pts.astype(np.float32).astype(np.float64)):
        det = aa.detect(other, structure, **params)
        np.testing.assert_array_equal(det.labels, ref.labels)


def test_repr(detections):
    det = detections["lines"][1]
    parts = int(det.part_labels.max()) + 1
    assert repr(det).startswith(
        f"Detection({len(det.structures)} structure(s), {parts} segment(s), 1550 points"
    )
