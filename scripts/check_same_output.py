#!/usr/bin/env python3
"""Runs two builds of the CLI on the same cases and checks that their
outputs are byte-identical: labels, part labels and the JSON report (less
its timings). For changes that must not change what the detector finds
(a restructuring, a speed-up).

    python3 scripts/check_same_output.py BASE_BIN NEW_BIN
    python3 scripts/check_same_output.py BASE_BIN NEW_BIN --seeds 1 --no-sim
    python3 scripts/check_same_output.py BASE_BIN NEW_BIN --only building,room

The cases:

* the paper's scenes (`synth lines|planes|polyhedron`) in every variant of
  scripts/eval_robustness.py (base, jitter 0.05 d and 0.1 d, random
  sampling, 3x and 10x background, crossing structures; the polyhedron has
  no crossing variant), for each seed, with the paper's explicit parameters
  (box sampler) and with no parameter at all (estimated, the data's
  orientations);
* CGAL's building and ball (crates/aniso-alpha/tests/fixtures/real/), planes,
  estimated, with the file's normals and with --ignore-normals, and with
  explicit parameters over the data's orientations (with and without the
  normals); PCL's lamppost, lines;
* the simulated room and house (`scripts/simulate_scan.py NAME --seed 1`,
  thinned to one point per voxel as scripts/bench_real.py does), estimated;
  they need numpy and open3d (`--python` names an interpreter that has
  them; `--no-sim` leaves them out);
* the tiled path (`--tile`) on a lines scene, a polyhedron and the building;
* `--threads 1` on the first seed's scenes and the real scans, besides the
  default thread count everywhere.

Each case runs both binaries with the same arguments; the table gives the
wall time of each and whether labels, part labels and report are the same.
The report's `seconds` and `timings` are left out of the comparison. Exit
status 1 on any difference or failure, 0 otherwise.

Generated inputs go to --work (a temporary folder by default; give one to
keep the simulated scans, which take minutes to make, between runs).
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
REAL = os.path.join(ROOT, "crates", "aniso-alpha", "tests", "fixtures", "real")

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
# The variants of the robustness table (short name -> long name), how each
# makes a scene, and the paper's explicit parameters.
from eval_robustness import KINDS, PAPER, SHORT, variant_args  # noqa: E402

# Voxel side (m) to which each simulated scan is thinned (scripts/bench_real.py).
SIM_VOXEL = {"room": 0.03, "house": 0.08}
# Explicit parameters for the real scans over the data's orientations: the
# estimates of the automatic mode, rounded.
REAL_EXPLICIT = {
    "building": ["--alpha", "0.16", "--lambda3", "2.1", "--min-size", "4", "--sampler", "data"],
    "ball": ["--alpha", "0.17", "--lambda3", "8", "--min-size", "4", "--sampler", "data"],
}
# Report fields that are wall times.
TIMING_FIELDS = ("seconds", "timings")


def synth_args(kind, variant):
    """`synth` options of a variant (short name), or None where it does not apply."""
    return variant_args(SHORT[variant], kind)


def make_scene(binary, work, kind, variant, seed):
    path = os.path.join(work, f"{kind}_{variant}_{seed}.xyz")
    if not os.path.exists(path):
        subprocess.run([binary, "synth", kind, "--seed", str(seed), "--output", path, "--quiet",
                        *synth_args(kind, variant)], check=True, capture_output=True)
    return path


def make_simulated(python, work, name):
    """The simulated scan, thinned (bench_real.py's `simulated`), cached in `work`."""
    path = os.path.join(work, f"{name}.xyz")
    if os.path.exists(path):
        return path
    raw = os.path.join(work, f"{name}.raw.xyz")
    subprocess.run([python, os.path.join(ROOT, "scripts", "simulate_scan.py"), name, "--seed", "1",
                    "--output", raw], check=True, capture_output=True)
    thin = (
        "import sys, numpy as np\n"
        "a = np.loadtxt(sys.argv[1])\n"
        "_, idx = np.unique(np.floor(a[:, :3] / float(sys.argv[3])).astype(np.int64), axis=0,"
        " return_index=True)\n"
        "np.savetxt(sys.argv[2], a[np.sort(idx)][:, :3], fmt='%.5f')\n"
    )
    subprocess.run([python, "-c", thin, raw, path + ".part", str(SIM_VOXEL[name])], check=True,
                   capture_output=True)
    os.replace(path + ".part", path)
    os.remove(raw)
    return path


def cases(args, work):
    """(name, input, detect options) of every case."""
    out = []
    for seed in args.seeds:
        for kind in KINDS:
            for variant in SHORT:
                if synth_args(kind, variant) is None:
                    continue
                scene = make_scene(args.base, work, kind, variant, seed)
                structure = "lines" if kind == "lines" else "planes"
                for params, opts in (("paper", PAPER[structure]), ("auto", ["--structure", structure])):
                    name = f"{kind} {variant} s{seed} {params}"
                    out.append((name, scene, opts))
                    if seed == args.seeds[0]:
                        out.append((name + " t1", scene, opts + ["--threads", "1"]))
    first = args.seeds[0]
    lines = make_scene(args.base, work, "lines", "base", first)
    poly = make_scene(args.base, work, "polyhedron", "base", first)
    out.append((f"lines base s{first} paper tile 20", lines, PAPER["lines"] + ["--tile", "20"]))
    out.append((f"lines base s{first} auto tile 20", lines, ["--structure", "lines", "--tile", "20"]))
    out.append((f"polyhedron base s{first} paper tile 15", poly, PAPER["planes"] + ["--tile", "15"]))
    for scan in ("building", "ball"):
        ply = os.path.join(REAL, scan + ".ply")
        for normals, extra in (("normals", []), ("ignore-normals", ["--ignore-normals"])):
            base = ["--structure", "planes", *extra]
            out.append((f"{scan} auto {normals}", ply, base))
            out.append((f"{scan} auto {normals} t1", ply, base + ["--threads", "1"]))
            out.append((f"{scan} explicit {normals}", ply, base + REAL_EXPLICIT[scan]))
    out.append(("building auto normals tile 8", os.path.join(REAL, "building.ply"),
                ["--structure", "planes", "--tile", "8"]))
    out.append(("lamppost auto lines", os.path.join(REAL, "lamppost.pcd"), ["--structure", "lines"]))
    if not args.no_sim:
        for name in ("room", "house"):
            path = make_simulated(args.python, work, name)
            out.append((f"{name} auto", path, ["--structure", "planes"]))
    if args.only:
        keep = args.only.split(",")
        out = [c for c in out if any(k in c[0] for k in keep)]
    return out


def run(binary, inp, opts, out_dir):
    """Runs one detection; (seconds, labels bytes, part labels bytes, report text or error)."""
    os.makedirs(out_dir, exist_ok=True)
    paths = {k: os.path.join(out_dir, k) for k in ("labels.txt", "parts.txt", "report.json")}
    for p in paths.values():
        if os.path.exists(p):
            os.remove(p)
    cmd = [binary, "detect", inp, "--quiet", "--labels", paths["labels.txt"], "--part-labels",
           paths["parts.txt"], "--report", paths["report.json"], *opts]
    t = time.perf_counter()
    r = subprocess.run(cmd, capture_output=True, text=True)
    seconds = time.perf_counter() - t
    if r.returncode != 0:
        return seconds, None, None, f"exit {r.returncode}: {r.stderr.strip()[-300:]}"
    with open(paths["labels.txt"], "rb") as f:
        labels = f.read()
    with open(paths["parts.txt"], "rb") as f:
        parts = f.read()
    with open(paths["report.json"]) as f:
        report = json.load(f)
    for k in TIMING_FIELDS:
        report.pop(k, None)
    return seconds, labels, parts, json.dumps(report, sort_keys=True)


def report_difference(a, b):
    """The first top-level report field that differs (for the table)."""
    try:
        da, db = json.loads(a), json.loads(b)
    except (TypeError, ValueError):
        return "error"
    for k in sorted(set(da) | set(db)):
        if da.get(k) != db.get(k):
            if isinstance(da.get(k), dict) and isinstance(db.get(k), dict):
                for j in sorted(set(da[k]) | set(db[k])):
                    if da[k].get(j) != db[k].get(j):
                        return f"{k}.{j}"
            return k
    return "?"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("base", help="the reference binary")
    ap.add_argument("new", help="the binary under test")
    ap.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3])
    ap.add_argument("--work", help="folder for the generated inputs and outputs (kept)")
    ap.add_argument("--python", default=sys.executable,
                    help="interpreter with numpy and open3d for the simulated scans")
    ap.add_argument("--no-sim", action="store_true", help="leave out the simulated room and house")
    ap.add_argument("--only", help="comma-separated substrings: only the cases whose name has one")
    args = ap.parse_args()
    for b in (args.base, args.new):
        if not os.access(b, os.X_OK):
            sys.exit(f"not an executable: {b}")
    tmp = None
    if args.work:
        work = args.work
        os.makedirs(work, exist_ok=True)
    else:
        tmp = tempfile.TemporaryDirectory()
        work = tmp.name
    rows = []
    failed = 0
    total = [0.0, 0.0]
    all_cases = cases(args, work)
    print(f"{len(all_cases)} cases", file=sys.stderr)
    print("| case | base s | new s | labels | parts | report |")
    print("|---|---:|---:|---|---|---|")
    for i, (name, inp, opts) in enumerate(all_cases):
        ra = run(args.base, inp, opts, os.path.join(work, "out", "base"))
        rb = run(args.new, inp, opts, os.path.join(work, "out", "new"))
        total[0] += ra[0]
        total[1] += rb[0]
        if ra[1] is None or rb[1] is None:
            verdicts = ["error"] * 3
            detail = ra[3] if ra[1] is None else rb[3]
        else:
            verdicts = ["same" if x == y else "DIFFERENT" for x, y in zip(ra[1:], rb[1:])]
            detail = "" if ra[3] == rb[3] else report_difference(ra[3], rb[3])
        ok = verdicts == ["same"] * 3
        failed += not ok
        row = f"| {name} | {ra[0]:.2f} | {rb[0]:.2f} | {verdicts[0]} | {verdicts[1]} | " \
              f"{verdicts[2]}{' (' + detail + ')' if detail else ''} |"
        rows.append(row)
        print(row, flush=True)
        print(f"[{i + 1}/{len(all_cases)}]", file=sys.stderr, flush=True)
    print(f"| **total** | {total[0]:.1f} | {total[1]:.1f} | | | |")
    print(f"\n{len(rows) - failed} of {len(rows)} cases identical", file=sys.stderr)
    if tmp is not None:
        tmp.cleanup()
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
