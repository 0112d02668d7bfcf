"""detect_regions: the detection region by region (docs/method.md §8
"Regions"): a plane across regions is one part, a small cloud runs whole
with detect's labels, progress per region, errors."""

import warnings

import numpy as np
import pytest

import aniso_alpha as aa
from conftest import ground_and_roof_scene


@pytest.fixture(scope="module")
def ground_and_roof():
    return ground_and_roof_scene()


def test_a_plane_across_regions_is_one_part(ground_and_roof):
    pts, roof = ground_and_roof
    r = aa.detect_regions(pts, "planes", side=30.0, threads=1)
    assert isinstance(r, aa.RegionDetection)
    assert (r.side, r.regions) == (30.0, 6)
    assert r.labels.shape == r.part_labels.shape == (len(pts),)
    assert r.joins > 0
    ground = r.parts[0]
    assert ground.pieces == 6 and ground.equation is not None and ground.direction is None
    assert abs(ground.equation[2]) > 0.999
    assert ground.points == int(np.sum(r.part_labels == 0))
    assert np.mean(r.part_labels[~roof] == 0) > 0.9
    inner = roof & (pts[:, 0] > 27) & (pts[:, 0] < 53) & (pts[:, 1] > 22) & (pts[:, 1] < 33)
    ids, counts = np.unique(r.part_labels[inner], return_counts=True)
    assert ids[np.argmax(counts)] > 0 and counts.max() > 0.95 * inner.sum()
    assert [p.id for p in r.parts] == list(range(len(r.parts)))


def test_a_small_cloud_runs_whole_with_detects_labels(ground_and_roof):
    pts, _ = ground_and_roof
    r = aa.detect_regions(pts, "planes", threads=1)
    assert (r.side, r.regions, r.joins) == (None, 1, 0)
    d = aa.detect(pts, "planes", threads=1)
    np.testing.assert_array_equal(r.part_labels, d.part_labels)
    np.testing.assert_array_equal(r.labels, d.labels)


def test_progress_per_region_and_false_cancels(ground_and_roof):
    pts, _ = ground_and_roof
    calls = []
    aa.detect_regions(pts, "planes", side=45.0, threads=1, progress=lambda d, t: calls.append((d, t)))
    assert calls == [(1, 4), (2, 4), (3, 4), (4, 4)]
    with pytest.raises(RuntimeError, match="cancelled"):
        aa.detect_regions(pts, "planes", side=45.0, threads=1, progress=lambda d, t: False)


def test_regions_at_once_give_the_same_run(ground_and_roof):
    # Six regions one at a time, and all at once on two threads (each
    # progress call still in the plan's order): the same labels and parts.
    pts, _ = ground_and_roof
    one = aa.detect_regions(pts, "planes", side=30.0, threads=1, jobs=1)
    calls = []
    many = aa.detect_regions(
        pts, "planes", side=30.0, threads=2, jobs=6, progress=lambda d, t: calls.append((d, t))
    )
    np.testing.assert_array_equal(many.labels, one.labels)
    np.testing.assert_array_equal(many.part_labels, one.part_labels)
    assert [(p.points, p.pieces) for p in many.parts] == [(p.points, p.pieces) for p in one.parts]
    assert calls == [(d, 6) for d in range(1, 7)]
    with pytest.raises(ValueError, match="jobs 0"):
        aa.detect_regions(pts, "planes", side=30.0, jobs=0)


def test_normals_that_disagree_warn_once_for_the_regions(ground_and_roof):
    pts, _ = ground_and_roof
    wrong = np.tile([1.0, 0.0, 0.0], (len(pts), 1))
    with pytest.warns(aa.AnisoAlphaWarning, match="normals disagree with its points in 6 of 6 region") as w:
        r = aa.detect_regions(pts, "planes", side=30.0, threads=1, normals=wrong)
    assert len(w) == 1 and r.warnings == [str(w[0].message)]
    up = np.tile([0.0, 0.0, 1.0], (len(pts), 1))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert aa.detect_regions(pts, "planes", side=30.0, threads=1, normals=up).warnings == []


@pytest.mark.parametrize("side", [0.0, -2.0, float("nan"), float("inf")])
def test_a_bad_side_is_a_value_error(ground_and_roof, side):
    pts, _ = ground_and_roof
    with pytest.raises(ValueError, match="region side"):
        aa.detect_regions(pts, "planes", side=side)


def test_a_region_run_is_written_with_its_labels(ground_and_roof, tmp_path):
    """aa.write takes a RegionDetection as it takes a Detection (the parts
    of a region run have no meshes: a PLY gets the points and ids)."""
    pts, _ = ground_and_roof
    r = aa.detect_regions(pts, "planes", side=30.0, threads=1)
    for name in ("labelled.laz", "labelled.ply"):
        out = tmp_path / name
        aa.write(out, pts, r, classify=6)
        back = aa.read(out)
        np.testing.assert_array_equal(back.attributes["structure"], r.labels)
        np.testing.assert_array_equal(back.attributes["part"], r.part_labels)
        assert (back.attributes["classification"][r.labels >= 0] == 6).all()


def test_a_region_run_gives_pdal_dimensions(ground_and_roof):
    pts, _ = ground_and_roof
    r = aa.detect_regions(pts, "planes", side=30.0, threads=1)
    assert r.kind == "planes"
    arr = np.zeros(len(pts), dtype=[("X", "<f8"), ("Y", "<f8"), ("Z", "<f8")])
    out = aa.labelled_array(arr, r, classify=6)
    np.testing.assert_array_equal(out["StructureId"], r.labels)
    np.testing.assert_array_equal(out["PlaneId"], r.part_labels)
    assert (out["Classification"][r.labels >= 0] == 6).all()
    lines = aa.detect_regions(pts[:500], "lines", threads=1)
    assert lines.kind == "lines" and set(lines.dimensions()) == {"StructureId", "LineId"}
