#!/usr/bin/env python3
"""Simulated laser scans of labelled scenes, for developing and testing
detection on scan-like data (occlusion, range noise, density falling with
range, outliers), with per-point ground truth.

    python3 scripts/simulate_scan.py room   --seed 1 --output room.xyz
    python3 scripts/simulate_scan.py house  --seed 1 --output house.xyz
    python3 scripts/simulate_scan.py halls  --seed 1 --output halls.xyz
    python3 scripts/simulate_scan.py street --seed 1 --output street.xyz
    python3 scripts/simulate_scan.py avenue --seed 1 --output avenue.xyz
    python3 scripts/simulate_scan.py object --mesh anchor.off --seed 1 --output anchor.xyz

Writes `x y z label` per line (label -1 = clutter/outlier, otherwise the
id of the planar surface, or of the pole/cable for `street`), and prints a
one-line JSON summary. Needs numpy and open3d (ray casting).

Scenes (dimensions in metres):
  room    a 6 x 5 x 2.8 m room scanned from its middle: floor, ceiling, four
          walls, a table and a cupboard (boxes: each face a plane), a door
          recess; range noise 3 mm, 2,000 uniform outliers in the room.
  house   a 10 x 7 m house with a gable roof (two slopes), a chimney,
          window recesses in its walls, on a ground plane, scanned from
          three stations outside; trees (random blobs of points) as
          clutter; range noise 1 cm.
  airborne  a 120 x 120 m block seen from an aircraft 300 m up: the
          ground, a large flat-roofed hall, five gable-roofed houses and a
          mono-pitch shed at random azimuths (each roof face and wall a
          plane), trees as clutter; one flight strip along y whose
          scanner sweeps across track, so that the points lie on scan
          lines 0.8-1.4 m apart with 0.3-0.5 m between points along a
          line (the anisotropic pattern of airborne tiles); range noise
          3 cm.
  halls   a 120 x 120 m industrial block seen from the air, as
          `airborne` but denser (scan lines 0.4-0.6 m apart, 0.2-0.3 m
          along a line): four halls 30-50 m a side at random azimuths
          with shallow roofs of two faces each (a gable, a butterfly roof
          whose faces fall to a valley, an asymmetric gable with faces of
          different widths and pitches, a two-bay sawtooth), every face
          pitched 3-12 degrees, so that the faces of one roof are within
          a few degrees of each other and of the ground; each roof face
          and wall a plane; trees as clutter; range noise 3 cm.
  street  a street with 5 poles (cylinders, radius 8-15 cm, 6-8 m tall,
          each with a crossbar), cables sagging between their tops, a
          facade and the ground, scanned from two stations; labels are the
          line structures (pole, crossbar, cable); planes are -1.
  avenue  the street's targets among a street's clutter, scanned from
          three stations at a mapping car's height: lamp posts with an
          arm, utility poles with a crossbar and sagging cables, sign
          posts with their plate, trees (a trunk, branches and a crown
          of 10-20 cm leaves at random orientations), parked cars, and
          two facades with window recesses; labels are the line targets
          (pole, arm, crossbar, cable, sign post); trees, plates, cars,
          facades and the ground are -1.
  object  a mechanical part (an OFF mesh, e.g. CGAL's demo meshes
          anchor.off, cross.off, fandisk.off) scaled to a 0.3 m diagonal
          and turned at random, scanned from eight stations 0.8 m away
          around it (elevations -20 to 70 degrees, 0.07 degree steps,
          rays only towards the object); range noise 0.3 mm; labels are
          its planar faces (triangles joined across shared edges while
          within 1 degree and 0.1% of the diagonal of the seed's plane)
          of at least 1% of its area; curved surfaces and smaller facets
          are -1.

Scanner: rays on an azimuth x elevation grid (0.1 to 0.2 degree steps,
jittered), first hit, Gaussian noise along the ray; points beyond 60 m
dropped.
"""

import argparse
import json
import sys

import numpy as np


