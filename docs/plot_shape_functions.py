#!/usr/bin/python3
"""Plot the 1D basis of every shape family from the real C++ code (docs/shape-functions.png).

Each family is evaluated by build/release/cairn_shape_probe (verification/node_force_integration/
shape_probe.cpp), which calls ShapeFamily::build exactly as a simulation does, for particles swept
across a 1D grid of 6 cells (h = 1, faces at 0 and 6, not periodic). The curve of node i is
S_i(x_p) as a function of the particle position x_p. GIMP and CPDI families use a particle of
initial size l_p0 = h/2 (two particles per cell); cpGIMP, CPDI and B2CPDI are drawn for a particle
stretched by F = 1.6 (dashed, cpGIMP / CPDI) next to the undeformed one.

Usage: docs/plot_shape_functions.py [--probe build/release/cairn_shape_probe] [--out docs/shape-functions.png]
"""
import argparse
import subprocess
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
CELLS = 6
L0 = 0.5

# (family, title, smoothing length, deformation F (1D), note)
PANELS = [
    ("linear", "linear (seed 003 Eq. 17)", 0.0, 1.0),
    ("ugimp", "ugimp, l = h/2 (Sec. 4.1)", 0.5, 1.0),
    ("ugimp", "ugimp, l = h: the quadratic B-spline", 1.0, 1.0),
    ("gimp", "gimp, l_p = l_p0 = h/2 (Eq. 29)", 0.0, 1.0),
    ("cpgimp", "cpgimp, l_p = l_p0 F, F = 1.6", 0.0, 1.6),
    ("b2gimp", "b2gimp, l_p0 = h/2 (seed 000 2.1)", 0.0, 1.0),
    ("cpdi", "cpdi, F = 1.6 (seed 000 2.1)", 0.0, 1.6),
    ("b2cpdi", "b2cpdi, F = 1.6 (seed 000 2.1)", 0.0, 1.6),
    ("bspline2", "bspline2, ghost nodes (Eq. 21)", 0.0, 1.0),
    ("bspline3", "bspline3, ghost nodes", 0.0, 1.0),
    ("bspline2_open", "bspline2_open, order 3 open knots (Eq. 22-23)", 0.0, 1.0),
    ("bspline3_open", "bspline3_open, order 4 open knots (Eq. 22-23)", 0.0, 1.0),
]


def evaluate(probe, family, smoothing, F, xs):
    """{dof position: S(xs)} from the probe's stencils."""
    lines = "\n".join(f"{x!r} {L0!r} {L0!r} {F!r}" for x in xs) + "\n"
    cmd = [str(probe), "--family", family, "--dim", "1", "--cells", str(CELLS), "--h", "1",
           "--origin", "0", "--smoothing", str(smoothing), "--mode", "stencils"]
    out = subprocess.run(cmd, input=lines, capture_output=True, text=True, check=True).stdout
    data = np.loadtxt(out.splitlines())
    curves = {}
    for p, pos, S, _ in data:
        curves.setdefault(round(pos, 9), np.zeros(len(xs)))[int(p)] = S
    return curves


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--probe", default=str(REPO / "build" / "release" / "cairn_shape_probe"))
    ap.add_argument("--out", default=str(REPO / "docs" / "shape-functions.png"))
    args = ap.parse_args()
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(4, 3, figsize=(13, 11), sharex=True, sharey=True)
    for ax, (family, title, smoothing, F) in zip(axes.flat, PANELS):
        # Families reaching ghost nodes are swept over the whole domain; the stretched GIMP/CPDI
        # domains stay inside the ghost layers.
        xs = np.linspace(0.0, CELLS, 1201)
        curves = evaluate(args.probe, family, smoothing, F, xs)
        for k, (pos, S) in enumerate(sorted(curves.items())):
            ax.plot(xs, S, lw=1.2, color=f"C{k % 10}")
            if 0 <= pos <= CELLS:
                ax.plot([pos], [0.0], "|", color=f"C{k % 10}", ms=8)
        total = np.sum(list(curves.values()), axis=0)
        ax.plot(xs, total, "k:", lw=0.8)
        ax.set_title(title, fontsize=9)
        ax.axvline(0, color="grey", lw=0.6)
        ax.axvline(CELLS, color="grey", lw=0.6)
        ax.grid(True, alpha=0.3)
    for ax in axes[-1]:
        ax.set_xlabel("particle position x_p / h (faces at 0 and 6)")
    for ax in axes[:, 0]:
        ax.set_ylabel("S_i(x_p)")
    fig.suptitle("1D bases of the Cairn shape families, evaluated by ShapeFamily::build "
                 "(ticks: dof positions; dotted: sum = 1)", fontsize=11)
    fig.tight_layout()
    fig.savefig(args.out, dpi=100)
    print(args.out)


if __name__ == "__main__":
    main()
