"""aniso_alpha.distributed: tiled detection on a Dask LocalCluster of 2
worker processes gives aa.detect's result, with tiles smaller than the
structures (so structures cross tile borders and must come out whole), from
every kind of source (array, point file, list of LAS tiles, Dask array)."""

import contextlib
import faulthandler
import os
import struct
import time

import numpy as np
import pytest

import aniso_alpha as aa
from conftest import PAPER, ground_and_roof_scene

if os.environ.get("CI"):
    import dask.distributed  # noqa: F401  (CI installs the [distributed] extra: never skip there)
else:
    pytest.importorskip("dask.distributed")

from aniso_alpha import distributed  # noqa: E402


# A test of this module that runs longer than this (they take seconds) is
# hung, in Dask or in the driver: every thread's stack goes to stderr and the
# process exits with an error, so a hang fails the run at once and says where.
HUNG_AFTER_S = 300


@pytest.fixture(autouse=True)
def hang_watchdog():
    faulthandler.dump_traceback_later(HUNG_AFTER_S, exit=True)
    yield
    faulthandler.cancel_dump_traceback_later()


@pytest.fixture(scope="module")
def client():
    from dask.distributed import Client, LocalCluster

    cluster = LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    )
    c = Client(cluster)
    yield c
    c.close(timeout=60)
    cluster.close(timeout=60)


def room(seed=3):
    """A floor and two walls of a room (spacing 0.25, noise 0.01) with 300
    background points: parameters from the data."""
    rng = np.random.default_rng(seed)
    g = np.arange(0, 10, 0.25)
    a, b = (v.ravel() for v in np.meshgrid(g, g))
    n = len(a)
    floor = np.c_[a, b, np.zeros(n)]
    wall1 = np.c_[a, np.zeros(n), b + 0.25]
    wall2 = np.c_[np.zeros(n), a + 0.25, b + 0.25]
    pts = np.vstack([floor, wall1, wall2, rng.uniform(0.5, 9.5, (300, 3))])
    return pts + rng.normal(0, 0.01, pts.shape)


def assert_same(det, ref):
    assert isinstance(det, aa.Detection)
    np.testing.assert_array_equal(det.labels, ref.labels)
    np.testing.assert_array_equal(det.part_labels, ref.part_labels)
    assert det.structures == ref.structures
    assert det.parameters == ref.parameters


def assert_crossing(points, labels, side):
    """Every structure spans several tiles (so the test is not vacuous)."""
    assert labels.max() >= 0
    for s in range(labels.max() + 1):
        cells = np.unique(np.floor(points[labels == s] / side).astype(np.int64), axis=0)
        assert len(cells) > 1, f"structure {s} lies in one tile"


def test_auto_planes_equal_in_process(client):
    pts = room()
    ref = aa.detect(pts, "planes")
    assert len(ref.structures) >= 1 and np.count_nonzero(ref.labels >= 0) > 3000
    tile = 3.0
    p = distributed.plan(pts, "planes", tile=tile)
    assert p.tile == tile and len(p.tiles(pts)) >= 8 and p.halo > 0
    det = distributed.detect(pts, "planes", tile=tile, client=client)
    assert_same(det, ref)
    assert_crossing(pts, det.labels, tile)


def test_paper_lines_from_a_file_equal_in_process(client, scenes, detections):
    """The paper's Fig. 12 scene and parameters (the box of orientations);
    its lines are about 100 long, the tiles 20."""
    structure, params = PAPER["lines"]
    pts, ref = detections["lines"]
    assert len(ref.structures) >= 4
    det = distributed.detect(str(scenes["lines"]), structure, tile=20.0, client=client, **params)
    assert_same(det, ref)
    assert_crossing(pts, det.labels, 20.0)