class Scene:
    """Triangles with a label each."""

    def __init__(self):
        self.v = []
        self.t = []
        self.lab = []
        self.n = 0

    def quad(self, p0, u, w, label, holes=()):
        """The parallelogram p0 + s*u + r*w, s, r in [0, 1], minus
        rectangular holes given as (s0, s1, r0, r1)."""
        p0, u, w = (np.asarray(x, float) for x in (p0, u, w))
        ss = sorted({0.0, 1.0, *[h[0] for h in holes], *[h[1] for h in holes]})
        rs = sorted({0.0, 1.0, *[h[2] for h in holes], *[h[3] for h in holes]})
        for i in range(len(ss) - 1):
            for j in range(len(rs) - 1):
                sm, rm = 0.5 * (ss[i] + ss[i + 1]), 0.5 * (rs[j] + rs[j + 1])
                if any(h[0] <= sm <= h[1] and h[2] <= rm <= h[3] for h in holes):
                    continue
                a = p0 + ss[i] * u + rs[j] * w
                b = p0 + ss[i + 1] * u + rs[j] * w
                c = p0 + ss[i + 1] * u + rs[j + 1] * w
                d = p0 + ss[i] * u + rs[j + 1] * w
                self.tri(a, b, c, label)
                self.tri(a, c, d, label)

    def tri(self, a, b, c, label):
        self.v.extend([a, b, c])
        self.t.append([self.n, self.n + 1, self.n + 2])
        self.lab.append(label)
        self.n += 3

    def box(self, lo, hi, first_label):
        """An axis-aligned box; each face its own label. Returns the next
        free label."""
        lo, hi = np.asarray(lo, float), np.asarray(hi, float)
        d = hi - lo
        ex, ey, ez = np.array([d[0], 0, 0]), np.array([0, d[1], 0]), np.array([0, 0, d[2]])
        faces = [
            (lo, ey, ez), (lo + ex, ey, ez),
            (lo, ex, ez), (lo + ey, ex, ez),
            (lo, ex, ey), (lo + ez, ex, ey),
        ]
        for k, (p, u, w) in enumerate(faces):
            self.quad(p, u, w, first_label + k)
        return first_label + 6

    def cylinder(self, a, b, r, label, segments=24):
        a, b = np.asarray(a, float), np.asarray(b, float)
        axis = b - a
        axis /= np.linalg.norm(axis)
        t = np.array([1.0, 0, 0]) if abs(axis[0]) < 0.9 else np.array([0, 1.0, 0])
        e1 = np.cross(axis, t)
        e1 /= np.linalg.norm(e1)
        e2 = np.cross(axis, e1)
        ring = lambda c, k: c + r * (np.cos(2 * np.pi * k / segments) * e1 + np.sin(2 * np.pi * k / segments) * e2)
        for k in range(segments):
            p, q = ring(a, k), ring(a, k + 1)
            p2, q2 = ring(b, k), ring(b, k + 1)
            self.tri(p, q, q2, label)
            self.tri(p, q2, p2, label)

    def arrays(self):
        return np.array(self.v, float), np.array(self.t, np.int64), np.array(self.lab, np.int64)


def scan(scene, stations, rng, step_deg, noise, max_range=60.0, elev=(-80, 85), aim=None):
    """Rays from each station on an azimuth x elevation grid of `step_deg`
    (all around, within `elev`; or, with `aim` = (centre, radius), over the
    cone that holds that sphere), first hit, Gaussian range noise."""
    import open3d as o3d

    v, t, lab = scene.arrays()
    rs = o3d.t.geometry.RaycastingScene()
    rs.add_triangles(o3d.core.Tensor(v.astype(np.float32)), o3d.core.Tensor(t.astype(np.uint32)))
    pts, labels = [], []
    for s in stations:
        if aim is None:
            az = np.arange(0, 360, step_deg)
            el = np.arange(elev[0], elev[1], step_deg)
        else:
            w = np.asarray(aim[0], float) - np.asarray(s, float)
            dist = np.linalg.norm(w)
            az0, el0 = np.degrees(np.arctan2(w[1], w[0])), np.degrees(np.arcsin(w[2] / dist))
            h = np.degrees(np.arcsin(min(1.0, aim[1] / dist)))
            ha = min(180.0, h / max(np.cos(np.radians(el0)), 1e-6))
            az = np.arange(az0 - ha, az0 + ha, step_deg)
            el = np.arange(el0 - h, el0 + h, step_deg)
        A, E = np.meshgrid(np.radians(az), np.radians(el))
        A = A + rng.normal(0, np.radians(step_deg) * 0.05, A.shape)
        E = E + rng.normal(0, np.radians(step_deg) * 0.05, E.shape)
        d = np.stack([np.cos(E) * np.cos(A), np.cos(E) * np.sin(A), np.sin(E)], -1).reshape(-1, 3)
        o = np.broadcast_to(np.asarray(s, float), d.shape)
        rays = o3d.core.Tensor(np.hstack([o, d]).astype(np.float32))
        ans = rs.cast_rays(rays)
        th = ans["t_hit"].numpy().astype(float)
        pid = ans["primitive_ids"].numpy()
        ok = np.isfinite(th) & (th < max_range)
        r = th[ok] + rng.normal(0, noise, ok.sum())
        pts.append(o[ok] + r[:, None] * d[ok])
        labels.append(lab[pid[ok]])
    return np.vstack(pts), np.concatenate(labels)


