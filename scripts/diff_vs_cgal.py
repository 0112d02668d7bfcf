#!/usr/bin/env python3
"""Differential test of our Delaunay tetrahedralization and alpha
intervals against CGAL's, on many generated degenerate and near-degenerate
point sets.

    python3 scripts/diff_vs_cgal.py                  # 200 cases, seed 1
    python3 scripts/diff_vs_cgal.py --cases 1000 --seed 7
    python3 scripts/diff_vs_cgal.py --families sphere grid_affine
    python3 scripts/diff_vs_cgal.py --what alpha     # intervals vs cgal_intervals

CGAL's perturbed Delaunay triangulation is unique whatever the insertion
order, and ours follows the same perturbation (docs/method.md §1), so the two sets of
finite tets must be equal, tet for tet. Each case is written as a text
`.xyz` file with every coordinate printed exactly (Python's `repr`), and
read by both programs: our CLI's `delaunay` command and the peer program
`cgal_tets` (see `scripts/bench_vs_cgal.py` for the setup; this script
expects `target/peers/bin/cgal_tets` and builds our CLI in release mode).
Both write one tet per line as input indices; both keep the first index of
a set of duplicates. A mismatch is re-checked with `cgal_verify`. A case
that differs, or on which a program fails, is kept under
`target/diff_vs_cgal/failures/` with both outputs.
Exit status 1 when any case differs or a program fails.

With `--what alpha`, our CLI's `alpha --intervals` CSV is compared with
`cgal_intervals` (CGAL's `Alpha_shape_3` over an exact kernel, each value
the double nearest to the exact radius): the same edges and triangles,
`inf` at the same places, and every finite value within 1e-9 relative (the
tolerance of the fixture tests); the largest deviation seen is printed.

Families (each case draws its sizes and maps from the seeded generator):
  grid          integer n1 x n2 x n3 grid, a random subset, shuffled
  grid_affine   a grid mapped by diag(e)·R (rounded as our Q·p)
  grid_dup      a grid with a third of its points repeated
  sphere        integer points on a few concentric integer spheres
  cocircular    stacked planes of cocircular integer points
  planes        integer points on a few lattice planes, plus a few others
  decimal       a grid of step 0.1 (non-dyadic: near-ties after rounding)
  jitter        a grid moved by tiny random offsets (filter stress)
  scaled        a grid scaled by 2^-40 or 2^40 and offset by 1e6
"""
import argparse
import math
import os
import random
import shutil
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PEERS = os.path.join(ROOT, "target", "peers", "bin")
WORK = os.path.join(ROOT, "target", "diff_vs_cgal")
OURS = os.path.join(ROOT, "target", "release", "aniso-alpha")


def grid_points(rng, lo=3, hi=14):
    dims = [rng.randint(lo, hi) for _ in range(3)]
    pts = [(float(x), float(y), float(z))
           for x in range(dims[0]) for y in range(dims[1]) for z in range(dims[2])]
    keep = rng.choice([1.0, 1.0, 0.7, 0.3])
    pts = [p for p in pts if rng.random() < keep] or pts[:1]
    rng.shuffle(pts)
    return pts


def random_rotation(rng):
    # Gram-Schmidt on a random matrix.
    rows = []
    while len(rows) < 3:
        v = [rng.gauss(0, 1) for _ in range(3)]
        for r in rows:
            d = sum(a * b for a, b in zip(v, r))
            v = [a - d * b for a, b in zip(v, r)]
        norm = math.sqrt(sum(a * a for a in v))
        if norm > 1e-3:
            rows.append([a / norm for a in v])
    return rows


def affine(rng, pts):
    e = [1.0, rng.choice([1.0, 0.5, 0.25, 0.2]), rng.choice([0.125, 0.1, 0.05])]
    r = random_rotation(rng)
    q = [[e[i] * r[i][j] for j in range(3)] for i in range(3)]
    return [tuple((q[i][0] * x + q[i][1] * y) + q[i][2] * z for i in range(3))
            for x, y, z in pts]


def sphere_points(rng):
    pts = set()
    for _ in range(rng.randint(1, 3)):
        r2 = rng.choice([21 * 21, 25, 50, 65, 81, 125, 169, 325])
        r = int(math.isqrt(r2))
        sph = [(x, y, z) for x in range(-r, r + 1) for y in range(-r, r + 1)
               for z in range(-r, r + 1) if x * x + y * y + z * z == r2]
        rng.shuffle(sph)
        pts.update(sph[: rng.randint(8, 200)])
    pts = [tuple(float(c) for c in p) for p in pts]
    rng.shuffle(pts)
    return pts


