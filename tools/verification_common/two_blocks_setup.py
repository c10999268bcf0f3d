"""The two-blocks impact of seed 000 Sec. 3.1, shared by verification/two_blocks and
verification/two_blocks_convergence.

Two 50 x 20 mm blocks, 4 cells apart, 2 x 2 particles per cell, plane strain, neo-Hookean
"j_squared" (seed 000 Eq. 6) with lambda = 7.29766 MPa, G = 3.7594 MPa, rho = 1500 kg/m^3 (our
choice: E = 10 MPa, nu = 0.33, bar wave speed sqrt(E/rho) = 81.65 m/s), initial velocities
+/-8.165 m/s (10 % of that wave speed). Each run stops about 0.35 ms after the blocks separate; the
energy loss is 1 - (KE+SE)_end / (KE+SE)_0 in percent.

A run is a `Spec`; `Runner(args)(spec)` writes the input, runs cairn (once per spec), analyses the
history and snapshots and returns a dict (None if cairn failed).
"""
from __future__ import annotations

import json
import math
import resource
from dataclasses import dataclass

import numpy as np

import cairn_case as cc

LAMBDA = 7.29766e6           # Pa, seed 000 Sec. 3.1
G = 3.7594e6                 # Pa
RHO = 1500.0                 # kg/m^3, our choice: bar wave speed sqrt(E/rho) = 81.65 m/s
E_MOD = G * (3 * LAMBDA + 2 * G) / (LAMBDA + G)      # 10.0 MPa
NU = LAMBDA / (2 * (LAMBDA + G))                     # 0.33
C_BAR = math.sqrt(E_MOD / RHO)                       # 81.65 m/s
V0 = 8.165                   # m/s, 10 % of C_BAR
L, W = 0.050, 0.020          # block length (x) and height (y), m
GAP_CELLS = 4
MARGIN = 0.010               # free grid space around the blocks, m
HEIGHT = 0.040               # grid height, m (blocks centred)
PPC = 2                      # particles per cell per axis (4 per cell)
SNAPSHOT_EVERY = 2.0e-5      # dense enough to time the separation from the bodies' mean velocity
HISTORY_EVERY = 2.0e-6
AFTER_SEPARATION = 0.3e-3    # end_time = contact + 2L/c + reach h/V0 + this (see end_time_for)
SEPARATED_TOL = 1e-6         # |mean v(t) - mean v(end)| <= tol * V0 from separation on
UNSTABLE_GAIN = 5.0          # %: a run whose energy grew by more than this is counted unstable
# How far beyond the particle domain each family reaches, in cells: the blocks share nodes once
# the gap is below twice this (seed 000 Sec. 3.1: "less than two grid cells" for CPDI).
SEPARATION_KEYS = ["ts", "vbar", "t_contact", "t_sep", "loss_sep", "loss_min", "loss_max", "loss_mean",
                   "restitution"]
REACH = {"cpdi": 1.0, "ugimp": 1.0, "gimp": 1.0, "cpgimp": 1.0, "b2cpdi": 1.5, "b2gimp": 1.5}


@dataclass(frozen=True)
class Spec:
    """One simulation: everything that differs between the runs of the two-blocks cases."""
    h: float = 1e-3
    shape: str = "cpdi"
    update: str = "flip"     # flip, fmpm or xpic
    k: int = 1               # method.order (FMPM / XPIC)
    stress: str = "usl"
    cfl: float = 0.2
    dt: float = 0.0          # fixed time step; 0 = CFL rule
    cfl_x: float = 0.0       # periodic full-mass steps (method.full_mass_cfl); 0 = every step
    snapshots: bool = True   # False: timing runs (no snapshots, sparse history)

    @property
    def name(self):
        s = f"{self.shape}_{self.update}{self.k if self.update != 'flip' else ''}_{self.stress.replace('+', 'p')}"
        s += f"_h{self.h * 1e3:g}mm" + (f"_dt{self.dt * 1e6:g}us" if self.dt else f"_cfl{self.cfl:g}")
        if self.cfl_x:
            s += f"_cflx{self.cfl_x:g}"
        if not self.snapshots:
            s += "_timing"
        return s

    @property
    def label(self):
        s = "FLIP" if self.update == "flip" else f"{self.update.upper()}({self.k})"
        return s + (f" CFL_X {self.cfl_x:g}" if self.cfl_x else "")