def room(rng):
    s = Scene()
    L, W, H = 6.0, 5.0, 2.8
    lab = 0
    s.quad([0, 0, 0], [L, 0, 0], [0, W, 0], lab); lab += 1          # floor
    s.quad([0, 0, H], [L, 0, 0], [0, W, 0], lab); lab += 1          # ceiling
    s.quad([0, 0, 0], [L, 0, 0], [0, 0, H], lab, holes=[(0.4, 0.55, 0.0, 0.75)]); lab += 1
    s.quad([0, W, 0], [L, 0, 0], [0, 0, H], lab); lab += 1
    s.quad([0, 0, 0], [0, W, 0], [0, 0, H], lab); lab += 1
    s.quad([L, 0, 0], [0, W, 0], [0, 0, H], lab); lab += 1
    # Door recess behind the hole in the first wall.
    s.quad([0.4 * L, -0.25, 0], [0.15 * L, 0, 0], [0, 0, 0.75 * H], lab); lab += 1
    lab = s.box([1.0, 3.2, 0.0], [2.6, 4.0, 0.75], lab)               # table
    lab = s.box([4.9, 0.5, 0.0], [5.6, 2.0, 2.0], lab)                # cupboard
    pts, labels = scan(s, [[3.2, 2.3, 1.5]], rng, 0.12, 0.003)
    # Uniform outliers in the room.
    out = rng.uniform([0, 0, 0], [L, W, H], (2000, 3))
    return np.vstack([pts, out]), np.concatenate([labels, -np.ones(2000, np.int64)])


def house(rng):
    s = Scene()
    lab = 0
    Lx, Ly, Hw, Hr = 10.0, 7.0, 5.0, 3.0
    s.quad([-25, -25, 0], [50, 0, 0], [0, 50, 0], lab); lab += 1       # ground
    win = [(0.15, 0.3, 0.35, 0.7), (0.45, 0.6, 0.35, 0.7), (0.75, 0.9, 0.35, 0.7)]
    # Walls with windows; recessed panes 0.2 m behind.
    for p0, u in [([0, 0, 0], [Lx, 0, 0]), ([Lx, Ly, 0], [-Lx, 0, 0])]:
        p0, u = np.array(p0, float), np.array(u, float)
        n = np.cross(u, [0, 0, 1.0]); n /= np.linalg.norm(n)
        s.quad(p0, u, [0, 0, Hw], lab, holes=win); lab += 1
        for h in win:
            s.quad(p0 - 0.2 * n + h[0] * u + [0, 0, h[2] * Hw], (h[1] - h[0]) * u, [0, 0, (h[3] - h[2]) * Hw], lab)
        lab += 1
    for p0, u in [([Lx, 0, 0], [0, Ly, 0]), ([0, Ly, 0], [0, -Ly, 0])]:
        s.quad(p0, u, [0, 0, Hw], lab); lab += 1
        # Gable triangle above.
        p0, u = np.array(p0, float), np.array(u, float)
        a, b, c = p0 + [0, 0, Hw], p0 + u + [0, 0, Hw], p0 + 0.5 * u + [0, 0, Hw + Hr]
        s.tri(a, b, c, lab - 1)
    # Roof slopes (with 0.5 m overhang).
    o = 0.5
    ridge = [[-o, Ly / 2, Hw + Hr], [Lx + o, Ly / 2, Hw + Hr]]
    s.quad([-o, -o, Hw - o * Hr / (Ly / 2)], [Lx + 2 * o, 0, 0], [0, Ly / 2 + o, Hr + o * Hr / (Ly / 2)], lab); lab += 1
    s.quad([-o, Ly + o, Hw - o * Hr / (Ly / 2)], [Lx + 2 * o, 0, 0], [0, -(Ly / 2 + o), Hr + o * Hr / (Ly / 2)], lab); lab += 1
    del ridge
    lab = s.box([6.5, 1.5, Hw + 0.5], [7.3, 2.3, Hw + Hr + 1.2], lab)   # chimney
    pts, labels = scan(s, [[-12, -9, 1.7], [22, -6, 1.7], [5, 20, 1.7]], rng, 0.09, 0.01)
    # Trees: blobs of points (foliage) near the house.
    trees = []
    for c in [[-5, 3, 4], [15, 10, 5], [12, -6, 3.5]]:
        k = 4000
        d = rng.normal(0, 1.0, (k, 3)) * [1.6, 1.6, 2.0]
        trees.append(np.asarray(c) + d)
    trees = np.vstack(trees)
    keep = np.hypot(pts[:, 0] - 5, pts[:, 1] - 3.5) < 30
    return np.vstack([pts[keep], trees]), np.concatenate([labels[keep], -np.ones(len(trees), np.int64)])