def test_default_tile_gives_the_same_result(client):
    pts = room(5)
    ref = aa.detect(pts, "planes", min_size=10)
    p = distributed.plan(pts, "planes", workers=2, min_size=10)
    # 4 tiles per worker at least, no side below 2 halos.
    assert len(p.tiles(pts)) >= 8 and p.tile >= 2 * p.halo
    det = distributed.detect(pts, "planes", client=client, min_size=10)
    assert_same(det, ref)


def write_las(path, points):
    """A minimal LAS 1.2 file (point format 0, scale 0.001)."""
    scale = 0.001
    q = np.round(points / scale).astype(np.int32)
    lo, hi = q.min(axis=0) * scale, q.max(axis=0) * scale
    header = b"LASF" + struct.pack("<HH16sBB32s32sHHHIIBHI5I", 0, 0, b"", 1, 2, b"test", b"test",
                                   1, 2024, 227, 227, 0, 0, 20, len(q), len(q), 0, 0, 0, 0)
    header += struct.pack("<3d3d", scale, scale, scale, 0.0, 0.0, 0.0)
    header += struct.pack("<6d", hi[0], lo[0], hi[1], lo[1], hi[2], lo[2])
    assert len(header) == 227
    rec = np.zeros(len(q), dtype=[("xyz", "<i4", 3), ("intensity", "<u2"), ("flags", "u1"),
                                  ("cls", "u1"), ("angle", "i1"), ("user", "u1"), ("src", "<u2")])
    rec["xyz"] = q
    rec["flags"] = 0b00001001  # return 1 of 1
    with open(path, "wb") as f:
        f.write(header)
        f.write(rec.tobytes())


def test_a_list_of_las_tiles(client, tmp_path):
    pts = room(7)
    west, east = pts[pts[:, 0] < 5.0], pts[pts[:, 0] >= 5.0]
    paths = [tmp_path / "west.las", tmp_path / "east.las"]
    write_las(paths[0], west)
    write_las(paths[1], east)
    whole = np.vstack([aa.read(p).points for p in paths])
    assert whole.shape == pts.shape
    np.testing.assert_array_equal(distributed.load([str(p) for p in paths]), whole)
    ref = aa.detect(whole, "planes")
    det = distributed.detect([str(p) for p in paths], "planes", tile=3.0, client=client)
    assert_same(det, ref)
    assert len(det.structures) >= 1


def test_a_dask_array(client):
    import dask.array as da

    pts = room(11)
    ref = aa.detect(pts, "planes")
    det = distributed.detect(da.from_array(pts, chunks=(1000, 3)), "planes", tile=4.0, client=client)
    assert_same(det, ref)


def test_bad_input_raises_value_error(client):
    with pytest.raises(ValueError, match="tile"):
        distributed.detect(room(), "planes", tile=-1.0, client=client)
    with pytest.raises(ValueError, match="shape"):
        distributed.detect(np.zeros((10, 2)), "planes", client=client)
    with pytest.raises(ValueError, match="structure"):
        distributed.detect(room(), "cubes", client=client)


def test_a_tile_alone_sees_only_its_points():
    """The per-tile step needs only the tile's arrays and the step's spec;
    every simplex it returns has its smallest vertex in the tile's cell."""
    pts = room()
    p = distributed.plan(pts, "planes", tile=3.0)
    spec = p.step_spec()
    (cell, ids) = max(p.tiles(pts), key=lambda t: len(t[1]))
    assert len(ids) < len(pts) / 2
    faces, offsets, triangulated = distributed._run_tile(
        spec, (cell, pts[ids], ids, p.members(ids)), 1
    )
    assert len(offsets) == p.jobs + 1 and offsets[-1] == len(faces) > 0 and triangulated > 0
    tri = faces.reshape(-1, 3)
    assert np.isin(tri, ids).all()
    owners = np.floor(pts[tri.min(axis=1)] / 3.0).astype(np.int64)
    assert (owners == np.array(cell)).all()


