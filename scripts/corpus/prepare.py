#!/usr/bin/env python3
"""Builds the evaluation corpus of issue 26 (scripts/corpus/README.md):
raw downloads under $ANISO_ALPHA_CORPUS/raw (default /work/corpus/raw) in,
prepared labelled scans under $ANISO_ALPHA_CORPUS/prepared out, every step
deterministic, every prepared file checked against the manifest's point
count and SHA-256.

    python3 scripts/corpus/prepare.py --acquire        # raw files (see below)
    python3 scripts/corpus/prepare.py                  # prepare and check all
    python3 scripts/corpus/prepare.py --scans ahn_2386_9702,mosd_test0
    python3 scripts/corpus/prepare.py --update         # record new sizes/hashes

--acquire places the raw files: from Debian (`apt-get download` of the
package version in the manifest, unpacked), from snapshots of public
repositories already on this machine under /work/.mirror (the search tool's
`fetch`; the file is taken with `git show COMMIT:PATH` at the manifest's
commit), and by running scripts/simulate_scan.py for simulated scans.

Needs: numpy, scipy, laspy with lazrs (AHN .laz), open3d (the simulator
and the Open3D normals variants).
"""
import argparse
import json
import os
import shutil
import struct
import subprocess
import sys
import tarfile

import numpy as np
from scipy import ndimage
from scipy.spatial import cKDTree

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import MANIFEST, PREPARED, RAW, ROOT, load_manifest, prepared_path, read_ply, sha256, write_ply  # noqa: E402

MIRRORS = os.environ.get("ANISO_ALPHA_MIRRORS", "/work/.mirror")


# ---------------------------------------------------------------- acquire

def raw_path(scan):
    return os.path.join(RAW, scan["raw"])


def acquire(scan):
    """Places the scan's raw file under RAW (nothing if it is there)."""
    dst = raw_path(scan)
    if os.path.exists(dst):
        return
    os.makedirs(os.path.dirname(dst), exist_ok=True)
    src = scan["source"]
    if src["type"] == "github":
        repo = os.path.join(MIRRORS, src["repo"].replace("/", "+"), "repo")
        if not os.path.isdir(repo):
            raise SystemExit(f"{scan['name']}: no snapshot of {src['repo']} under {MIRRORS} "
                             "(bring it with the search tool's fetch)")
        blob = subprocess.run(["git", "-C", repo, "show", f"{src['commit']}:{src['path']}"],
                              check=True, capture_output=True).stdout
        with open(dst, "wb") as f:
            f.write(blob)
    elif src["type"] == "debian":
        from_debian(src, dst)
    elif src["type"] == "simulated":
        extra = []
        if "mesh" in src:
            mesh = os.path.join(RAW, src["mesh"]["raw"])
            if not os.path.exists(mesh):
                os.makedirs(os.path.dirname(mesh), exist_ok=True)
                from_debian(src["mesh"], mesh)
            extra = ["--mesh", mesh]
        subprocess.run([sys.executable, os.path.join(ROOT, src["script"]), src["scene"], "--seed",
                        str(src["seed"]), "--output", dst, *extra], check=True, capture_output=True)
    else:
        raise SystemExit(f"{scan['name']}: unknown source type {src['type']}")


def from_debian(src, dst):
    """Extracts `src["path"]` (archive:member) of a Debian package to `dst`."""
    deb_dir = os.path.join(RAW, "debian")
    os.makedirs(deb_dir, exist_ok=True)
    deb = os.path.join(deb_dir, f"{src['package']}_{src['version']}_all.deb")
    if not os.path.exists(deb):
        subprocess.run(["apt-get", "download", f"{src['package']}={src['version']}"], cwd=deb_dir,
                       check=True)
    unpacked = os.path.join(deb_dir, src["package"])
    if not os.path.isdir(unpacked):
        subprocess.run(["dpkg-deb", "-x", deb, unpacked], check=True)
    archive, member = src["path"].split(":")
    with tarfile.open(os.path.join(unpacked, archive)) as t:
        with t.extractfile(member) as fin, open(dst, "wb") as fout:
            shutil.copyfileobj(fin, fout)


# ---------------------------------------------------------------- geometry helpers

def pca_normals(xyz, k):
    """Unit normals: the smallest principal axis of each point's k nearest neighbours."""
    _, nn = cKDTree(xyz).query(xyz, k=k)
    nb = xyz[nn] - xyz[nn].mean(axis=1, keepdims=True)
    cov = np.einsum("nki,nkj->nij", nb, nb)
    _, vec = np.linalg.eigh(cov)
    return vec[:, :, 0]


