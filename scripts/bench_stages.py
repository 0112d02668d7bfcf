#!/usr/bin/env python3
"""Per-stage wall time of `detect` on one thread and on N, and each
stage's parallel fraction (issue 27: where a run is serial).

For every scan, `detect SCAN --structure planes --quiet --timings` runs
`--reps` times on `--threads 1` and on `--threads N`, interleaved (1, N,
1, N, ...), and the median of each phase (`estimate`, `detect`) and of
each stage of the detect phase (`stages`: scan, union, candidates, widen,
claims, significance, select, merge, proportions, structures; see
`aniso_alpha::detect::Stage`) is kept. The parallel fraction of a stage is
Amdahl's p from its speed-up s on N threads: p = (1 - 1/s) / (1 - 1/N),
clipped to [0, 1] (0: nothing gained, 1: N times faster). On a machine
whose cores share one memory bus the fractions are lower bounds of what
the code allows.

    python3 scripts/bench_stages.py [--bin target/release/aniso-alpha] [--threads 2] [--reps 5]
        [--against OTHER_BIN] [--md OUT.md] [--json OUT.json] SCAN.ply [SCAN.ply ...]

With `--against`, a second build runs in the same loop (each repetition
runs both builds, on 1 and N threads each), so that a drift of the
machine's speed over the minutes of a run falls on both alike; its rows
go under `"against"` in the JSON and after the first build's in the
Markdown.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
STAGES = ["scan", "union", "candidates", "widen", "claims", "significance", "select", "merge",
          "proportions", "structures"]


def timings(binary, scan, threads):
    """The `--timings` object of one run."""
    r = subprocess.run([binary, "detect", scan, "--structure", "planes", "--quiet", "--timings",
                        "--threads", str(threads)], capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"{scan}: {r.stderr.strip()}")
    return json.loads(r.stderr.strip().splitlines()[-1])


def flat(t):
    """Phases and stages of one `--timings` object in one dict."""
    out = {k: v for k, v in t.items() if isinstance(v, (int, float))}
    out.update({"stage:" + k: v for k, v in t.get("stages", {}).items()})
    return out


def fraction(t1, tn, n):
    """Amdahl's parallel fraction from the times on 1 and n threads."""
    if tn <= 0 or t1 <= 0 or n < 2:
        return None
    s = t1 / tn
    return max(0.0, min(1.0, (1 - 1 / s) / (1 - 1 / n)))


def bench(binaries, scan, n, reps):
    """Per build of `binaries`, the rows of `scan`: each phase's and
    stage's median on 1 and `n` threads and its parallel fraction, the
    builds' runs interleaved."""
    runs = [{1: [], n: []} for _ in binaries]
    for _ in range(reps):
        for b, r in zip(binaries, runs):
            for t in (1, n):
                r[t].append(flat(timings(b, scan, t)))
    return [rows_of(r, n) for r in runs]


def rows_of(runs, n):
    keys = [k for k in runs[1][0] if all(k in r for r in runs[1] + runs[n])]
    med = {t: {k: statistics.median(r[k] for r in runs[t]) for k in keys} for t in (1, n)}
    rows = []
    for k in keys:
        rows.append({"what": k, "t1": med[1][k], "tn": med[n][k], "p": fraction(med[1][k], med[n][k], n)})
    order = {"read": 0, "estimate": 1, "detect": 2}
    order.update({"stage:" + s: 3 + i for i, s in enumerate(STAGES)})
    order["total"] = 99
    rows.sort(key=lambda r: order.get(r["what"], 50))
    return rows


def table(scan, rows, n, build=None):
    name = os.path.splitext(os.path.basename(scan))[0]
    if build:
        name += f" (`{build}`)"
    total = next((r["t1"] for r in rows if r["what"] == "total"), None)
    out = [f"**{name}**", "", f"| phase / stage | 1 thread s | {n} threads s | share of 1-thread total | "
           f"speed-up | parallel fraction |", "|---|---:|---:|---:|---:|---:|"]
    for r in rows:
        what = r["what"].replace("stage:", "  detect: ")
        share = f"{r['t1'] / total:.0%}" if total else ""
        sp = f"{r['t1'] / r['tn']:.2f}" if r["tn"] > 0 else ""
        p = f"{r['p']:.2f}" if r["p"] is not None else ""
        out.append(f"| {what} | {r['t1']:.3f} | {r['tn']:.3f} | {share} | {sp} | {p} |")
    return "\n".join(out) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scans", nargs="+")
    ap.add_argument("--bin", default=os.path.join(ROOT, "target/release/aniso-alpha"))
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--against", help="a second build, run in the same loop")
    ap.add_argument("--md")
    ap.add_argument("--json")
    a = ap.parse_args()
    if a.threads < 2:
        sys.exit("--threads: at least 2 (the comparison is against one thread)")
    builds = [a.bin] + ([a.against] if a.against else [])
    names = " against ".join(f"`{os.path.basename(b)}`" for b in builds)
    text = [f"`detect --structure planes` on 1 and {a.threads} threads, median of {a.reps} interleaved runs "
            f"each ({names})", ""]
    payload = {"bin": a.bin, "threads": a.threads, "reps": a.reps, "scans": {}}
    if a.against:
        payload.update({"against_bin": a.against, "against": {}})
    for scan in a.scans:
        per_build = bench(builds, scan, a.threads, a.reps)
        payload["scans"][scan] = per_build[0]
        if a.against:
            payload["against"][scan] = per_build[1]
        for b, rows in zip(builds, per_build):
            text.append(table(scan, rows, a.threads, os.path.basename(b) if a.against else None))
            print(text[-1], flush=True)
    if a.md:
        with open(a.md, "w") as f:
            f.write("\n".join(text))
    if a.json:
        with open(a.json, "w") as f:
            json.dump(payload, f, indent=1)


if __name__ == "__main__":
    main()