def test_unaligned_points_are_read():
    """An unaligned float64 buffer (as unpickled by Dask) is copied, not
    read as empty."""
    pts = room()[:500]
    buf = bytearray(pts.nbytes + 1)
    un = np.frombuffer(buf, dtype=np.float64, offset=1, count=pts.size).reshape(-1, 3)
    un[...] = pts
    assert not un.flags.aligned
    np.testing.assert_array_equal(aa.delaunay(un), aa.delaunay(pts))


def test_normals_equal_in_process(client):
    # The scan's normals reach the estimate and the final step of the
    # tiled run: the same result as aa.detect with them, and not the one
    # without them (a window frame's sides on a wall, see test_auto).
    from test_auto import wall_with_frame

    pts, normals = wall_with_frame()
    ref = aa.detect(pts, "planes", normals=normals)
    det = distributed.detect(pts, "planes", tile=2.0, client=client, normals=normals)
    assert_same(det, ref)
    plain = aa.detect(pts, "planes")
    assert not np.array_equal(plain.part_labels, ref.part_labels)
    with pytest.raises(ValueError, match="normals"):
        distributed.detect(pts, "planes", tile=2.0, client=client, normals=normals[:5])


@contextlib.contextmanager
def killing_cluster(marker, always=False, task="_run_tile"):
    """A client of a 2-process LocalCluster whose workers kill their own
    process when a task (a tile's, or ``task``) starts: once (the first
    task of the run, the marker file records it) or every time
    (``always``). The nannies start a new worker in its place, as a
    cluster's would. Both are closed on leaving."""
    from dask.distributed import Client, LocalCluster, WorkerPlugin

    class KillOnTile(WorkerPlugin):  # defined here: pickled by value
        name = "kill-on-tile"

        def transition(self, key, start, finish, **kwargs):
            if finish != "executing" or task not in str(key):
                return
            if not always:
                try:
                    os.close(os.open(marker, os.O_CREAT | os.O_EXCL))
                except FileExistsError:
                    return
            os._exit(1)

    cluster = LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    )
    c = Client(cluster)
    try:
        c.register_plugin(KillOnTile())
        yield c
    finally:
        try:
            settle(c, 2)
        finally:
            c.close(timeout=60)
            cluster.close(timeout=60)


def settle(c, n_workers, timeout=60.0):
    """Waits until ``n_workers`` workers are registered and none runs a
    task (no task left to kill one). A nanny restarting a killed worker
    when its cluster closes fails the close (distributed asserts that the
    process it joins has started); a registered worker's process has."""

    def busy(dask_scheduler):
        return sum(len(ws.processing) for ws in dask_scheduler.workers.values())

    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if len(c.scheduler_info()["workers"]) == n_workers and c.run_on_scheduler(busy) == 0:
            return
        time.sleep(0.1)
    raise AssertionError(f"the cluster did not settle to {n_workers} idle workers")


def test_a_worker_killed_mid_run_gives_the_same_labels(tmp_path):
    """The first tile task kills its worker (its scattered points are lost
    with it): the tile is sent again and the result is aa.detect's."""
    pts = room(11)
    ref = aa.detect(pts, "planes")
    marker = tmp_path / "killed"
    with killing_cluster(str(marker)) as c:
        det = distributed.detect(pts, "planes", tile=3.0, client=c)
    assert marker.exists(), "no worker was killed: the test tested nothing"
    assert_same(det, ref)


def test_a_tile_that_always_kills_its_worker_is_a_clear_error(tmp_path):
    pts = room(13)
    with killing_cluster(str(tmp_path / "unused"), always=True) as c:
        with pytest.raises(distributed.TileLost, match=r"was lost 3 times"):
            distributed.detect(pts, "planes", tile=100.0, client=c)


def ground_and_roof():
    return ground_and_roof_scene()[0]


