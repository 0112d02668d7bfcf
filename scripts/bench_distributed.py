#!/usr/bin/env python3
"""Benchmark of aniso_alpha.distributed (BENCHMARKS.md, "Distributed
detection"): wall time against the number of Dask workers and against the
cloud's size, with the in-process aa.detect on the same cloud in the same
run as the reference (and the check that the labels are the same).

The cloud is a synthetic town at constant density: a ground plane and box
buildings (walls and flat roofs) on a square whose side grows with the
number of points, spacing 0.5, noise 0.02, 2% uniform background; so the
cost per point should stay flat as the cloud grows.

Needs the package with its [distributed] extra:

    python3 -m venv .venv && .venv/bin/pip install "./crates/aniso-alpha-py[distributed]"
    .venv/bin/python scripts/bench_distributed.py --sizes 1000000 2000000 --workers 1 2

Each distributed run has its own LocalCluster (worker processes of one
thread each), started before the timer; the in-process run uses `--threads`
threads (default: all cores). Prints one Markdown table row per run.

`--regions` runs `distributed.detect_regions` (one task per region, the
driver joins) against the in-process `aa.detect_regions` instead, and
gives the peak RSS of the driver (this process: run with
`--no-reference` for the driver's own figure) and of the workers.

`--regions --tiling SCAN K --per-file G` runs it on a tiling of a real
tile instead of the town: SCAN (a PLY, e.g. the corpus's AHN tile) copied
K x K times edge to edge, written as LAS files of G x G copies each (in
`--workdir`, kept for the next run), the source the list of files, as a
user's survey would come; the driver reads them (no in-process
reference). `--memory-limit` gives each worker Dask's memory limit. With `--tiles
OUT` the run is `distributed.detect_tiles` instead: no process reads the
cloud whole, and the labelled tiles are written to OUT (the F1 read back
from them). `--one-file` concatenates the tiling's LAS files into one LAS
file (their records in list order: the same cloud) and runs
`detect_tiles` on that file alone, which tasks and driver read in pieces.
`--kill-after S` kills one worker process S seconds into each run (a
machine lost mid-run; the run must finish with the same outputs: with
`--tiles` the labelled tiles' SHA-256 is printed, to compare with a run
without it). The worker peak RSS is then the survivors' and the new one's.

    .venv/bin/python scripts/bench_distributed.py --regions --workers 2 \
        --tiling ahn_2386_9702.ply 48 --per-file 8 --memory-limit 3GiB
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np


def town(n: int, seed: int = 1, spacing: float = 0.5, noise: float = 0.02) -> np.ndarray:
    """About n points: a ground plane and box buildings, constant density."""
    rng = np.random.default_rng(seed)
    # Per 40 x 40 block: ground (1600), one building 16 x 16 x 12 (4 walls
    # of 16 x 12 and a roof of 16 x 16, minus the ground it covers): about
    # 1600 + 768 = 2368 square units per block, 4 points per unit (spacing 0.5).
    per_block = 2368 / spacing**2
    blocks = max(1, int(round(np.sqrt(n * 0.98 / per_block))))
    side = 40.0 * blocks
    parts = []

    def rect(o, u, v, a, b):
        k = int(a * b / spacing**2)
        s, t = rng.uniform(0, a, k), rng.uniform(0, b, k)
        return np.asarray(o) + s[:, None] * np.asarray(u) + t[:, None] * np.asarray(v)

    ground = rect([0, 0, 0], [1, 0, 0], [0, 1, 0], side, side)
    parts.append(ground)
    for i in range(blocks):
        for j in range(blocks):
            x0, y0 = 40.0 * i + 12 + rng.uniform(-4, 4), 40.0 * j + 12 + rng.uniform(-4, 4)
            w, d, h = 16.0, 16.0, rng.uniform(8, 16)
            parts += [
                rect([x0, y0, 0], [1, 0, 0], [0, 0, 1], w, h),
                rect([x0, y0 + d, 0], [1, 0, 0], [0, 0, 1], w, h),
                rect([x0, y0, 0], [0, 1, 0], [0, 0, 1], d, h),
                rect([x0 + w, y0, 0], [0, 1, 0], [0, 0, 1], d, h),
                rect([x0, y0, h], [1, 0, 0], [0, 1, 0], w, d),
            ]
    pts = np.vstack(parts)
    pts += rng.normal(0, noise, pts.shape)
    bg = rng.uniform([0, 0, 0], [side, side, 16], (int(0.02 * len(pts)), 3))
    return np.ascontiguousarray(np.vstack([pts, bg]))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sizes", type=float, nargs="+", default=[1e6])
    ap.add_argument("--workers", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--threads", type=int, default=None, help="in-process run and driver threads")
    ap.add_argument("--tile", type=float, default=None, help="tile side (default: distributed's)")
    ap.add_argument("--no-reference", action="store_true", help="skip the in-process run")
    ap.add_argument("--regions", action="store_true", help="detect_regions instead of the tiled detect")
    ap.add_argument("--tiling", nargs=2, metavar=("SCAN", "K"), default=None,
                    help="with --regions: a K x K tiling of a real tile (PLY) as LAS files")
    ap.add_argument("--per-file", type=int, default=8, help="copies per side in each LAS file of --tiling")
    ap.add_argument("--workdir", default="/tmp/aa_tiling", help="where --tiling writes its files")
    ap.add_argument("--memory-limit", default=None, help="each worker's Dask memory limit (e.g. 3GiB)")
    ap.add_argument("--one-file", action="store_true",
                    help="with --tiling and --tiles: the tiles concatenated into one LAS file, read in pieces")
    ap.add_argument("--piece", type=int, default=None,
                    help="with --tiles: detect_tiles' piece (default: the package's PIECE_POINTS)")
    ap.add_argument("--tiles", default=None, metavar="OUT",
                    help="with --tiling: distributed.detect_tiles, the labelled tiles written to OUT")
    ap.add_argument("--kill-after", type=float, default=None, metavar="S",
                    help="with --regions: kill one worker process (SIGKILL) S seconds into each run")
    args = ap.parse_args()
    if args.regions:
        return regions(args)

    import aniso_alpha as aa
    from aniso_alpha import distributed
    from dask.distributed import Client, LocalCluster

    print(f"load average before: {os.getloadavg()[0]:.2f}, cores: {os.cpu_count()}")
    print("| points | run | wall s | plan s | tiles s | finish s | tiles | ratio to in-process | same labels |")
    print("|---:|---|---:|---:|---:|---:|---:|---:|---|")
    for size in args.sizes:
        pts = town(int(size))
        n = len(pts)
        ref = None
        t_ref = None
        if not args.no_reference:
            t0 = time.perf_counter()
            ref = aa.detect(pts, "planes", threads=args.threads)
            t_ref = time.perf_counter() - t0
            print(f"| {n:,} | in-process ({args.threads or os.cpu_count()} threads) | {t_ref:.1f} | | | | | 1 | |", flush=True)
        for w in args.workers:
            cluster = LocalCluster(n_workers=w, threads_per_worker=1, processes=True, dashboard_address=None)
            client = Client(cluster)
            try:
                t0 = time.perf_counter()
                p = distributed.plan(pts, "planes", tile=args.tile, workers=w, threads=args.threads)
                t1 = time.perf_counter()
                outputs = distributed._run(client, p, pts, 1)
                t2 = time.perf_counter()
                labels, _, _ = p.finish(pts, outputs, args.threads)
                t3 = time.perf_counter()
                tiles = len(outputs)
            finally:
                client.close()
                cluster.close()
            same = "" if ref is None else ("yes" if np.array_equal(labels, ref.labels) else "**NO**")
            ratio = "" if t_ref is None else f"{(t3 - t0) / t_ref:.2f}"
            print(
                f"| {n:,} | {w} worker(s) | {t3 - t0:.1f} | {t1 - t0:.1f} | {t2 - t1:.1f} | {t3 - t2:.1f} "
                f"| {tiles} | {ratio} | {same} |",
                flush=True,
            )
    print(f"load average after: {os.getloadavg()[0]:.2f}")


def peak_rss_mib() -> float:
    """This process's peak RSS (MiB): Linux's VmHWM, which starts again at
    exec (getrusage's ru_maxrss does not: a worker process spawned by the
    driver would report the driver's peak at the time of the spawn)."""
    try:
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) / 1024
    except OSError:
        pass
    import resource

    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def kill_a_worker_after(client, seconds: float, log: list):
    """A timer that kills one worker process of `client` (the first by
    address) with SIGKILL `seconds` from now, as a machine lost mid-run
    would; its nanny starts a new one and Dask runs the lost tasks again.
    What happened is appended to `log`."""
    import signal
    import threading

    def kill() -> None:
        try:
            pids = client.run(os.getpid)
            addr = sorted(pids)[0]
            os.kill(pids[addr], signal.SIGKILL)
            log.append(f"killed worker {addr} (pid {pids[addr]}) at {seconds:.0f} s")
        except Exception as e:  # the run may have ended first
            log.append(f"no worker killed: {e!r}")

    timer = threading.Timer(seconds, kill)
    timer.daemon = True
    timer.start()
    return timer


