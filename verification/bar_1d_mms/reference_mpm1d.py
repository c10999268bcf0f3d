#!/usr/bin/python3
"""Independent NumPy re-implementation of the 1D periodic bar MMS, for cross-checking Cairn.

Not run by the test suite. It implements seed 003 Eq. 1-10 (lumped-mass FLIP, stress from the
particle F at the start of the step, body force Eq. 49 projected with Eq. 16) on a periodic grid,
with the two choices on which Cairn and the paper differ selectable:
  --position-update forward    x += dt S v(k+1)                 (seed 003 Eq. 10)
                    trapezoid  x += dt S (v(k) + v(k+1)) / 2    (Cairn's FLIP, seed 000 Task 4)
  --F-update        linear     F = (1 + L dt) F                 (seed 003 Eq. 8)
                    exp        F = exp(L dt) F                  (Cairn)
With `--position-update trapezoid --F-update exp` it reproduces Cairn's errors to ~8 digits.

  ./reference_mpm1d.py --shape bspline2 --ppc 4 --cells 16 32 64 128
"""
import argparse

import numpy as np


def weights(shape, r):
    """Shape value and derivative (per cell size) at r = (x - x_i) / h."""
    a = np.abs(r)
    if shape == "linear":
        return np.where(a < 1, 1 - a, 0.0), np.where(a < 1, -np.sign(r), 0.0)
    w = np.where(a < 0.5, 0.75 - a * a, np.where(a < 1.5, 0.5 * (1.5 - a) ** 2, 0.0))
    dw = np.where(a < 0.5, -2 * r, np.where(a < 1.5, -np.sign(r) * (1.5 - a), 0.0))
    return w, dw


def run(cells, ppc=4, shape="bspline2", dt=4e-6, A=0.05, E=1e4, rho=1.0,
        position_update="trapezoid", F_update="exp"):
    C = np.sqrt(E / rho)
    T = 1.0 / C
    h = 1.0 / cells
    n = cells * ppc
    X = (np.arange(n) + 0.5) / n                       # even sampling of the reference interval
    V0 = np.full(n, 1.0 / n)
    m = rho * V0
    x = X + A * np.sin(2 * np.pi * X)                  # Eq. 47 at t = 0
    F = 1 + 2 * A * np.pi * np.cos(2 * np.pi * X)      # Eq. 48 at t = 0
    v = np.zeros(n)
    offsets = [-1, 0, 1] if shape == "bspline2" else [0, 1]
    t = 0.0
    while t < T - 1e-15:
        step = min(dt, T - t)
        base = np.floor(x / h + (0.5 if shape == "bspline2" else 0.0)).astype(int)
        idx, W, G = [], [], []
        for o in offsets:
            i = base + o
            w, dw = weights(shape, x / h - i)
            idx.append(i % cells)
            W.append(w)
            G.append(dw / h)
        sigma = 0.5 * E * (F - 1 / F)                  # Eq. 50
        u = A * np.sin(2 * np.pi * X) * np.cos(C * np.pi * t)
        Fa = 1 + 2 * A * np.pi * np.cos(2 * np.pi * X) * np.cos(C * np.pi * t)
        b = C ** 2 * np.pi ** 2 * u * (2 / Fa ** 2 + 1)  # Eq. 49
        mi, pi, fi = np.zeros(cells), np.zeros(cells), np.zeros(cells)
        for i, w, g in zip(idx, W, G):
            np.add.at(mi, i, w * m)
            np.add.at(pi, i, w * m * v)
            np.add.at(fi, i, -g * sigma * F * V0 + w * m * b)
        vi = pi / mi
        ai = fi / mi
        vn = vi + ai * step
        L = sum(g * vn[i] for i, g in zip(idx, G))
        F = (1 + L * step) * F if F_update == "linear" else np.exp(L * step) * F
        v = v + sum(w * ai[i] for i, w in zip(idx, W)) * step
        vx = vn if position_update == "forward" else 0.5 * (vi + vn)
        x = (x + sum(w * vx[i] for i, w in zip(idx, W)) * step) % 1.0
        t += step
    e = (x - X - A * np.sin(2 * np.pi * X) * np.cos(C * np.pi * t) + 0.5) % 1.0 - 0.5  # Eq. 54
    return np.abs(e).max(), float(np.sqrt(np.mean(e ** 2)))


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--shape", choices=["linear", "bspline2"], default="bspline2")
    p.add_argument("--ppc", type=int, default=4)
    p.add_argument("--dt", type=float, default=4e-6)
    p.add_argument("--cells", type=int, nargs="+", default=[16, 32, 64, 128, 256])
    p.add_argument("--position-update", choices=["forward", "trapezoid"], default="trapezoid")
    p.add_argument("--F-update", choices=["linear", "exp"], default="exp")
    a = p.parse_args()
    print("cells  max_error   rms_error")
    for c in a.cells:
        emax, erms = run(c, a.ppc, a.shape, a.dt, position_update=a.position_update, F_update=a.F_update)
        print(f"{c:5d}  {emax:.4e}  {erms:.4e}", flush=True)


if __name__ == "__main__":
    main()