def assert_same_regions(r, ref):
    assert isinstance(r, aa.RegionDetection)
    np.testing.assert_array_equal(r.labels, ref.labels)
    np.testing.assert_array_equal(r.part_labels, ref.part_labels)
    assert (r.side, r.regions, r.widened, r.joins, r.skipped) == (
        ref.side, ref.regions, ref.widened, ref.joins, ref.skipped)
    assert [(p.id, p.structure, p.points, p.pieces) for p in r.parts] == [
        (p.id, p.structure, p.points, p.pieces) for p in ref.parts]
    for a, b in zip(r.parts, ref.parts):
        np.testing.assert_allclose(a.equation, b.equation)


def test_regions_equal_in_process(client):
    pts = ground_and_roof()
    ref = aa.detect_regions(pts, "planes", side=30.0)
    # Each region's estimate reaches past side/16: every task is sent
    # again with a wider margin, and the ground crosses every border.
    assert ref.regions == 6 and ref.widened == 6 and ref.parts[0].pieces == 6
    seen = []
    r = distributed.detect_regions(pts, "planes", side=30.0, client=client, progress=lambda d, t: seen.append((d, t)))
    assert_same_regions(r, ref)
    assert seen == [(k, 6) for k in range(1, 7)]
    with pytest.raises(RuntimeError, match="cancelled by the progress callback"):
        distributed.detect_regions(pts, "planes", side=30.0, client=client, progress=lambda d, t: False)
    # No side: about one region here, as aa.detect_regions.
    whole = distributed.detect_regions(pts, "planes", client=client)
    assert whole.side is None and whole.regions == 1
    np.testing.assert_array_equal(whole.part_labels, aa.detect(pts, "planes").part_labels)
    with pytest.raises(ValueError, match="region side"):
        distributed.detect_regions(pts, "planes", side=0.0, client=client)
    # Normals that no region uses: the tasks say so, and the driver warns
    # once, as in process.
    wrong = np.tile([1.0, 0.0, 0.0], (len(pts), 1))
    with pytest.warns(aa.AnisoAlphaWarning, match="in 6 of 6 region"):
        r = distributed.detect_regions(pts, "planes", side=30.0, normals=wrong, client=client)
    assert len(r.warnings) == 1


def test_a_region_whose_worker_is_killed_gives_the_same_labels(tmp_path):
    pts = ground_and_roof()
    ref = aa.detect_regions(pts, "planes", side=30.0)
    marker = tmp_path / "killed"
    with killing_cluster(str(marker), task="_run_region") as c:
        r = distributed.detect_regions(pts, "planes", side=30.0, client=c)
    assert marker.exists(), "no worker was killed: the test tested nothing"
    assert_same_regions(r, ref)


def test_a_region_that_always_kills_its_worker_is_a_clear_error(tmp_path):
    pts = ground_and_roof()
    with killing_cluster(str(tmp_path / "unused"), always=True, task="_run_region") as c:
        with pytest.raises(distributed.RegionLost, match=r"region \d+ \(\d+ points\) lost its worker"):
            distributed.detect_regions(pts, "planes", side=45.0, client=c)


def tiles_of(tmp_path, pts):
    """``pts`` cut in three bands of y that the region grid does not
    follow, as two LAS tiles and a text tile; their paths and their
    points as read back, stacked in list order."""
    bands = [pts[:, 1] < 17.0, (pts[:, 1] >= 17.0) & (pts[:, 1] < 41.0), pts[:, 1] >= 41.0]
    paths = [str(tmp_path / "south.las"), str(tmp_path / "middle.xyz"), str(tmp_path / "north.las")]
    write_las(paths[0], pts[bands[0]])
    np.savetxt(paths[1], pts[bands[1]])
    write_las(paths[2], pts[bands[2]])
    return paths, distributed.load(paths)


