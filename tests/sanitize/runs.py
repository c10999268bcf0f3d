#!/usr/bin/python3
"""Short runs under the sanitizer build (preset "sanitize", issue 36): every engine, dimension,
shape family, particle update and stress-update timing, contact, WLS, the FEM, a checkpoint
restart and a 2-rank MPI run, each for a few steps with AddressSanitizer and UBSan watching.

    tests/sanitize/runs.py --cairn build/sanitize/cairn --group shapes --out DIR [--mpirun mpirun]

A run passes when it exits 0 and prints no sanitizer report (the build makes every report
fatal, -fno-sanitize-recover=all, so a report is also a non-zero exit). Groups: shapes (two
disks in multimaterial contact, tests/mpi/cases/contact_disks.toml, under every shape family, the
updates and timings assigned round-robin), dims (1D, 3D, geometry from files, shocks), engines (WLS 2D and 3D, the
FEM, a restart), mpi (2 and 3 ranks, both halos).
"""
import argparse
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
CORPUS = ROOT / "tests" / "robustness" / "corpus"
DISKS = ROOT / "tests" / "mpi" / "cases" / "contact_disks.toml"

SHAPES = ["linear", "gimp", "cpgimp", "ugimp", "bspline2", "bspline2_open", "bspline3",
          "bspline3_open", "cpdi", "b2gimp", "b2cpdi"]
UPDATES = [("flip", 1), ("pic", 1), ("xpic", 3), ("fmpm", 2), ("apic", 1), ("blend", 1),
           ("flip1", 1), ("flip2", 1), ("flip_vv", 1)]
TIMINGS = ["usl", "usf", "usavg", "usl+", "usavg+"]

RUBBER = """
[method]
integration = "wls"
[[material]]
name = "rubber"
model = "neo_hookean"
density = 1000.0
youngs_modulus = 1e6
poissons_ratio = 0.3
"""
WLS = {2: """
[simulation]
dimension = 2
mode = "plane_strain"
end_time = 1.0
[grid]
origin = [0.0, 0.0]
extent = [1.0, 1.0]
cell_size = 0.0625
""" + RUBBER + """
[[body]]
name = "disk"
material = "rubber"
shape = { circle = { center = [0.5, 0.5], radius = 0.25 } }
velocity = ["Y - 0.5", "0.5 - X"]
[body_force]
expression = [0.0, -9.81]
""", 3: """
[simulation]
dimension = 3
end_time = 1.0
[grid]
origin = [0.0, 0.0, 0.0]
extent = [1.0, 1.0, 1.0]
cell_size = 0.125
""" + RUBBER + """
[[body]]
name = "ball"
material = "rubber"
shape = { sphere = { center = [0.5, 0.5, 0.5], radius = 0.3 } }
velocity = [0.0, 0.0, "0.5 - Z"]
"""}


LATEST = "<the checkpoint run's last checkpoint>"


def runs(group, out):
    """(name, command arguments after the binary, MPI ranks) of one group."""
    if group == "shapes":
        for i, shape in enumerate(SHAPES):
            update, order = UPDATES[i % len(UPDATES)]
            yield (f"{shape}_{update}", ["run", str(DISKS), "--set", f'method.shape="{shape}"',
                   "--set", f'method.update="{update}"', "--set", f"method.order={order}",
                   "--set", f'method.stress_update="{TIMINGS[i % len(TIMINGS)]}"'], 1)
    elif group == "dims":
        yield ("bar_1d", ["run", str(CORPUS / "bar_1d.toml")], 1)
        yield ("ball_3d_gimp_apic", ["run", str(CORPUS / "ball_3d.toml")], 1)
        yield ("ball_3d_b2cpdi_fmpm", ["run", str(CORPUS / "ball_3d.toml"), "--set", 'method.shape="b2cpdi"',
               "--set", 'method.update="fmpm"', "--set", "method.order=2"], 1)
        for example in ["meshed_projectile_3d", "plate_with_holes_2d", "nickel_shock", "taylor_bar"]:
            yield (example, ["run", str(ROOT / "examples" / f"{example}.toml")], 1)
    elif group == "engines":
        for dim, text in WLS.items():
            path = out / f"wls_{dim}d.toml"
            path.write_text(text)
            yield (f"wls_{dim}d", ["run", str(path)], 1)
        yield ("fem_ring", ["run", str(ROOT / "tests" / "fem" / "ring_mms.toml")], 1)
        yield ("checkpoint", ["run", str(DISKS)], 1)
        yield ("restart", ["restart", LATEST, "--set", "simulation.max_steps=30"], 1)
    elif group == "mpi":
        yield ("contact_disks_2ranks", ["run", str(DISKS)], 2)  # (contact under the node halo)
        cases = ROOT / "tests" / "mpi" / "cases"
        yield ("cpdi_wall_2ranks_nodes", ["run", str(cases / "cpdi_wall.toml")], 2)  # node halo, conduction
        yield ("fmpm_periodic_3ranks_nodes", ["run", str(cases / "fmpm_periodic.toml")], 3)
    else:
        raise SystemExit(f"runs.py: unknown group {group!r}")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cairn", required=True)
    ap.add_argument("--group", required=True)
    ap.add_argument("--out", type=Path, required=True)
    ap.add_argument("--mpirun", default="mpirun")
    ap.add_argument("--steps", type=int, default=20)
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    failed = []
    for name, cmd, ranks in runs(args.group, args.out):
        folder = args.out / ("checkpoint" if name in ("checkpoint", "restart") else name)
        if cmd[0] == "run":
            cmd = cmd + ["--set", f"simulation.max_steps={args.steps}", "--set", f'output.directory="{folder}"']
        if LATEST in cmd:
            cmd[cmd.index(LATEST)] = str(sorted((args.out / "checkpoint").glob("checkpoint-*.h5"))[-1])
        full = [args.cairn] + cmd + ["-q"]
        env = dict(os.environ)
        if ranks > 1:
            full = [args.mpirun, "--oversubscribe", "--allow-run-as-root", "-np", str(ranks)] + full
            # Open MPI's plug-ins (mca_*.so, loaded and unloaded at run time) keep allocations
            # that LeakSanitizer can no longer name by library: leaks are checked by the serial
            # runs and the unit tests; memory errors and UB stay fatal here.
            env["ASAN_OPTIONS"] = env.get("ASAN_OPTIONS", "") + ":detect_leaks=0"
        r = subprocess.run(full, capture_output=True, text=True, env=env)
        report = "Sanitizer" in r.stderr or "runtime error:" in r.stderr
        ok = r.returncode == 0 and not report
        print(f"{'ok  ' if ok else 'FAIL'} {name}: exit {r.returncode}{', sanitizer report' if report else ''}")
        if not ok:
            print("  " + " ".join(full))
            print("\n".join("  | " + line for line in (r.stdout + r.stderr).splitlines()[-60:]))
            failed.append(name)
    print(f"RESULT: {args.group}: {'all runs clean' if not failed else 'failed: ' + ', '.join(failed)}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