def contact_time(h, shape):
    # Each block reaches the nodes within REACH cells of its edge, so the blocks share nodes once
    # the gap (4h) has closed to 2 REACH h at the closing speed 2 V0.
    return (GAP_CELLS - 2 * REACH[shape]) * h / (2 * V0)


def end_time_for(h, shape):
    # The blocks keep sharing nodes after the rebound until the gap has reopened past 2 REACH h,
    # which takes about REACH h / V0; the stress wave needs 2L/c in between. The measured
    # separation lands about 0.33-0.36 ms before this end time (see two_blocks/README.md).
    return contact_time(h, shape) + 2 * L / C_BAR + REACH[shape] * h / V0 + AFTER_SEPARATION


def make_input(s: Spec, run_dir, header: str = "") -> str:
    h = s.h
    gap = GAP_CELLS * h
    extent_x = 2 * MARGIN + 2 * L + gap
    y0 = 0.5 * (HEIGHT - W)
    end_time = end_time_for(h, s.shape)
    sim = {"title": f"two blocks, {s.label}, {s.shape}, {s.stress}, {h * 1e3:g} mm cells",
           "dimension": 2, "mode": "plane_strain", "end_time": end_time}
    if s.dt:
        sim["dt"] = s.dt
    else:
        sim["cfl"] = s.cfl
    method = {"shape": s.shape, "update": s.update, "stress_update": s.stress}
    if s.update != "flip":
        method["order"] = s.k
    if s.cfl_x:
        method["full_mass_cfl"] = s.cfl_x
    doc = {
        "simulation": sim,
        "grid": {"origin": [0.0, 0.0], "extent": [extent_x, HEIGHT], "cell_size": h},
        "method": method,
        "material": [{"name": "rubber", "model": "neo_hookean", "form": "j_squared",
                      "density": RHO, "lambda": LAMBDA, "shear_modulus": G}],
        "body": [
            {"name": "left", "material": "rubber",
             "shape": {"box": {"min": [MARGIN, y0], "max": [MARGIN + L, y0 + W]}},
             "particles_per_cell": PPC, "velocity": [V0, 0.0]},
            {"name": "right", "material": "rubber",
             "shape": {"box": {"min": [MARGIN + L + gap, y0], "max": [MARGIN + 2 * L + gap, y0 + W]}},
             "particles_per_cell": PPC, "velocity": [-V0, 0.0]},
        ],
        "output": {"directory": str(run_dir), "every": SNAPSHOT_EVERY if s.snapshots else 0.0,
                   "history_every": HISTORY_EVERY if s.snapshots else end_time / 10,
                   "checkpoints": False},
    }
    return cc.toml_text(doc, header=header)


def analyse(run_dir):
    """Energies, momentum error, and (from the snapshots) contact and separation times."""
    hist = cc.read_history(run_dir)
    t = hist["time"]
    etot = hist["kinetic_energy"] + hist["strain_energy"]
    e0, e_end = etot[0], etot[-1]
    P = np.stack([hist["momentum_x"], hist["momentum_y"], hist["momentum_z"]], axis=1)
    snaps = cc.snapshots(run_dir)
    s0 = cc.read_snapshot(snaps[0], fields=("velocity", "mass", "body"))
    norm = float(np.sum(s0["mass"] * np.linalg.norm(s0["velocity"], axis=1)))
    dP = np.linalg.norm(P - P[0], axis=1) / norm
    loss_t = 100 * (1 - etot / e0)
    r = {"t": t, "ke": hist["kinetic_energy"], "se": hist["strain_energy"], "etot": etot,
         "e0": e0, "e_end": e_end, "loss": float(loss_t[-1]), "momentum": float(dP.max()),
         "t_end": float(t[-1]), "steps": int(hist["step"][-1]), "n_particles": len(s0["mass"]),
         "snap_count": len(snaps), "unstable": bool(loss_t.min() < -UNSTABLE_GAIN)}
    if len(snaps) < 3:      # timing runs: no separation analysis
        return r
    # Mean x-velocity of each body per snapshot.
    ts, vbar = [], []
    for s in snaps:
        d = cc.read_snapshot(s, fields=("velocity", "mass", "body"))
        ts.append(d["time"])
        vbar.append([np.sum((d["mass"] * d["velocity"][:, 0])[d["body"] == b]) /
                     np.sum(d["mass"][d["body"] == b]) for b in (0, 1)])
    ts, vbar = np.array(ts), np.array(vbar)
    changed = np.any(np.abs(vbar - vbar[0]) > SEPARATED_TOL * V0, axis=1)
    t_contact = ts[np.argmax(changed)] if changed.any() else float("nan")
    moving = np.any(np.abs(vbar - vbar[-1]) > SEPARATED_TOL * V0, axis=1)
    # first snapshot after the last one whose mean velocities still differ from the final ones
    last = moving.nonzero()[0][-1] if moving.any() else -1
    t_sep = ts[last + 1] if moving.any() and last + 1 < len(ts) - 1 else float("nan")
    after = t >= t_sep
    r.update({
        "ts": ts, "vbar": vbar, "t_contact": t_contact, "t_sep": t_sep,
        "loss_sep": float(np.interp(t_sep, t, loss_t)) if after.any() else float("nan"),
        "loss_min": float(loss_t[after].min()) if after.any() else float("nan"),
        "loss_max": float(loss_t[after].max()) if after.any() else float("nan"),
        "loss_mean": float(loss_t[after].mean()) if after.any() else float("nan"),
        "restitution": (vbar[-1, 1] - vbar[-1, 0]) / (2 * V0),
    })
    return r