def assert_tiles_equal_regions(r, ref, n):
    """A tiled run ``r`` whose outputs hold ``ref``'s labels, with its
    parts fitted bit for bit as ``ref``'s."""
    assert isinstance(r, aa.TileDetection) and r.points == n
    labels = np.concatenate([aa.read(o).attributes["structure"] for o in r.outputs])
    parts = np.concatenate([aa.read(o).attributes["part"] for o in r.outputs])
    np.testing.assert_array_equal(labels, ref.labels)
    np.testing.assert_array_equal(parts, ref.part_labels)
    assert (r.side, r.regions, r.widened, r.joins, r.skipped) == (
        ref.side, ref.regions, ref.widened, ref.joins, ref.skipped)
    for a, b in zip(r.parts, ref.parts, strict=True):
        assert (a.id, a.structure, a.points, a.pieces, a.rms) == (b.id, b.structure, b.points, b.pieces, b.rms)
        assert a.equation.tobytes() == b.equation.tobytes()


def test_tiles_equal_regions_on_the_stacked_points(client, tmp_path):
    pts, _ = ground_and_roof_scene()
    paths, stacked = tiles_of(tmp_path, pts)
    ref = aa.detect_regions(stacked, "planes", side=30.0)
    assert ref.regions == 6 and ref.widened == 6 and ref.joins > 0
    out = tmp_path / "out"
    seen = []
    r = distributed.detect_tiles(
        paths, "planes", out, side=30.0, client=client, classify=6, progress=lambda d, t: seen.append((d, t))
    )
    assert seen == [(k, 6) for k in range(1, 7)]
    assert [os.path.basename(o) for o in r.outputs] == ["south.las", "middle.ply", "north.las"]
    assert_tiles_equal_regions(r, ref, len(stacked))
    # A LAS tile's records are kept, the class set on the structures' points.
    south, tile = aa.read(r.outputs[0]), aa.read(paths[0])
    np.testing.assert_array_equal(south.points, tile.points)
    for name, values in tile.attributes.items():
        if name != "classification":
            np.testing.assert_array_equal(south.attributes[name], values, err_msg=name)
    on = south.attributes["structure"] >= 0
    assert on.any() and (south.attributes["classification"][on] == 6).all()
    # No folder: the parts alone; no side: one region, as in process.
    bare = distributed.detect_tiles(paths, "planes", side=30.0, client=client)
    assert bare.outputs == [] and [p.points for p in bare.parts] == [p.points for p in r.parts]
    whole = distributed.detect_tiles(paths, "planes", tmp_path / "whole", client=client)
    ref_whole = aa.detect_regions(stacked, "planes")
    assert whole.side is None and whole.regions == 1
    assert_tiles_equal_regions(whole, ref_whole, len(stacked))


