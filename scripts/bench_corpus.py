#!/usr/bin/env python3
"""Issue 26's corpus benchmark: `aniso-alpha detect SCAN --structure planes`
(and `--structure lines` where the scan has line labels) with NO other flag,
against CGAL's Efficient RANSAC, CGAL's region growing and an Open3D
`segment_plane` loop, in the same run, on the prepared corpus
(scripts/corpus/README.md; build it first with scripts/corpus/prepare.py).

    python3 scripts/bench_corpus.py --bin PATH [--split train|heldout|all] [--peers]
        [--jobs N] [--repeat N] [--scans a,b] [--kinds depth,airborne] [--set core|sweep|all]
        [--json out.json] [--md out.md]

The train and held-out halves are reported in separate tables, never mixed.

Scores per scan (as scripts/bench_real.py and tests/real_scans.rs):
* planes: per-point precision / recall / F1 of "in a plane" against the
  `plane` truth column; the labelled planes of >= 1,000 points found as one
  part (one part holds at least half of the plane's points, and at least
  half of that part's points are the plane's); the number of parts;
* lines (scans whose manifest `scores` has "lines"): the same per-point
  scores of "in a line" against the `line` column, from `--structure lines`;
* classes (airborne tiles): per mapped class, the share of its points that
  a method puts in a plane (recall for ground, roofs by facing, walls; a
  false-positive rate for vegetation and other);
* wall time (the process, reading included) and peak memory (max RSS of
  the process, from /usr/bin/time -v), with their ratios to the best
  Efficient RANSAC preset's; with --repeat N, aniso-alpha's and that
  preset's wall times are the medians of N runs each, taken alternately.

Peers get presets, not one setting: epsilon (CGAL) and distance (Open3D)
at 1, 2 and 3 times the scan's `noise` (manifest), and CGAL's own defaults
for Efficient RANSAC; the table shows each peer's best preset by plane F1
on the truth (an upper bound for the peers, said in the table). CGAL's
cluster epsilon is 3 times the scan's median nearest-neighbour spacing;
min points 100. The CGAL peers estimate PCA normals over 12 neighbours,
except on scans whose source file has normals (CGAL's scans), where they
take the file's (`--k 0`) as aniso-alpha does. The Open3D peer runs in
its own Python process (its time and memory include importing open3d).

Needs: numpy, scipy; open3d for the Open3D peer; the CGAL peer built from
scripts/peers/cgal_shapes.cpp (build line in BENCHMARKS.md) at --peer;
/usr/bin/time (Debian `time`).
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "corpus"))
from common import load_manifest, prepared_path, read_ply, write_results  # noqa: E402

sys.path.insert(1, os.path.dirname(os.path.abspath(__file__)))
from bench_real import score  # noqa: E402  (the scores of every plane benchmark)

RANSAC = "CGAL Efficient RANSAC"
REGION = "CGAL region growing"
OPEN3D = "Open3D segment_plane loop"
OURS = "aniso-alpha (no flag)"


def timed(cmd, env=None):
    """Runs cmd under /usr/bin/time -v: (wall seconds, max RSS in MiB, stdout)."""
    with tempfile.NamedTemporaryFile("r", suffix=".time") as tf:
        t = time.perf_counter()
        r = subprocess.run(["/usr/bin/time", "-v", "-o", tf.name, *cmd], capture_output=True, text=True, env=env)
        wall = time.perf_counter() - t
        if r.returncode != 0:
            raise RuntimeError(f"{' '.join(cmd)}: exit {r.returncode}: {r.stderr.strip()[-500:]}")
        rss = 0.0
        for line in tf.read().splitlines():
            if "Maximum resident set size" in line:
                rss = int(line.split(":")[1]) / 1024
    return wall, rss, r.stdout


def class_recall(cls, pred, names):
    out = {}
    for k, name in names.items():
        m = cls == int(k)
        if m.sum():
            out[name] = {"points": int(m.sum()), "in_plane": round(float(np.mean(pred[m] >= 0)), 4)}
    return out


def spacing(xyz):
    from scipy.spatial import cKDTree

    sample = xyz[:: max(1, len(xyz) // 20000)]
    d, _ = cKDTree(xyz).query(sample, k=2)
    return float(np.median(d[:, 1]))


OPEN3D_WORKER = r"""
import sys, numpy as np, open3d as o3d
pts = np.loadtxt(sys.argv[1], usecols=(0, 1, 2)); dist = float(sys.argv[2]); minp = int(sys.argv[3])
o3d.utility.random.seed(1)
rest = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(pts)); idx = np.arange(len(pts))
lab = -np.ones(len(pts), np.int64); k = 0
while k < 60 and len(idx) >= minp:
    _, inl = rest.segment_plane(distance_threshold=dist, ransac_n=3, num_iterations=1000)
    if len(inl) < minp:
        break
    lab[idx[inl]] = k; k += 1
    keep = np.ones(len(idx), bool); keep[inl] = False; idx = idx[keep]
    rest = rest.select_by_index(inl, invert=True)
