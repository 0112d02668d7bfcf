#!/usr/bin/env python3
"""Growth of `detect` (automatic mode) with the number of points at
constant density, and with the number of threads (issue 27): copies of a
scan laid out on a grid, from 1 copy to many. By default the CGAL ball
scan (the fixture, 31,374 points), each copy 1.5 object sizes from the
next; `--scan` takes any binary PLY (e.g. an airborne tile of the corpus,
scripts/corpus/) and `--spacing 1` lays its copies edge to edge, as the
tiles of one survey: the ground of every copy is then one plane across the
tiles, and every roof has a coplanar twin in each copy (the case where
merging coplanar parts was quadratic).

Each row is one run: copies × `--regions` × `--threads` (each a comma
list; `--threads 1,16` gives the speed-up, and the `labels` column, the
first digits of the part labels' SHA-256, shows that every thread count
gave the same labels). Prints wall time, peak RSS, microseconds per
point, planes found per copy, the CLI's phases (`--timings`) and, when the
scan has a truth column `plane` (scripts/corpus/), the per-point plane F1
of the copies. `--regions` passes detect's `--regions` (`auto`: region by
region above 1,000,000 points, the CLI's default; `off`: one whole run).
With `--peer` (scripts/peers/cgal_shapes.cpp), CGAL's Efficient RANSAC
(one thread) runs on the same cloud in the same loop (`--peer-args`, e.g.
the scan's best preset of scripts/bench_corpus.py; `--peer-copies` limits
the sizes it runs on), and its rows get its wall time, peak RSS and our
ratios to them (each thread count's). `--inputs ply,laz` runs
each row on the copies as a binary PLY and as one LAZ file (laspy with
lazrs; coordinates quantised to 1 mm first, the PLY holding the same
values): the CLI reads a PLY whole and a LAS/LAZ region run a piece of
2^20 points at a time, never whole, so the two rows compare the memory of
the two reads on the same points (and their labels must agree). `--deadline S` skips the runs that
would start after S seconds and caps each run's timeout at what is left
(the device machine's one prepared script); `--json FILE` appends every
row as one JSON object as soon as it is measured.

    python3 scripts/bench_scaling.py [--bin target/release/aniso-alpha] [--copies 1,4,16,32]
        [--scan FILE.ply --spacing 1] [--timeout S] [--threads 1,2] [--regions auto,off]
        [--peer cgal_shapes --peer-args "--epsilon 0.15 --cluster-epsilon 0.49 --min-points 100"]
        [--peer-copies 16] [--inputs ply,laz] [--deadline S] [--json FILE]

Needs numpy (and laspy with lazrs for `--inputs laz`); GNU time
(`/usr/bin/time`, Debian `time`) for the peak RSS, else /proc's VmHWM
read while the command runs.
"""
import argparse
import hashlib
import json
import os
import signal
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
from bench_real import read_ply, score  # noqa: E402

sys.path.insert(0, os.path.join(ROOT, "scripts", "corpus"))
from common import read_ply as read_any_ply  # noqa: E402


