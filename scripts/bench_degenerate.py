#!/usr/bin/env python3
"""Degenerate inputs next to points in general position (issue 19, part 5).

Runs the `triangulate` example (built in release) on each degenerate series
and on uniform points of the same count, in the same run, interleaved, and
prints a Markdown table: build time (in-process, median of the reps), peak
RSS of the whole process (/usr/bin/time), and the ratio to uniform points.

    python3 scripts/bench_degenerate.py                  # default series
    python3 scripts/bench_degenerate.py --sizes 25000 50000 100000 --reps 3
    python3 scripts/bench_degenerate.py --dups 31000000   # the 31M / 1M case
    python3 scripts/bench_degenerate.py --detect          # detection (below) only
    python3 scripts/bench_degenerate.py --detect --detect-sizes 2000 --copies 2000000 --timeout 120

Series:
  line          points on a segment, random order, rounded to 1e-6
  decimal_line  i/n along a segment, rounded to 1e-6 (exactly collinear in
                decimal for n dividing 10^5: every predicate a near-tie)
  dups31        n points drawn from n/31 uniform points (about 31 copies
                each), on 1 and 2 threads; compared with uniform n/31 (the
                distinct points alone) and uniform n

With --detect, the release CLI's `detect` (`aniso-alpha detect FILE
--structure planes|lines`) instead, wall time and peak RSS from
/usr/bin/time, once each, with the paper's parameters (planes: --alpha 1
--lambda2 4 --lambda3 8 --min-size 20, 1,944 orientations; lines: --alpha 1
--lambda3 10 --min-size 4, 162 orientations) and with none (automatic),
each next to uniform points of the same count, in the same run; a run over
--timeout seconds is killed and shown as "> T". Once a series times out,
its larger sizes are not run (shown as "> T" too, marked "not run").
Clouds (text, 3 decimals, seed 1; s = sqrt(n)):
  uniform     n points uniform in the cube [0, s]^3
  plane       exactly coplanar: z = 0, x, y uniform in [0, s] at 1e-3
  plane_grid  exactly coplanar: the integer grid of ceil(s) columns on z = 0
  line        exactly collinear: y = z = 0, x uniform in [0, n/2] at 1e-3
  line_grid   exactly collinear: 0.25 * (i, i, 0), i < n
  copies      n points, each of 1,000 uniform points of [0, 10]^3 repeated
              n/1000 times (--copies sizes, both structures)
With --reference jittered, the reference of each series is the same cloud
with every coordinate moved by a uniform amount in [-0.01, 0.01] (the same
points, density and structures, in general position) instead of uniform
points in the cube, which at these sizes are mostly isolated at alpha = 1
and so cost little.
"""
import argparse
import json
import math
import random
import re
import tempfile
import time
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


PAPER = {
    "planes": ["--alpha", "1", "--lambda2", "4", "--lambda3", "8", "--min-size", "20"],
    "lines": ["--alpha", "1", "--lambda3", "10", "--min-size", "4"],
}


# Half-width of the jitter of the "jittered" reference (--reference
# jittered): 1% of the plane's spacing (1), 2% of the random line's (0.5).
JITTER = 0.01


