#!/usr/bin/env python3
"""Depth frames seen from farther away: each prepared depth frame of the
corpus (scripts/corpus/README.md) with its depth rounded to steps of k times
its median nearest-neighbour spacing, x and y moved along the pixel's ray
(from the camera at the origin) to the new depth, as a depth camera a few
metres away stores them (a Kinect's steps: about 1 spacing at 1 m, 3-5 at
2.5-3.5 m). Each binary runs `detect --structure planes` with no flag on
one thread; the table gives the plane F1 and the labelled planes of >= 1,000
points found as one part (scripts/bench_real.py's `score`), per step size.

With --peer, CGAL's Efficient RANSAC (scripts/peers/cgal_shapes.cpp) runs on
the same files in the same run, with presets as scripts/bench_corpus.py
gives them (CGAL's defaults; epsilon 1, 2 and 3 times the frame's `noise`
(manifest) or half the step, whichever is larger: the quantization error
is up to half a step; cluster epsilon 3 spacings; min points 100), its
best preset by F1 per frame and step (an upper bound for the peer).

    python3 scripts/eval_quantized.py --bin BEFORE --bin AFTER \\
        --scans mosd_learn0,mosd_learn5 [--steps 0,2,3,5] [--corpus DIR] \\
        [--peer /work/peers-bin/cgal_shapes]

Step 0 is the frame as scanned. BENCHMARKS.md, "Depth frames as PCL writes
them", has the figures of the train and held-out frames.
"""

import argparse
import os
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor

import numpy as np
from scipy.spatial import cKDTree

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "corpus"))
sys.path.insert(0, HERE)
from bench_real import score  # noqa: E402
from common import PREPARED, load_manifest, read_ply  # noqa: E402

RANSAC = "CGAL Efficient RANSAC (best preset)"


def requantized(points, spacing, k):
    """The depth (z) rounded to steps of k * spacing, x and y scaled along
    the ray to the new depth; k = 0 leaves the points as they are."""
    if k == 0:
        return points
    step = k * spacing
    z = np.round(points[:, 2] / step) * step
    z[z == 0] = step
    out = points * (z / points[:, 2])[:, None]
    out[:, 2] = z
    return out


def ransac_best(peer, xyz, truth, noise, spacing, step):
    """CGAL's Efficient RANSAC on `xyz` with each preset; the best score."""
    eps = max(noise, step / 2)
    presets = [[]] + [["--epsilon", f"{f * eps:.6g}", "--cluster-epsilon", f"{3 * spacing:.6g}",
                       "--min-points", "100"] for f in (1, 2, 3)]
    best = None
    out = f"{xyz}.ransac.txt"
    for p in presets:
        subprocess.run([peer, "ransac", xyz, out, *p], check=True,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        s = score(truth, np.loadtxt(out, dtype=np.int64))
        if best is None or s["f1"] > best["f1"]:
            best = s
    return best


def run_scan(name, args, tmp):
    ply = read_ply(os.path.join(args.corpus, name + ".ply"))
    pts = np.c_[ply["x"], ply["y"], ply["z"]]
    truth = ply["plane"]
    spacing = np.median(cKDTree(pts).query(pts, 2)[0][:, 1])
    rows = {}
    for k in args.steps:
        xyz = os.path.join(tmp, f"{name}_q{k}.xyz")
        np.savetxt(xyz, requantized(pts, spacing, k), fmt="%.7g")
        for b, binary in enumerate(args.bin):
            out = f"{xyz}.{b}.txt"
            subprocess.run(
                [binary, "detect", xyz, "--structure", "planes", "--quiet", "--threads", "1",
                 "--part-labels", out],
                check=True, stderr=subprocess.DEVNULL,
            )
            s = score(truth, np.loadtxt(out, dtype=np.int64))
            rows[(k, b)] = (s["f1"], s["found"], s["big"])
        if args.peer:
            s = ransac_best(args.peer, xyz, truth, args.noise[name], spacing, k * spacing)
            rows[(k, RANSAC)] = (s["f1"], s["found"], s["big"])
    return name, rows


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--bin", action="append", required=True, help="an aniso-alpha binary (repeat)")
    ap.add_argument("--scans", required=True, help="prepared depth frames, comma-separated")
    ap.add_argument("--steps", default="0,2,3,5", help="step sizes in spacings (0: as scanned)")
    ap.add_argument("--corpus", default=PREPARED, help="prepared scans ($ANISO_ALPHA_CORPUS/prepared)")
    ap.add_argument("--peer", help="the CGAL peer binary (scripts/peers/cgal_shapes.cpp): RANSAC too")
    args = ap.parse_args()
    args.noise = {s["name"]: s["noise"] for s in load_manifest()["scans"]}
    args.steps = [int(k) for k in args.steps.split(",")]
    totals = {}
    with tempfile.TemporaryDirectory() as tmp, ThreadPoolExecutor(2) as pool:
        for name, rows in pool.map(lambda n: run_scan(n, args, tmp), args.scans.split(",")):
            print(name, {f"step {k} bin {b}": v[:2] for (k, b), v in rows.items()}, flush=True)
            for key, v in rows.items():
                totals.setdefault(key, []).append(v)
    print("| steps of | binary | mean F1 | found |")
    print("|---:|---|---:|---:|")
    for (k, b), v in sorted(totals.items(), key=lambda e: (e[0][0], str(e[0][1]))):
        v = np.array(v)
        who = b if b == RANSAC else args.bin[b]
        print(f"| {k or 'as scanned'} | {who} | {v[:, 0].mean():.4f} | {int(v[:, 1].sum())}/{int(v[:, 2].sum())} |")


if __name__ == "__main__":
    main()
