#!/usr/bin/env python3
"""Degenerate inputs next to points in general position (issue 19, part 5).

Runs the `triangulate` example (built in release) on each degenerate series
and on uniform points of the same count, in the same run, interleaved, and
prints a Markdown table: build time (in-process, median of the reps), peak
RSS of the whole process (/usr/bin/time), and the ratio to uniform points.

    python3 scripts/bench_degenerate.py                  # default series
    python3 scripts/bench_degenerate.py --sizes 25000 50000 100000 --reps 3
    python3 scripts/bench_degenerate.py --dups 31000000   # the 31M / 1M case

Series:
  line          points on a segment, random order, rounded to 1e-6
  decimal_line  i/n along a segment, rounded to 1e-6 (exactly collinear in
                decimal for n dividing 10^5: every predicate a near-tie)
  dups31        n points drawn from n/31 uniform points (about 31 copies
                each), on 1 and 2 threads; compared with uniform n/31 (the
                distinct points alone) and uniform n
"""
import argparse
import json
import statistics
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def build():
    subprocess.run(
        ["cargo", "build", "--release", "-p", "aniso-alpha", "--example", "triangulate"],
        cwd=ROOT,
        check=True,
    )
    return ROOT / "target" / "release" / "examples" / "triangulate"


def run(exe, kind, n, threads):
    """One run: (in-process seconds, peak RSS in MiB, finite tets)."""
    cmd = ["/usr/bin/time", "-f", "RSS %M", str(exe), kind, str(n), "--threads", str(threads)]
    p = subprocess.run(cmd, capture_output=True, text=True, check=True)
    rec = json.loads(p.stdout.strip().splitlines()[-1])
    rss = next(int(l.split()[1]) for l in p.stderr.splitlines() if l.startswith("RSS "))
    return rec["time_s"], rss / 1024.0, rec["finite_tets"]


def series(exe, cases, reps):
    """Runs every case `reps` times, interleaved; returns medians."""
    times = {c: [] for c in cases}
    rss = {c: 0.0 for c in cases}
    tets = {}
    for _ in range(reps):
        for c in cases:
            t, m, k = run(exe, *c)
            times[c].append(t)
            rss[c] = max(rss[c], m)
            tets[c] = k
    return {c: (statistics.median(times[c]), rss[c], tets[c]) for c in cases}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sizes", type=int, nargs="+", default=[25000, 50000, 100000, 200000])
    ap.add_argument("--dups", type=int, nargs="+", default=[3100000])
    ap.add_argument("--reps", type=int, default=3)
    args = ap.parse_args()
    exe = build()
    load = lambda: open("/proc/loadavg").read().split()[0]
    print(f"load before: {load()}", file=sys.stderr)

    print("| series | n | threads | time (s) | uniform n (s) | time ratio | peak RSS (MiB) | uniform RSS | RSS ratio |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    for n in args.sizes:
        cases = [("uniform", n, 1), ("line", n, 1), ("decimal_line", n, 1)]
        r = series(exe, cases, args.reps)
        tu, mu, _ = r[("uniform", n, 1)]
        for kind in ["line", "decimal_line"]:
            t, m, _ = r[(kind, n, 1)]
            print(f"| {kind} | {n} | 1 | {t:.3f} | {tu:.3f} | {t / tu:.2f} | {m:.0f} | {mu:.0f} | {m / mu:.2f} |")
        sys.stdout.flush()
    for n in args.dups:
        d = n // 31
        cases = [("dups31", n, 1), ("dups31", n, 2), ("uniform", d, 1), ("uniform", n, 1)]
        r = series(exe, cases, args.reps)
        td, md, _ = r[("uniform", d, 1)]
        tu, mu, _ = r[("uniform", n, 1)]
        for threads in [1, 2]:
            t, m, _ = r[("dups31", n, threads)]
            print(
                f"| dups31 (vs uniform n) | {n} | {threads} | {t:.3f} | {tu:.3f} | {t / tu:.2f} "
                f"| {m:.0f} | {mu:.0f} | {m / mu:.2f} |"
            )
            print(
                f"| dups31 (vs its {d} distinct points) | {n} | {threads} | {t:.3f} | {td:.3f} | {t / td:.2f} "
                f"| {m:.0f} | {md:.0f} | {m / md:.2f} |"
            )
        sys.stdout.flush()
    print(f"load after: {load()}", file=sys.stderr)


if __name__ == "__main__":
    main()
