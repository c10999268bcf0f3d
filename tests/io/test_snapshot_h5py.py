"""Run a tiny 2D case with the cairn binary and check its HDF5/XDMF snapshots with h5py.

Usage: python3 test_snapshot_h5py.py <path to cairn binary> <source dir>
Exits non-zero with a message on the first failed check.
"""
import glob
import math
import os
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET

import h5py
import numpy as np

CASE = """\
[simulation]
dimension = 2
end_time = 1.0e-4

[grid]
origin = [0.0, 0.0]
extent = [0.01, 0.01]
cell_size = 1.0e-3

[[material]]
name = "steel"
model = "linear_elastic"
density = 7800.0
youngs_modulus = 200.0e9
poissons_ratio = 0.3

[[body]]
material = "steel"
shape = { box = { min = [0.002, 0.002], max = [0.006, 0.005] } }
velocity = [10.0, 0.0]

[output]
every = 5.0e-5
"""

DENSITY = 7800.0
AREA = 0.004 * 0.003
THICKNESS = 1.0


class CheckFailed(Exception):
    pass


def check(condition, message):
    if not condition:
        raise CheckFailed(message)


def run_case(cairn, tmpdir):
    case = os.path.join(tmpdir, "case.toml")
    out = os.path.join(tmpdir, "out")
    with open(case, "w", encoding="utf-8") as f:
        f.write(CASE)
    cmd = [cairn, "run", case, "--set", f"output.directory={out}", "--quiet"]
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    except subprocess.TimeoutExpired:
        raise CheckFailed(f"'{' '.join(cmd)}' did not finish within 600 s")
    check(proc.returncode == 0,
          f"'{' '.join(cmd)}' exited with {proc.returncode}\n"
          f"--- stdout ---\n{proc.stdout}\n--- stderr ---\n{proc.stderr}")
    return out


def snapshot_index(path):
    stem = os.path.splitext(os.path.basename(path))[0]
    return int(stem.rsplit("-", 1)[1])


def check_newest_snapshot(out):
    files = glob.glob(os.path.join(out, "snapshots", "particles-*.h5"))
    check(files, f"no snapshots/particles-*.h5 files under {out}")
    newest = max(files, key=snapshot_index)
    with h5py.File(newest, "r") as f:
        check("particles" in f, f"{newest}: no /particles group")
        p = f["particles"]
        pos = p["position"]
        check(pos.ndim == 2 and pos.shape[1] == 3,
              f"{newest}: /particles/position has shape {pos.shape}, expected (n, 3)")
        n = pos.shape[0]
        check(n > 0, f"{newest}: no particles")
        mass = np.asarray(p["mass"][()], dtype=float)
        check(mass.shape == (n,), f"{newest}: /particles/mass has shape {mass.shape}, expected ({n},)")
        expected = DENSITY * AREA * THICKNESS
        total = math.fsum(mass)
        check(abs(total - expected) <= 1e-12 * expected,
              f"{newest}: total mass {total!r} differs from density*area*thickness = {expected!r} "
              f"(relative error {abs(total - expected) / expected:.3e})")
        stress = np.asarray(p["stress"][()], dtype=float)
        check(stress.shape == (n, 6), f"{newest}: /particles/stress has shape {stress.shape}, expected ({n}, 6)")
        check(np.all(np.isfinite(stress)), f"{newest}: /particles/stress has non-finite values")
        check("time" in f.attrs, f"{newest}: no 'time' attribute on the root")
        time = float(f.attrs["time"])
        check(time > 0.0, f"{newest}: root attribute time = {time!r}, expected > 0")
    return newest


def check_xdmf(out):
    xdmf = os.path.join(out, "particles.xdmf")
    check(os.path.isfile(xdmf), f"{xdmf} does not exist")
    try:
        root = ET.parse(xdmf).getroot()
    except ET.ParseError as e:
        raise CheckFailed(f"{xdmf} is not well-formed XML: {e}")
    check(root.tag == "Xdmf", f"{xdmf}: root element is <{root.tag}>, expected <Xdmf>")
    items = [d for d in root.iter("DataItem") if d.get("Format", "XML").upper() == "HDF"]
    check(items, f"{xdmf} references no HDF5 data")
    referenced = set()
    for item in items:
        text = (item.text or "").strip()
        check(":" in text, f"{xdmf}: HDF DataItem '{text}' is not of the form file:/dataset")
        rel, dataset = text.split(":", 1)
        path = os.path.join(out, rel)
        check(os.path.isfile(path), f"{xdmf} references {rel}, which does not exist")
        with h5py.File(path, "r") as f:
            check(dataset in f, f"{xdmf} references {rel}:{dataset}, which is not in the file")
            dims = tuple(int(x) for x in item.get("Dimensions", "").split())
            check(f[dataset].shape == dims,
                  f"{xdmf}: {rel}:{dataset} has shape {f[dataset].shape}, XDMF says {dims}")
        referenced.add(rel)
    snapshots = {os.path.join("snapshots", os.path.basename(p))
                 for p in glob.glob(os.path.join(out, "snapshots", "particles-*.h5"))}
    check(snapshots <= referenced,
          f"{xdmf} does not list snapshot files {sorted(snapshots - referenced)}")
    return len(referenced)


def main():
    if len(sys.argv) < 2:
        print("usage: test_snapshot_h5py.py <cairn binary> [source dir]", file=sys.stderr)
        return 2
    cairn = sys.argv[1]
    if not (os.path.isfile(cairn) and os.access(cairn, os.X_OK)):
        print(f"FAIL: cairn binary '{cairn}' does not exist or is not executable", file=sys.stderr)
        return 1
    with tempfile.TemporaryDirectory(prefix="cairn_h5py_") as tmpdir:
        try:
            out = run_case(cairn, tmpdir)
            newest = check_newest_snapshot(out)
            count = check_xdmf(out)
        except CheckFailed as e:
            print(f"FAIL: {e}", file=sys.stderr)
            return 1
    print(f"ok: {os.path.basename(newest)} checked, particles.xdmf references {count} snapshot files")
    return 0


if __name__ == "__main__":
    sys.exit(main())