def _rotated_box_walls(s, c, R, lx, ly, h, lab):
    """The four walls of a footprint lx x ly centred at c, rotated by R
    (2 x 2), from z = 0 to h: one label each; returns the next label."""
    corners = [np.array([-lx / 2, -ly / 2]), np.array([lx / 2, -ly / 2]),
               np.array([lx / 2, ly / 2]), np.array([-lx / 2, ly / 2])]
    for a, b in zip(corners, corners[1:] + corners[:1]):
        pa = np.r_[c + R @ a, 0.0]
        u = np.r_[R @ (b - a), 0.0]
        s.quad(pa, u, [0, 0, h], lab)
        lab += 1
    return lab


def _strip(rng, rs, labs, size, along, across, shift, sense):
    """The points of one strip over the block: scan lines `along` apart
    (shifted by `shift`), `across` between points on a line, the sweep's
    slant in the direction `sense`; with their labels."""
    import open3d as o3d

    H = 300.0
    xs = np.arange(-5, size + 5, across)
    rows = np.arange(-5, size + 5, along) + shift
    X, Y = np.meshgrid(xs, rows)
    # The sweep's slant: each line drifts one line spacing along y over the swath.
    Y = Y + sense * along * (X - X.min()) / (X.max() - X.min()) * np.where(np.arange(len(rows)) % 2 == 0, 1, -1)[:, None]
    X = X + rng.normal(0, across * 0.05, X.shape)
    target = np.stack([X.ravel(), Y.ravel(), np.zeros(X.size)], -1)
    origin = np.stack([np.full(X.size, size / 2), Y.ravel(), np.full(X.size, H)], -1)
    d = target - origin
    d /= np.linalg.norm(d, axis=1)[:, None]
    ans = rs.cast_rays(o3d.core.Tensor(np.hstack([origin, d]).astype(np.float32)))
    th_ = ans["t_hit"].numpy().astype(float)
    pid = ans["primitive_ids"].numpy()
    ok = np.isfinite(th_)
    r = th_[ok] + rng.normal(0, 0.03, ok.sum())
    return origin[ok] + r[:, None] * d[ok], labs[pid[ok]]


def airborne(rng, strips=1):
    s = Scene()
    lab = 0
    size = 120.0
    s.quad([-10, -10, 0], [size + 20, 0, 0], [0, size + 20, 0], lab); lab += 1   # ground
    # A flat-roofed hall, 30-45 x 25-35 m, 8-12 m high.
    lx, ly, h = rng.uniform(30, 45), rng.uniform(25, 35), rng.uniform(8, 12)
    c = np.array([35.0, 40.0]) + rng.uniform(-5, 5, 2)
    th = rng.uniform(0, np.pi / 2)
    R = np.array([[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]])
    lab = _rotated_box_walls(s, c, R, lx, ly, h, lab)
    s.quad(np.r_[c + R @ [-lx / 2, -ly / 2], h], np.r_[R @ [lx, 0], 0], np.r_[R @ [0, ly], 0], lab); lab += 1
    # Gable-roofed houses (ridge along the local x axis) and one shed.
    sites = [[85, 25], [85, 60], [95, 95], [55, 95], [20, 90], [25, 10]]
    for i, site in enumerate(sites):
        lx, ly = rng.uniform(8, 14), rng.uniform(6, 10)
        h, hr = rng.uniform(4, 7), rng.uniform(2, 4)
        c = np.asarray(site, float) + rng.uniform(-3, 3, 2)
        th = rng.uniform(0, 2 * np.pi)
        R = np.array([[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]])
        lab = _rotated_box_walls(s, c, R, lx, ly, h, lab)
        if i == len(sites) - 1:
            # Mono-pitch shed: one slope from h to h + hr across the footprint.
            s.quad(np.r_[c + R @ [-lx / 2, -ly / 2], h], np.r_[R @ [lx, 0], 0],
                   np.r_[R @ [0, ly], hr], lab); lab += 1
            continue
        for side in (-1, 1):
            eave = np.r_[c + R @ [-lx / 2, side * ly / 2], h]
            s.quad(eave, np.r_[R @ [lx, 0], 0], np.r_[R @ [0, -side * ly / 2], hr], lab); lab += 1
    # Strips along y, 300 m up, sweeping across track (a zig-zag); a
    # second strip flies the other way over the same block, its lines
    # shifted by a random part of the line spacing (the overlap of two
    # strips, where points of the two come in near pairs).
    along = rng.uniform(0.8, 1.4)
    across = rng.uniform(0.3, 0.5)
    return _fly(rng, s, size, along, across, strips, trees=8, tree_points=(150, 400))