class Clock:
    """The script's time budget (`--deadline`): what is left of it."""

    def __init__(self, deadline):
        self.start = time.perf_counter()
        self.deadline = deadline

    def left(self):
        if self.deadline is None:
            return None
        return self.deadline - (time.perf_counter() - self.start)

    def timeout(self, per_run):
        """A run's timeout: `per_run` capped at what is left (None: none)."""
        left = self.left()
        if left is None:
            return per_run
        return left if per_run is None else min(per_run, left)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", default=os.path.join(ROOT, "target/release/aniso-alpha"))
    ap.add_argument("--copies", default="1,4,16,32")
    ap.add_argument("--threads", default=None, help="thread counts, a comma list (default: the CLI's, all cores)")
    ap.add_argument("--scan", default=None, help="a binary PLY to copy (default: CGAL's ball)")
    ap.add_argument("--spacing", type=float, default=1.5,
                    help="copy pitch in units of the scan's extent (1: edge to edge)")
    ap.add_argument("--timeout", type=float, default=None, help="seconds per run, ours and the peer's (then: > timeout)")
    ap.add_argument("--deadline", type=float, default=None, help="seconds for the whole script")
    ap.add_argument("--peer", default=None, help="CGAL peer binary (scripts/peers/cgal_shapes.cpp)")
    ap.add_argument("--peer-args", default="", help="its options, one string")
    ap.add_argument("--peer-copies", default=None, help="the copies the peer runs on (default: all)")
    ap.add_argument("--regions", default=None,
                    help="detect's --regions, a comma list (SIDE, auto or off; default: the CLI's, auto)")
    ap.add_argument("--json", default=None, help="append each row to this file as one JSON object")
    ap.add_argument("--inputs", default="ply", help="input formats, a comma list of ply and laz")
    a = ap.parse_args()
    truth = None
    if a.scan:
        v = read_any_ply(a.scan)
        pts = np.stack([v["x"], v["y"], v["z"]], axis=1).astype(np.float64)
        if "plane" in v.dtype.names:
            truth = v["plane"].astype(np.int64)
    else:
        pts, _ = read_ply(os.path.join(ROOT, "crates/aniso-alpha/tests/fixtures/real/ball.ply"))
    lo, hi = pts.min(0), pts.max(0)
    pitch = a.spacing * (hi - lo)
    threads = a.threads.split(",") if a.threads else [None]
    regions = a.regions.split(",") if a.regions else [None]
    peer_copies = None if a.peer_copies is None else set(map(int, a.peer_copies.split(",")))
    clock = Clock(a.deadline)
    peer_cols = " RANSAC wall s | RANSAC RSS MiB | wall / RANSAC | RSS / RANSAC |" if a.peer else ""
    f1_col = " plane F1 |" if truth is not None else ""
    inputs = a.inputs.split(",")
    print("| copies | points | input | regions | threads | wall s | peak RSS MiB | µs / point | parts | parts / copy"
          " | labels | phases (s) |" + f1_col + peer_cols)
    print("|---:|---:|---|---|---:|---:|---:|---:|---:|---:|---|---|" + ("---:|" if truth is not None else "")
          + ("---:|" * 4 if a.peer else ""))
    with tempfile.TemporaryDirectory() as tmp:
        for c in map(int, a.copies.split(",")):
            side = int(np.ceil(np.sqrt(c)))
            cloud = np.concatenate([pts + np.array([pitch[0] * (k % side), pitch[1] * (k // side), 0.0])
                                    for k in range(c)])
            files = {"ply": os.path.join(tmp, "copies.ply")}
            if "laz" in inputs:
                files["laz"] = os.path.join(tmp, "copies.laz")
                cloud = write_laz(files["laz"], cloud)
            write_xyz_ply(files["ply"], cloud)
            peer = None
            if a.peer and (peer_copies is None or c in peer_copies):
                peer = measure_peer(a, clock, cloud, tmp)
            for reg in regions:
                for th in threads:
                    for fmt in inputs:
                        row = measure_ours(a, clock, files[fmt], c, len(cloud), reg, th, truth, tmp)
                        row["input"] = fmt
                        print_row(a, row, peer, truth is not None)
            del cloud


def write_laz(path, xyz):
    """`xyz` quantised to 1 mm as one LAZ file (point format 0, laspy):
    returns the coordinates the file holds, as a LAS reader computes them
    (integer × scale + offset)."""
    import laspy

    offset = np.floor(xyz.min(0))
    scale = np.array([0.001, 0.001, 0.001])
    ints = np.round((xyz - offset) / scale).astype(np.int64)
    header = laspy.LasHeader(point_format=0, version="1.2")
    header.offsets, header.scales = offset, scale
    las = laspy.LasData(header)
    las.X, las.Y, las.Z = ints[:, 0], ints[:, 1], ints[:, 2]
    las.write(path)
    return ints * scale + offset


def write_xyz_ply(path, xyz):
    """`xyz` as a binary PLY of double x y z (what `detect` reads fastest)."""
    head = f"ply\nformat binary_little_endian 1.0\nelement vertex {len(xyz)}\n"
    head += "property double x\nproperty double y\nproperty double z\nend_header\n"
    with open(path, "wb") as f:
        f.write(head.encode())
        f.write(np.ascontiguousarray(xyz, dtype="<f8").tobytes())


def measure_ours(a, clock, f, c, n, reg, th, truth, tmp):
    """One run of `detect` on `f`: a row's fields (wall None when it did
    not finish in time, or was not started for lack of it)."""
    row = dict(copies=c, points=n, regions=reg or "auto", threads=th or "all", wall=None)
    timeout = clock.timeout(a.timeout)
    if timeout is not None and timeout <= 1:
        row["skipped"] = True
        return row
    rep = os.path.join(tmp, "r.json")
    lab = os.path.join(tmp, "parts.txt")
    args = [a.bin, "detect", f, "--structure", "planes", "--report", rep,
            "--part-labels", lab, "--quiet", "--timings"]
    if th:
        args += ["--threads", th]
    if reg:
        args += ["--regions", reg]
    try:
        wall, rss, _, err = run_measured(args, timeout)
    except subprocess.TimeoutExpired:
        row["timeout"] = timeout
        return row
    phases = next((json.loads(x) for x in err.splitlines() if x.startswith("{")), {})
    report = json.load(open(rep))
    # A whole run reports structures and their parts; a region run its
    # joined parts.
    parts = (len(report["parts"]) if "regions" in report
             else sum(len(s.get("parts", [])) for s in report["structures"]))
    del report
    with open(lab, "rb") as g:
        raw = g.read()
    row.update(wall=wall, rss=rss, parts=parts, labels=hashlib.sha256(raw).hexdigest()[:12], phases=phases)
    if truth is not None:
        pred = np.array(raw.split(), dtype=np.int64)
        row["f1"] = score(np.tile(truth, c), pred)["f1"]
    return row


def measure_peer(a, clock, cloud, tmp):
    """CGAL's Efficient RANSAC on the cloud: {wall, rss} (wall None when
    it did not finish in time)."""
    timeout = clock.timeout(a.timeout)
    if timeout is not None and timeout <= 1:
        return dict(wall=None, timeout=0)
    xyz = os.path.join(tmp, "copies.xyz")
    np.savetxt(xyz, cloud, fmt="%.5f")
    args = [a.peer, "ransac", xyz, os.path.join(tmp, "peer.txt"), *a.peer_args.split()]
    try:
        wall, rss, _, _ = run_measured(args, timeout)
    except subprocess.TimeoutExpired:
        return dict(wall=None, timeout=timeout)
    return dict(wall=wall, rss=rss)


def print_row(a, row, peer, has_truth):
    """One markdown row (and one JSON line with `--json`)."""
    head = f"| {row['copies']} | {row['points']} | {row.get('input', 'ply')} | {row['regions']} | {row['threads']} |"
    if row["wall"] is None:
        why = "skipped" if row.get("skipped") else f"> {row['timeout']:.0f}"
        print(head + f" {why} | | | | | | |" + (" |" if has_truth else "") + (" | | | |" if a.peer else ""),
              flush=True)
    else:
        ph = ", ".join(f"{k} {v:.1f}" for k, v in row["phases"].items()
                       if k != "total" and isinstance(v, (int, float)))
        line = (head + f" {row['wall']:.2f} | {row['rss']:.0f} | {1e6 * row['wall'] / row['points']:.1f} |"
                f" {row['parts']} | {row['parts'] / row['copies']:.1f} | {row['labels']} | {ph} |")
        if has_truth:
            line += f" {row['f1']:.3f} |"
        if a.peer:
            if peer is None:
                line += " | | | |"
            elif peer["wall"] is None:
                line += f" > {peer['timeout']:.0f} | | | |"
            else:
                line += (f" {peer['wall']:.2f} | {peer['rss']:.0f} | {row['wall'] / peer['wall']:.2f} |"
                         f" {row['rss'] / peer['rss']:.2f} |")
        print(line, flush=True)
    if a.json:
        with open(a.json, "a") as g:
            g.write(json.dumps(dict(row, peer=peer)) + "\n")


def run_measured(args, timeout):
    """`args` to completion: (wall s, peak RSS MiB, stdout, stderr), or
    killed with every process it started after `timeout` seconds, raising
    subprocess.TimeoutExpired. The peak RSS is GNU time's `%M` of the
    command (`/usr/bin/time -o`): the command is forked by `time`, a small
    process. The child's own `ru_maxrss` from `os.wait4` is not used: Linux
    carries the parent's high-water mark into a child across fork and exec,
    so it reports at least this script's RSS (the copies it holds: 1.3 GiB
    at 11M points). Without GNU time (a bare machine), the command's
    `VmHWM` is read from /proc every 20 ms until it exits: the last reading,
    a lower bound of the peak by at most the last 20 ms' growth."""
    gnu_time = os.path.exists("/usr/bin/time")
    with tempfile.TemporaryFile("w+") as out, tempfile.TemporaryFile("w+") as err, \
            tempfile.NamedTemporaryFile("r") as peak:
        cmd = ["/usr/bin/time", "-f", "%M", "-o", peak.name, *args] if gnu_time else list(args)
        t = time.perf_counter()
        p = subprocess.Popen(cmd, stdout=out, stderr=err, text=True, start_new_session=True)
        hwm = 0
        while p.poll() is None:
            if not gnu_time:
                hwm = max(hwm, vm_hwm_kib(p.pid))
            if timeout is not None and time.perf_counter() - t > timeout:
                os.killpg(p.pid, signal.SIGKILL)
                p.wait()
                raise subprocess.TimeoutExpired(args, timeout)
            time.sleep(0.02)
        wall = time.perf_counter() - t
        out.seek(0)
        err.seek(0)
        o, e = out.read(), err.read()
        lines = [x for x in peak.read().splitlines() if x.strip().isdigit()]
    if p.returncode != 0:
        raise subprocess.CalledProcessError(p.returncode, args, o, e)
    return wall, (int(lines[-1]) if gnu_time else hwm) / 1024, o, e


def vm_hwm_kib(pid):
    """The process's peak resident set so far (`VmHWM`, KiB), 0 when gone."""
    try:
        with open(f"/proc/{pid}/status") as f:
            for line in f:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1])
    except OSError:
        pass
    return 0


if __name__ == "__main__":
    main()
