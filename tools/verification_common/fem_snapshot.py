"""Reading the FEM's output (docs/fem.md, Outputs) for verification cases.

  fem_snapshots(run_dir)              -> sorted snapshots/fem-NNNN.h5 files
  read_fem_snapshot(path)             -> dict: time, step, nodes{...}, elements{...} (numpy arrays)
  hole_von_mises(snap, center, radius, band)
                                      -> (angle, von_mises) of the Gauss points (element centroids)
                                         whose reference position lies within `band` of the hole
                                         surface, sorted by angle (seed 001 Sec. 5.3, Fig. 10)
  node_displacement_error(snap, exact)-> max over nodes of |u - exact(X, Y, t)| (seed 001 Eq. 38)

history.csv of a run with fem.exact_displacement already holds Eq. 38 over all nodes and all
steps (column displacement_error_max); read it with cairn_case.read_history.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np


def fem_snapshots(run_dir: Path) -> list[Path]:
    return sorted((Path(run_dir) / "snapshots").glob("fem-*.h5"))


def read_fem_snapshot(path: Path) -> dict:
    import h5py
    with h5py.File(path, "r") as f:
        out = {"time": float(f.attrs["time"]), "step": int(f.attrs["step"])}
        out["nodes"] = {k: f["nodes"][k][()] for k in f["nodes"]}
        out["elements"] = {k: f["elements"][k][()] for k in f["elements"]}
    out["elements"]["connectivity"] = out["elements"]["connectivity"].reshape(-1, 3)
    return out


def hole_von_mises(snap: dict, center, radius: float, band: float):
    """Angle (from the +x axis, counter-clockwise) and von Mises stress of the elements whose
    reference centroid is within `band` of the circle |X - center| = radius."""
    c = snap["elements"]["reference_centroid"][:, :2] - np.asarray(center, dtype=float)
    r = np.hypot(c[:, 0], c[:, 1])
    keep = np.abs(r - radius) <= band
    angle = np.arctan2(c[keep, 1], c[keep, 0])
    vm = snap["elements"]["von_mises"][keep]
    order = np.argsort(angle)
    return angle[order], vm[order]


def node_displacement_error(snap: dict, exact) -> float:
    """exact(X, Y, t) -> (ux, uy) arrays."""
    X = snap["nodes"]["reference_position"]
    u = snap["nodes"]["displacement"]
    ux, uy = exact(X[:, 0], X[:, 1], snap["time"])
    return float(np.max(np.hypot(u[:, 0] - ux, u[:, 1] - uy)))