np.savetxt(sys.argv[4], lab, fmt="%d")
"""


def presets(scan, sp):
    noise = scan["noise"]
    ceps = round(3 * sp, 6)
    eps = [round(f * noise, 6) for f in (1, 2, 3)]
    return {
        "ransac": [{}] + [{"epsilon": e, "cluster-epsilon": ceps, "min-points": 100} for e in eps],
        "region": [{"epsilon": e, "min-points": 100} for e in eps],
        "open3d": [{"distance": e, "min_points": 100} for e in eps],
    }


def bench_scan(scan, a, have_cgal, have_o3d):
    v = read_ply(prepared_path(scan))
    xyz = np.stack([v["x"], v["y"], v["z"]], axis=1)
    plane, line, cls = v["plane"].astype(np.int64), v["line"].astype(np.int64), v["cls"].astype(np.int64)
    res = {"scan": scan["name"], "kind": scan["kind"], "split": scan["split"], "points": int(len(xyz)),
           "simulated": bool(scan.get("simulated")), "normals": "nx" in v.dtype.names, "methods": {}}
    ply = prepared_path(scan)
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "labels.txt")
        do_planes = "planes" in scan["scores"]
        if do_planes:
            ours_cmd = [a.bin, "detect", ply, "--structure", "planes", "--part-labels", out, "--quiet"]
            wall, rss, _ = timed(ours_cmd)
            pred = np.loadtxt(out, dtype=np.int64)
            m = {"wall_s": round(wall, 3), "rss_mib": round(rss, 1), "planes": score(plane, pred, digits=4)}
            if "classes" in scan["scores"]:
                m["classes"] = class_recall(cls, pred, scan["classes"])
            res["methods"][OURS] = m
        if "lines" in scan["scores"]:
            wall, rss, _ = timed([a.bin, "detect", ply, "--structure", "lines", "--part-labels", out, "--quiet"])
            pred = np.loadtxt(out, dtype=np.int64)
            res["methods"].setdefault(OURS, {})["lines"] = {"wall_s": round(wall, 3), "rss_mib": round(rss, 1),
                                                            **score(line, pred, min_true=10 ** 9, digits=4)}
        if not (a.peers and do_planes):
            return res
        sp = spacing(xyz)
        res["spacing"] = round(sp, 6)
        file_normals = scan["reader"] == "cgal"
        xyzf = os.path.join(tmp, "points.xyz")
        cols = xyz if not file_normals else np.c_[xyz, np.stack([v["nx"], v["ny"], v["nz"]], axis=1)]
        np.savetxt(xyzf, cols, fmt="%.4f" if np.abs(xyz).max() > 1e4 else "%.6f")
        runs = []
        if have_cgal:
            for mode, name in (("ransac", RANSAC), ("region", REGION)):
                for p in presets(scan, sp)[mode]:
                    args = [a.peer, mode, xyzf, out]
                    for k, val in {**p, **({"k": 0} if file_normals else {})}.items():
                        args += ["--" + k, str(val)]
                    wall, rss, _ = timed(args)
                    runs.append((name, p, wall, rss, np.loadtxt(out, dtype=np.int64), args))
        if have_o3d:
            worker = os.path.join(tmp, "o3d_worker.py")
            with open(worker, "w") as f:
                f.write(OPEN3D_WORKER)
            for p in presets(scan, sp)["open3d"]:
                cmd = [sys.executable, worker, xyzf, str(p["distance"]), str(p["min_points"]), out]
                wall, rss, _ = timed(cmd)
                runs.append((OPEN3D, p, wall, rss, np.loadtxt(out, dtype=np.int64), cmd))
        best_cmd = {}
        for name, p, wall, rss, pred, cmd in runs:
            s = score(plane, pred, digits=4)
            best = res["methods"].get(name)
            entry = {"wall_s": round(wall, 3), "rss_mib": round(rss, 1), "planes": s,
                     "preset": p or "CGAL defaults", "presets_tried": (best or {}).get("presets_tried", 0) + 1}
            if "classes" in scan["scores"]:
                entry["classes"] = class_recall(cls, pred, scan["classes"])
            if best is None or s["f1"] > best["planes"]["f1"]:
                res["methods"][name] = entry
                best_cmd[name] = cmd
            else:
                best["presets_tried"] = entry["presets_tried"]
        base = res["methods"].get(RANSAC)
        if base and do_planes and a.repeat > 1:
            repeat_timing(res["methods"][OURS], ours_cmd, base, best_cmd[RANSAC], a.repeat)
        if base:
            for m in res["methods"].values():
                if "planes" in m:
                    m["wall_ratio"] = round(m["wall_s"] / max(base["wall_s"], 1e-9), 2)
                    m["rss_ratio"] = round(m["rss_mib"] / max(base["rss_mib"], 1e-9), 2)
    return res


def repeat_timing(ours, ours_cmd, ransac, ransac_cmd, n):
    """Times aniso-alpha's planes run and RANSAC's best preset n times in
    all, alternately (the first run of each is the one already made), and
    keeps the median wall time of each: a single run of a one-second scan
    moves by a third either way."""
    walls = {"ours": [ours["wall_s"]], "ransac": [ransac["wall_s"]]}
    for _ in range(n - 1):
        walls["ours"].append(timed(ours_cmd)[0])
        walls["ransac"].append(timed(ransac_cmd)[0])
    for m, k in ((ours, "ours"), (ransac, "ransac")):
        m["wall_s"] = round(float(np.median(walls[k])), 3)
        m["wall_runs"] = n


def fmt_table(rows, split):
    lines = [f"### {split}", "",
             "| scan | kind | points | method | P | R | F1 | planes >= 1k found | parts | wall s | / RANSAC | RSS MiB | / RANSAC | preset |",
             "|---|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|"]
    for r in rows:
        sim = " (sim)" if r["simulated"] else ""
        for name, m in r["methods"].items():
            if "planes" in m:
                s = m["planes"]
                preset = m.get("preset", "")
                preset = json.dumps(preset) if isinstance(preset, dict) else preset
                lines.append(f"| {r['scan']} | {r['kind']}{sim} | {r['points']} | {name} | {s['precision']:.3f} | "
                             f"{s['recall']:.3f} | **{s['f1']:.3f}** | {s['found']}/{s['big']} | {s['parts']} | "
                             f"{m['wall_s']:.2f} | {m.get('wall_ratio', '')} | {m['rss_mib']:.0f} | "
                             f"{m.get('rss_ratio', '')} | {preset} |")
    lines.append("")
    lr = [(r, r["methods"][OURS]["lines"]) for r in rows if OURS in r["methods"] and "lines" in r["methods"][OURS]]
    if lr:
        lines += ["| scan | kind | points | lines: P | R | F1 | parts | wall s | RSS MiB |", "|---|---|---:|---:|---:|---:|---:|---:|---:|"]
        for r, s in lr:
            lines.append(f"| {r['scan']} | {r['kind']}{' (sim)' if r['simulated'] else ''} | {r['points']} | "
                         f"{s['precision']:.3f} | {s['recall']:.3f} | **{s['f1']:.3f}** | {s['parts']} | {s['wall_s']:.2f} | "
                         f"{s['rss_mib']:.0f} |")
        lines.append("")
    cr = [r for r in rows if any("classes" in m for m in r["methods"].values())]
    for r in cr:
        names = list(next(m["classes"] for m in r["methods"].values() if "classes" in m))
        lines += [f"Per-class share in a plane, {r['scan']} (recall for ground, roofs, walls; false positives for "
                  "other and vegetation):", "",
                  "| method | " + " | ".join(names) + " |", "|---|" + "---:|" * len(names)]
        for name, m in r["methods"].items():
            if "classes" in m:
                lines.append(f"| {name} | " + " | ".join(f"{m['classes'][n]['in_plane']:.2f} ({m['classes'][n]['points']})"
                                                       if n in m["classes"] else "" for n in names) + " |")
        lines.append("")
    return lines


def summary(by_split):
    """Means per method and split, the halves side by side."""
    methods = [OURS, RANSAC, REGION, OPEN3D]
    lines = ["| method | train: mean plane F1 | train: planes found | train: scans | held-out: mean plane F1 | "
             "held-out: planes found | held-out: scans |", "|---|---:|---:|---:|---:|---:|---:|"]
    for name in methods:
        cells = []
        for split in ("train", "heldout"):
            ms = [r["methods"][name] for r in by_split.get(split, []) if name in r["methods"] and "planes" in r["methods"][name]]
            if not ms:
                cells += ["", "", ""]
                continue
            cells += [f"{np.mean([m['planes']['f1'] for m in ms]):.3f}",
                      f"{sum(m['planes']['found'] for m in ms)}/{sum(m['planes']['big'] for m in ms)}", str(len(ms))]
        if any(cells):
            lines.append(f"| {name} | " + " | ".join(cells) + " |")
    return lines + [""]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin", required=True, help="the aniso-alpha binary")
    ap.add_argument("--split", default="train", choices=["train", "heldout", "all"])
    ap.add_argument("--peers", action="store_true", help="run CGAL's and Open3D's detectors too")
    ap.add_argument("--peer", default="/work/peers-bin/cgal_shapes", help="the CGAL peer binary")
    ap.add_argument("--jobs", type=int, default=1, help="scans at once (timings are only comparable at 1)")
    ap.add_argument("--repeat", type=int, default=1,
                    help="with --peers: time aniso-alpha (planes) and RANSAC's best preset this many times each, "
                         "alternately, and report the medians (the other peers: one run)")
    ap.add_argument("--scans", default="", help="comma-separated scan names")
    ap.add_argument("--kinds", default="", help="comma-separated kinds")
    ap.add_argument("--set", default="core", choices=["core", "sweep", "all"],
                    help="core: the corpus of the tables (default); sweep: the other mOSD frames of the "
                         "boxes, stacked boxes and cylindric categories (manifest `sweep`); all: both")
    ap.add_argument("--json", help="write every figure here")
    ap.add_argument("--md", help="write the tables here too")
    a = ap.parse_args()
    man = load_manifest()
    scans = [s for s in man["scans"] if a.split == "all" or s["split"] == a.split]
    if a.set != "all":
        scans = [s for s in scans if bool(s.get("sweep")) == (a.set == "sweep")]
    if a.scans:
        scans = [s for s in scans if s["name"] in a.scans.split(",")]
    if a.kinds:
        scans = [s for s in scans if s["kind"] in a.kinds.split(",")]
    missing = [s["name"] for s in scans if not os.path.exists(prepared_path(s))]
    if missing:
        sys.exit(f"not prepared: {', '.join(missing)} (python3 scripts/corpus/prepare.py)")
    have_cgal = have_o3d = False
    if a.peers:
        have_cgal = os.access(a.peer, os.X_OK)
        try:
            import open3d  # noqa: F401
            have_o3d = True
        except ImportError:
            pass
        if not (have_cgal and have_o3d):
            sys.exit(f"--peers needs {a.peer} and open3d (cgal: {have_cgal}, open3d: {have_o3d})")
    t0 = time.perf_counter()

    def one(scan):
        r = bench_scan(scan, a, have_cgal, have_o3d)
        print(f"{scan['name']}: " + ", ".join(f"{k} F1 {m['planes']['f1']:.3f}" for k, m in r["methods"].items()
                                              if "planes" in m), file=sys.stderr, flush=True)
        return r

    with ThreadPoolExecutor(max_workers=max(1, a.jobs)) as ex:
        rows = list(ex.map(one, scans))
    by_split = {}
    for r in rows:
        by_split.setdefault(r["split"], []).append(r)
    out = [f"aniso-alpha: `{a.bin}`; {len(rows)} scans; peers: {'yes (best preset of each by plane F1 on the truth)' if a.peers else 'no'}; "
           f"jobs {a.jobs}; wall times of aniso-alpha and RANSAC: median of {a.repeat} run(s) each; "
           f"{time.perf_counter() - t0:.0f} s in all", ""]
    out += summary(by_split)
    for split in ("train", "heldout"):
        if split in by_split:
            out += fmt_table(by_split[split], split)
    write_results("\n".join(out), a.md, a.json, {"bin": a.bin, "peers": a.peers, "jobs": a.jobs, "repeat": a.repeat, "scans": rows})


if __name__ == "__main__":
    main()
