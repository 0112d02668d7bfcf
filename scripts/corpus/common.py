"""Shared helpers of the evaluation corpus (scripts/corpus/README.md): the
manifest, the prepared-file format, and the paths outside the repository.

Prepared scan: binary little-endian PLY with `double x y z`, optionally
`float nx ny nz` (kept where the source has normals, or added on purpose by
a normals variant), and three `int` truth columns that `aniso-alpha detect`
ignores:

* `plane`: the id of the labelled (or derived) plane the point lies on, or -1;
* `line`: the id of the labelled line structure (pole, wire, crossarm), or -1;
* `cls`: the scan's semantic class code after mapping (the manifest's
  `classes` gives the names), used for per-class recall.
"""
import hashlib
import json
import os

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
MANIFEST = os.path.join(ROOT, "scripts", "corpus", "manifest.json")
CORPUS = os.environ.get("ANISO_ALPHA_CORPUS", "/work/corpus")
RAW = os.path.join(CORPUS, "raw")
PREPARED = os.path.join(CORPUS, "prepared")


def load_manifest():
    with open(MANIFEST) as f:
        return json.load(f)


def prepared_path(scan):
    return os.path.join(PREPARED, scan["name"] + ".ply")


def write_ply(path, xyz, plane, line, cls, normals=None):
    """The prepared file: x y z (double), normals (float) if given, plane line cls (int)."""
    fields = [("x", "<f8"), ("y", "<f8"), ("z", "<f8")]
    if normals is not None:
        fields += [("nx", "<f4"), ("ny", "<f4"), ("nz", "<f4")]
    fields += [("plane", "<i4"), ("line", "<i4"), ("cls", "<i4")]
    rec = np.zeros(len(xyz), dtype=fields)
    rec["x"], rec["y"], rec["z"] = xyz[:, 0], xyz[:, 1], xyz[:, 2]
    if normals is not None:
        rec["nx"], rec["ny"], rec["nz"] = normals[:, 0], normals[:, 1], normals[:, 2]
    rec["plane"], rec["line"], rec["cls"] = plane, line, cls
    types = {"<f8": "double", "<f4": "float", "<i4": "int"}
    head = ["ply", "format binary_little_endian 1.0", f"element vertex {len(xyz)}"]
    head += [f"property {types[t]} {n}" for n, t in fields]
    head += ["end_header"]
    with open(path, "wb") as f:
        f.write(("\n".join(head) + "\n").encode())
        f.write(rec.tobytes())


def read_ply(path):
    """A binary little-endian PLY's vertex element as a numpy record array."""
    with open(path, "rb") as f:
        data = f.read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode("ascii", "replace")
    if "binary_little_endian" not in header:
        raise ValueError(f"{path}: only binary little-endian PLY is read here")
    n = int(header.split("element vertex ")[1].split()[0])
    types = {"float": "<f4", "float32": "<f4", "double": "<f8", "float64": "<f8", "int": "<i4",
             "int32": "<i4", "uint": "<u4", "uchar": "u1", "uint8": "u1", "char": "i1",
             "short": "<i2", "ushort": "<u2"}
    fields = []
    in_vertex = False
    for line in header.splitlines():
        parts = line.split()
        if parts[:1] == ["element"]:
            in_vertex = parts[1] == "vertex"
        elif parts[:1] == ["property"] and in_vertex:
            fields.append((parts[2], types[parts[1]]))
    return np.frombuffer(data[end:], dtype=fields, count=n)


def sha256(path):
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def write_results(text, md, json_path, payload):
    """Prints the tables `text`, and writes them to `md` and `payload` to
    `json_path` where those are given (the benchmark scripts' outputs)."""
    print(text)
    if md:
        with open(md, "w") as f:
            f.write(text + "\n")
    if json_path:
        with open(json_path, "w") as f:
            json.dump(payload, f, indent=1)