def components(xyz, cell):
    """Connected components of the occupied cells of a grid of side `cell`
    (26-neighbourhood): one id per point, 0-based, in order of first point."""
    key = np.floor((xyz - xyz.min(axis=0)) / cell).astype(np.int64)
    shape = key.max(axis=0) + 1
    if np.prod(shape) > 3e8:
        raise SystemExit(f"grid of {shape} cells too large for cell {cell}")
    occ = np.zeros(shape, dtype=bool)
    occ[key[:, 0], key[:, 1], key[:, 2]] = True
    lab, _ = ndimage.label(occ, structure=np.ones((3, 3, 3), bool))
    ids = lab[key[:, 0], key[:, 1], key[:, 2]]
    _, first, inv = np.unique(ids, return_index=True, return_inverse=True)
    order = np.argsort(np.argsort(first))
    return order[inv]


def voxel_first(xyz, side):
    """Indices of the first point (in file order) of each voxel of `side`."""
    _, idx = np.unique(np.floor(xyz / side).astype(np.int64), axis=0, return_index=True)
    return np.sort(idx)


def dominant_axis(normals, candidates, cos_tol):
    """The direction (up to sign) that most normals lie within acos(cos_tol) of,
    refined as the principal axis of those normals."""
    support = np.abs(normals @ candidates.T) > cos_tol
    best = candidates[np.argmax(support.sum(axis=0))]
    near = normals[np.abs(normals @ best) > cos_tol]
    _, vec = np.linalg.eigh(near.T @ near)
    return vec[:, -1]


# ---------------------------------------------------------------- readers

def lzf_decompress(src, out_len):
    """LZF (liblzf), as PCL's binary_compressed PCD uses it."""
    out = bytearray(out_len)
    i = o = 0
    n = len(src)
    while i < n:
        ctrl = src[i]
        i += 1
        if ctrl < 32:
            ln = ctrl + 1
            out[o:o + ln] = src[i:i + ln]
            i += ln
            o += ln
        else:
            ln = ctrl >> 5
            if ln == 7:
                ln += src[i]
                i += 1
            ref = o - ((ctrl & 0x1F) << 8) - src[i] - 1
            i += 1
            ln += 2
            if ref + ln <= o:
                out[o:o + ln] = out[ref:ref + ln]
                o += ln
            else:
                for _ in range(ln):
                    out[o] = out[ref]
                    o += 1
                    ref += 1
    return bytes(out)


def read_pcd_compressed(path):
    """A binary_compressed PCD: dict field -> array (each field COUNT 1)."""
    with open(path, "rb") as f:
        data = f.read()
    end = data.index(b"DATA binary_compressed\n") + len(b"DATA binary_compressed\n")
    head = dict(line.split(" ", 1) for line in data[:end].decode().splitlines() if not line.startswith("#"))
    names = head["FIELDS"].split()
    sizes = [int(s) for s in head["SIZE"].split()]
    types = head["TYPE"].split()
    n = int(head["POINTS"])
    comp, unc = struct.unpack("<II", data[end:end + 8])
    raw = lzf_decompress(data[end + 8:end + 8 + comp], unc)
    out, off = {}, 0
    for name, size, typ in zip(names, sizes, types):
        dt = {"F": "<f", "U": "<u", "I": "<i"}[typ] + str(size)
        out[name] = np.frombuffer(raw, dt, n, off)
        off += size * n
    return out