def cocircular_points(rng):
    r2 = rng.choice([25, 65, 85, 325])
    r = int(math.isqrt(r2))
    circle = [(x, y) for x in range(-r, r + 1) for y in range(-r, r + 1) if x * x + y * y == r2]
    pts = [(float(x), float(y), float(z)) for z in range(rng.randint(2, 6)) for x, y in circle]
    rng.shuffle(pts)
    return pts


def plane_points(rng):
    pts = set()
    for _ in range(rng.randint(2, 4)):
        a, b, c = (rng.randint(-2, 2) for _ in range(3))
        if (a, b, c) == (0, 0, 0):
            c = 1
        d = rng.randint(-3, 3)
        for _ in range(rng.randint(20, 120)):
            x, y, z = (rng.randint(-6, 6) for _ in range(3))
            # Move the point onto a·p = d along the axis with a non-zero
            # coefficient, when it stays an integer.
            s = a * x + b * y + c * z - d
            for k, coef in enumerate((a, b, c)):
                if coef != 0 and s % coef == 0:
                    p = [x, y, z]
                    p[k] -= s // coef
                    pts.add(tuple(float(t) for t in p))
                    break
    for _ in range(rng.randint(1, 5)):
        pts.add(tuple(float(rng.randint(-6, 6)) for _ in range(3)))
    pts = list(pts)
    rng.shuffle(pts)
    return pts


