#!/usr/bin/env python3
"""Does the no-flag detector give the same answer when nothing that matters
changes? Each prepared corpus scan (scripts/corpus/README.md) is run as it
is and again after a change that leaves its geometry the same or samples it
the same way, and the plane (or line) F1 of both runs is reported side by
side.

    python3 scripts/eval_invariance.py --bin PATH [--split train|heldout|all]
        [--set core|sweep|all] [--scans a,b] [--transforms t1,t2] [--json out.json]

Transforms (fixed seeds):
* `mm`: coordinates × 1000 (metres written as millimetres);
* `km`: coordinates / 1000;
* `rotate`: a random rotation about the centroid (normals rotated too);
* `offset`: + (412,345.0, 5,412,345.0, 123.0): a projected-CRS origin;
* `shuffle`: the points in a random order (labels mapped back);
* `half`: a random half of the points (scored on that half);
* `flip`: the normals given with the points, every second one reversed
  (only on scans that carry normals);
* `o3d_knn5`, `o3d_knn10`, `o3d_knn30`, `o3d_r3`, `o3d_r20`: normals
  estimated by Open3D and given with the points, signs as Open3D leaves
  them: over the 5, 10 or 30 nearest neighbours (30: `estimate_normals()`
  without arguments), within 3 spacings (at most 30 neighbours),
  within 20 spacings (at most 300 neighbours: smoothed across edges);
  scored against the run without normals (needs open3d).

A scan is run once per transform and once as it is; the table gives the
F1 of both and the labelled planes of >= 1,000 points found as one part.
The transforms change no constant of the method: a difference is a
dependence on units, position, order or density that the method should
not have (except `half`, whose density really changes).

Needs numpy (and scipy through bench_real's helpers).
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "corpus"))
from common import load_manifest, prepared_path, read_ply, write_ply  # noqa: E402

sys.path.insert(1, HERE)
from bench_real import score  # noqa: E402

TRANSFORMS = ["mm", "km", "rotate", "offset", "shuffle", "half", "flip", "o3d_knn5", "o3d_knn10", "o3d_knn30", "o3d_r3", "o3d_r20"]


def median_spacing(xyz):
    from scipy.spatial import cKDTree

    sample = xyz[:: max(1, len(xyz) // 20000)]
    d, _ = cKDTree(xyz).query(sample, k=2)
    return float(np.median(d[:, 1]))


def open3d_normals(xyz, name):
    """Open3D's `estimate_normals` with the search the transform names."""
    import open3d as o3d

    pc = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(xyz - xyz.mean(axis=0)))
    sp = median_spacing(xyz)
    search = {
        "o3d_knn5": o3d.geometry.KDTreeSearchParamKNN(knn=5),
        "o3d_knn10": o3d.geometry.KDTreeSearchParamKNN(knn=10),
        "o3d_knn30": o3d.geometry.KDTreeSearchParamKNN(knn=30),
        "o3d_r3": o3d.geometry.KDTreeSearchParamHybrid(radius=3 * sp, max_nn=30),
        "o3d_r20": o3d.geometry.KDTreeSearchParamHybrid(radius=20 * sp, max_nn=300),
    }[name]
    pc.estimate_normals(search_param=search)
    return np.asarray(pc.normals).astype(np.float32)


def rotation(rng):
    """A uniformly random rotation (QR of a Gaussian matrix, sign-fixed)."""
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    if np.linalg.det(q) < 0:
        q[:, 0] = -q[:, 0]
    return q