def _fly(rng, s, size, along, across, strips, trees, tree_points):
    """The scene `s` over a `size` x `size` block seen by `strips` flight
    strips (scan lines `along` apart, `across` between points on a line),
    with `trees` blobs of foliage of `tree_points` (low, high) points as
    clutter: the points inside the block and their labels."""
    import open3d as o3d

    v, t, labs = s.arrays()
    rs = o3d.t.geometry.RaycastingScene()
    rs.add_triangles(o3d.core.Tensor(v.astype(np.float32)), o3d.core.Tensor(t.astype(np.uint32)))
    parts = [_strip(rng, rs, labs, size, along, across, 0.0, 1.0)]
    for _ in range(1, strips):
        parts.append(_strip(rng, rs, labs, size, along, across, rng.uniform(0, along), -1.0))
    pts = np.vstack([p for p, _ in parts])
    labels = np.concatenate([l for _, l in parts])
    # Trees: blobs of foliage points above the ground.
    blobs = []
    for cx, cy in rng.uniform(5, size - 5, (trees, 2)):
        k = int(rng.integers(*tree_points))
        blobs.append(np.array([cx, cy, rng.uniform(5, 9)]) + rng.normal(0, 1.0, (k, 3)) * [2.0, 2.0, 1.5])
    blobs = np.vstack(blobs)
    keep = np.all((pts[:, :2] >= 0) & (pts[:, :2] <= size), axis=1)
    return np.vstack([pts[keep], blobs]), np.concatenate([labels[keep], -np.ones(len(blobs), np.int64)])


def _hall(s, rng, c, th, lx, ly, h, kind, lab):
    """A hall lx x ly at c, turned by th, eaves at h, with a shallow roof
    of `kind` (faces across the local y axis); returns the next label."""
    R = np.array([[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]])
    pitch = lambda: np.tan(np.radians(rng.uniform(3.0, 12.0)))
    lab = _rotated_box_walls(s, c, R, lx, ly, h, lab)
    at = lambda x, y, z: np.r_[c + R @ [x, y], z]
    along = np.r_[R @ [lx, 0], 0]
    if kind == "gable" or kind == "asymmetric":
        # The ridge at y = split, faces falling to the eaves on both sides.
        # (The far eave lies where the second pitch takes it.)
        split = ly * (0.5 if kind == "gable" else rng.uniform(0.25, 0.4))
        t1, t2 = pitch(), pitch()
        top = h + split * t1
        fall = (ly - split) * t2
        s.quad(at(-lx / 2, -ly / 2, h), along, np.r_[R @ [0, split], top - h], lab); lab += 1
        s.quad(at(-lx / 2, -ly / 2 + split, top), along, np.r_[R @ [0, ly - split], -fall], lab); lab += 1
    elif kind == "butterfly":
        # Two faces falling from the eaves to a valley at mid-width.
        t = pitch()
        drop = ly / 2 * t
        s.quad(at(-lx / 2, -ly / 2, h + drop), along, np.r_[R @ [0, ly / 2], -drop], lab); lab += 1
        s.quad(at(-lx / 2, 0.0, h), along, np.r_[R @ [0, ly / 2], drop], lab); lab += 1
    else:
        # Sawtooth: two bays, each a shallow face rising to a vertical step.
        t = pitch()
        for k in range(2):
            y = -ly / 2 + k * ly / 2
            rise = ly / 2 * t
            s.quad(at(-lx / 2, y, h), along, np.r_[R @ [0, ly / 2], rise], lab); lab += 1
            s.quad(at(-lx / 2, y + ly / 2, h), along, [0, 0, rise], lab); lab += 1
    return lab