def outputs_digest(paths: list) -> str:
    """SHA-256 of the output files' bytes, in order (first 16 hex digits)."""
    import hashlib

    h = hashlib.sha256()
    for p in paths:
        with open(p, "rb") as f:
            while chunk := f.read(64 << 20):
                h.update(chunk)
    return h.hexdigest()[:16]


def tiling(scan: str, k: int, per_file: int, workdir: str) -> list:
    """SCAN copied k x k times edge to edge (each copy shifted by the
    tile's x-y extent), as LAS files of per_file x per_file copies each
    (written once: files already there are kept); their paths."""
    import laspy

    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "corpus"))
    from common import read_ply

    v = read_ply(scan)
    xyz = np.stack([v["x"], v["y"], v["z"]], 1).astype(np.float64)
    lo, hi = xyz.min(axis=0), xyz.max(axis=0)
    step = (hi - lo)[:2] + 1.0
    os.makedirs(workdir, exist_ok=True)
    paths = []
    for fi in range(0, k, per_file):
        for fj in range(0, k, per_file):
            path = os.path.join(workdir, f"{os.path.basename(scan)[:-4]}_{k}_{fi}_{fj}.las")
            paths.append(path)
            if os.path.exists(path):
                continue
            blocks = []
            for i in range(fi, min(fi + per_file, k)):
                for j in range(fj, min(fj + per_file, k)):
                    blocks.append(xyz + [i * step[0], j * step[1], 0.0])
            pts = np.vstack(blocks)
            header = laspy.LasHeader(point_format=1, version="1.2")
            header.offsets = lo
            header.scales = [0.001, 0.001, 0.001]
            las = laspy.LasData(header)
            las.x, las.y, las.z = pts[:, 0], pts[:, 1], pts[:, 2]
            las.write(path + ".part")
            os.replace(path + ".part", path)
    return paths


