#!/usr/bin/python3
"""Where the rolling disk's lost acceleration goes (issue 38, item 3; README "Where the rolling error goes").

    energy_split.py R_OVER_H [R_OVER_H ...] [--impulse] [--contact KEY=VALUE ...] [--cairn BIN] [--out DIR]

Runs the case's rolling input (mu = 0.5, theta = 30 deg, rolling settings) at each R/h and splits
the work gravity did over the fit window into the disk's rigid-body kinetic energy (translation and
rotation, from the particles), its other kinetic energy, the strain energy, the contact's
dissipation and what is left (not tallied); prints R_kin = a / alpha and k = I / (M R_kin^2).
"""
import argparse
import importlib.machinery
import importlib.util
import math
import subprocess
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[1] / "tools" / "verification_common"))
import cairn_case as cc  # noqa: E402

loader = importlib.machinery.SourceFileLoader("rolling_cylinder", str(HERE / "run"))
spec = importlib.util.spec_from_loader("rolling_cylinder", loader)
rc = importlib.util.module_from_spec(spec)
loader.exec_module(rc)


def split(run_dir: Path, n: float):
    rows = []
    for s in cc.snapshots(run_dir):
        r = cc.read_snapshot(s)
        b = r["body"] == 1
        m, x, v = r["mass"][b], r["position"][b][:, :2], r["velocity"][b][:, :2]
        M = m.sum()
        rel, vrel = x - m @ x / M, v - m @ v / M
        inertia = np.sum(m * (rel ** 2).sum(1))
        w = -np.sum(m * (rel[:, 0] * vrel[:, 1] - rel[:, 1] * vrel[:, 0])) / inertia
        vc = m @ v / M
        rows.append([r["time"], (m @ x / M)[0], w, 0.5 * M * vc @ vc, 0.5 * inertia * w * w,
                     0.5 * np.sum(m * (v ** 2).sum(1)), inertia / M])
    t, xc, w, ket, ker, ke, i_m = np.array(rows).T
    win = (t >= rc.FIT[0] - 1e-12) & (t <= rc.FIT[1] + 1e-12)
    a = 2.0 * np.polyfit(t[win], xc[win], 2)[0]
    r_kin = a / np.polyfit(t[win], w[win], 1)[0]
    k = i_m[win].mean() / r_kin ** 2
    h = cc.read_history(run_dir)
    i1, i2 = np.argmin(abs(t - rc.FIT[0])), np.argmin(abs(t - rc.FIT[1]))
    t1, t2 = t[i1], t[i2]
    d = {c: np.interp(t2, h["time"], h[c]) - np.interp(t1, h["time"], h[c])
         for c in ("external_work", "contact_dissipated_energy", "strain_energy")}
    work = d["external_work"]
    rigid = (ket[i2] - ket[i1] + ker[i2] - ker[i1]) / work
    other = (ke[i2] - ke[i1]) / work - rigid
    strain, contact = d["strain_energy"] / work, d["contact_dissipated_energy"] / work
    g_sin = rc.G * math.sin(math.radians(30.0))
    exact = 2.0 / 3.0 * g_sin
    print(f"R/h = {n:g}: a error {100 * (a / exact - 1):+.2f} %, R_kin = {r_kin * 1e3:.3f} mm "
          f"((R - R_kin)/h = {(rc.R - r_kin) / (rc.R / n):+.2f}), k = {k:.3f} (from k alone "
          f"{100 * (g_sin / (1 + k) / exact - 1):+.2f} %), f = {100 * (1 - rigid):.2f} %; shares of gravity's "
          f"work: contact dissipation {100 * contact:.2f} %, strain {100 * strain:.2f} %, other disk KE "
          f"{100 * other:.2f} %, not tallied {100 * (1 - rigid - other - strain - contact):.2f} %; "
          f"a = g sin(1 - f)/(1 + k) = {g_sin * rigid / (1 + k):.4f} against {a:.4f} m/s^2")


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("r_over_h", nargs="+", type=float)
    p.add_argument("--impulse", action="store_true", help='first_correction = "impulse"')
    p.add_argument("--contact", action="append", default=[], metavar="KEY=VALUE",
                   help='a [contact] key over the rolling settings, e.g. release=gap (string values)')
    p.add_argument("--cairn", default=str(HERE.parents[1] / "build" / "release" / "cairn"))
    p.add_argument("--out", default=str(HERE / "results" / "energy_split"))
    args = p.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    for n in args.r_over_h:
        extra = {"first_correction": "impulse"} if args.impulse else {}
        extra.update(kv.split("=", 1) for kv in args.contact)
        name = f"roll30_mu0.5_Rh{n:g}" + ("_impulse" if args.impulse else "") + \
            "".join(f"_{k}_{v}" for k, v in extra.items() if k != "first_correction")
        extra = extra or None
        toml = rc.make_input(name, rc.R / n, math.radians(30.0), 0.5, out, extra=extra)
        subprocess.run([args.cairn, "run", str(toml), "-q", "--set", "simulation.threads=1"], check=True)
        split(out / name, n)


if __name__ == "__main__":
    main()
