"""detect's progress callback: called once per orientation with (done,
total), the result unchanged; False cancels; an exception it raises comes
back."""

import threading

import numpy as np
import pytest

import aniso_alpha as aa


@pytest.fixture(scope="module")
def planes():
    g = np.arange(30.0)
    x, y = (a.ravel() for a in np.meshgrid(g, g))
    pts = np.vstack([np.c_[x, y, np.full(900, 10.0)], np.c_[x, np.full(900, 15.0), y]])
    return pts + np.random.default_rng(1).normal(0, 0.01, pts.shape)


def test_called_per_orientation_result_unchanged(planes):
    calls = []
    lock = threading.Lock()

    def progress(done, total):
        with lock:
            calls.append((done, total))

    plain = aa.detect(planes, "planes")
    watched = aa.detect(planes, "planes", progress=progress)
    np.testing.assert_array_equal(plain.labels, watched.labels)
    np.testing.assert_array_equal(plain.part_labels, watched.part_labels)
    assert calls, "the callback was never called"
    totals = {t for _, t in calls}
    assert len(totals) == 1
    total = totals.pop()
    assert total >= 1 and len(calls) == total
    assert sorted(d for d, _ in calls) == list(range(1, total + 1))


def test_false_cancels(planes):
    with pytest.raises(RuntimeError, match="cancelled by the progress callback"):
        aa.detect(planes, "planes", progress=lambda done, total: False)


def test_none_and_true_go_on(planes):
    # tqdm's update() returns None or True: neither cancels.
    aa.detect(planes, "planes", progress=lambda done, total: None)
    aa.detect(planes, "planes", progress=lambda done, total: True)


def test_exception_comes_back(planes):
    class Stop(Exception):
        pass

    def progress(done, total):
        raise Stop("enough")

    with pytest.raises(Stop, match="enough"):
        aa.detect(planes, "planes", progress=progress)