def one_file(paths: list, workdir: str) -> str:
    """The LAS tiles of a tiling (one header's scale and offset, no VLRs
    between header and points) concatenated into one LAS file, their
    records in list order (written once, kept); its path."""
    import struct

    out = os.path.join(workdir, os.path.basename(paths[0]).rsplit("_", 2)[0] + "_all.las")
    if os.path.exists(out):
        return out
    heads = []
    for p in paths:
        with open(p, "rb") as f:
            heads.append(f.read(227))
    starts = [struct.unpack_from("<I", h, 96)[0] for h in heads]
    counts = [struct.unpack_from("<I", h, 107)[0] for h in heads]
    bounds = np.array([struct.unpack_from("<6d", h, 179) for h in heads])
    if set(starts) != {227}:
        raise ValueError("tiles with VLRs: not a tiling written by this script")
    head = bytearray(heads[0])
    struct.pack_into("<I", head, 107, sum(counts))
    struct.pack_into("<5I", head, 111, sum(counts), 0, 0, 0, 0)
    struct.pack_into("<6d", head, 179, bounds[:, 0].max(), bounds[:, 1].min(), bounds[:, 2].max(),
                     bounds[:, 3].min(), bounds[:, 4].max(), bounds[:, 5].min())
    with open(out + ".part", "wb") as w:
        w.write(head)
        for p, start in zip(paths, starts):
            with open(p, "rb") as f:
                f.seek(start)
                while chunk := f.read(64 << 20):
                    w.write(chunk)
    os.replace(out + ".part", out)
    return out


def tiling_counts(truth: np.ndarray, pred: np.ndarray) -> np.ndarray:
    """True positives, false positives and false negatives of the plane
    points of copies of a tile (every copy is the tile's points in its
    order), one copy at a time."""
    m = len(truth)
    counts = np.zeros(3, dtype=np.int64)
    for c in range(len(pred) // m):
        got = pred[c * m : (c + 1) * m] >= 0
        counts += [np.sum(truth & got), np.sum(~truth & got), np.sum(truth & ~got)]
    return counts


def tiling_truth(scan: str) -> np.ndarray:
    """The tile's points that lie on a labelled plane."""
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "corpus"))
    from common import read_ply

    return read_ply(scan)["plane"].astype(np.int64) >= 0


def f1_of(counts: np.ndarray) -> float:
    tp, fp, fn = (int(c) for c in counts)
    p, r = tp / max(tp + fp, 1), tp / max(tp + fn, 1)
    return 2 * p * r / max(p + r, 1e-12)


