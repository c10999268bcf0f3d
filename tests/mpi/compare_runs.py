#!/usr/bin/python3
"""Run one case serially and on several MPI ranks and require the same results: bit for bit with
the ghost-particle halo (--halo particles), to round-off with the node halo (--halo nodes:
every value within --tolerance times the largest magnitude of its history column or snapshot
dataset, a vector's components and the energies against their group's largest, the stresses
against the stiffness (max|stress| / max|F - I|), integers exact; and a second run on the same ranks bit-identical to the first).

Checks (docs/parallel.md, "Determinism"):
  - history.csv: every column of the serial file is in the MPI file with the same text in every
    row (17 significant digits, so the same doubles); the MPI file adds `imbalance`;
  - the last snapshot: every particle dataset equal to the serial one after sorting by id;
  - --migrate / --repartition: the MPI run moved particles between ranks / partitioned the
    domain again (its summary line says how often);
  - --restart N:M: the checkpoint the N-rank run wrote first, continued on M ranks, ends with
    the serial run's history and final particles;
  - --balance cost: the MPI runs balanced cost, not particle counts (parallel.balance; the
    summary's imbalance line says which) and their repartitions reported the particles they moved;
  - --compression Z: every run writes gzip level Z (output.compression), and the MPI runs' last
    snapshot and first checkpoint hold compressed datasets (written collectively).
Exit 0 only when every check holds; the last line says RESULT: ...
"""
import argparse
import csv
import os
import re
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np


def run(cmd, cwd=None):
    env = dict(os.environ, OMP_NUM_THREADS="1", OMP_WAIT_POLICY="PASSIVE")
    done = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True)
    if done.returncode != 0:
        print(" ".join(map(str, cmd)))
        print(done.stdout[-3000:])
        print(done.stderr[-3000:])
        raise SystemExit(f"RESULT: FAIL ({Path(cmd[-1]).name if cmd else '?'}: exit {done.returncode})")
    return done.stdout + done.stderr


def mpirun(args, n):
    return [args.mpirun, "--oversubscribe", "--allow-run-as-root", "-np", str(n)]


