"""Shared set-up and measurements of the nickel shock cases (seed 000 Sec. 3.5, seed 004 Sec. 4.3).

A 50 x 2.5 mm nickel bar lies against zero-velocity walls at x = 0, y = 0 and y = 2.5 mm and is hit
on its right end by a wall moving at -v_impact. Theory (Mie-Grueneisen reference Hugoniot, see
docs/materials.md): behind the shock the material moves with the wall, u_p = v_impact, and

    U_s = C0 + S1 u_p,   C0 = sqrt(K / rho0),   p_H = rho0 U_s u_p,   eta = u_p / U_s

so the front is at x_front(t) = L - U_s t in the grid frame. The temperature on the Hugoniot of
this EOS (hugoniot_temperature) follows from T dS = dE + p dV along the Hugoniot; see
verification/hugoniot_sweep/README.md for the derivation.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

import cairn_case

K = 188e9
RHO0 = 8870.0
GAMMA0 = 2.0
S1 = 1.44
G = 76e9          # nickel shear modulus (not given in the seeds; plasticity bounds its effect)
YIELD = 0.5e9     # nickel-like yield stress: keeps deviatoric stress below 0.5 % of p_H
CV = 440.0        # heat capacity (J/(kg K)) of the material input below
CONDUCTIVITY = 90.7  # W/(m K), nickel (not in the seeds), used when conduction is on
T0 = 298.15       # initial temperature (K)
LENGTH = 50e-3
WIDTH = 2.5e-3
CELL = 0.25e-3


def hugoniot(v_impact: float) -> tuple[float, float]:
    """(plateau pressure p_H, shock speed U_s) for an impact at v_impact."""
    c0 = math.sqrt(K / RHO0)
    us = c0 + S1 * v_impact
    return RHO0 * us * v_impact, us


def hugoniot_temperature(v_impact: float, cv: float = CV, t0: float = T0, n: int = 4000) -> float:
    """Temperature behind the shock on the reference Hugoniot of this Mie-Grueneisen EOS.

    With Gamma rho = gamma0 rho0 and a constant heat capacity c_v, c_v dT = T dS - c_v T Gamma dV / V,
    and on the Hugoniot T dS = dE_H + p_H dV with E_H = p_H (V0 - V) / 2. In eta = 1 - V/V0:
        dT_H/deta = gamma0 T_H + (eta p_H' - p_H) / (2 rho0 c_v),   p_H = K eta / (1 - S1 eta)^2,
    and eta p_H' - p_H = 2 K S1 eta^2 / (1 - S1 eta)^3, so
        T_H = exp(gamma0 eta) [T0 + K S1 / (rho0 c_v) int_0^eta exp(-gamma0 s) s^2 / (1 - S1 s)^3 ds].
    The integral is evaluated with Simpson's rule on n intervals.
    """
    _, us = hugoniot(v_impact)
    eta = v_impact / us
    s = np.linspace(0.0, eta, n + 1)
    f = np.exp(-GAMMA0 * s) * s ** 2 / (1.0 - S1 * s) ** 3
    w = np.ones(n + 1)
    w[1:-1:2], w[2:-1:2] = 4.0, 2.0
    integral = float(np.dot(w, f)) * (eta / n) / 3.0
    return math.exp(GAMMA0 * eta) * (t0 + K * S1 / (RHO0 * cv) * integral)


def case_input(run_dir: Path, v_impact: float, end_time: float, update: str, order: int,
               a1: float = 0.4, a2: float = 4.0, shape: str = "b2cpdi", every: float | None = None,
               yield_stress: float = YIELD, conduction: bool = False) -> dict:
    d = 1.5
    doc = {
        "simulation": {"title": f"nickel shock {update}({order}) v = {v_impact}", "dimension": 2,
                       "mode": "plane_strain", "end_time": end_time, "cfl": 0.2},
        "grid": {"origin": [-1e-3, -1e-3], "extent": [53e-3, 4.5e-3], "cell_size": CELL},
        "method": {"shape": shape, "update": update, "order": order, "stress_update": "usl"},
        "material": [{"name": "nickel", "model": "mie_gruneisen", "density": RHO0, "bulk_modulus": K,
                      "shear_modulus": G, "gamma0": GAMMA0, "s1": S1, "yield_stress": yield_stress,
                      "av_a1": a1, "av_a2": a2, "heat_capacity": CV, "initial_temperature": T0}],
        "body": [{"name": "bar", "material": "nickel",
                  "shape": {"box": {"min": [0.0, 0.0], "max": [LENGTH, WIDTH]}}, "particles_per_cell": 2}],
        "wall": [
            {"name": "left", "axis": "x", "inside": "above", "position": 0.0, "depth": d},
            {"name": "bottom", "axis": "y", "inside": "above", "position": 0.0, "depth": d},
            {"name": "top", "axis": "y", "inside": "below", "position": WIDTH, "depth": d},
            {"name": "impact", "axis": "x", "inside": "below", "position": LENGTH,
             "velocity": f"{-v_impact!r}", "gradient": "estimate", "depth": d},
        ],
        "output": {"directory": str(run_dir), "every": every if every else end_time},
    }
    if conduction:  # seed 000 Sec. 3.5: "coupled heat conduction"
        doc["thermal"] = {"conduction": True}
        doc["material"][0]["conductivity"] = CONDUCTIVITY
    return doc


def profile(snapshot: Path, field: str = "pressure"):
    """A particle field (pressure by default) along x averaged over the particles of each column
    (mid-width rows only)."""
    s = cairn_case.read_snapshot(snapshot, ("position", field))
    x, y, p = s["position"][:, 0], s["position"][:, 1], s[field]
    keep = (y > 0.25 * WIDTH) & (y < 0.75 * WIDTH)
    x, p = x[keep], p[keep]
    bins = np.round(x / (CELL / 2)).astype(int)
    xs, ps = [], []
    for b in np.unique(bins):
        sel = bins == b
        xs.append(float(np.mean(x[sel])))
        ps.append(float(np.mean(p[sel])))
    return np.array(xs), np.array(ps), s["time"]


def measure(xs, ps, t, v_impact):
    """Plateau pressure, front position (half-plateau crossing) and overshoot at the front."""
    p_h, us = hugoniot(v_impact)
    wall = LENGTH - v_impact * t
    front_theory = LENGTH - us * t
    # plateau: between 4 cells behind the theoretical front and 4 cells before the wall
    sel = (xs > front_theory + 4 * CELL) & (xs < wall - 4 * CELL)
    plateau = float(np.mean(ps[sel])) if np.any(sel) else float("nan")
    # front: first position from the left where the pressure reaches half the plateau
    idx = np.argmax(ps >= 0.5 * plateau)
    if idx > 0:
        x0, x1, p0, p1 = xs[idx - 1], xs[idx], ps[idx - 1], ps[idx]
        front = float(x0 + (0.5 * plateau - p0) * (x1 - x0) / (p1 - p0))
    else:
        front = float(xs[idx])
    near = (xs > front) & (xs < front + 8 * CELL)
    overshoot = float(np.max(ps[near]) / plateau - 1.0) if np.any(near) else float("nan")
    return {"plateau": plateau, "p_H": p_h, "front": front, "front_theory": front_theory,
            "U_s": us, "overshoot": overshoot}


def plateau_mean(xs, values, t, v_impact):
    """Mean of a profile over the plateau window of measure() (4 cells behind the theoretical
    front to 4 cells before the wall)."""
    _, us = hugoniot(v_impact)
    sel = (xs > LENGTH - us * t + 4 * CELL) & (xs < LENGTH - v_impact * t - 4 * CELL)
    return float(np.mean(values[sel])) if np.any(sel) else float("nan")
