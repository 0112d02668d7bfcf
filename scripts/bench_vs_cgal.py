#!/usr/bin/env python3
"""Runs aniso-alpha and CGAL on the same point files, in one run, and prints
the ratios (ours / CGAL) of time and peak RSS as a Markdown table.

    python3 scripts/bench_vs_cgal.py                       # Delaunay, default sets
    python3 scripts/bench_vs_cgal.py --what alpha --sets uniform_100k uniform_1m
    python3 scripts/bench_vs_cgal.py --reps 5 --sets grid50
    python3 scripts/bench_vs_cgal.py --what alpha --threads 1   # our side on one core
    python3 scripts/bench_vs_cgal.py --build-threads 2 --sets uniform_1m   # parallel build

Setup (once): CGAL from Debian (`apt-get install libcgal-dev libgmp-dev
libmpfr-dev`), numpy (`pip install numpy`). The script copies the peer
programs of `../shared/peers` into `target/peers`, builds them with their
`build.sh`, and generates their datasets with their `gen.py` (raw
little-endian f64 triples), so both sides read bit-identical points.

Timed regions (in-process, I/O excluded on both sides):
  delaunay: ours = `Triangulation::new` (example `triangulate`), CGAL =
            `cgal_delaunay` (Delaunay_triangulation_3 range insert);
  alpha:    ours = triangulation + `AlphaComplex::new` (example `alpha_time`),
            CGAL = `cgal_alpha` Delaunay + Alpha_shape_3 GENERAL construction.
Peak RSS is /usr/bin/time's maximum resident set size of the whole process
(input arrays included on both sides). Repetitions are interleaved; the
table shows medians, the ratio of the two medians ("time ratio") and the
median of the per-rep ratios (ours / CGAL of the same rep). The machine is
shared: read the ratios, not the absolute seconds, and note the load
average printed with them.
"""
import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SHARED = os.path.join(os.path.dirname(ROOT), "shared", "peers")
PEERS = os.path.join(ROOT, "target", "peers")


def sh(cmd, **kw):
    return subprocess.run(cmd, check=True, text=True, **kw)


def setup():
    if not os.path.isdir(SHARED):
        sys.exit(f"peer programs not found at {SHARED}")
    os.makedirs(PEERS, exist_ok=True)
    for f in os.listdir(SHARED):
        src = os.path.join(SHARED, f)
        if os.path.isfile(src):
            dst = os.path.join(PEERS, f)
            shutil.copyfile(src, dst)
            os.chmod(dst, 0o755)
    if not os.path.exists("/usr/include/CGAL"):
        sys.exit("CGAL headers missing: apt-get install libcgal-dev libgmp-dev libmpfr-dev")
    sh(["./build.sh"], cwd=PEERS, stdout=subprocess.DEVNULL)
    if not os.path.exists(os.path.join(PEERS, "data", "uniform_1m.bin")):
        os.makedirs(os.path.join(PEERS, "data"), exist_ok=True)
        sh([sys.executable, "gen.py"], cwd=PEERS, stdout=subprocess.DEVNULL)
    sh(["cargo", "build", "--release", "-q", "-p", "aniso-alpha",
        "--example", "triangulate", "--example", "alpha_time"], cwd=ROOT)


def timed(cmd, env=None):
    """Runs cmd under /usr/bin/time; returns (last JSON line of stdout, peak RSS MiB)."""
    p = subprocess.run(["/usr/bin/time", "-f", "RSS_KB %M"] + cmd,
                       capture_output=True, text=True, check=True, env=env)
    rss = next(int(l.split()[1]) for l in p.stderr.splitlines() if l.startswith("RSS_KB"))
    line = [l for l in p.stdout.splitlines() if l.startswith("{")][-1]
    return json.loads(line), rss / 1024.0


def run_case(what, data, reps, threads=None, build_threads=1):
    ours_bin = os.path.join(ROOT, "target", "release", "examples",
                            "triangulate" if what == "delaunay" else "alpha_time")
    cgal_bin = os.path.join(PEERS, "bin", "cgal_delaunay" if what == "delaunay" else "cgal_alpha")
    ours_t, cgal_t, ours_m, cgal_m = [], [], [], []
    info = {}
    env = dict(os.environ)
    if threads:
        env["RAYON_NUM_THREADS"] = str(threads)
    extra = ["--threads", str(build_threads)] if build_threads > 1 else []
    for _ in range(reps):
        o, om = timed([ours_bin, data] + extra, env)
        c, cm = timed([cgal_bin, data])
        if what == "delaunay":
            ours_t.append(o["time_s"])
            cgal_t.append(c["time_s"])
            info = {"ours_tets": o["finite_tets"], "cgal_tets": c["finite_tets"]}
        else:
            ours_t.append(o["triangulate"] + o["intervals"])
            cgal_t.append(c["t_delaunay_s"] + c["t_alpha_init_s"])
            info = {"ours_edges": o.get("edges"), "cgal_edges": c.get("finite_edges"),
                    "ours_triangles": o.get("triangles"), "cgal_triangles": c.get("finite_facets")}
        ours_m.append(om)
        cgal_m.append(cm)
    return (statistics.median(ours_t), statistics.median(cgal_t),
            statistics.median(ours_m), statistics.median(cgal_m), ours_t, cgal_t, info)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--what", choices=["delaunay", "alpha"], default="delaunay")
    ap.add_argument("--sets", nargs="+", default=["uniform_100k", "uniform_1m", "grid50"])
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--threads", type=int, default=None,
                    help="threads for our side (RAYON_NUM_THREADS; default: all cores): "
                         "the alpha intervals use rayon. CGAL's programs are single-threaded.")
    ap.add_argument("--build-threads", type=int, default=1,
                    help="threads of our triangulation (default 1: the single-threaded "
                         "build; more runs the parallel build).")
    args = ap.parse_args()
    setup()
    print(f"load average before: {open('/proc/loadavg').read().split()[:3]}")
    print(f"our threads: {args.threads or 'all cores'} (of {os.cpu_count()}); "
          f"build threads: {args.build_threads}")
    print()
    print(f"| {args.what} | ours (s) | CGAL (s) | time ratio | per-rep ratio | ours RSS (MiB) | CGAL RSS (MiB) | RSS ratio | counts | all reps ours / CGAL (s) |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---|---|")
    for s in args.sets:
        data = os.path.join(PEERS, "data", s + ".bin")
        ot, ct, om, cm, ol, cl, info = run_case(args.what, data, args.reps, args.threads,
                                                  args.build_threads)
        counts = ", ".join(f"{k} {v}" for k, v in info.items())
        reps = "; ".join(f"{a:.3f}/{b:.3f}" for a, b in zip(ol, cl))
        per_rep = statistics.median(a / b for a, b in zip(ol, cl))
        print(f"| {s} | {ot:.3f} | {ct:.3f} | {ot / ct:.2f} | {per_rep:.2f} | {om:.0f} | {cm:.0f} | {om / cm:.2f} | {counts} | {reps} |")
    print()
    print(f"load average after: {open('/proc/loadavg').read().split()[:3]}")


if __name__ == "__main__":
    main()