def halls(rng, strips=1):
    s = Scene()
    lab = 0
    size = 120.0
    s.quad([-10, -10, 0], [size + 20, 0, 0], [0, size + 20, 0], lab); lab += 1   # ground
    sites = [[32, 32], [88, 32], [32, 88], [88, 88]]
    kinds = list(rng.permutation(["gable", "butterfly", "asymmetric", "sawtooth"]))
    for site, kind in zip(sites, kinds):
        lx, ly, h = rng.uniform(30, 45), rng.uniform(25, 40), rng.uniform(6, 12)
        c = np.asarray(site, float) + rng.uniform(-3, 3, 2)
        lab = _hall(s, rng, c, rng.uniform(0, np.pi), lx, ly, h, kind, lab)
    along = rng.uniform(0.4, 0.6)
    across = rng.uniform(0.2, 0.3)
    return _fly(rng, s, size, along, across, strips, trees=6, tree_points=(300, 800))


def _cable(s, a, b, label):
    """A cable from `a` to `b` sagging 0.6 m, as 12 straight cylinders 1.5
    cm in radius, all labelled `label`."""
    a, b = np.array(a), np.array(b)
    k = 12
    for i in range(k):
        t0, t1 = i / k, (i + 1) / k
        p = a + t0 * (b - a) - [0, 0, 2.4 * t0 * (1 - t0)]
        q = a + t1 * (b - a) - [0, 0, 2.4 * t1 * (1 - t1)]
        s.cylinder(p, q, 0.015, label, segments=8)


def street(rng):
    s = Scene()
    lab = 0
    s.quad([-40, -8, 0], [80, 0, 0], [0, 30, 0], 1000)                 # ground (plane: -1)
    s.quad([-40, 12, 0], [80, 0, 0], [0, 0, 9], 1001)                  # facade (plane: -1)
    xs = np.linspace(-24, 24, 5) + rng.uniform(-2, 2, 5)
    tops = []
    for x in xs:
        r = rng.uniform(0.08, 0.15)
        h = rng.uniform(6, 8)
        s.cylinder([x, 0, 0], [x, 0, h], r, lab); lab += 1            # pole
        s.cylinder([x, -0.8, h - 0.5], [x, 0.8, h - 0.5], 0.05, lab); lab += 1  # crossbar
        tops.append([x, 0.7, h - 0.45])
    for a, b in zip(tops[:-1], tops[1:]):
        _cable(s, a, b, lab); lab += 1
    pts, labels = scan(s, [[-10, -5, 1.8], [12, -5, 1.8]], rng, 0.06, 0.005, elev=(-60, 70))
    labels = np.where(labels >= 1000, -1, labels)
    return pts, labels


def _tree(s, rng, base, label):
    """A tree as a mapping scan sees it: a trunk, a few branches from its
    top, and a crown of small leaves (triangles 10-20 cm across at random
    orientations) filling an ellipsoid, all labelled `label`."""
    base = np.asarray(base, float)
    h = rng.uniform(2.2, 3.5)
    top = base + [0, 0, h]
    s.cylinder(base, top, rng.uniform(0.12, 0.25), label, segments=12)
    rx, rz = rng.uniform(1.8, 2.8), rng.uniform(2.0, 3.0)
    centre = top + [0, 0, 0.7 * rz]
    for _ in range(int(rng.integers(3, 6))):
        d = rng.normal(0, 1, 3) * [1, 1, 0.6] + [0, 0, 0.8]
        d /= np.linalg.norm(d)
        s.cylinder(top, top + d * rng.uniform(1.0, 2.0), rng.uniform(0.03, 0.07), label, segments=8)
    k = int(3000 * rx * rx * rz / 16)
    u = rng.normal(0, 1, (k, 3))
    u /= np.linalg.norm(u, axis=1)[:, None]
    c = centre + u * rng.uniform(0, 1, (k, 1)) ** (1 / 3) * [rx, rx, rz]
    for p in c:
        e = rng.normal(0, 1, (2, 3))
        size = rng.uniform(0.1, 0.2)
        a, b = e[0] / np.linalg.norm(e[0]) * size, e[1] / np.linalg.norm(e[1]) * size
        s.tri(p, p + a, p + 0.5 * (a + b), label)


