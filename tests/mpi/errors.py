#!/usr/bin/python3
"""Errors on several MPI ranks behave as on one (docs/parallel.md, "Errors").

  - an input error (a bad value in the case file) exits 2 on every rank and is printed once, the
    same line as in a serial run;
  - a simulation failure (a particle driven out of the grid) exits 3, names the same step, time,
    particle and position as the serial run (particles are named by id on every rank count),
    writes failure.xdmf and the same history.csv as the serial run;
  - an initial stress of a point file that the material cannot carry is refused at the same row
    as serially (the ranks share the file's rows out), exit 2, printed once;
  - the methods that run on one rank only (the WLS method, method.integration = "wls", and the
    reference FEM, [fem]) are refused on several ranks with exit 2 and one message from rank 0
    naming the case file and docs/parallel.md.
Exit 0 only when every check holds; the last line says RESULT: ...
"""
import argparse
import os
import re
import subprocess
import sys
from pathlib import Path


def run(cmd):
    env = dict(os.environ, OMP_NUM_THREADS="1", OMP_WAIT_POLICY="PASSIVE")
    done = subprocess.run([str(c) for c in cmd], env=env, capture_output=True, text=True)
    return done.returncode, done.stderr


def cairn_lines(stderr):
    """The lines Cairn printed (mpirun adds its own report of the non-zero exit)."""
    return [line for line in stderr.splitlines() if line.startswith("cairn: ")]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cairn", required=True)
    ap.add_argument("--mpirun", default="mpirun")
    ap.add_argument("--case", required=True, type=Path, help="a case that runs (flip_blocks.toml)")
    ap.add_argument("--out", required=True, type=Path)
    ap.add_argument("--np", type=int, default=2)
    ap.add_argument("--fem-case", type=Path, help="an input with [fem] (refused on several ranks)")
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    mpirun = [args.mpirun, "--oversubscribe", "--allow-run-as-root", "-np", str(args.np)]
    text = args.case.read_text()
    problems = []

    bad = args.out / "bad.toml"
    bad.write_text(re.sub(r"(?m)^cfl = .*$", "cfl = -0.3", text))
    rc_s, err_s = run([args.cairn, "run", bad])
    rc_m, err_m = run(mpirun + [args.cairn, "run", bad])
    lines_s, lines_m = cairn_lines(err_s), cairn_lines(err_m)
    if rc_s != 2 or rc_m != 2:
        problems.append(f"input error: exit {rc_m} on {args.np} ranks, {rc_s} serially (expected 2)")
    if len(lines_m) != 1 or lines_m != lines_s:
        problems.append(f"input error: {args.np} ranks printed {lines_m}, serially {lines_s}")

    failing = args.out / "fail.toml"
    failing.write_text(re.sub(r"(?m)^velocity = \[-40.0, 0.0\]$", "velocity = [-4.0e4, 0.0]", text))
    outcome = {}
    for label, prefix in (("serial", []), ("mpi", mpirun)):
        d = args.out / f"fail_{label}"
        rc, err = run(prefix + [args.cairn, "run", failing, "--set", f'output.directory="{d}"'])
        lines = [line.replace(str(d), "OUT") for line in cairn_lines(err)]
        outcome[label] = (rc, lines, d)
    (rc_s, lines_s, d_s), (rc_m, lines_m, d_m) = outcome["serial"], outcome["mpi"]
    if rc_s != 3 or rc_m != 3:
        problems.append(f"failure: exit {rc_m} on {args.np} ranks, {rc_s} serially (expected 3)")
    fail_s = [line for line in lines_s if "simulation failed" in line]
    fail_m = [line for line in lines_m if "simulation failed" in line]
    if len(fail_s) != 1 or fail_m != fail_s:
        problems.append(f"failure: {args.np} ranks said {fail_m}, serially {fail_s}")
    if not (d_m / "failure.xdmf").is_file():
        problems.append(f"failure: no failure.xdmf on {args.np} ranks")
    if (d_m / "history.csv").read_text().splitlines()[1:] and [
            r.rsplit(",", 1)[0] for r in (d_m / "history.csv").read_text().splitlines()] != \
            (d_s / "history.csv").read_text().splitlines():
        problems.append("failure: history.csv differs from the serial one (imbalance column aside)")

    # An initial stress a material cannot carry, in a point file whose rows the ranks share out
    # (sim/bodies.cpp): refused at the same row as serially, once, exit 2, whichever rank solved it.
    (args.out / "stressed.csv").write_text(
        "x,y,volume,sxx,syy,sxy\n" + "".join(
            f"{0.3 + 0.05 * i},0.3,1e-4,{1.0e15 if i == 7 else 1.0e3},0,0\n" for i in range(9)))
    stressed = args.out / "stressed.toml"
    stressed.write_text(
        "[simulation]\ndimension = 2\nend_time = 1e-4\n[grid]\norigin = [0.0, 0.0]\nextent = [1.0, 0.5]\n"
        "cell_size = 0.05\n[[material]]\nname = \"m\"\nmodel = \"neo_hookean\"\ndensity = 1000.0\n"
        "youngs_modulus = 1.0e6\npoissons_ratio = 0.3\n[[body]]\nmaterial = \"m\"\n"
        "shape = { points = { file = \"stressed.csv\" } }\n")
    rc_s, err_s = run([args.cairn, "run", stressed])
    rc_m, err_m = run(mpirun + [args.cairn, "run", stressed])
    lines_s, lines_m = cairn_lines(err_s), cairn_lines(err_m)
    if rc_s != 2 or rc_m != 2:
        problems.append(f"refused initial stress: exit {rc_m} on {args.np} ranks, {rc_s} serially (expected 2)")
    if len(lines_m) != 1 or lines_m != lines_s or "particle 8 of" not in lines_m[0]:
        problems.append(f"refused initial stress: {args.np} ranks printed {lines_m}, serially {lines_s}")

    # One-rank methods: refused on several ranks, once, exit 2.
    refused = [("wls", [args.cairn, "run", args.case, "--set", 'method.integration="wls"'])]
    if args.fem_case:
        refused.append(("fem", [args.cairn, "run", args.fem_case]))
    for label, cmd in refused:
        rc, err = run(mpirun + cmd)
        lines = cairn_lines(err)
        if rc != 2 or len(lines) != 1 or "one MPI rank only" not in lines[0] or "docs/parallel.md" not in lines[0]:
            problems.append(f"{label} on {args.np} ranks: exit {rc} (expected 2), printed {lines}")

    for p in problems:
        print(p)
    if problems:
        print(f"RESULT: FAIL errors on {args.np} ranks ({len(problems)} problems)")
        return 1
    print(f"RESULT: PASS errors on {args.np} ranks: input error once with exit 2, failure with exit 3 as serially, refused initial stress as serially, WLS/FEM refused once with exit 2")
    return 0


if __name__ == "__main__":
    sys.exit(main())