def prepare_mosd(scan):
    """OSD/mOSD Kinect frame: table parts (labels 1-9) are planes as labelled;
    each box object (labels >= 20, one per disjoint part) is split into its
    faces; objects listed in `nonplanar_objects` (cylinders) are not planes."""
    f = read_pcd_compressed(raw_path(scan))
    ok = np.isfinite(f["z"]) & (f["label"] > 0)
    xyz = np.stack([f["x"][ok], f["y"][ok], f["z"][ok]], axis=1).astype(np.float64)
    lab = f["label"][ok].astype(np.int64)
    p = scan["prepare"]
    keep = voxel_first(xyz, p["voxel"])
    xyz, lab = xyz[keep], lab[keep]
    plane = -np.ones(len(xyz), np.int32)
    cls = np.zeros(len(xyz), np.int32)
    nid = 0
    for t in np.unique(lab[lab < 10]):
        plane[lab == t] = nid
        cls[lab == t] = 1
        nid += 1
    cos_tol = np.cos(np.radians(20))
    for obj in np.unique(lab[lab >= 20]):
        m = np.where(lab == obj)[0]
        if p.get("objects") == "nonplanar" or len(m) < 50:
            cls[m] = 3
            continue
        pts = xyz[m]
        nrm = pca_normals(pts, min(16, len(m)))
        nrm[np.einsum("ij,ij->i", nrm, pts) > 0] *= -1  # towards the camera at the origin
        cand = nrm[:: max(1, len(m) // 400)]
        a1 = dominant_axis(nrm, cand, cos_tol)
        rest = nrm[np.abs(nrm @ a1) < np.sin(np.radians(20))]
        a2 = dominant_axis(rest, rest[:: max(1, len(rest) // 400)], cos_tol) if len(rest) >= 10 else \
            np.cross(a1, [1.0, 0.0, 0.0] if abs(a1[0]) < 0.9 else [0.0, 1.0, 0.0])
        a2 = a2 - (a2 @ a1) * a1
        a2 /= np.linalg.norm(a2)
        axes = np.stack([a1, a2, np.cross(a1, a2)])
        d = nrm @ axes.T
        k = np.argmax(np.abs(d), axis=1)
        face = 2 * k + (d[np.arange(len(m)), k] > 0)
        for fc in np.unique(face):
            fm = m[face == fc]
            comp = components(xyz[fm], p["cell"])
            plane[fm] = nid + comp
            nid += comp.max() + 1
        cls[m] = 2
    return xyz, plane, -np.ones(len(xyz), np.int32), cls, None


# Mapped classes of the airborne tiles (the manifest repeats them).
AIR = {"other": 0, "ground": 1, "roof_flat": 2, "roof_E": 3, "roof_N": 4, "roof_W": 5, "roof_S": 6,
       "wall": 7, "vegetation": 8}


def prepare_asprs(scan):
    """Airborne LAS/LAZ with ASPRS classes: ground (2, 11) is one plane per
    connected component; building points (6) are split by their PCA normal
    into flat roofs, pitched roofs by facing azimuth (E/N/W/S quadrants of
    the projected x = east, y = north) and walls, each one plane per
    connected component; everything else is not a plane."""
    import laspy

    las = laspy.read(raw_path(scan))
    xyz = np.stack([np.asarray(las.x), np.asarray(las.y), np.asarray(las.z)], axis=1)
    c = np.asarray(las.classification).astype(np.int64)
    p = scan["prepare"]
    cls = np.zeros(len(xyz), np.int32)
    cls[np.isin(c, [3, 4, 5])] = AIR["vegetation"]
    cls[np.isin(c, [2, 11])] = AIR["ground"]
    b = np.where(c == 6)[0]
    n = pca_normals(xyz[b], p["k"])
    n[n[:, 2] < 0] *= -1
    az = np.degrees(np.arctan2(n[:, 1], n[:, 0])) % 360
    quad = np.array([AIR["roof_E"], AIR["roof_N"], AIR["roof_W"], AIR["roof_S"]])[((az + 45) % 360 // 90).astype(int)]
    bc = np.where(n[:, 2] > 0.95, AIR["roof_flat"], np.where(n[:, 2] > 0.3, quad, AIR["wall"]))
    cls[b] = bc
    plane = -np.ones(len(xyz), np.int32)
    nid = 0
    for k in [AIR["ground"], AIR["roof_flat"], AIR["roof_E"], AIR["roof_N"], AIR["roof_W"], AIR["roof_S"],
              AIR["wall"]]:
        m = np.where(cls == k)[0]
        if len(m) == 0:
            continue
        comp = components(xyz[m], p["cell"])
        plane[m] = nid + comp
        nid += comp.max() + 1
    return xyz, plane, -np.ones(len(xyz), np.int32), cls, None


def prepare_cgal(scan):
    """CGAL's labelled scans: `segment_index` is the plane; the file's normals kept."""
    v = read_ply(raw_path(scan)) if _is_binary_ply(raw_path(scan)) else _read_ascii_ply(raw_path(scan))
    xyz = np.stack([v["x"], v["y"], v["z"]], axis=1).astype(np.float64)
    nrm = np.stack([v["nx"], v["ny"], v["nz"]], axis=1).astype(np.float32)
    plane = v["segment_index"].astype(np.int32)
    return xyz, plane, -np.ones(len(xyz), np.int32), (plane >= 0).astype(np.int32), nrm


def _is_binary_ply(path):
    with open(path, "rb") as f:
        return b"binary_little_endian" in f.read(200)


def _read_ascii_ply(path):
    with open(path, "rb") as f:
        lines = f.read().decode().splitlines()
    end = lines.index("end_header")
    names = [ln.split()[2] for ln in lines[:end] if ln.startswith("property ")]
    n = int([ln for ln in lines if ln.startswith("element vertex")][0].split()[2])
    a = np.loadtxt(lines[end + 1:end + 1 + n], ndmin=2)
    return {nm: a[:, i] for i, nm in enumerate(names)}


def prepare_sim(scan):
    """scripts/simulate_scan.py output (x y z label), one point per voxel.
    room/house/object: the label is the plane; street and avenue: the label is the
    line structure (pole, arm, crossbar, cable, sign post), and their
    planes are unlabelled."""
    a = np.loadtxt(raw_path(scan))
    a = a[voxel_first(a[:, :3], scan["prepare"]["voxel"])]
    if "crop" in scan["prepare"]:
        lo, hi = np.array(scan["prepare"]["crop"][0]), np.array(scan["prepare"]["crop"][1])
        a = a[np.all((a[:, :3] >= lo) & (a[:, :3] <= hi), axis=1)]
    xyz, lab = a[:, :3], a[:, 3].astype(np.int32)
    none = -np.ones(len(xyz), np.int32)
    if scan["source"]["scene"] in ("street", "avenue"):
        return xyz, none, lab, (lab >= 0).astype(np.int32), None
    return xyz, lab, none, (lab >= 0).astype(np.int32), None


READERS = {"mosd": prepare_mosd, "asprs": prepare_asprs, "cgal": prepare_cgal, "sim": prepare_sim}


def add_normals(xyz, spec):
    """A normals variant: Open3D's estimate_normals (signs as it leaves them),
    or PCA over k neighbours oriented towards a viewpoint (as PCL's
    flipNormalTowardsViewpoint)."""
    if spec["tool"] == "open3d":
        import open3d as o3d

        pc = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(xyz))
        pc.estimate_normals(o3d.geometry.KDTreeSearchParamHybrid(radius=spec["radius"], max_nn=spec["max_nn"]))
        return np.asarray(pc.normals).astype(np.float32)
    if spec["tool"] == "pca":
        n = pca_normals(xyz, spec["k"])
        view = 0.5 * (xyz.min(axis=0) + xyz.max(axis=0)) if spec["viewpoint"] == "centre" else np.array(spec["viewpoint"])
        n[np.einsum("ij,ij->i", n, view - xyz) < 0] *= -1
        return n.astype(np.float32)
    raise SystemExit(f"unknown normals tool {spec['tool']}")


def prepare(scan):
    xyz, plane, line, cls, nrm = READERS[scan["reader"]](scan)
    if "normals" in scan:
        nrm = add_normals(xyz, scan["normals"])
    os.makedirs(PREPARED, exist_ok=True)
    out = prepared_path(scan)
    write_ply(out, xyz, plane, line, cls, nrm)
    sizes, counts = np.unique(plane[plane >= 0], return_counts=True)
    return {"points": int(len(xyz)), "sha256": sha256(out),
            "planes": int(len(sizes)), "planes_1k": int(np.sum(counts >= 1000)),
            "plane_points": int(np.sum(plane >= 0)), "line_points": int(np.sum(line >= 0)),
            "lines": int(len(np.unique(line[line >= 0])))}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--acquire", action="store_true", help="place the raw files first")
    ap.add_argument("--scans", default="", help="comma-separated names (default: all)")
    ap.add_argument("--update", action="store_true", help="write the new counts and hashes into the manifest")
    a = ap.parse_args()
    man = load_manifest()
    names = [s for s in a.scans.split(",") if s]
    bad = 0
    for scan in man["scans"]:
        if names and scan["name"] not in names:
            continue
        if a.acquire:
            acquire(scan)
        got = prepare(scan)
        want = scan.get("prepared", {})
        same = want.get("points") == got["points"] and want.get("sha256") == got["sha256"]
        # A simulated scan's coordinates come from Open3D's ray caster, whose
        # last digits vary between machines: the same points and labels in
        # other bytes. Its counts are still checked.
        near = scan.get("simulated") and all(want.get(k) == v for k, v in got.items() if k != "sha256")
        verdict = "ok" if same else "ok (counts; bytes of this machine)" if near else "CHANGED" if want else "new"
        bad += not same and not near and not a.update
        print(f"{scan['name']:24s} {got['points']:8d} points  {got['planes_1k']:3d} planes >= 1k  "
              f"{got['line_points']:6d} line points  {verdict}", flush=True)
        scan["prepared"] = got
    if a.update:
        with open(MANIFEST, "w") as f:
            json.dump(man, f, indent=1)
            f.write("\n")
    if bad:
        sys.exit(f"{bad} prepared file(s) differ from the manifest")


if __name__ == "__main__":
    main()
