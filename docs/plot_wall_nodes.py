#!/usr/bin/python3
"""Draw the moving wall of seed 000 Sec. 2.5 and the nodes it controls, from the real code
(docs/boundary-conditions.png).

Runs build/release/cairn for one tiny step on a small 2D bar whose right end (x = 1.625, between
two nodes of a 0.25 grid) is a [[wall]] with depth d = 1.5 and v_b = 1 while the bar is at rest,
with linear and with quadratic B-spline grid functions, and reads the grid snapshot: the node
masses (panel A, the blurred edge of Fig. 1A) and the nodes whose updated velocity the wall set
to 1 (panel B, the circled nodes of Fig. 1B).

Usage: docs/plot_wall_nodes.py [--cairn build/release/cairn] [--out docs/boundary-conditions.png]
"""
import argparse
import subprocess
import tempfile
from pathlib import Path

import h5py
import numpy as np

REPO = Path(__file__).resolve().parents[1]
H = 0.25
X_END = 1.625
DEPTH = 1.5


def run(cairn, shape, work):
    out = work / shape
    toml = work / f"{shape}.toml"
    toml.write_text(f"""
[simulation]
dimension = 2
end_time = 1.0e-6
dt = 1.0e-6
[grid]
origin = [-0.5, -0.5]
extent = [3.0, 2.0]
cell_size = {H}
[method]
shape = "{shape}"
[[material]]
name = "m"
model = "linear_elastic"
density = 1.0
youngs_modulus = 1.0
poissons_ratio = 0.0
[[body]]
material = "m"
shape = {{ box = {{ min = [0.0, 0.0], max = [{X_END}, 1.0] }} }}
particles_per_cell = 2
[[wall]]
axis = "x"
inside = "below"
position = {X_END}
velocity = 1.0
depth = {DEPTH}
[output]
directory = "{out}"
every = 1.0e-6
grid_snapshots = true
checkpoints = false
""")
    subprocess.run([cairn, "run", str(toml), "-q"], check=True)
    snap = sorted((out / "snapshots").glob("particles-*.h5"))[-1]
    with h5py.File(snap, "r") as f:
        g = f["grid"]
        mass = g["node_mass"][()]
        vel = g["node_velocity"][()]
        origin = g.attrs["origin"]
        spacing = g.attrs["spacing"]
        xp = f["particles"]["position"][()]
        mp = f["particles"]["mass"][()]
    # node_mass is stored with the x index fastest: shape (ny, nx)
    ny, nx = mass.shape
    xs = origin[0] + spacing[0] * np.arange(nx)
    ys = origin[1] + spacing[1] * np.arange(ny)
    return xs, ys, mass, vel[..., 0], xp, mp


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--cairn", default=str(REPO / "build" / "release" / "cairn"))
    p.add_argument("--out", default=str(REPO / "docs" / "boundary-conditions.png"))
    args = p.parse_args()
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        lin = run(args.cairn, "linear", work)
        quad = run(args.cairn, "bspline2", work)

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(13, 4.8), gridspec_kw={"width_ratios": [1, 1.3]})
    # A: lumped mass along the middle row of nodes, per unit of the interior value.
    for (xs, ys, mass, _, _, _), label, style in ((lin, "linear", "o-"), (quad, "quadratic B-spline", "s-")):
        row = int(np.argmin(np.abs(ys - 0.5)))
        interior = mass[row, int(np.argmin(np.abs(xs - 0.5)))]
        ax1.plot(xs, mass[row] / interior, style, label=f"grid mass, {label}")
    ax1.plot([-0.5, 0.0, 0.0, X_END, X_END, 2.5], [0, 0, 1, 1, 0, 0], "k--", lw=1, label="particle-basis mass")
    ax1.axvline(X_END, color="C3", lw=2)
    ax1.set_xlim(0.75, 2.25)
    ax1.set_xlabel("x")
    ax1.set_ylabel("mass / interior value")
    ax1.set_title("A. the edge of the body is blurred on the grid (seed 000 Fig. 1A)")
    ax1.legend(fontsize=8, loc="lower left")

    xs, ys, mass, vx, xp, _ = quad
    X, Y = np.meshgrid(xs, ys)
    ax2.scatter(xp[:, 0], xp[:, 1], s=6, color="0.6", label="particles")
    has_mass = mass > 0
    ax2.scatter(X[~has_mass], Y[~has_mass], s=8, marker="+", color="0.75")
    ax2.scatter(X[has_mass], Y[has_mass], s=14, color="k", label="nodes with mass")
    controlled = np.abs(vx - 1.0) < 1e-12
    ax2.scatter(X[controlled], Y[controlled], s=150, facecolors="none", edgecolors="C3", lw=1.8,
                label="controlled by the wall")
    ax2.axvspan(X_END - DEPTH * H, X_END, color="C3", alpha=0.08)
    ax2.axvline(X_END, color="C3", lw=2.5)
    ax2.annotate("", xy=(X_END - DEPTH * H, 1.32), xytext=(X_END, 1.32),
                 arrowprops=dict(arrowstyle="<->", color="C3"))
    ax2.text(X_END - DEPTH * H / 2, 1.36, "d = 1.5 cells", ha="center", color="C3", fontsize=9)
    ax2.text(X_END + 0.03, -0.38, "wall x_wall(t), moves with v_b", color="C3", fontsize=9)
    ax2.annotate("", xy=(X_END + 0.3, 1.15), xytext=(X_END, 1.15), arrowprops=dict(arrowstyle="->", color="C3"))
    # Nodes 1 and 2 of Eq. 4 on one row.
    row_y = 0.5
    for label, xn in (("2", 1.25), ("1", 1.0)):
        ax2.annotate(label, (xn, row_y), xytext=(xn - 0.07, row_y + 0.1), fontsize=11, color="C0",
                     fontweight="bold")
    ax2.set_xlim(0.4, 2.3)
    ax2.set_ylim(-0.5, 1.5)
    ax2.set_aspect("equal")
    ax2.set_xlabel("x")
    ax2.set_ylabel("y")
    ax2.set_title("B. quadratic B-splines, d = 1.5: v_i = v_b + grad v_b (x_i - x_wall) (Fig. 1B)")
    ax2.legend(fontsize=8, loc="lower left")
    fig.tight_layout()
    fig.savefig(args.out, dpi=110, bbox_inches="tight")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