def read_history(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    return rows[0], rows[1:]


STRESSES = ("stress", "pressure", "von_mises")  # compared on the stiffness scale (compare_snapshots)
LARGEST = [0.0, ""]  # largest difference over its scale seen in a tolerance comparison, and where


def within(x, y, scale, tolerance, where=""):
    if tolerance <= 0:
        return False
    d = abs(x - y) / scale if scale > 0 else (0.0 if x == y else float("inf"))
    if d > LARGEST[0]:
        LARGEST[:] = [d, where]
    return d <= tolerance


def column_group(name):
    """Columns compared against a common scale: the components of a vector (momentum, a wall's
    reaction) and the energies (a balance's error is measured against the energies it balances)."""
    if name.endswith("energy") or name in ("energy_error", "external_work"):
        return "energy"
    for axis in ("_x", "_y", "_z"):
        if name.endswith(axis):
            return name[:-2]
    return name


def compare_history(serial_dir, mpi_dir, label, skip=(), tolerance=0.0):
    """Every history column bit for bit (or within tolerance x the largest magnitude of its
    group, column_group), but those in `skip`."""
    problems = []
    head_s, rows_s = read_history(serial_dir / "history.csv")
    head_m, rows_m = read_history(mpi_dir / "history.csv")
    if len(rows_s) != len(rows_m):
        return [f"{label}: {len(rows_m)} history rows, serial {len(rows_s)}"]
    for c, name in enumerate(head_s):
        if name in skip:
            continue
        if name not in head_m:
            problems.append(f"{label}: history column {name} missing")
            continue
        cm = head_m.index(name)
        group = [k for k, other in enumerate(head_s) if column_group(other) == column_group(name)]
        scale = max((abs(float(a[k])) for a in rows_s for k in group), default=0.0) if tolerance > 0 else 0.0
        for r, (a, b) in enumerate(zip(rows_s, rows_m)):
            if a[c] != b[cm] and not within(float(a[c]), float(b[cm]), scale, tolerance, f"{label} history {name}"):
                x, y = float(a[c]), float(b[cm])
                rel = abs(x - y) / max(abs(x), abs(y), 1e-300)
                problems.append(f"{label}: history {name} row {r}: serial {a[c]}, MPI {b[cm]} (relative {rel:.2e})")
                break
    return problems


def last_snapshot(directory):
    files = sorted((directory / "snapshots").glob("particles-*.h5"))
    if not files:
        raise SystemExit(f"RESULT: FAIL (no snapshot in {directory})")
    return files[-1]


def by_id(path):
    with h5py.File(path, "r") as f:
        g = f["particles"]
        ids = g["id"][()]
        order = np.argsort(ids, kind="stable")
        data = {name: g[name][()][order] for name in g}
        time = f.attrs["time"]
    return time, data


def compare_snapshots(serial_dir, mpi_dir, label, tolerance=0.0):
    t_s, a = by_id(last_snapshot(serial_dir))
    t_m, b = by_id(last_snapshot(mpi_dir))
    problems = []
    # Stresses follow from F through the material: F's relative round-off d gives stress errors of
    # (stiffness) x d, and the stiffness is about max|stress| / max|F - I|. So the stress datasets
    # are held to the tolerance on that scale (the same relative bound on F, carried through).
    strain = 0.0
    if "deformation_gradient" in a:
        F = a["deformation_gradient"]
        strain = np.nanmax(np.abs(F - np.eye(3).reshape(1, 9))) if F.size else 0.0
    if t_s != t_m and not within(t_s, t_m, abs(t_s), tolerance):
        problems.append(f"{label}: last snapshot at t = {t_m}, serial {t_s}")
    for name, values in a.items():
        if name == "connectivity":  # the file's row numbers (XDMF cells), not a particle property
            continue
        if name not in b:
            problems.append(f"{label}: snapshot dataset {name} missing")
        elif values.shape != b[name].shape:
            problems.append(f"{label}: snapshot {name} shape {b[name].shape}, serial {values.shape}")
        elif values.dtype.kind == "f" and tolerance > 0:
            scale = np.nanmax(np.abs(values)) if values.size else 0.0
            if name in STRESSES and strain > 0:
                scale /= strain
            diff = np.nanmax(np.abs(values - b[name])) if values.size else 0.0
            within(diff, 0.0, scale, tolerance, f"{label} snapshot {name}")
            if not diff <= tolerance * scale:
                problems.append(f"{label}: snapshot {name} differs by {diff:.3e}, over {tolerance:g} x {scale:.3e}")
        elif not np.array_equal(values, b[name], equal_nan=values.dtype.kind == "f"):
            diff = np.nanmax(np.abs(values - b[name])) if values.dtype.kind == "f" else "ints"
            problems.append(f"{label}: snapshot {name} differs (largest difference {diff})")
    return problems


def counts(summary):
    m = re.search(r"(\d+) domain partitions, (\d+) particles moved between ranks", summary)
    if not m:
        raise SystemExit("RESULT: FAIL (no MPI summary line)\n" + summary[-2000:])
    return int(m.group(1)), int(m.group(2))


def check_compressed(run_dir, label):
    """The largest particle dataset of the last snapshot and of the first checkpoint is gzip'd."""
    problems = []
    files = [sorted((run_dir / "snapshots").glob("particles-*.h5"))[-1]]
    if (run_dir / "checkpoint-0000.h5").exists():
        files.append(run_dir / "checkpoint-0000.h5")
    for path in files:
        with h5py.File(path, "r") as f:
            sets = [d for d in f["particles"].values() if isinstance(d, h5py.Dataset)]
            largest = max(sets, key=lambda d: d.size)
            if largest.compression != "gzip":
                problems.append(f"{label}: {path.name} {largest.name} is not compressed ({largest.compression})")
    print(f"{label}: {len(files)} files with compressed datasets checked")
    return problems


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cairn", required=True)
    ap.add_argument("--mpirun", default="mpirun")
    ap.add_argument("--case", required=True, type=Path)
    ap.add_argument("--out", required=True, type=Path)
    ap.add_argument("--np", type=int, nargs="+", default=[2])
    ap.add_argument("--migrate", action="store_true", help="require particles to move between ranks")
    ap.add_argument("--repartition", action="store_true", help="require a repartition during the run")
    ap.add_argument("--restart", default="", help="N:M - continue the N-rank run's first checkpoint on M ranks")
    ap.add_argument("--halo", choices=["particles", "nodes", "auto"], default="particles",
                    help="parallel.halo of the MPI runs (nodes: compared to round-off, see --tolerance)")
    ap.add_argument("--tolerance", type=float, default=1e-12,
                    help="--halo nodes: largest difference over the largest magnitude of a column/dataset")
    ap.add_argument("--compression", type=int, default=0, help="output.compression of every run (0: plain)")
    ap.add_argument("--balance", choices=["count", "cost"], default="",
                    help="require the MPI runs to have balanced this (the case's parallel.balance)")
    args = ap.parse_args()
    common = ["--set", f"output.compression={args.compression}"] if args.compression else []  # every run
    halo = ["--set", f'parallel.halo="{args.halo}"'] + common
    tol = args.tolerance if args.halo != "particles" else 0.0
    args.out.mkdir(parents=True, exist_ok=True)
    problems = []
    serial = args.out / "serial"
    run([args.cairn, "run", args.case, "--set", f"output.directory=\"{serial}\""] + common)
    for n in args.np:
        d = args.out / f"np{n}"
        summary = run(mpirun(args, n) + [args.cairn, "run", args.case, "--set", f"output.directory=\"{d}\""] + halo)
        m = re.search(r"halo of (\w+)", summary)
        print(f"np {n}: halo of {m.group(1) if m else '?'}")
        if f"with {n} MPI ranks x 1 thread" not in summary:
            problems.append(f"np {n}: the summary does not say '{n} MPI ranks x 1 thread'")
        partitions, moved = counts(summary)
        print(f"np {n}: {partitions} partitions, {moved} particles moved between ranks")
        if args.migrate and moved == 0:
            problems.append(f"np {n}: no particle moved between ranks")
        if args.repartition and partitions < 2:
            problems.append(f"np {n}: the domain was never repartitioned")
        if args.balance:
            what = "cost" if args.balance == "cost" else "particle counts"
            if f"(of {what}, parallel.balance)" not in summary:
                problems.append(f"np {n}: the summary does not say the imbalance is of {what}")
            if partitions > 1 and not re.search(r"\d+ repartitions? moved \d+ particles, at most \d+ in one", summary):
                problems.append(f"np {n}: {partitions - 1} repartitions but no line of the particles they moved")
        problems += compare_history(serial, d, f"np {n}", tolerance=tol)
        problems += compare_snapshots(serial, d, f"np {n}", tolerance=tol)
        if args.compression:
            problems += check_compressed(d, f"np {n}")
        if tol > 0 and n == args.np[0]:
            # The same ranks again: the node sums' fixed order gives the same bits.
            again = args.out / f"np{n}-again"
            run(mpirun(args, n) + [args.cairn, "run", args.case, "--set", f"output.directory=\"{again}\""] + halo)
            problems += compare_history(d, again, f"np {n} run twice", skip=("imbalance",))
            problems += compare_snapshots(d, again, f"np {n} run twice")
    if args.restart:
        first, then = (int(v) for v in args.restart.split(":"))
        checkpoint = args.out / f"np{first}" / "checkpoint-0000.h5"
        d = args.out / f"restart{first}to{then}"
        run(mpirun(args, then) + [args.cairn, "restart", checkpoint, "--set", f"output.directory=\"{d}\""] + halo)
        problems += compare_history(serial, d, f"restart {first}->{then}", tolerance=tol)
        problems += compare_snapshots(serial, d, f"restart {first}->{then}", tolerance=tol)
    for p in problems:
        print(p)
    if tol > 0:
        print(f"largest difference from the serial run: {LARGEST[0]:.2e} of its column's scale ({LARGEST[1] or 'none'})")
    ranks = ", ".join(map(str, args.np)) + (f"; restart {args.restart}" if args.restart else "")
    if problems:
        print(f"RESULT: FAIL {args.case.stem} ({len(problems)} differences from the serial run; ranks {ranks})")
        return 1
    how = "bit-identical to" if tol == 0 else f"within {tol:g} (relative to each column's scale) of"
    print(f"RESULT: PASS {args.case.stem} (halo {args.halo}): history and particles {how} the serial run on {ranks} ranks")
    return 0


if __name__ == "__main__":
    sys.exit(main())
