#!/usr/bin/env python3
"""Growth of `detect` (automatic mode) with the number of points at
constant density (issue: real scans, tiles): copies of the CGAL ball scan
(the fixture, 31,374 points) laid out on a grid, each copy 1.5 object
sizes from the next, from 1 copy to 32 (1.0M points). Prints wall time,
peak RSS, microseconds per point and planes found per copy.

    python3 scripts/bench_scaling.py [--bin target/release/aniso-alpha] [--copies 1,4,16,32]

Needs numpy and GNU time (/usr/bin/time) for the peak RSS.
"""
import argparse
import json
import os
import subprocess
import tempfile
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys_path = os.path.join(ROOT, "scripts")
import sys  # noqa: E402

sys.path.insert(0, sys_path)
from bench_real import read_ply  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", default=os.path.join(ROOT, "target/release/aniso-alpha"))
    ap.add_argument("--copies", default="1,4,16,32")
    ap.add_argument("--threads", default=None)
    a = ap.parse_args()
    pts, _ = read_ply(os.path.join(ROOT, "crates/aniso-alpha/tests/fixtures/real/ball.ply"))
    size = (pts.max(0) - pts.min(0)).max()
    print("| copies | points | wall s | peak RSS MiB | µs / point | parts | parts / copy |")
    print("|---:|---:|---:|---:|---:|---:|---:|")
    with tempfile.TemporaryDirectory() as tmp:
        for c in map(int, a.copies.split(",")):
            side = int(np.ceil(np.sqrt(c)))
            cloud = np.concatenate([pts + np.array([1.5 * size * (k % side), 1.5 * size * (k // side), 0.0])
                                    for k in range(c)])
            f = os.path.join(tmp, "copies.xyz")
            np.savetxt(f, cloud, fmt="%.5f")
            rep = os.path.join(tmp, "r.json")
            args = ["/usr/bin/time", "-f", "%M", a.bin, "detect", f, "--structure", "planes", "--report", rep, "--quiet"]
            if a.threads:
                args += ["--threads", a.threads]
            t = time.perf_counter()
            r = subprocess.run(args, check=True, capture_output=True, text=True)
            wall = time.perf_counter() - t
            rss = int(r.stderr.strip().splitlines()[-1]) / 1024
            parts = sum(len(s.get("parts", [])) for s in json.load(open(rep))["structures"])
            print(f"| {c} | {len(cloud)} | {wall:.2f} | {rss:.0f} | {1e6 * wall / len(cloud):.1f} | {parts} | {parts / c:.1f} |",
                  flush=True)


if __name__ == "__main__":
    main()