def test_one_las_file_read_in_pieces_equals_regions(client, tmp_path):
    """One LAS file (and the same points as LAZ) read in pieces of 700
    points, fewer than any region holds: the labels and fits of the
    stacked points, and the same labelled file, byte for byte, as a run
    that reads it in one piece."""
    pts, _ = ground_and_roof_scene()
    las = str(tmp_path / "all.las")
    write_las(las, pts)
    laz = str(tmp_path / "all.laz")
    aa.write(laz, aa.read(las), aa.detect_regions(aa.read(las).points, "planes"))
    for path in (las, laz):
        stacked = aa.read(path).points
        ref = aa.detect_regions(stacked, "planes", side=30.0)
        n = len(stacked)
        assert len(distributed._pieces([path], 700)) == -(-n // 700) > 6
        out = tmp_path / "pieces"
        scratch = []
        r = distributed.detect_tiles([path], "planes", out, side=30.0, client=client, piece=700, classify=6,
                                     progress=lambda d, t: scratch.append(
                                         [f.stat().st_size for f in out.glob(".*/.*part-ids*")]))
        assert_tiles_equal_regions(r, ref, n)
        # The part ids were in a scratch file inside the output folder,
        # removed with its hidden folder.
        assert scratch and all(sizes == [4 * n] for sizes in scratch)
        assert os.path.basename(path) in [p.name for p in out.iterdir()]
        assert not list(out.glob(".*"))
        one = distributed.detect_tiles([path], "planes", tmp_path / "one", side=30.0, client=client,
                                       classify=6)
        assert_tiles_equal_regions(one, ref, n)
        with open(r.outputs[0], "rb") as a, open(one.outputs[0], "rb") as b:
            assert a.read() == b.read()
    with pytest.raises(ValueError, match="piece must be"):
        distributed.detect_tiles([las], "planes", tmp_path / "o", client=client, piece=0)


def test_tiles_refuse_bad_input_before_any_work(client, tmp_path):
    pts, _ = ground_and_roof_scene()
    paths, _ = tiles_of(tmp_path, pts)
    with pytest.raises(ValueError, match="no tiles"):
        distributed.detect_tiles([], "planes", tmp_path / "o", client=client)
    with pytest.raises(ValueError, match="region side"):
        distributed.detect_tiles(paths, "planes", tmp_path / "o", side=-1.0, client=client)
    with pytest.raises(ValueError, match="classify"):
        distributed.detect_tiles(paths, "planes", tmp_path / "o", classify=300, client=client)
    (tmp_path / "b").mkdir()
    twin = str(tmp_path / "b" / "south.las")
    write_las(twin, pts[:100])
    with pytest.raises(ValueError, match="would both be written as"):
        distributed.detect_tiles(paths + [twin], "planes", tmp_path / "o", client=client)
    with pytest.raises(ValueError, match="holds the tile itself"):
        distributed.detect_tiles(paths, "planes", tmp_path, client=client)
    assert not (tmp_path / "o").exists()
    with pytest.raises(OSError):
        distributed.detect_tiles([str(tmp_path / "missing.las")], "planes", client=client)
    with pytest.raises(RuntimeError, match="cancelled by the progress callback"):
        distributed.detect_tiles(paths, "planes", tmp_path / "o", side=30.0, client=client,
                                 progress=lambda d, t: d < 2 and None)
    assert not (tmp_path / "o").exists()


def test_a_tiled_run_that_fails_writes_no_labelled_tile(client, tmp_path):
    """A tile rewritten during the run (fewer points) is an error when the
    driver reads it back; the labelled tiles already written are not left
    in the folder, nor the scratch file of the part ids."""
    pts, _ = ground_and_roof_scene()
    paths, _ = tiles_of(tmp_path, pts)
    north = pts[pts[:, 1] >= 41.0]

    def shrink_north(done, total):
        if done == total:
            write_las(paths[2], north[:-10])

    out = tmp_path / "out"
    with pytest.raises(ValueError, match="north.las: .* when the run began"):
        distributed.detect_tiles(paths, "planes", out, side=30.0, client=client, progress=shrink_north)
    assert not out.exists(), "the folder the run made is removed with its scratch"
    # A folder that was there stays, empty.
    out.mkdir()
    write_las(paths[2], north)
    with pytest.raises(ValueError, match="north.las: .* when the run began"):
        distributed.detect_tiles(paths, "planes", out, side=30.0, client=client, progress=shrink_north)
    assert list(out.iterdir()) == []


def test_a_tiled_region_whose_worker_is_killed_gives_the_same_labels(tmp_path):
    """The first region task kills its worker: Dask runs it again (it reads
    its tiles from their paths) and the outputs are those of an
    undisturbed run."""
    pts, _ = ground_and_roof_scene()
    paths, stacked = tiles_of(tmp_path, pts)
    ref = aa.detect_regions(stacked, "planes", side=30.0)
    marker = tmp_path / "killed"
    with killing_cluster(str(marker), task="_tile_region") as c:
        r = distributed.detect_tiles(paths, "planes", tmp_path / "out", side=30.0, client=c)
    assert marker.exists(), "no worker was killed: the test tested nothing"
    assert_tiles_equal_regions(r, ref, len(stacked))