def tiling_f1(scan: str, pred: np.ndarray) -> float:
    """Per-point plane F1 of a tiling's part labels against the tile's
    plane labels."""
    return f1_of(tiling_counts(tiling_truth(scan), pred))


def tiles_f1(args: argparse.Namespace, outputs: list) -> float:
    """tiling_f1 of a detect_tiles run, its part labels read back from
    the labelled tiles one at a time."""
    import aniso_alpha as aa

    truth = tiling_truth(args.tiling[0])
    counts = np.zeros(3, dtype=np.int64)
    step = 64 * len(truth)  # whole copies at a time
    for o in outputs:
        start = 0
        while True:
            try:
                part = aa.read(o, start=start, count=step).attributes["part"]
            except ValueError:  # past the end
                break
            counts += tiling_counts(truth, part)
            start += len(part)
    return f1_of(counts)


def regions(args: argparse.Namespace) -> None:
    """The `--regions` table: distributed.detect_regions against
    aa.detect_regions."""
    import aniso_alpha as aa
    from aniso_alpha import distributed
    from dask.distributed import Client, LocalCluster

    print(f"load average before: {os.getloadavg()[0]:.2f}, cores: {os.cpu_count()}")
    print("| points | run | wall s | regions | parts | driver peak RSS MiB | worker peak RSS MiB | same labels |")
    print("|---:|---|---:|---:|---:|---:|---:|---|")
    sources = [None] if args.tiling else args.sizes
    for size in sources:
        if args.tiling:
            # Written by a child process, so that the driver's peak RSS is
            # the run's.
            from concurrent.futures import ProcessPoolExecutor

            with ProcessPoolExecutor(1) as ex:
                pts = ex.submit(tiling, args.tiling[0], int(args.tiling[1]), args.per_file, args.workdir).result()
            print(f"tiling: {len(pts)} LAS files in {args.workdir}", flush=True)
            if args.one_file:
                with ProcessPoolExecutor(1) as ex:
                    pts = [ex.submit(one_file, pts, args.workdir).result()]
                print(f"one file: {pts[0]} ({os.path.getsize(pts[0]) / 2**30:.2f} GiB)", flush=True)
        else:
            pts = town(int(size))
        ref = None
        if not args.no_reference and not args.tiling:
            t0 = time.perf_counter()
            ref = aa.detect_regions(pts, "planes", threads=args.threads)
            t = time.perf_counter() - t0
            print(f"| {n:,} | in-process ({args.threads or os.cpu_count()} threads) | {t:.1f} | {ref.regions} "
                  f"| {len(ref.parts)} | {peak_rss_mib():.0f} | | |", flush=True)
        for w in args.workers:
            cluster = LocalCluster(n_workers=w, threads_per_worker=1, processes=True, dashboard_address=None,
                                   memory_limit=args.memory_limit or "auto")
            client = Client(cluster)
            killed: list = []
            timer = kill_a_worker_after(client, args.kill_after, killed) if args.kill_after else None
            try:
                t0 = time.perf_counter()
                if args.tiles:
                    piece = args.piece or distributed.PIECE_POINTS
                    r = distributed.detect_tiles(pts, "planes", args.tiles, client=client, piece=piece)
                else:
                    r = distributed.detect_regions(pts, "planes", client=client)
                t = time.perf_counter() - t0
                if timer is not None:
                    timer.cancel()
                workers = client.run(peak_rss_mib)
            finally:
                client.close()
                cluster.close()
            same = "" if ref is None else (
                "yes" if np.array_equal(r.part_labels, ref.part_labels) else "**NO**")
            n = r.points if args.tiles else len(r.labels)
            driver = peak_rss_mib()
            print(f"| {n:,} | {w} worker(s){' (tiles)' if args.tiles else ''} | {t:.1f} | {r.regions} "
                  f"| {len(r.parts)} | {driver:.0f} | {max(workers.values()):.0f} | {same} |", flush=True)
            for line in killed:
                print(line, flush=True)
            if args.tiles:
                print(f"labelled tiles' SHA-256: {outputs_digest(r.outputs)}", flush=True)
            if args.tiling:
                # After the driver's peak was read: the labels are read back
                # from the outputs one file at a time.
                f1 = tiles_f1(args, r.outputs) if args.tiles else tiling_f1(args.tiling[0], r.part_labels)
                print(f"plane F1 of the copies: {f1:.3f}", flush=True)
    print(f"load average after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
