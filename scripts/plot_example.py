#!/usr/bin/env python3
"""Renders docs/example.png (the README's picture) from detection outputs.

    cargo run --release -- detect                       # writes aniso-alpha-example/
    cargo run --release -- synth lines --seed 1 --output lines1.xyz
    cargo run --release -- detect lines1.xyz --structure lines --alpha 1 --lambda3 10 \
        --min-size 4 --labels lines1_labels.txt
    pip install matplotlib && python3 scripts/plot_example.py
"""
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def load(scene, labels, parts=None):
    pts = [[float(x) for x in l.split()[:3]] for l in open(scene)
           if l.strip() and not l.startswith("#")]
    lab = [int(x) for x in open(labels)]
    par = [int(x) for x in open(parts)] if parts else lab
    return pts, lab, par


ex = "aniso-alpha-example/"
panels = [
    ("Fig. 10-like scene: polyhedral surface (190 pts)\nin 800 background points "
     "(λ2=4, λ3=8, α=1, nb_c=20)", ex + "scene.xyz", ex + "labels.txt", ex + "parts.txt", False),
    ("the detected surface (zoom): 1 structure,\n5 planar facets (F1 0.995)",
     ex + "scene.xyz", ex + "labels.txt", ex + "parts.txt", True),
    ("Fig. 12-like scene: 5 lines (50 pts) in 1500 background\npoints "
     "(λ3=10, α=1, nb_c=4): 5/5 lines, F1 0.98", "lines1.xyz", "lines1_labels.txt", None, False),
]
fig = plt.figure(figsize=(15, 5))
for k, (title, scene, labels, parts, zoom) in enumerate(panels):
    pts, lab, par = load(scene, labels, parts)
    ax = fig.add_subplot(1, 3, k + 1, projection="3d")
    bg = [p for p, l in zip(pts, lab) if l < 0]
    fg = [(p, q) for p, l, q in zip(pts, lab, par) if l >= 0]
    if not zoom:
        ax.scatter(*zip(*bg), s=2, c="#bbbbbb", depthshade=False)
    ax.scatter(*zip(*[p for p, _ in fg]), s=14 if zoom else 8, c=[q for _, q in fg],
               cmap="tab10", vmin=0, vmax=9, depthshade=False)
    ax.set_title(title, fontsize=9)
    ax.set_xticks([])
    ax.set_yticks([])
    ax.set_zticks([])
fig.subplots_adjust(left=0.01, right=0.99, top=0.86, bottom=0.02, wspace=0.02)
plt.savefig("docs/example.png", dpi=80)