class Runner:
    """Runs each Spec once (a run shared by several sweeps is reused) and analyses it.

    args: the cairn_case arguments plus keep_snapshots and reuse (re-analyse an existing run whose
    generated input is unchanged). Returns None for a run cairn could not finish.
    """

    def __init__(self, args, header=""):
        self.args = args
        self.header = header
        self.res = {}

    def __call__(self, s: Spec, fresh: bool = False):
        if s in self.res and not fresh:
            return self.res[s]
        args = self.args
        run_dir = args.out / s.name
        toml = args.out / f"{s.name}.toml"
        text = make_input(s, run_dir, self.header)
        meta = args.out / f"{s.name}.json"
        reuse = (getattr(args, "reuse", False) and not fresh and meta.exists() and toml.exists()
                 and toml.read_text() == text)
        if reuse:
            timing = json.loads(meta.read_text())
            if timing.get("failed"):
                self.res[s] = None
                return None
        else:
            toml.write_text(text)
            cpu0 = resource.getrusage(resource.RUSAGE_CHILDREN)
            try:
                wall = cc.run_cairn(args, toml, run_dir, quiet=False)
            except RuntimeError as err:
                why = [x for x in str(err).splitlines() if "simulation failed" in x or "error" in x]
                print(f"  {s.name:44s} FAILED: {(why or ['?'])[0][:160]}", flush=True)
                meta.write_text(json.dumps({"failed": True}))
                self.res[s] = None
                return None
            cpu1 = resource.getrusage(resource.RUSAGE_CHILDREN)
            timing = {"wall": wall,
                      "cpu": (cpu1.ru_utime - cpu0.ru_utime) + (cpu1.ru_stime - cpu0.ru_stime),
                      "stages": cc.stage_times(args.out / f"{s.name}.log")}
            meta.write_text(json.dumps(timing))
        r = analyse(run_dir)
        if reuse and "separation" in timing and "t_sep" not in r:   # snapshots pruned already
            r.update({k: np.array(v) if isinstance(v, list) else v for k, v in timing["separation"].items()})
        r.update({k: v for k, v in timing.items() if k != "separation"})
        r["end_time"] = end_time_for(s.h, s.shape)
        if not reuse:
            if "t_sep" in r:
                timing["separation"] = {k: (r[k].tolist() if isinstance(r[k], np.ndarray) else r[k])
                                        for k in SEPARATION_KEYS}
                meta.write_text(json.dumps(timing))
            if not getattr(args, "keep_snapshots", False) and r["snap_count"] > 2:
                cc.prune_snapshots(run_dir, {0, r["snap_count"] - 1})
        self.res[s] = r
        print(f"  {s.name:44s} loss {r['loss']:8.3f} %  steps {r['steps']:5d}  cpu {r['cpu']:6.1f} s"
              + ("  UNSTABLE" if r["unstable"] else ""), flush=True)
        return r


def loss(r):
    """Energy loss in percent; nan for a failed or unstable run."""
    return r["loss"] if r is not None and not r["unstable"] else float("nan")