def avenue(rng):
    s = Scene()
    lab = 0
    clutter = 10000                                                     # relabelled -1 below
    s.quad([-45, -12, 0], [90, 0, 0], [0, 26, 0], clutter)                   # road and walkways
    for y, n in [(-12, 1), (14, -1)]:                                   # facades with window recesses
        win = [(x0, x0 + 0.025, 0.25, 0.45) for x0 in np.arange(0.03, 0.97, 0.06)]
        win += [(x0, x0 + 0.025, 0.6, 0.8) for x0 in np.arange(0.03, 0.97, 0.06)]
        s.quad([-45, y, 0], [90, 0, 0], [0, 0, 10], clutter, holes=win)
        for h in win:
            p0 = np.array([-45 + 90 * h[0], y - 0.25 * n, 10 * h[2]])
            s.quad(p0, [90 * (h[1] - h[0]), 0, 0], [0, 0, 10 * (h[3] - h[2])], clutter)
    # Lamp posts on the south walkway, each with an arm over the road.
    for x in np.linspace(-30, 30, 4) + rng.uniform(-3, 3, 4):
        h = rng.uniform(6, 9)
        s.cylinder([x, -7.5, 0], [x, -7.5, h], rng.uniform(0.07, 0.14), lab); lab += 1
        tilt = rng.uniform(0, 0.4)
        s.cylinder([x, -7.5, h - 0.3], [x, -7.5 + rng.uniform(1.2, 2.2), h - 0.3 + tilt], 0.05, lab); lab += 1
    # Utility poles on the north walkway, crossbars, cables between their tops.
    tops = []
    for x in np.linspace(-32, 32, 4) + rng.uniform(-2, 2, 4):
        h = rng.uniform(7, 9)
        s.cylinder([x, 9, 0], [x, 9, h], rng.uniform(0.1, 0.16), lab); lab += 1
        s.cylinder([x, 8.2, h - 0.5], [x, 9.8, h - 0.5], 0.05, lab); lab += 1
        tops.append([x, 9.7, h - 0.45])
    for a, b in zip(tops[:-1], tops[1:]):
        _cable(s, a, b, lab); lab += 1
    # Sign posts with a plate (the plate is clutter).
    for x, y in [(rng.uniform(-38, -20), -8.5), (rng.uniform(-5, 5), 10.0), (rng.uniform(20, 38), -8.5)]:
        s.cylinder([x, y, 0], [x, y, 2.8], 0.035, lab); lab += 1
        s.quad([x - 0.3, y + 0.06, 2.2], [0.6, 0, 0], [0, 0, 0.6], clutter)
    # Trees on both walkways, between the posts.
    for x in np.linspace(-36, 36, 7) + rng.uniform(-2, 2, 7):
        _tree(s, rng, [x, -9.5 if rng.uniform() < 0.5 else 11.0, 0], clutter)
    # Parked cars along both kerbs.
    for x in rng.uniform(-40, 36, 5):
        y = -6 if rng.uniform() < 0.5 else 6.2
        s.box([x, y - 0.9, 0.3], [x + 4.3, y + 0.9, 1.0], clutter)
        s.box([x + 1.1, y - 0.8, 1.0], [x + 3.2, y + 0.8, 1.5], clutter)
    pts, labels = scan(s, [[-20, -2, 2.2], [0, 2, 2.2], [20, -2, 2.2]], rng, 0.07, 0.01, elev=(-60, 70))
    return pts, np.where(labels >= clutter, -1, labels)


def read_off(path):
    """The vertices and triangles of an OFF mesh (polygons fanned)."""
    with open(path) as f:
        rows = [ln.split() for ln in f if ln.strip() and not ln.lstrip().startswith("#")]
    if rows[0][0] != "OFF":
        raise SystemExit(f"{path}: not an OFF file")
    head = rows[0][1:] if len(rows[0]) > 1 else rows.pop(1)
    nv, nf = int(head[0]), int(head[1])
    v = np.array([[float(x) for x in r[:3]] for r in rows[1:1 + nv]])
    tris = []
    for r in rows[1 + nv:1 + nv + nf]:
        idx = [int(x) for x in r[1:1 + int(r[0])]]
        tris += [[idx[0], idx[j], idx[j + 1]] for j in range(1, len(idx) - 1)]
    return v, np.array(tris, np.int64)


