#!/usr/bin/env python3
"""How much each plane part found by `aniso-alpha detect --structure planes`
(no other flag) bends, on the prepared corpus, against the truth: can a
flatness test tell a labelled plane's part from a facet of a curved surface
(the mOSD cylinders' sides, which the truth calls non-planar)?

    python3 scripts/part_flatness.py --bin PATH [--split train|heldout|all]
        [--set core|sweep|all] [--min-points 20] [--json out.json]

Per part (at least --min-points members): the least-squares plane of its
members, then a quadratic r = a + b·u + c·v + d·u² + e·u·v + f·v² of their
residuals r over the in-plane coordinates (u, v), fitted robustly (the
inner 80% of the part along u and v, Tukey biweight reweighting); the turn
of the quadratic's normal across the part is 2·atan(|κ|·W/2) for each
eigenvalue κ of its Hessian, W the part's uniform-equivalent width along
that eigenvector (√12 standard deviations), the larger of the two. A part
is "true" when most of its members lie on a labelled plane.

Prints, per band of turn, the true and the other parts and their points.
A flatness rule would be a threshold on the turn; it helps only if the
bands separate the two.

Needs numpy and the corpus (scripts/corpus/prepare.py).
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "corpus"))
from common import load_manifest, prepared_path, read_ply  # noqa: E402

BANDS = [0, 5, 10, 15, 20, 30, 45, 90, 181]


def quadratic_turn(q):
    """The turn in degrees of a robust quadratic fitted to the points `q`."""
    c = q.mean(0)
    _, _, vt = np.linalg.svd(q - c, full_matrices=False)
    u, v, r = ((q - c) @ vt[k] for k in range(3))
    lo_u, hi_u = np.percentile(u, [10, 90])
    lo_v, hi_v = np.percentile(v, [10, 90])
    core = (u >= lo_u) & (u <= hi_u) & (v >= lo_v) & (v <= hi_v)
    uu, vv, rr = u[core], v[core], r[core]
    design = np.c_[np.ones(len(uu)), uu, vv, uu * uu, uu * vv, vv * vv]
    w = np.ones(len(uu))
    for _ in range(5):
        s = np.sqrt(w)
        coef = np.linalg.lstsq(design * s[:, None], rr * s, rcond=None)[0]
        res = rr - design @ coef
        sigma = 1.4826 * np.median(np.abs(res)) + 1e-12
        z = res / (4.685 * sigma)
        w = np.where(np.abs(z) < 1, (1 - z * z) ** 2, 0.0)
    hessian = np.array([[2 * coef[3], coef[4]], [coef[4], 2 * coef[5]]])
    kappa, axes = np.linalg.eigh(hessian)
    turn = 0.0
    for k in range(2):
        width = np.sqrt(12.0) * (np.c_[u, v] @ axes[:, k]).std()
        turn = max(turn, 2 * np.degrees(np.arctan(abs(kappa[k]) * width / 2)))
    return turn


def parts_of(binary, scan, tmp):
    out = os.path.join(tmp, scan["name"] + ".parts")
    subprocess.run([binary, "detect", prepared_path(scan), "--structure", "planes",
                    "--part-labels", out], check=True, capture_output=True)
    return np.loadtxt(out, dtype=np.int64)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--bin", required=True)
    ap.add_argument("--split", default="train", choices=["train", "heldout", "all"])
    ap.add_argument("--set", default="all", choices=["core", "sweep", "all"])
    ap.add_argument("--min-points", type=int, default=20)
    ap.add_argument("--json")
    a = ap.parse_args()
    scans = [s for s in load_manifest()["scans"]
             if "planes" in s["scores"] and a.split in ("all", s["split"])
             and (a.set == "all" or bool(s.get("sweep")) == (a.set == "sweep"))]
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for scan in scans:
            v = read_ply(prepared_path(scan))
            xyz = np.stack([v["x"], v["y"], v["z"]], 1).astype(float)
            truth = v["plane"].astype(np.int64)
            parts = parts_of(a.bin, scan, tmp)
            for p in range(int(parts.max()) + 1 if len(parts) else 0):
                m = parts == p
                if m.sum() < a.min_points:
                    continue
                labels, counts = np.unique(truth[m], return_counts=True)
                rows.append({"scan": scan["name"], "part": p, "points": int(m.sum()),
                             "true": bool(labels[np.argmax(counts)] >= 0),
                             "turn_deg": float(quadratic_turn(xyz[m]))})
    print(f"{len(scans)} scans ({a.split}, {a.set}), {len(rows)} parts of {a.min_points}+ points")
    print("| turn (degrees) | true parts | their points | other parts | their points |")
    print("|---|---:|---:|---:|---:|")
    for lo, hi in zip(BANDS, BANDS[1:]):
        band = [r for r in rows if lo <= r["turn_deg"] < hi]
        t = [r for r in band if r["true"]]
        f = [r for r in band if not r["true"]]
        print(f"| {lo}–{hi} | {len(t)} | {sum(r['points'] for r in t)} "
              f"| {len(f)} | {sum(r['points'] for r in f)} |")
    if a.json:
        with open(a.json, "w") as f:
            json.dump(rows, f, indent=1)


if __name__ == "__main__":
    main()
