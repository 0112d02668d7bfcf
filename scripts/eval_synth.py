#!/usr/bin/env python3
"""Issue 26's synthetic table: mean per-point F1 (docs/method.md §6) of
`aniso-alpha detect` on the `synth` families, with NO flag but
`--structure`, and the same scenes with the paper's explicit parameters
(which must keep their scores), seeds split into train and held-out.

    python3 scripts/eval_synth.py --bin PATH [--split train|heldout|all]
        [--seeds 1 2 3] [--kinds lines planes crossing polyhedron]
        [--variants base jitter10 random bg3 bg10] [--modes noflag [paper]]
        [--jobs N] [--json out.json] [--md out.md]

Kinds: `synth lines`, `synth planes`, crossing planes (`synth planes
--structures 2 --crossing`), `synth polyhedron`. Variants: base, jitter
0.1 d (`--jitter-d 0.1`), random sampling (`--random-sampling`), 3x and
10x background (`--density 0.03`, `--density 0.1`). Seeds: train 1-5,
held-out 101-105 (fixed with the corpus split, scripts/corpus/README.md);
--seeds overrides both. Modes: `noflag` (`detect SCENE --structure
lines|planes`) and `paper` (scripts/eval_robustness.py's parameters:
lines alpha 1, lambda3 10, min-size 4; planes alpha 1, lambda2 4,
lambda3 8, min-size 20). The default is `noflag` alone, the quick loop for
tuning; `--modes noflag paper` gives the full table. Each labelling is scored by `aniso-alpha eval
--json`.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "corpus"))
from common import write_results  # noqa: E402

SEEDS = {"train": [1, 2, 3, 4, 5], "heldout": [101, 102, 103, 104, 105]}
KINDS = {
    "lines": ("lines", []),
    "planes": ("planes", []),
    "crossing": ("planes", ["--structures", "2", "--crossing"]),
    "polyhedron": ("polyhedron", []),
}
VARIANTS = {
    "base": [],
    "jitter10": ["--jitter-d", "0.1"],
    "random": ["--random-sampling"],
    "bg3": ["--density", "0.03"],
    "bg10": ["--density", "0.1"],
}
VARIANT_NAMES = {"base": "base", "jitter10": "jitter 0.1 d", "random": "random sampling", "bg3": "3x background",
                 "bg10": "10x background"}
PAPER = {
    "lines": ["--alpha", "1", "--lambda3", "10", "--min-size", "4"],
    "planes": ["--alpha", "1", "--lambda2", "4", "--lambda3", "8", "--min-size", "20"],
}


def run(cmd):
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)}: {r.stderr.strip()}")
    return r.stdout


def one(a, tmp, kind, variant, seed, mode):
    scene_kind, extra = KINDS[kind]
    structure = "lines" if scene_kind == "lines" else "planes"
    base = os.path.join(tmp, f"{kind}_{variant}_{seed}_{mode}")
    scene = base + ".xyz"
    run([a.bin, "synth", scene_kind, "--seed", str(seed), "--output", scene, "--quiet", *extra, *VARIANTS[variant]])
    labels = base + ".labels"
    args = [a.bin, "detect", scene, "--structure", structure, "--labels", labels, "--quiet"]
    if mode == "paper":
        args += PAPER[structure]
    t = time.perf_counter()
    run(args)
    wall = time.perf_counter() - t
    ev = json.loads(run([a.bin, "eval", "--truth", scene, "--labels", labels, "--json"]))
    for p in (scene, labels):
        os.remove(p)
    return {"kind": kind, "variant": variant, "seed": seed, "mode": mode, "wall_s": round(wall, 3),
            "f1": ev.get("f1"), "precision": ev.get("precision"), "recall": ev.get("recall")}


def mean(xs):
    xs = [x for x in xs if x is not None]
    return sum(xs) / len(xs) if xs else None


def table(rows, mode, splits, kinds, variants):
    head = "| kind | variant | " + " | ".join(f"{s}: mean F1 (min)" for s in splits) + " |"
    lines = [f"#### {'no flag' if mode == 'noflag' else 'paper parameters'}", "", head,
             "|---|---|" + "---:|" * len(splits)]
    for k in kinds:
        for v in variants:
            cells = []
            for s in splits:
                f1 = [r["f1"] for r in rows if r["mode"] == mode and r["kind"] == k and r["variant"] == v
                      and r["split"] == s]
                cells.append("" if not f1 else f"**{mean(f1):.2f}** ({min(f1):.2f})")
            lines.append(f"| {k} | {VARIANT_NAMES[v]} | " + " | ".join(cells) + " |")
    return lines + [""]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin", required=True)
    ap.add_argument("--split", default="train", choices=["train", "heldout", "all"])
    ap.add_argument("--seeds", type=int, nargs="+", help="these seeds (split 'custom') instead of the split's")
    ap.add_argument("--kinds", nargs="+", default=list(KINDS), choices=list(KINDS))
    ap.add_argument("--variants", nargs="+", default=list(VARIANTS), choices=list(VARIANTS))
    ap.add_argument("--modes", nargs="+", default=["noflag"], choices=["noflag", "paper"],
                    help="noflag (default; about 1 minute a split) and/or paper (about 15-20 minutes a split: "
                         "the box sampler)")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--json")
    ap.add_argument("--md")
    a = ap.parse_args()
    if a.seeds:
        seeds = {"custom": a.seeds}
    else:
        seeds = {s: SEEDS[s] for s in (["train", "heldout"] if a.split == "all" else [a.split])}
    jobs = [(k, v, seed, m, split) for split, ss in seeds.items() for k in a.kinds for v in a.variants
            for seed in ss for m in a.modes]
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="aniso_synth_") as tmp, ThreadPoolExecutor(a.jobs) as ex:
        futs = [(split, ex.submit(one, a, tmp, k, v, seed, m)) for k, v, seed, m, split in jobs]
        rows = []
        for split, f in futs:
            r = f.result()
            r["split"] = split
            rows.append(r)
    splits = list(seeds)
    out = [f"aniso-alpha: `{a.bin}`; seeds {json.dumps(seeds)}; {len(rows)} runs in "
           f"{time.perf_counter() - t0:.0f} s (jobs {a.jobs})", ""]
    for m in a.modes:
        out += table(rows, m, splits, a.kinds, a.variants)
    write_results("\n".join(out), a.md, a.json, {"bin": a.bin, "seeds": seeds, "runs": rows})


if __name__ == "__main__":
    main()
