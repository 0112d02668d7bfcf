#!/usr/bin/env python3
"""Growth of `detect` (automatic mode) with the number of points at
constant density (issue: real scans, tiles): copies of a scan laid out on
a grid, from 1 copy to many. By default the CGAL ball scan (the fixture,
31,374 points), each copy 1.5 object sizes from the next; `--scan` takes
any binary PLY (e.g. an airborne tile of the corpus, scripts/corpus/) and
`--spacing 1` lays its copies edge to edge, as the tiles of one survey:
the ground of every copy is then one plane across the tiles, and every
roof has a coplanar twin in each copy (the case where merging coplanar
parts was quadratic). Prints wall time, peak RSS, microseconds per point,
planes found per copy, the CLI's phases (`--timings`) and, when the scan
has a truth column `plane` (scripts/corpus/), the per-point plane F1 of
the copies. `--regions` passes detect's `--regions` (default: the CLI's,
`auto`: region by region above 1,000,000 points; `off`: one whole run).
With `--peer`
(scripts/peers/cgal_shapes.cpp), CGAL's Efficient RANSAC runs on the same
cloud in the same loop (`--peer-args`, e.g. the scan's best preset of
scripts/bench_corpus.py), and the table gets its wall time, peak RSS and
our ratios to them.

    python3 scripts/bench_scaling.py [--bin target/release/aniso-alpha] [--copies 1,4,16,32]
        [--scan FILE.ply --spacing 1] [--timeout S] [--threads N] [--regions auto|off|SIDE]
        [--peer cgal_shapes --peer-args "--epsilon 0.15 --cluster-epsilon 0.49 --min-points 100"]

Needs numpy and GNU time (/usr/bin/time) for the peak RSS.
"""
import argparse
import json
import os
import signal
import subprocess
import tempfile
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys_path = os.path.join(ROOT, "scripts")
import sys  # noqa: E402

sys.path.insert(0, sys_path)
from bench_real import read_ply, score  # noqa: E402

sys.path.insert(0, os.path.join(sys_path, "corpus"))
from common import read_ply as read_any_ply  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", default=os.path.join(ROOT, "target/release/aniso-alpha"))
    ap.add_argument("--copies", default="1,4,16,32")
    ap.add_argument("--threads", default=None)
    ap.add_argument("--scan", default=None, help="a binary PLY to copy (default: CGAL's ball)")
    ap.add_argument("--spacing", type=float, default=1.5,
                    help="copy pitch in units of the scan's extent (1: edge to edge)")
    ap.add_argument("--timeout", type=float, default=None, help="seconds per run, ours and the peer's (then: > timeout)")
    ap.add_argument("--peer", default=None, help="CGAL peer binary (scripts/peers/cgal_shapes.cpp)")
    ap.add_argument("--peer-args", default="", help="its options, one string")
    ap.add_argument("--regions", default=None,
                    help="detect's --regions (SIDE, auto or off; default: the CLI's, auto)")
    a = ap.parse_args()
    truth = None
    if a.scan:
        v = read_any_ply(a.scan)
        pts = np.stack([v["x"], v["y"], v["z"]], axis=1).astype(np.float64)
        if "plane" in v.dtype.names:
            truth = v["plane"].astype(np.int64)
    else:
        pts, _ = read_ply(os.path.join(ROOT, "crates/aniso-alpha/tests/fixtures/real/ball.ply"))
    lo, hi = pts.min(0), pts.max(0)
    pitch = a.spacing * (hi - lo)
    peer_cols = " RANSAC wall s | RANSAC RSS MiB | wall / RANSAC | RSS / RANSAC |" if a.peer else ""
    f1_col = " plane F1 |" if truth is not None else ""
    print("| copies | points | wall s | peak RSS MiB | µs / point | parts | parts / copy | phases (s) |" + f1_col
          + peer_cols)
    print("|---:|---:|---:|---:|---:|---:|---:|---|" + ("---:|" if truth is not None else "")
          + ("---:|" * 4 if a.peer else ""))
    with tempfile.TemporaryDirectory() as tmp:
        for c in map(int, a.copies.split(",")):
            side = int(np.ceil(np.sqrt(c)))
            cloud = np.concatenate([pts + np.array([pitch[0] * (k % side), pitch[1] * (k // side), 0.0])
                                    for k in range(c)])
            f = os.path.join(tmp, "copies.xyz")
            np.savetxt(f, cloud, fmt="%.5f")
            rep = os.path.join(tmp, "r.json")
            lab = os.path.join(tmp, "parts.txt")
            args = ["/usr/bin/time", "-f", "%M", a.bin, "detect", f, "--structure", "planes", "--report", rep,
                    "--part-labels", lab, "--quiet", "--timings"]
            if a.threads:
                args += ["--threads", a.threads]
            if a.regions:
                args += ["--regions", a.regions]
            t = time.perf_counter()
            try:
                r = run_group(args, a.timeout)
            except subprocess.TimeoutExpired:
                print(f"| {c} | {len(cloud)} | > {a.timeout:.0f} | | | | | |", flush=True)
                continue
            wall = time.perf_counter() - t
            lines = r.stderr.strip().splitlines()
            rss = int(lines[-1]) / 1024
            phases = next((json.loads(x) for x in lines if x.startswith("{")), {})
            ph = ", ".join(f"{k} {v:.1f}" for k, v in phases.items()
                           if k != "total" and isinstance(v, (int, float)))
            report = json.load(open(rep))
            # A whole run reports structures and their parts; a region run
            # its joined parts.
            parts = (len(report["parts"]) if "regions" in report
                     else sum(len(s.get("parts", [])) for s in report["structures"]))
            f1 = ""
            if truth is not None:
                pred = np.loadtxt(lab, dtype=np.int64)
                f1 = f" {score(np.tile(truth, c), pred)['f1']:.3f} |"
            del report
            peer = ""
            if a.peer:
                try:
                    pw, prss = run_peer(a, f, os.path.join(tmp, "peer.txt"))
                    peer = f" {pw:.2f} | {prss:.0f} | {wall / pw:.2f} | {rss / prss:.2f} |"
                except subprocess.TimeoutExpired:
                    peer = f" > {a.timeout:.0f} | | < {wall / a.timeout:.2f} | |"
            print(f"| {c} | {len(cloud)} | {wall:.2f} | {rss:.0f} | {1e6 * wall / len(cloud):.1f} | {parts} | {parts / c:.1f} | {ph} |"
                  + f1 + peer, flush=True)


def run_group(args, timeout):
    """`args` to completion (stdout and stderr captured), or killed with
    every process it started after `timeout` seconds (GNU time's child
    too), raising subprocess.TimeoutExpired."""
    p = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)
    try:
        out, err = p.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(p.pid, signal.SIGKILL)
        p.communicate()
        raise
    if p.returncode != 0:
        raise subprocess.CalledProcessError(p.returncode, args, out, err)
    return subprocess.CompletedProcess(args, p.returncode, out, err)


def run_peer(a, xyz, labels):
    """Wall time and peak RSS (MiB) of CGAL's Efficient RANSAC on `xyz`."""
    args = ["/usr/bin/time", "-f", "%M", a.peer, "ransac", xyz, labels, *a.peer_args.split()]
    t = time.perf_counter()
    r = run_group(args, a.timeout)
    return time.perf_counter() - t, int(r.stderr.strip().splitlines()[-1]) / 1024


if __name__ == "__main__":
    main()
