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
"""

from __future__ import annotations

import argparse
import os
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


def regions(args: argparse.Namespace) -> None:
    """The `--regions` table: distributed.detect_regions against
    aa.detect_regions."""
    import aniso_alpha as aa
    from aniso_alpha import distributed
    from dask.distributed import Client, LocalCluster

    print(f"load average before: {os.getloadavg()[0]:.2f}, cores: {os.cpu_count()}")
    print("| points | run | wall s | regions | parts | driver peak RSS MiB | worker peak RSS MiB | same labels |")
    print("|---:|---|---:|---:|---:|---:|---:|---|")
    for size in args.sizes:
        pts = town(int(size))
        n = len(pts)
        ref = None
        if not args.no_reference:
            t0 = time.perf_counter()
            ref = aa.detect_regions(pts, "planes", threads=args.threads)
            t = time.perf_counter() - t0
            print(f"| {n:,} | in-process ({args.threads or os.cpu_count()} threads) | {t:.1f} | {ref.regions} "
                  f"| {len(ref.parts)} | {peak_rss_mib():.0f} | | |", flush=True)
        for w in args.workers:
            cluster = LocalCluster(n_workers=w, threads_per_worker=1, processes=True, dashboard_address=None)
            client = Client(cluster)
            try:
                t0 = time.perf_counter()
                r = distributed.detect_regions(pts, "planes", client=client)
                t = time.perf_counter() - t0
                workers = client.run(peak_rss_mib)
            finally:
                client.close()
                cluster.close()
            same = "" if ref is None else (
                "yes" if np.array_equal(r.part_labels, ref.part_labels) else "**NO**")
            print(f"| {n:,} | {w} worker(s) | {t:.1f} | {r.regions} | {len(r.parts)} | {peak_rss_mib():.0f} "
                  f"| {max(workers.values()):.0f} | {same} |", flush=True)
    print(f"load average after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