def transform(name, xyz, normals, seed):
    """(points, normals, kept indices) after the named change; None when
    the change does not apply to this scan."""
    rng = np.random.default_rng(seed)
    keep = np.arange(len(xyz))
    if name == "mm":
        return xyz * 1000.0, normals, keep
    if name == "km":
        return xyz / 1000.0, normals, keep
    if name == "rotate":
        r = rotation(rng)
        c = xyz.mean(axis=0)
        n = None if normals is None else (normals @ r.T).astype(np.float32)
        return (xyz - c) @ r.T + c, n, keep
    if name == "offset":
        return xyz + np.array([412_345.0, 5_412_345.0, 123.0]), normals, keep
    if name == "shuffle":
        keep = rng.permutation(len(xyz))
    elif name == "half":
        keep = np.sort(rng.choice(len(xyz), size=len(xyz) // 2, replace=False))
    elif name == "flip":
        if normals is None:
            return None
        n = normals.copy()
        n[1::2] *= -1
        return xyz, n, keep
    elif name.startswith("o3d_"):
        return xyz, open3d_normals(xyz, name), keep
    else:
        raise ValueError(name)
    return xyz[keep], None if normals is None else normals[keep], keep


def run(binary, ply, structure, out):
    r = subprocess.run([binary, "detect", ply, "--structure", structure, "--part-labels", out, "--quiet"],
                       capture_output=True, text=True)
    if r.returncode != 0:
        return None, r.stderr.strip()[-300:]
    return np.loadtxt(out, dtype=np.int64), ""


def one_scan(scan, a):
    v = read_ply(prepared_path(scan))
    xyz = np.stack([v["x"], v["y"], v["z"]], axis=1)
    normals = np.stack([v["nx"], v["ny"], v["nz"]], axis=1) if "nx" in v.dtype.names else None
    truth = {"planes": v["plane"].astype(np.int64), "lines": v["line"].astype(np.int64)}
    kinds = [k for k in ("planes", "lines") if k in scan["scores"]]
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "labels.txt")
        base = {}
        for kind in kinds:
            pred, err = run(a.bin, prepared_path(scan), kind, out)
            base[kind] = None if pred is None else score(truth[kind], pred, min_true=1000 if kind == "planes" else 10**9, digits=4)
        if normals is not None and any(t.startswith("o3d_") for t in a.transforms):
            # the Open3D rows compare with the run on estimated normals
            ply = os.path.join(tmp, "plain.ply")
            write_ply(ply, xyz, v["plane"], v["line"], v["cls"])
            plain = {}
            for kind in kinds:
                pred, err = run(a.bin, ply, kind, out)
                plain[kind] = None if pred is None else score(truth[kind], pred, min_true=1000 if kind == "planes" else 10**9, digits=4)
        else:
            plain = base
        for t in a.transforms:
            got = transform(t, xyz, normals, seed=a.seed)
            if got is None:
                continue
            pts, nrm, keep = got
            ply = os.path.join(tmp, "t.ply")
            write_ply(ply, pts, v["plane"][keep], v["line"][keep], v["cls"][keep], normals=nrm)
            for kind in kinds:
                pred, err = run(a.bin, ply, kind, out)
                s = None if pred is None else score(truth[kind][keep], pred, min_true=1000 if kind == "planes" else 10**9, digits=4)
                b = (plain if t.startswith("o3d_") else base)[kind]
                rows.append({"scan": scan["name"], "split": scan["split"], "kind": kind, "transform": t,
                             "base": b, "changed": s, "error": err})
                print(f"{scan['name']:24s} {kind:6s} {t:8s} F1 {b and b['f1']} -> {s and s['f1']}  "
                      f"found {b and b['found']}/{b and b['big']} -> {s and s['found']}/{s and s['big']}"
                      + (f"  ERROR {err}" if err else ""), flush=True)
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", default=os.path.join(os.path.dirname(HERE), "target", "release", "aniso-alpha"))
    ap.add_argument("--split", default="train", choices=["train", "heldout", "all"])
    ap.add_argument("--set", default="core", choices=["core", "sweep", "all"])
    ap.add_argument("--scans", default="")
    ap.add_argument("--transforms", default=",".join(TRANSFORMS))
    ap.add_argument("--seed", type=int, default=7)
    ap.add_argument("--json", default="")
    a = ap.parse_args()
    a.transforms = [t for t in a.transforms.split(",") if t]
    for t in a.transforms:
        if t not in TRANSFORMS:
            ap.error(f"unknown transform {t!r} (known: {', '.join(TRANSFORMS)})")
    scans = load_manifest()["scans"]
    wanted = set(s for s in a.scans.split(",") if s)
    rows = []
    for scan in scans:
        if wanted and scan["name"] not in wanted:
            continue
        if not wanted:
            if a.split != "all" and scan["split"] != a.split:
                continue
            sweep = bool(scan.get("sweep"))
            if (a.set == "core" and sweep) or (a.set == "sweep" and not sweep):
                continue
        if not os.path.exists(prepared_path(scan)):
            print(f"{scan['name']}: not prepared, skipped", file=sys.stderr)
            continue
        rows += one_scan(scan, a)
    if a.json:
        with open(a.json, "w") as f:
            json.dump(rows, f, indent=1)


if __name__ == "__main__":
    main()
