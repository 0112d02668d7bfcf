"""Long calls release the GIL; calls from several Python threads at once
work and give the sequential results; `threads=` does not change results."""

import threading
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

import aniso_alpha as aa
from conftest import PAPER


def at_once(*calls):
    """Runs the calls on as many Python threads, released together."""
    barrier = threading.Barrier(len(calls))

    def run(call):
        barrier.wait()
        return call()

    with ThreadPoolExecutor(len(calls)) as ex:
        futures = [ex.submit(run, c) for c in calls]
        return [f.result() for f in futures]


def same_detection(a, b):
    np.testing.assert_array_equal(a.labels, b.labels)
    np.testing.assert_array_equal(a.part_labels, b.part_labels)
    assert a.structures == b.structures and a.parameters == b.parameters


def test_detections_at_once_equal_sequential(detections):
    # Three at once (default threads: each its own pool of all cores), two of
    # them the same call on the same array.
    (lines, seq_lines), (poly, seq_poly) = detections["lines"], detections["polyhedron"]
    s_lines, p_lines = PAPER["lines"]
    s_poly, p_poly = PAPER["polyhedron"]
    one = lambda: aa.detect(lines, s_lines, **p_lines)  # noqa: E731
    two = lambda: aa.detect(poly, s_poly, **p_poly)  # noqa: E731
    got = at_once(two, one, two)
    same_detection(got[0], seq_poly)
    same_detection(got[1], seq_lines)
    same_detection(got[2], seq_poly)


def test_other_calls_at_once():
    pts = np.random.default_rng(11).random((50_000, 3))
    calls = [
        lambda: aa.delaunay(pts, threads=2),
        lambda: aa.alpha_intervals(pts[:20_000], threads=2).triangle_alpha,
        lambda: aa.delaunay(pts[:30_000], threads=1),
    ]
    seq = [c() for c in calls]
    for got, want in zip(at_once(*calls), seq):
        np.testing.assert_array_equal(got, want)


@pytest.mark.parametrize("threads", [1, 3])
def test_thread_count_does_not_change_detection(detections, threads):
    structure, params = PAPER["polyhedron"]
    pts, ref = detections["polyhedron"]
    same_detection(aa.detect(pts, structure, threads=threads, **params), ref)


def test_gil_is_released_during_a_call():
    # While a worker thread is inside aa.delaunay, the main thread runs Python
    # code. Held GIL: the main thread could run only before the call takes it
    # or after it returns, never in the middle of the call.
    pts = np.random.default_rng(2).random((200_000, 3))
    span = {}

    def work():
        span["start"] = time.perf_counter()
        aa.delaunay(pts, threads=1)
        span["end"] = time.perf_counter()

    t = threading.Thread(target=work)
    ticks = []
    t.start()
    while t.is_alive():
        ticks.append(time.perf_counter())
    t.join()
    start, end = span["start"], span["end"]
    # The call must be long enough for "the middle" to mean something
    # (a switch interval is 5 ms).
    assert end - start > 0.1, "call too short to test the GIL"
    third = (end - start) / 3
    middle = [x for x in ticks if start + third < x < end - third]
    assert len(middle) > 100
