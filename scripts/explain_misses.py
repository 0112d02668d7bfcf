#!/usr/bin/env python3
"""Where a detection and a scan's plane labels disagree, and which of the
two each disagreeing point lies nearer to.

For a prepared corpus scan (scripts/corpus/, `plane` column) and the part
labels of a run (`detect SCAN --structure planes --part-labels OUT.txt`),
each part is matched to the labelled plane holding most of its points.
Then:

* a point labelled plane A but in a part matched to plane B: counted as
  nearer its part's plane or nearer its labelled plane (least-squares
  planes of the labelled points, the same for both);
* a labelled point left in the background: its distance to its labelled
  plane, in percentiles, beside those of every labelled point.

A label made by a greedy detector (points of an edge given to whichever
plane was found first) shows as disagreeing points nearer the part's plane.

    python3 scripts/explain_misses.py SCAN.ply PART_LABELS.txt
"""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "corpus"))
from common import read_ply  # noqa: E402


def plane_of(p):
    c = p.mean(axis=0)
    return c, np.linalg.svd(p - c, full_matrices=False)[2][2]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scan")
    ap.add_argument("part_labels")
    a = ap.parse_args()
    v = read_ply(a.scan)
    xyz = np.stack([v["x"], v["y"], v["z"]], axis=1)
    truth = v["plane"].astype(np.int64)
    part = np.loadtxt(a.part_labels, dtype=np.int64)
    if len(part) != len(xyz):
        sys.exit(f"{len(part)} labels for {len(xyz)} points")
    matched = {}
    for p in np.unique(part[part >= 0]):
        t, n = np.unique(truth[part == p], return_counts=True)
        matched[p] = t[n.argmax()]
    as_truth = np.array([matched.get(p, -1) for p in part])
    planes = {t: plane_of(xyz[truth == t]) for t in np.unique(truth[truth >= 0])}

    def dist(i, t):
        c, n = planes[t]
        return abs((xyz[i] - c) @ n)

    other = np.where((as_truth >= 0) & (truth >= 0) & (as_truth != truth))[0]
    nearer_part = sum(dist(i, as_truth[i]) < dist(i, truth[i]) for i in other)
    print(f"{len(xyz)} points, {len(planes)} labelled planes, {len(matched)} parts")
    print(f"in a part matched to another labelled plane: {len(other)}; "
          f"nearer the part's plane {nearer_part}, nearer the labelled plane {len(other) - nearer_part}")
    left = np.where((part < 0) & (truth >= 0))[0]
    every = np.concatenate([np.abs((xyz[truth == t] - c) @ n) for t, (c, n) in planes.items()])
    q = [10, 50, 90]
    print(f"labelled points every part left out: {len(left)}")
    if len(left):
        d = np.array([dist(i, truth[i]) for i in left])
        print(f"  their distance to their labelled plane, percentiles {q}: {np.percentile(d, q).round(4).tolist()}")
    print(f"  every labelled point's, percentiles {q + [99]}: {np.percentile(every, q + [99]).round(4).tolist()}")
    print(f"unlabelled points in a part: {int(((part >= 0) & (truth < 0)).sum())}")


if __name__ == "__main__":
    main()