def cloud(kind, n, seed=1):
    """The points of one detection series (see the module's docstring)."""
    r = random.Random(seed)
    s = math.sqrt(n)
    if kind.startswith("jittered:"):
        j = random.Random(seed + 1)
        return [tuple(c + j.uniform(-JITTER, JITTER) for c in p) for p in cloud(kind[9:], n, seed)]
    if kind == "uniform":
        return [(r.uniform(0, s), r.uniform(0, s), r.uniform(0, s)) for _ in range(n)]
    if kind == "plane":
        return [(r.uniform(0, s), r.uniform(0, s), 0.0) for _ in range(n)]
    if kind == "plane_grid":
        c = math.ceil(s)
        return [(float(i % c), float(i // c), 0.0) for i in range(n)]
    if kind == "line":
        return [(r.uniform(0, n / 2), 0.0, 0.0) for _ in range(n)]
    if kind == "line_grid":
        return [(0.25 * i, 0.25 * i, 0.0) for i in range(n)]
    if kind == "copies":
        d = [(r.uniform(0, 10), r.uniform(0, 10), r.uniform(0, 10)) for _ in range(1000)]
        return (d[i % 1000] for i in range(n))
    raise ValueError(kind)


def cloud_file(tmp, kind, n):
    path = Path(tmp) / f"{kind}_{n}.xyz"
    if not path.exists():
        with open(path, "w") as f:
            f.writelines(f"{x:.3f} {y:.3f} {z:.3f}\n" for x, y, z in cloud(kind, n))
    return path


def detect(exe, path, structure, paper, timeout):
    """One `detect` run: (wall seconds or None on timeout, peak RSS MiB, structures found)."""
    cmd = ["/usr/bin/time", "-f", "RSS %M", "timeout", "-s", "KILL", str(timeout), str(exe)]
    cmd += ["detect", str(path), "--structure", structure] + (PAPER[structure] if paper else [])
    start = time.monotonic()
    p = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.monotonic() - start
    line = next(l for l in p.stderr.splitlines() if l.startswith("RSS "))
    rss = int(line.split()[1]) / 1024.0
    if p.returncode != 0:
        if wall >= timeout - 1:
            return None, None, None  # (the peak RSS of a killed run is not reported)
        err = next((l for l in p.stderr.splitlines() if l.startswith("error")), p.stderr.strip())
        print(f"{' '.join(cmd[6:])}: exit {p.returncode}: {err}", file=sys.stderr)
        return wall, rss, "error"
    m = re.search(r"(\d+) structure\(s\)", p.stdout)
    return wall, rss, int(m.group(1)) if m else None


def detect_table(exe, sizes, copies, timeout, series, reference="uniform"):
    fmt_t = lambda t: f"> {timeout}" if t is None else f"{t:.1f}"
    ratio = lambda a, b: "—" if a is None or not b else f"{a / b:.2f}"
    print(f"| cloud | n | structure | parameters | time (s) | {reference} n (s) | time ratio "
          f"| peak RSS (MiB) | {reference} RSS | RSS ratio | structures |")
    print("|---|---:|---|---|---:|---:|---:|---:|---:|---:|---:|")
    plan = [(k, "planes") for k in ["plane", "plane_grid"]] + [(k, "lines") for k in ["line", "line_grid"]]
    plan = [(k, st, sizes) for k, st in plan] + [("copies", st, copies) for st in ["planes", "lines"]]
    plan = [p for p in plan if series is None or p[0] in series]
    with tempfile.TemporaryDirectory(prefix="bench_degenerate") as tmp:
        for paper in [True, False]:
            gave_up = {}  # (cloud, structure): the smallest n that timed out
            done = {}  # the uniform runs, shared by the series of one structure
            for kind, structure, ns in plan:
                for n in ns:
                    label = "paper" if paper else "automatic"
                    row = []
                    ref = "uniform" if reference == "uniform" else f"jittered:{kind}"
                    for k in [ref, kind]:
                        key = (k, n, structure)
                        if k == ref and key in done:
                            row.append(done[key])
                            continue
                        if n >= gave_up.get((k, structure), math.inf):
                            row.append((None, None, "not run"))
                            continue
                        done[key] = detect(exe, cloud_file(tmp, k, n), structure, paper, timeout)
                        t, m, found = done[key]
                        if t is None:
                            gave_up[(k, structure)] = min(n, gave_up.get((k, structure), math.inf))
                        row.append((t, m, found))
                    (tu, mu, _), (t, m, found) = row
                    rss = lambda x: "—" if x is None else f"{x:.0f}"
                    print(f"| {kind} | {n} | {structure} | {label} | {fmt_t(t)} | {fmt_t(tu)} | {ratio(t, tu)} "
                          f"| {rss(m)} | {rss(mu)} | {ratio(m, mu)} | {'—' if found is None else found} |")
                    sys.stdout.flush()


def build_cli():
    subprocess.run(["cargo", "build", "--release", "-p", "aniso-alpha-cli"], cwd=ROOT, check=True)
    return ROOT / "target" / "release" / "aniso-alpha"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sizes", type=int, nargs="+", default=[25000, 50000, 100000, 200000])
    ap.add_argument("--dups", type=int, nargs="+", default=[3100000])
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--detect", action="store_true", help="run the detection series instead")
    ap.add_argument("--detect-sizes", type=int, nargs="+", default=[2000, 5000, 20000])
    ap.add_argument("--copies", type=int, nargs="+", default=[2000000, 10000000])
    ap.add_argument("--timeout", type=int, default=180, help="seconds before a detect run is killed")
    ap.add_argument("--series", nargs="+", help="detection series to run (default: all)")
    ap.add_argument("--reference", choices=["uniform", "jittered"], default="uniform",
                    help="the general-position cloud each detection series is compared with")
    ap.add_argument("--exe", help="an aniso-alpha binary to run instead of building the release CLI")
    args = ap.parse_args()
    load = lambda: open("/proc/loadavg").read().split()[0]
    if args.detect:
        exe = args.exe or build_cli()
        print(f"load before: {load()}", file=sys.stderr)
        detect_table(exe, args.detect_sizes, args.copies, args.timeout, args.series, args.reference)
        print(f"load after: {load()}", file=sys.stderr)
        return
    exe = build()
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
