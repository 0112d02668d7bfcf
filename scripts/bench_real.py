#!/usr/bin/env python3
"""Plane detection on real scans: aniso-alpha's automatic mode against
CGAL's Efficient RANSAC, CGAL's region growing and an Open3D
`segment_plane` loop, in one run, on the same files (issue: real scans).

    python3 scripts/bench_real.py [--repeat 3] [--bin target/release/aniso-alpha]
        [--peer /work/peers-bin/cgal_shapes] [--scans building,ball] [--sim room,house]

Needs: numpy; open3d for the Open3D peer (skipped without it); the CGAL
peer built from scripts/peers/cgal_shapes.cpp (skipped without it; see the
build line in BENCHMARKS.md). Scans: the labelled fixtures in
crates/aniso-alpha/tests/fixtures/real/ (binary PLY, x y z label).

Scores, as tests/real_scans.rs: per-point precision / recall / F1 of
"in a plane" against the labels, and the labelled planes of >= 1,000
points found (one part holds at least half of the plane's points, and at
least half of that part's points are the plane's). Times: the wall time of
each process (reading included), median of the repeats, and the ratio to
Efficient RANSAC's wall time in the same run.

aniso-alpha runs with no parameter at all. The peers get parameters: the
CGAL defaults where they do well, and where they do not, values tuned by
hand on that scan (listed in PEER_PARAMS; an advantage to the peers).

CGAL's two scans carry the normals of their source files (`nx ny nz`):
aniso-alpha reads them as `detect SCAN` does (and runs again with
`--ignore-normals`), and the CGAL peers use them too (`cgal_shapes --k 0`)
instead of estimating PCA normals.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FIXTURES = os.path.join(ROOT, "crates/aniso-alpha/tests/fixtures/real")

# Hand-tuned on each scan (a sweep of epsilon 0.05-0.5 and cluster epsilon
# 0.2-2 for the building); the ball keeps CGAL's defaults.
PEER_PARAMS = {
    "building": {"ransac": {"epsilon": 0.3, "cluster-epsilon": 1.0, "min-points": 200},
                 "region": {"epsilon": 0.3, "min-points": 200},
                 "open3d": {"distance": 0.3, "min_points": 200}},
    "ball": {"ransac": {}, "region": {},
             "open3d": {"distance": 0.05, "min_points": 200}},
    # Simulated scans (scripts/simulate_scan.py, `--sim`): epsilon three
    # times the range noise (3 mm room, 1 cm house), cluster epsilon a few
    # voxels.
    "room": {"ransac": {"epsilon": 0.01, "cluster-epsilon": 0.1, "min-points": 200},
             "region": {"epsilon": 0.01, "min-points": 200},
             "open3d": {"distance": 0.01, "min_points": 200}},
    "house": {"ransac": {"epsilon": 0.03, "cluster-epsilon": 0.25, "min-points": 100},
              "region": {"epsilon": 0.03, "min-points": 100},
              "open3d": {"distance": 0.03, "min_points": 100}},
}

# Voxel side (m) to which each simulated scan is thinned: the simulator's
# 0.1-0.2 degree rays give millions of points, mostly next to the
# stations; one point per voxel keeps a few hundred thousand.
SIM_VOXEL = {"room": 0.03, "house": 0.08}


def simulated(name, tmp, seed=1):
    """`simulate_scan.py NAME --seed SEED`, one point per voxel: (points, labels, path)."""
    raw = os.path.join(tmp, name + ".raw.xyz")
    subprocess.run([sys.executable, os.path.join(ROOT, "scripts/simulate_scan.py"), name,
                    "--seed", str(seed), "--output", raw], check=True, capture_output=True)
    a = np.loadtxt(raw)
    _, idx = np.unique(np.floor(a[:, :3] / SIM_VOXEL[name]).astype(np.int64), axis=0, return_index=True)
    a = a[np.sort(idx)]
    path = os.path.join(tmp, name + ".xyz")
    np.savetxt(path, a[:, :3], fmt="%.5f")
    return a[:, :3], a[:, 3].astype(np.int64), path


def read_ply(path, normals=False):
    """A fixture: (points, labels), or (points, labels, normals or None)."""
    with open(path, "rb") as f:
        data = f.read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode()
    n = int(header.split("element vertex ")[1].split()[0])
    types = {"float": "<f4", "double": "<f8", "int": "<i4"}
    fields = [(line.split()[2], types[line.split()[1]]) for line in header.splitlines()
              if line.startswith("property ")]
    rec = np.frombuffer(data[end:], dtype=fields, count=n)
    xyz = np.stack([rec["x"], rec["y"], rec["z"]], axis=1).astype(np.float64)
    labels = rec["label"].astype(np.int64)
    if not normals:
        return xyz, labels
    nrm = None
    if "nx" in rec.dtype.names:
        nrm = np.stack([rec["nx"], rec["ny"], rec["nz"]], axis=1).astype(np.float64)
    return xyz, labels, nrm


def score(truth, pred, min_true=1000, digits=3):
    """Per-point precision, recall and F1 of "in a plane" (rounded to
    `digits`), the labelled planes of at least `min_true` points that one
    part holds at least half of (and at least half of that part is theirs),
    their number, and the parts."""
    tp = np.sum((truth >= 0) & (pred >= 0))
    fp = np.sum((truth < 0) & (pred >= 0))
    fn = np.sum((truth >= 0) & (pred < 0))
    p = tp / max(tp + fp, 1)
    r = tp / max(tp + fn, 1)
    f1 = 2 * p * r / max(p + r, 1e-12)
    found = big = 0
    for t, c in zip(*np.unique(truth[truth >= 0], return_counts=True)):
        if c < min_true:
            continue
        big += 1
        m = truth == t
        ps, cs = np.unique(pred[m & (pred >= 0)], return_counts=True)
        if len(ps):
            j = np.argmax(cs)
            if 2 * cs[j] >= c and 2 * cs[j] > np.sum(pred == ps[j]):
                found += 1
    parts = len(np.unique(pred[pred >= 0]))
    return dict(precision=round(float(p), digits), recall=round(float(r), digits), f1=round(float(f1), digits),
                found=found, big=big, parts=int(parts))


def run_ours(binary, ply, out, extra=()):
    t = time.perf_counter()
    subprocess.run([binary, "detect", ply, "--structure", "planes", "--part-labels", out, "--quiet", *extra],
                   check=True, capture_output=True)
    return time.perf_counter() - t, np.loadtxt(out, dtype=np.int64)


def run_cgal(peer, mode, xyz, out, params):
    args = [peer, mode, xyz, out]
    for k, v in params.items():
        args += ["--" + k, str(v)]
    t = time.perf_counter()
    r = subprocess.run(args, check=True, capture_output=True, text=True)
    wall = time.perf_counter() - t
    info = json.loads(r.stdout.strip().splitlines()[-1])
    return wall, np.loadtxt(out, dtype=np.int64), info


def run_open3d(pts, distance, min_points, max_planes=60):
    import open3d as o3d
    t = time.perf_counter()
    rest = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(pts))
    idx = np.arange(len(pts))
    lab = -np.ones(len(pts), np.int64)
    k = 0
    while k < max_planes and len(idx) >= min_points:
        _, inl = rest.segment_plane(distance_threshold=distance, ransac_n=3, num_iterations=1000)
        if len(inl) < min_points:
            break
        lab[idx[inl]] = k
        k += 1
        keep = np.ones(len(idx), bool)
        keep[inl] = False
        idx = idx[keep]
        rest = rest.select_by_index(inl, invert=True)
    return time.perf_counter() - t, lab


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--bin", default=os.path.join(ROOT, "target/release/aniso-alpha"))
    ap.add_argument("--peer", default="/work/peers-bin/cgal_shapes")
    ap.add_argument("--scans", default="building,ball")
    ap.add_argument("--sim", default="", help="simulated scans too, e.g. room,house (needs open3d)")
    a = ap.parse_args()
    try:
        import open3d  # noqa: F401
        have_o3d = True
    except ImportError:
        have_o3d = False
        print("(open3d not importable: its peer is skipped)", file=sys.stderr)
    have_cgal = os.access(a.peer, os.X_OK)
    if not have_cgal:
        print(f"({a.peer} not found: the CGAL peers are skipped)", file=sys.stderr)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        scans = [n for n in a.scans.split(",") if n] + [n for n in a.sim.split(",") if n]
        for name in scans:
            if name in SIM_VOXEL:
                pts, truth, xyz = simulated(name, tmp)
                ply = xyz
                normals = None
            else:
                ply = os.path.join(FIXTURES, name + ".ply")
                pts, truth, normals = read_ply(ply, normals=True)
                xyz = os.path.join(tmp, name + ".xyz")
                np.savetxt(xyz, pts if normals is None else np.c_[pts, normals], fmt="%.6f")
            out = os.path.join(tmp, name + ".labels")
            runs = {}
            # A scan with normals: aniso-alpha reads them (as `detect
            # SCAN` does), and also runs without them; the CGAL peers use
            # them (`--k 0`) instead of PCA normals, as CGAL's examples do
            # with a scan that has normals.
            ours = [("aniso-alpha (auto)", ())]
            peer_normals = {}
            if normals is not None:
                ours = [("aniso-alpha (auto, the scan's normals)", ()),
                        ("aniso-alpha (auto, --ignore-normals)", ("--ignore-normals",))]
                peer_normals = {"k": 0}
            for _ in range(a.repeat):
                for label, extra in ours:
                    w, lab = run_ours(a.bin, ply, out, extra)
                    runs.setdefault(label, []).append((w, lab, None))
                if have_cgal:
                    for mode in ("ransac", "region"):
                        w, lab, info = run_cgal(a.peer, mode, xyz, out, {**PEER_PARAMS[name][mode], **peer_normals})
                        runs.setdefault("CGAL " + ("Efficient RANSAC" if mode == "ransac" else "region growing"),
                                        []).append((w, lab, info))
                if have_o3d:
                    p = PEER_PARAMS[name]["open3d"]
                    w, lab = run_open3d(pts, p["distance"], p["min_points"])
                    runs.setdefault("Open3D segment_plane loop", []).append((w, lab, None))
            base = statistics.median(w for w, _, _ in runs.get("CGAL Efficient RANSAC", [(float("nan"), 0, 0)]))
            for peer, rs in runs.items():
                wall = statistics.median(w for w, _, _ in rs)
                s = score(truth, rs[-1][1])
                inproc = ""
                if rs[-1][2]:
                    inproc = "%.2f" % statistics.median(r[2]["normals_seconds"] + r[2]["detect_seconds"] for r in rs)
                rows.append((name, len(pts), peer, wall, wall / base, inproc, s))
    print("| scan | points | method | wall s (median of %d) | / RANSAC wall | in-process s | planes found (>= 1k) | parts | P | R | F1 |" % a.repeat)
    print("|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    for name, n, peer, wall, ratio, inproc, s in rows:
        print(f"| {name} | {n} | {peer} | {wall:.2f} | {ratio:.1f}x | {inproc} | {s['found']}/{s['big']} | {s['parts']} "
              f"| {s['precision']} | {s['recall']} | {s['f1']} |")


if __name__ == "__main__":
    main()
