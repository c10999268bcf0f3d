"""The 1D bar with a manufactured solution (seed 003 Sec. 5.2, Eq. 47-50; Sec. 6.2, Fig. 10),
shared by verification/bar_1d_mms and verification/bar_1d_mms_order_4ppc.

u(X, t) = A sin(2 pi X) cos(C pi t) on the unit interval (periodic, or with fixed faces: u = 0 at
X = 0 and 1 for all t), driven by the body force of Eq. 49,
neo-Hookean with nu = 0 (sigma = E/2 (F - 1/F), Eq. 50), run to T = 1/C with dt = 4e-6.
Error per particle (Eq. 54): e_p = x_p(T) - X_p - u(X_p, T); max and RMS over particles.

A convergence series is a `Series` (shape family, particles per cell, extra [method] keys, boundary
faces); `run_series` runs it over a list of cell counts and returns one row per run. A new series
(open-knot splines, ghost nodes, ...) is one more `Series(...)` in the case's list; anything that
differs from the periodic default goes into its `method` / `boundary` / `grid` fields.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

import cairn_case as cc

A = 0.05           # displacement amplitude (5 %), seed 003 Sec. 6.2
E = 1.0e4          # Young's modulus
RHO = 1.0          # reference density
C = math.sqrt(E / RHO)  # bar wave speed = 100
T = 1.0 / C        # half a period of the oscillation
DT = 4.0e-6        # fixed time step of Sec. 6.2 (CFL ~0.2 at 512 cells)
PERIODIC = {"x_min": "periodic", "x_max": "periodic"}


@dataclass(frozen=True)
class Series:
    label: str                  # unique; names the runs (<label>_<cells>) and the table
    shape: str                  # method.shape
    ppc: int = 4                # particles per cell
    asserted: bool = True       # False: reported only
    method: dict = field(default_factory=dict, hash=False)    # extra [method] keys
    boundary: dict = field(default_factory=lambda: dict(PERIODIC), hash=False)
    colour: str = "C0"

    @property
    def periodic(self):
        return self.boundary == PERIODIC

    @property
    def faces(self):
        """'periodic', or the face conditions, e.g. 'fixed'."""
        if self.periodic:
            return "periodic"
        return "/".join(sorted(set(self.boundary.values())))

    @property
    def title(self):
        extra = "".join(f", {k} = {v}" for k, v in self.method.items())
        return (f"{self.label} ({self.shape}, {self.ppc} ppc, {self.faces} faces{extra}"
                f"{'' if self.asserted else ', not asserted'})")


def exact_u(X, t):
    return A * np.sin(2 * np.pi * X) * np.cos(C * np.pi * t)


def make_input(series: Series, cells: int, run_dir, header: str = "") -> str:
    u = "A*sin(2*_pi*X)*cos(C*_pi*t)"
    F = "(1 + 2*A*_pi*cos(2*_pi*X)*cos(C*_pi*t))"
    doc = {
        "simulation": {"title": f"1D bar MMS, {series.shape}, {series.ppc} ppc, {series.faces} faces, {cells} cells",
                       "dimension": 1, "mode": "uniaxial", "end_time": T, "dt": DT},
        "constants": {"A": A, "C": C},
        "grid": {"origin": [0.0], "extent": [1.0], "cell_size": 1.0 / cells},
        "method": {"shape": series.shape, "update": "flip", "stress_update": "usl", **series.method},
        "material": [{"name": "bar", "model": "neo_hookean", "form": "ln_j", "density": RHO,
                      "youngs_modulus": E, "poissons_ratio": 0.0}],
        "body": [{"name": "bar", "material": "bar",
                  "shape": {"box": {"min": [0.0], "max": [1.0]}},
                  "particles_per_cell": series.ppc,
                  "displacement": ["A*sin(2*_pi*X)"]}],  # Eq. 47 at t = 0; F = 1 + du/dX (Eq. 48)
        # Eq. 49: b = C^2 pi^2 u (2/F^2 + 1), per unit mass, in the reference coordinate X
        "body_force": {"expression": [f"C^2*_pi^2*{u}*(2/{F}^2 + 1)"]},
        "boundary": dict(series.boundary),
        "output": {"directory": str(run_dir), "every": 0.0, "history_every": T / 10,
                   "checkpoints": False},
    }
    return cc.toml_text(doc, header=header)


def errors(run_dir, periodic=True):
    snap = cc.read_snapshot(cc.snapshots(run_dir)[-1], fields=("position", "displacement"))
    x = snap["position"][:, 0]
    X = x - snap["displacement"][:, 0]
    e = x - X - exact_u(X, snap["time"])
    if periodic:
        e = (e + 0.5) % 1.0 - 0.5          # the domain is periodic with length 1
    order = np.argsort(X)
    return snap["time"], np.abs(e).max(), float(np.sqrt(np.mean(e ** 2))), X[order], e[order]


def run_series(args, series: Series, cells, header: str = ""):
    """Run one series over the cell counts; rows of {cells, h, max, rms, wall, X, e}."""
    rows = []
    for n in cells:
        name = f"{series.label}_{n}"
        run_dir = args.out / name
        toml = args.out / f"{name}.toml"
        toml.write_text(make_input(series, n, run_dir, header))
        wall = cc.run_cairn(args, toml, run_dir)
        t_end, emax, erms, X, e = errors(run_dir, series.periodic)
        if abs(t_end - T) > 1e-12:
            raise RuntimeError(f"{name}: last snapshot at t = {t_end}, expected {T}")
        rows.append({"cells": n, "h": 1.0 / n, "max": emax, "rms": erms, "wall": wall, "X": X, "e": e})
    return rows


def order_between(rows, lo, hi, key="max"):
    """Least-squares order (slope of log error against log h) over lo..hi cells."""
    sel = [r for r in rows if lo <= r["cells"] <= hi]
    return cc.lsq_slope([r["h"] for r in sel], [r[key] for r in sel])


def series_table(series: Series, rows) -> str:
    trows = []
    for i, r in enumerate(rows):
        o_max = o_rms = float("nan")
        if i > 0:
            q = rows[i - 1]
            o_max = math.log(q["max"] / r["max"]) / math.log(q["h"] / r["h"])
            o_rms = math.log(q["rms"] / r["rms"]) / math.log(q["h"] / r["h"])
        trows.append([r["cells"], r["h"], r["max"], o_max, r["rms"], o_rms, r["wall"]])
    return f"### {series.title}\n\n" + cc.table(
        ["cells", "h", "max error", "order", "RMS error", "order", "wall s"], trows,
        ["d", ".5g", ".3e", ".2f", ".3e", ".2f", ".1f"])


def orders_table(results: dict, ranges) -> str:
    """results: label -> rows. ranges: (lo, hi) cell ranges, skipped where a series lacks them."""
    out = []
    for label, rows in results.items():
        have = {r["cells"] for r in rows}
        for lo, hi in ranges:
            if lo in have and hi in have:
                out.append([label, f"{lo}-{hi}", order_between(rows, lo, hi, "max"),
                            order_between(rows, lo, hi, "rms")])
    return "### least-squares orders (slope of log error vs log h)\n\n" + cc.table(
        ["series", "cells", "order (max)", "order (RMS)"], out, ["s", "s", ".2f", ".2f"])


def write_csv(path, results: dict):
    with open(path, "w") as f:
        f.write("series,cells,h,max_error,rms_error,wall_s\n")
        for label, rows in results.items():
            for r in rows:
                f.write(f"{label},{r['cells']},{r['h']!r},{r['max']!r},{r['rms']!r},{r['wall']:.2f}\n")


def plot_errors(ax, series_list, results, cells, slope_ref=None, slope1_ref=None, title=None):
    """Fig. 10 style: max (solid) and RMS (dashed) error against the number of cells."""
    for s in series_list:
        rows = results[s.label]
        n = [r["cells"] for r in rows]
        name = f"{s.shape}, {s.ppc} ppc, {s.faces}"
        ax.loglog(n, [r["max"] for r in rows], "o-", color=s.colour, label=f"{name}, max")
        ax.loglog(n, [r["rms"] for r in rows], "s--", color=s.colour, ms=4, alpha=0.7, label=f"{name}, RMS")
    n = np.array(cells, float)
    if slope_ref:
        e0 = results[slope_ref][0]["max"]
        ax.loglog(n, e0 * (n[0] / n) ** 2, "k:", label="slope 2")
    if slope1_ref:
        e0 = results[slope1_ref][0]["max"]
        ax.loglog(n, e0 * (n[0] / n), "k-.", label="slope 1")
    ax.set_xticks(cells)
    ax.set_xticklabels([str(c) for c in cells])
    ax.minorticks_off()
    ax.set_xlabel("grid cells on [0, 1]")
    ax.set_ylabel("position error at T (Eq. 54)")
    ax.set_title(title or f"1D bar MMS, A = {A}, dt = {DT:g}, T = 1/C")
    ax.legend(fontsize=7)
    ax.grid(True, which="both", alpha=0.3)
