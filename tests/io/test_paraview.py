"""Open the outputs of a 2D and a 3D run with ParaView itself (pvbatch, offscreen).

Usage: /usr/bin/python3 test_paraview.py <cairn binary> <source dir>
Runs shortened examples/two_blocks.toml (2D) and examples/falling_cube_3d.toml (3D) with grid
snapshots, derives what ParaView must show from the inputs (particle and node counts, grid
bounds) and from the HDF5 files (times, value ranges), and lets tests/io/paraview_check.py check
it inside pvbatch: points and cells of particles.xdmf and grid.xdmf with the default (XDMF 3) and
the legacy reader, array and component names, time steps, and a rendered PNG. ParaView comes from
Debian's paraview and python3-paraview packages and draws on a private Xvfb display when there is
no DISPLAY (tools/install-deps installs all three); without them the test fails.
Set CAIRN_PARAVIEW_KEEP=DIR to keep the outputs and pictures there.
"""
import json
import os
import shutil
import subprocess
import sys
import tempfile

import h5py
import numpy as np

STRESS = ["XX", "YY", "ZZ", "XY", "YZ", "XZ"]
XYZ = ["X", "Y", "Z"]
PARTICLE_ARRAYS = {"velocity": XYZ, "displacement": XYZ, "mass": [], "volume": [], "stress": STRESS,
                   "deformation_gradient_x": XYZ, "deformation_gradient_y": XYZ,
                   "deformation_gradient_z": XYZ, "pressure": [], "von_mises": [],
                   "temperature": [], "material": [], "body": []}
GRID_ARRAYS = {"node_mass": [], "node_velocity": XYZ}

# Shortened runs: (label, example, overrides, particles from the input: cells x particles per cell,
# grid origin, cells, cell size)
CASES = [
    ("2d", "two_blocks.toml",
     ["simulation.end_time=3.0e-4", "output.every=1.0e-4", "output.history_every=1.0e-4"],
     2 * (50 * 20) * 2 ** 2, (0.0, 0.0, 0.0), (124, 40, 0), 1.0e-3),
    ("3d", "falling_cube_3d.toml",
     ["simulation.end_time=0.02", "output.every=0.01", "output.history_every=0.01"],
     (12 * 12 * 2 + 5 * 5 * 5) * 2 ** 3, (0.0, 0.0, 0.0), (12, 12, 16), 0.01),
]


class CheckFailed(Exception):
    pass


def check(cond, message):
    if not cond:
        raise CheckFailed(message)


def run(cmd, timeout=900):
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    check(proc.returncode == 0, f"'{' '.join(cmd)}' exited with {proc.returncode}\n"
                                f"--- stdout ---\n{proc.stdout[-4000:]}\n--- stderr ---\n{proc.stderr[-4000:]}")
    return proc.stdout


def run_pvbatch(pvbatch, args):
    """pvbatch offscreen. Debian's ParaView renders through X (it has no EGL or OSMesa build):
    without a DISPLAY, a private Xvfb server (package xvfb) is started for the call and stopped
    after it; -displayfd makes the server pick a free display and say when it is ready."""
    cmd = [pvbatch, "--force-offscreen-rendering"] + args
    if os.environ.get("DISPLAY"):
        return run(cmd)
    read_end, write_end = os.pipe()
    xvfb = subprocess.Popen(["Xvfb", "-displayfd", str(write_end), "-screen", "0", "1280x1024x24",
                             "-nolisten", "tcp", "-noreset"], pass_fds=(write_end,),
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    os.close(write_end)
    try:
        with os.fdopen(read_end) as f:
            display = f.readline().strip()
        check(display.isdigit(), "Xvfb did not start (no display number)")
        env = dict(os.environ, DISPLAY=":" + display)
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=900, env=env)
        check(proc.returncode == 0, f"'{' '.join(cmd)}' exited with {proc.returncode}\n"
                                    f"--- stdout ---\n{proc.stdout[-4000:]}\n--- stderr ---\n{proc.stderr[-4000:]}")
        return proc.stdout
    finally:
        xvfb.terminate()
        xvfb.wait(timeout=30)