def family_points(fam, rng):
    if fam == "grid":
        return grid_points(rng)
    if fam == "grid_affine":
        return affine(rng, grid_points(rng, 3, 12))
    if fam == "grid_dup":
        pts = grid_points(rng, 2, 10)
        pts = pts + rng.sample(pts, len(pts) // 3)
        rng.shuffle(pts)
        return pts
    if fam == "sphere":
        return sphere_points(rng)
    if fam == "cocircular":
        return cocircular_points(rng)
    if fam == "planes":
        return plane_points(rng)
    if fam == "decimal":
        return [tuple(c * 0.1 for c in p) for p in grid_points(rng, 3, 10)]
    if fam == "jitter":
        eps = rng.choice([1e-9, 1e-12, 1e-15])
        return [tuple(c + rng.uniform(-eps, eps) for c in p) for p in grid_points(rng, 3, 10)]
    if fam == "scaled":
        s = rng.choice([2.0 ** -40, 2.0 ** 40])
        return [tuple(c * s + 1e6 * s for c in p) for p in grid_points(rng, 3, 10)]
    raise ValueError(fam)


FAMILIES = ["grid", "grid_affine", "grid_dup", "sphere", "cocircular", "planes",
            "decimal", "jitter", "scaled"]


def canon(path):
    with open(path) as f:
        return sorted(tuple(sorted(int(t) for t in line.split())) for line in f if line.strip())


def read_intervals(path):
    t = {}
    with open(path) as f:
        next(f)  # header
        for line in f:
            dim, v0, v1, v2, lo, hi = line.strip().split(",")
            t[(int(dim), int(v0), int(v1), int(v2) if v2 else -1)] = (float(lo), float(hi))
    return t


def rel_dev(a, b):
    if math.isinf(a) or math.isinf(b):
        return 0.0 if a == b else math.inf
    m = max(abs(a), abs(b))
    return abs(a - b) / m if m > 0 else 0.0


def run_both(ours_args, peer, peer_args):
    """Runs our CLI and a CGAL peer program; on a failure of either, the
    message to report, else None."""
    o = subprocess.run([OURS] + ours_args, capture_output=True, text=True)
    c = subprocess.run([os.path.join(PEERS, peer)] + peer_args, capture_output=True, text=True)
    if o.returncode != 0 or c.returncode != 0:
        return (f"ours {o.returncode}: {o.stderr.strip()[:200]}; "
                f"cgal {c.returncode}: {c.stderr.strip()[:200]}")
    return None


def compare_delaunay(xyz, d):
    ours_t = os.path.join(d, "ours.tets")
    cgal_t = os.path.join(d, "cgal.tets")
    failed = run_both(["delaunay", xyz, "--tets", ours_t], "cgal_tets", [xyz, cgal_t])
    if failed:
        return "program failed", failed, 0.0
    a, b = canon(ours_t), canon(cgal_t)
    if a == b:
        return "equal", f"{len(a)} tets", 0.0
    v = subprocess.run([os.path.join(PEERS, "cgal_verify"), xyz, ours_t], capture_output=True, text=True)
    return ("DIFFERENT",
            f"ours {len(a)} tets, CGAL {len(b)}; cgal_verify on ours: {v.stdout.strip()[:200]}", 0.0)


def compare_alpha(xyz, d):
    ours_c = os.path.join(d, "ours.csv")
    cgal_c = os.path.join(d, "cgal.csv")
    failed = run_both(["alpha", xyz, "--intervals", ours_c], "cgal_intervals", [xyz, cgal_c])
    if failed:
        return "program failed", failed, 0.0
    a, b = read_intervals(ours_c), read_intervals(cgal_c)
    if a.keys() != b.keys():
        return "DIFFERENT", (f"simplices: {len(a.keys() - b.keys())} only ours, "
                             f"{len(b.keys() - a.keys())} only CGAL's"), 0.0
    dev = max((max(rel_dev(x[0], y[0]), rel_dev(x[1], y[1])) for x, y in
               ((a[key], b[key]) for key in a)), default=0.0)
    if dev > 1e-9:
        return "DIFFERENT", f"largest relative deviation {dev:.3g}", dev
    return "equal", f"{len(a)} simplices, largest relative deviation {dev:.3g}", dev


def run_case(case):
    """Writes one generated set, compares the two programs on it, and keeps
    the case's files under failures/ unless they agree."""
    k, fam, seed, what = case
    rng = random.Random(seed)
    pts = family_points(fam, rng)
    d = os.path.join(WORK, f"case{k:05d}")
    os.makedirs(d, exist_ok=True)
    xyz = os.path.join(d, "points.xyz")
    with open(xyz, "w") as f:
        for p in pts:
            f.write(f"{p[0]!r} {p[1]!r} {p[2]!r}\n")
    compare = compare_alpha if what == "alpha" else compare_delaunay
    status, info, dev = compare(xyz, d)
    if status == "equal":
        shutil.rmtree(d)
    else:
        fail = os.path.join(WORK, "failures", f"case{k:05d}_{fam}")
        shutil.rmtree(fail, ignore_errors=True)
        shutil.move(d, fail)
    return (k, fam, seed, len(pts), status, info, dev)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cases", type=int, default=200)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--families", nargs="+", default=FAMILIES, choices=FAMILIES)
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--what", choices=["delaunay", "alpha"], default="delaunay")
    args = ap.parse_args()
    peer = "cgal_tets" if args.what == "delaunay" else "cgal_intervals"
    if not os.path.exists(os.path.join(PEERS, peer)):
        sys.exit(f"target/peers/bin/{peer} not found: run scripts/bench_vs_cgal.py once to build the peers")
    subprocess.run(["cargo", "build", "--release", "-q", "-p", "aniso-alpha-cli"], cwd=ROOT, check=True)
    shutil.rmtree(WORK, ignore_errors=True)
    os.makedirs(WORK)
    master = random.Random(args.seed)
    cases = [(k, args.families[k % len(args.families)], master.getrandbits(63), args.what)
             for k in range(args.cases)]
    with ThreadPoolExecutor(args.jobs) as ex:
        results = list(ex.map(run_case, cases))
    tally = {}
    bad = 0
    worst = 0.0
    for k, fam, seed, n, status, info, dev in results:
        worst = max(worst, dev)
        t = tally.setdefault(fam, [0, 0, 0])
        t[0] += 1
        t[1] += n
        if status != "equal":
            t[2] += 1
            bad += 1
            print(f"case {k} ({fam}, seed {seed}, {n} points): {status}: {info}")
    print("| family | cases | points (total) | differing |")
    print("|---|---:|---:|---:|")
    for fam in args.families:
        if fam in tally:
            t = tally[fam]
            print(f"| {fam} | {t[0]} | {t[1]} | {t[2]} |")
    if args.what == "delaunay":
        print(f"{len(results) - bad} of {len(results)} cases equal to CGAL, tet for tet")
    else:
        print(f"{len(results) - bad} of {len(results)} cases with CGAL's simplices and intervals; "
              f"largest relative deviation of a value: {worst:.3g}")
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
