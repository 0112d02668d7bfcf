#!/usr/bin/env python3
"""Issue 14's robustness table: mean per-point F1 of aniso-alpha against the
Euclidean alpha-shape and RANSAC baselines, on synthetic scenes made like
the paper's Figs. 12 (lines), 5 (planes) and 10 (polyhedron), under jitter,
random sampling and denser backgrounds.

    python3 scripts/eval_robustness.py                    # full table, 3 seeds
    python3 scripts/eval_robustness.py --seeds 11 12 --variants base bg10
    python3 scripts/eval_robustness.py --methods ours     # only this project

Needs: Python >= 3.9, numpy and scipy (lines RANSAC), open3d (planes
RANSAC: `pip install numpy scipy open3d`); a release build of the CLI
(`cargo build --release -p aniso-alpha-cli`, or --bin PATH). A method
whose module is missing is reported as n/a.

For each variant x kind x seed the script runs `aniso-alpha synth KIND
--seed S [variant options]`, then

* **ours**: `aniso-alpha detect` with the paper's parameters (lines:
  alpha 1, lambda3 10, min-size 4; planes and polyhedron: alpha 1,
  lambda2 4, lambda3 8, min-size 20; box sampler) and the significance
  test at its default epsilon 1;
* **euclid**: the same pipeline with lambda = 1 (E = (1, 1, 1), the
  paper's own comparison, one orientation: a Euclidean alpha-shape is the
  same in every orientation), the paper's min-size, no significance test
  (the paper's method), at its best alpha: the alpha of a small grid
  whose mean F1 over the seeds is highest (chosen on the ground truth:
  an upper bound for the baseline);
* **ransac**: sequential RANSAC. Planes: Open3D's `segment_plane`
  (threshold alpha = 1, 3-point samples, 20,000 iterations) in a loop,
  each plane's inliers cut to their largest DBSCAN cluster (eps =
  alpha*lambda2 = 4, the reach of the paper's ellipsoid in the plane),
  kept when it has >= 10 points (the detector's smallest part), at most
  12 planes. Lines: every pair of a point and one of its 6 nearest
  neighbours is a hypothesis (local sampling: uniform pairs never hit a
  10-point line among 15,000 points), scored by the points within
  alpha = 1 of the line inside the ball of radius 2*alpha*lambda3 = 20
  around the point; best first, each line takes the unclaimed points
  within 1 of it, cut to the run around its seed with gaps <= 20, kept
  when >= 5 points (nb_c + 1).

and scores each labelling with `aniso-alpha eval --json` (per-point F1 of
structure against background, docs/method.md §6). The table is printed as
Markdown; --json also writes every run.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

VARIANTS = {
    "base": [],
    "jitter 0.05 d": ["--jitter-d", "0.05"],
    "jitter 0.1 d": ["--jitter-d", "0.1"],
    "random sampling": ["--random-sampling"],
    "3x background": ["--density", "0.03"],
    "10x background": ["--density", "0.1"],
    "crossing": ["--crossing"],
}
# Short names for --variants.
SHORT = {
    "base": "base",
    "jitter05": "jitter 0.05 d",
    "jitter10": "jitter 0.1 d",
    "random": "random sampling",
    "bg3": "3x background",
    "bg10": "10x background",
    "crossing": "crossing",
}
KINDS = ["lines", "planes", "polyhedron"]
PAPER = {
    "lines": ["--structure", "lines", "--alpha", "1", "--lambda3", "10", "--min-size", "4"],
    "planes": ["--structure", "planes", "--alpha", "1", "--lambda2", "4", "--lambda3", "8",
               "--min-size", "20"],
}
# Euclidean alpha grids: lines need alpha >= d/2 = 3.5 to join points
# spaced d = 7; plane grids (h = 3) need about h/sqrt(2) = 2.1.
EUCLID_ALPHAS = {"lines": [3.0, 3.5, 4.0, 5.0, 6.0, 8.0], "planes": [1.5, 2.0, 2.5, 3.0, 4.0, 5.0]}


def structure_of(kind):
    return "lines" if kind == "lines" else "planes"


def run(cmd):
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)}: {r.stderr.strip()}")
    return r.stdout


def variant_args(variant, kind):
    a = list(VARIANTS[variant])
    if variant == "crossing":
        if kind == "polyhedron":
            return None  # one polyhedron per scene
        if kind == "planes":
            a = ["--structures", "2", "--crossing"]
    return a


def evaluate(bin_, scene, labels):
    out = run([bin_, "eval", "--truth", scene, "--labels", labels, "--json"])
    return json.loads(out)


def read_scene(path):
    import numpy as np

    data = np.loadtxt(path)
    return data[:, :3], data[:, 3].astype(int)


def write_labels(path, labels):
    with open(path, "w") as f:
        f.write("".join(f"{int(l)}\n" for l in labels))


def ransac_planes(points):
    import numpy as np
    import open3d as o3d

    labels = -np.ones(len(points), dtype=int)
    remaining = np.arange(len(points))
    for pid in range(12):
        if len(remaining) < 10:
            break
        pc = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(points[remaining]))
        o3d.utility.random.seed(pid + 1)
        _, inl = pc.segment_plane(distance_threshold=1.0, ransac_n=3, num_iterations=20000)
        inl = np.asarray(inl, dtype=int)
        if len(inl) < 10:
            break
        sub = pc.select_by_index(inl.tolist())
        cl = np.asarray(sub.cluster_dbscan(eps=4.0, min_points=3))
        if cl.size == 0 or cl.max() < 0:
            break
        best = np.bincount(cl[cl >= 0]).argmax()
        keep = inl[cl == best]
        if len(keep) < 10:
            # The best plane is chance: stop, as a user's loop would.
            break
        labels[remaining[keep]] = pid
        remaining = np.delete(remaining, keep)
    return labels


def ransac_lines(points, tau=1.0, reach=20.0, k=6, min_pts=5):
    import numpy as np
    from scipy.spatial import cKDTree

    n = len(points)
    tree = cKDTree(points)
    _, nn = tree.query(points, k=k + 1)
    balls = tree.query_ball_point(points, reach)
    hyp = []  # (score, i, j)
    for i in range(n):
        ball = np.asarray(balls[i])
        w = points[ball] - points[i]
        for j in nn[i, 1:]:
            u = points[j] - points[i]
            nu = np.linalg.norm(u)
            if nu == 0:
                continue
            u = u / nu
            t = w @ u
            d2 = np.einsum("ij,ij->i", w, w) - t * t
            hyp.append((int((d2 <= tau * tau).sum()), i, int(j)))
    hyp.sort(key=lambda h: (-h[0], h[1], h[2]))
    labels = -np.ones(n, dtype=int)
    lid = 0
    for score, i, j in hyp:
        if score < min_pts:
            break
        if labels[i] >= 0 or labels[j] >= 0:
            continue
        u = points[j] - points[i]
        u = u / np.linalg.norm(u)
        w = points - points[i]
        t = w @ u
        d2 = np.einsum("ij,ij->i", w, w) - t * t
        cand = np.where((d2 <= tau * tau) & (labels < 0))[0]
        order = cand[np.argsort(t[cand])]
        ts = t[order]
        # The run around the seed with gaps <= reach.
        pos = int(np.searchsorted(ts, 0.0))
        pos = min(max(pos, 0), len(ts) - 1)
        lo = hi = pos
        while lo > 0 and ts[lo] - ts[lo - 1] <= reach:
            lo -= 1
        while hi + 1 < len(ts) and ts[hi + 1] - ts[hi] <= reach:
            hi += 1
        run_ = order[lo : hi + 1]
        if len(run_) >= min_pts:
            labels[run_] = lid
            lid += 1
    return labels


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin", default=os.path.join(ROOT, "target", "release", "aniso-alpha"))
    ap.add_argument("--seeds", type=int, nargs="+", default=[101, 102, 103])
    ap.add_argument("--variants", nargs="+", default=list(SHORT), choices=list(SHORT))
    ap.add_argument("--kinds", nargs="+", default=KINDS, choices=KINDS)
    ap.add_argument("--methods", nargs="+", default=["ours", "euclid", "ransac"],
                    choices=["ours", "euclid", "ransac"])
    ap.add_argument("--json", help="write every run's scores here")
    args = ap.parse_args()
    if not os.path.exists(args.bin):
        sys.exit(f"{args.bin} not found: cargo build --release -p aniso-alpha-cli")
    rows = []
    tmp = tempfile.mkdtemp(prefix="aniso_robust_")
    for vshort in args.variants:
        variant = SHORT[vshort]
        for kind in args.kinds:
            va = variant_args(variant, kind)
            if va is None:
                continue
            res = {m: [] for m in args.methods}
            euclid = {a: [] for a in EUCLID_ALPHAS[structure_of(kind)]}
            secs = []
            for seed in args.seeds:
                scene = os.path.join(tmp, f"{kind}_{vshort}_{seed}.xyz")
                run([args.bin, "synth", kind, "--seed", str(seed), "--output", scene, "--quiet"]
                    + va)
                lab = os.path.join(tmp, "labels.txt")
                if "ours" in args.methods:
                    t0 = time.perf_counter()
                    run([args.bin, "detect", scene, "--labels", lab, "--quiet"]
                        + PAPER[structure_of(kind)])
                    secs.append(time.perf_counter() - t0)
                    res["ours"].append(evaluate(args.bin, scene, lab))
                if "euclid" in args.methods:
                    nbc = PAPER[structure_of(kind)][-1]
                    for a in euclid:
                        run([args.bin, "detect", scene, "--labels", lab, "--quiet",
                             "--structure", structure_of(kind), "--alpha", str(a),
                             "--lambda2", "1", "--lambda3", "1", "--min-size", nbc,
                             "--no-significance", "--sampler", "fibonacci", "--step", "90"])
                        euclid[a].append(evaluate(args.bin, scene, lab))
                if "ransac" in args.methods:
                    try:
                        pts, _ = read_scene(scene)
                        lbl = ransac_lines(pts) if kind == "lines" else ransac_planes(pts)
                        write_labels(lab, lbl)
                        res["ransac"].append(evaluate(args.bin, scene, lab))
                    except ImportError as e:
                        res["ransac"].append({"error": str(e)})
            if "euclid" in args.methods:
                best = max(euclid, key=lambda a: sum(e["f1"] for e in euclid[a]))
                res["euclid"] = euclid[best]
                res["euclid_alpha"] = best
            rows.append({"variant": variant, "kind": kind, "res": res, "secs": secs})
            line = f"{variant:16s} {kind:10s}"
            for m in args.methods:
                f1 = [e.get("f1") for e in res[m]]
                line += f" {m} " + (" ".join(f"{x:.3f}" if x is not None else "n/a" for x in f1))
            print(line, file=sys.stderr, flush=True)
    # Markdown table.
    def mean(xs):
        xs = [x for x in xs if x is not None]
        return sum(xs) / len(xs) if xs else None

    def fmt(x):
        return "n/a" if x is None else f"{x:.2f}"

    head = "| variant | kind | " + " | ".join(
        {"ours": "aniso-alpha F1 (min, precision, recall)", "euclid": "Euclidean α-shape F1 (α)",
         "ransac": "RANSAC F1"}[m] for m in args.methods) + " |"
    print(head)
    print("|---|---|" + "---:|" * len(args.methods))
    for r in rows:
        cells = []
        for m in args.methods:
            ev = r["res"][m]
            f1 = [e.get("f1") for e in ev]
            if m == "ours":
                cells.append(f"**{fmt(mean(f1))}** ({fmt(min(f1))}, "
                             f"{fmt(mean([e['precision'] for e in ev]))}, "
                             f"{fmt(mean([e['recall'] for e in ev]))})")
            elif m == "euclid":
                cells.append(f"{fmt(mean(f1))} ({r['res']['euclid_alpha']})")
            else:
                cells.append(fmt(mean(f1)))
        print(f"| {r['variant']} | {r['kind']} | " + " | ".join(cells) + " |")
    if rows and rows[0]["secs"]:
        print(f"\nseeds {args.seeds}; ours' wall time per detect: "
              + ", ".join(f"{r['variant']}/{r['kind']} {mean(r['secs']):.2f} s" for r in rows
                          if r["secs"]))
    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=1)


if __name__ == "__main__":
    main()