def expectations(label, out, n_particles, origin, cells, h, png):
    files = sorted(f for f in os.listdir(os.path.join(out, "snapshots")) if f.startswith("particles-"))
    times = []
    for name in files:
        with h5py.File(os.path.join(out, "snapshots", name), "r") as f:
            times.append(float(f.attrs["time"]))
    with h5py.File(os.path.join(out, "snapshots", files[-1]), "r") as f:
        p = f["particles"]
        x = p["position"][:]
        s = p["stress"][:]
        F = p["deformation_gradient"][:]
        v = f["grid/node_velocity"][:].reshape(-1, 3)
        dim = int(f.attrs["dimension"])
    check(x.shape[0] == n_particles, f"{label}: {x.shape[0]} particles in the HDF5 file, the input makes {n_particles}")
    ranges = [["stress", c, float(s[:, k].min()), float(s[:, k].max())] for k, c in enumerate(STRESS)]
    ranges += [["deformation_gradient_x", c, float(F[:, k].min()), float(F[:, k].max())] for k, c in enumerate(XYZ)]
    if dim == 2:
        # The shear of a plane problem is XY; XZ and YZ vanish. A swapped order would show up here.
        check(np.abs(s[:, 3]).max() > 1e-3 * np.abs(s[:, 0]).max() > 0,
              f"{label}: no shear stress at the last snapshot; the order check would be void")
        check(np.all(s[:, 4] == 0) and np.all(s[:, 5] == 0), f"{label}: 2D stress with YZ or XZ components")
    bounds = [float(b) for k in range(3) for b in (x[:, k].min(), x[:, k].max())]
    node_counts = [c + 1 if c > 0 else 1 for c in cells]
    grid_bounds = [v for k in range(3) for v in (origin[k], origin[k] + cells[k] * h)]
    grid_cells = int(np.prod([c for c in cells if c > 0]))
    return {
        "label": label,
        "particles_xdmf": os.path.join(out, "particles.xdmf"),
        "grid_xdmf": os.path.join(out, "grid.xdmf"),
        "times": times,
        "png": png,
        "png_size": [900, 500],
        "particles": {"points": n_particles, "cells": n_particles, "bounds": bounds,
                      "arrays": PARTICLE_ARRAYS, "ranges": ranges},
        "grid": {"points": int(np.prod(node_counts)), "cells": grid_cells, "bounds": grid_bounds,
                 "arrays": GRID_ARRAYS,
                 "ranges": [["node_velocity", c, float(v[:, k].min()), float(v[:, k].max())]
                            for k, c in enumerate(XYZ)]},
    }


def main():
    if len(sys.argv) < 3:
        print("usage: test_paraview.py <cairn binary> <source dir>", file=sys.stderr)
        return 2
    cairn, source = sys.argv[1], sys.argv[2]
    pvbatch = shutil.which("pvbatch")
    if pvbatch is None or (not os.environ.get("DISPLAY") and shutil.which("Xvfb") is None):
        print("FAIL: pvbatch or Xvfb not found; install Debian's paraview, python3-paraview and "
              "xvfb (./tools/install-deps)", file=sys.stderr)
        return 1
    keep = os.environ.get("CAIRN_PARAVIEW_KEEP")
    with tempfile.TemporaryDirectory(prefix="cairn_paraview_") as tmp:
        work = keep or tmp
        os.makedirs(work, exist_ok=True)
        try:
            spec = {"cases": []}
            for label, example, overrides, n, origin, cells, h in CASES:
                out = os.path.join(work, label)
                shutil.rmtree(out, ignore_errors=True)
                cmd = [cairn, "run", os.path.join(source, "examples", example), "-q",
                       "--set", f"output.directory={out}", "--set", "output.grid_snapshots=true"]
                for o in overrides:
                    cmd += ["--set", o]
                run(cmd)
                spec["cases"].append(expectations(label, out, n, origin, cells, h,
                                                  os.path.join(work, f"{label}_stress.png")))
            spec_file = os.path.join(work, "spec.json")
            with open(spec_file, "w") as f:
                json.dump(spec, f, indent=1)
            script = os.path.join(source, "tests", "io", "paraview_check.py")
            print(run_pvbatch(pvbatch, [script, spec_file]))
            for case in spec["cases"]:
                check(os.path.getsize(case["png"]) > 10000, f"{case['png']} is too small to show anything")
        except (CheckFailed, subprocess.TimeoutExpired) as e:
            print(f"FAIL: {e}", file=sys.stderr)
            return 1
    print("ok: ParaView opened the 2D and 3D outputs")
    return 0


if __name__ == "__main__":
    sys.exit(main())