def planar_groups(v, t, angle_deg=1.0, tol=1e-3):
    """Each triangle's planar face: triangles joined across shared edges
    while their normal is within `angle_deg` of the seed's and their
    vertices within `tol` x the mesh's diagonal of the seed's plane, seeds
    taken by decreasing area. Returns (group per triangle, triangle areas)."""
    a, b, c = v[t[:, 0]], v[t[:, 1]], v[t[:, 2]]
    n = np.cross(b - a, c - a)
    area = 0.5 * np.linalg.norm(n, axis=1)
    n = n / np.maximum(2 * area, 1e-300)[:, None]
    tol *= np.linalg.norm(np.ptp(v, axis=0))
    by_edge = {}
    for i, tri in enumerate(t):
        for e in ((tri[0], tri[1]), (tri[1], tri[2]), (tri[2], tri[0])):
            by_edge.setdefault((min(e), max(e)), []).append(i)
    near = [[] for _ in t]
    for fs in by_edge.values():
        for i in fs:
            near[i] += [j for j in fs if j != i]
    group = -np.ones(len(t), np.int64)
    cos = np.cos(np.radians(angle_deg))
    k = 0
    for seed in np.argsort(-area, kind="stable"):
        if group[seed] >= 0 or area[seed] == 0:
            continue
        ns, d0 = n[seed], n[seed] @ a[seed]
        group[seed], todo = k, [seed]
        while todo:
            for j in near[todo.pop()]:
                if group[j] < 0 and abs(n[j] @ ns) >= cos and np.abs(v[t[j]] @ ns - d0).max() <= tol:
                    group[j] = k
                    todo.append(j)
        k += 1
    return group, area


def scanned_object(rng, mesh):
    """A mechanical part (an OFF mesh) scanned as a desktop scanner does:
    scaled to a 0.3 m diagonal and turned at random, seen from eight
    stations 0.8 m away around it at elevations from -20 to 70 degrees;
    its planar faces of at least 1% of its area are the planes, the rest
    (curved surfaces, small facets) unlabelled."""
    v, t = read_off(mesh)
    v = v - 0.5 * (v.min(axis=0) + v.max(axis=0))
    v *= 0.3 / np.linalg.norm(np.ptp(v, axis=0))
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    v = v @ (q * np.sign(np.diag(r))).T
    group, area = planar_groups(v, t)
    share = np.bincount(group, weights=area) / area.sum()
    big = np.flatnonzero(share >= 0.01)
    label = np.full(len(share), -1, np.int64)
    label[big] = np.arange(len(big))
    s = Scene()
    s.v, s.t, s.lab, s.n = list(v), [list(x) for x in t], list(label[group]), len(v)
    radius = np.linalg.norm(v, axis=1).max()
    stations = []
    for k, el in enumerate([-20, 10, 40, 70] * 2):
        az, el = np.radians(45 * k + rng.uniform(-10, 10)), np.radians(el + rng.uniform(-5, 5))
        stations.append(0.8 * np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)]))
    return scan(s, stations, rng, 0.07, 0.0003, max_range=2.0, aim=([0, 0, 0], radius))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scene", choices=["room", "house", "airborne", "halls", "street", "avenue", "object"])
    ap.add_argument("--mesh", help="object: the OFF mesh to scan")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--output", required=True)
    ap.add_argument("--strips", type=int, default=1, help="airborne: overlapping flight strips (default 1)")
    a = ap.parse_args()
    rng = np.random.default_rng(a.seed)
    scenes = {"room": room, "house": house, "airborne": lambda r: airborne(r, a.strips),
              "halls": lambda r: halls(r, a.strips), "street": street, "avenue": avenue,
              "object": lambda r: scanned_object(r, a.mesh)}
    pts, labels = scenes[a.scene](rng)
    # Shuffle (scanner order would make every neighbour query trivial).
    perm = rng.permutation(len(pts))
    pts, labels = pts[perm], labels[perm]
    with open(a.output, "w") as f:
        for p, l in zip(pts, labels):
            f.write(f"{p[0]:.5f} {p[1]:.5f} {p[2]:.5f} {int(l)}\n")
    u, c = np.unique(labels[labels >= 0], return_counts=True)
    print(json.dumps({"scene": a.scene, "seed": a.seed, "points": int(len(pts)),
                      "labelled": int((labels >= 0).sum()), "structures": int(len(u)),
                      "structures_1000": int((c >= 1000).sum())}))


if __name__ == "__main__":
    sys.exit(main())
