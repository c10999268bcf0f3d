#!/usr/bin/python3
"""Strong and weak scaling of MPI ranks against OpenMP threads on this machine (docs/performance.md, "MPI").

Problem (c) of bench/problems/ (3D linear-elastic block, linear shapes, FLIP, 64 000 particles),
cut to --steps steps. Configurations, run in rounds whose order rotates from round to round:

  strong  1x1   cairn run -t 1                                   64 000 particles
  strong  2x1   mpirun -np 2 cairn run -t 1                      64 000 particles
  strong  1x2   cairn run -t 2 (adaptive thread count off)       64 000 particles
  weak    2x1   mpirun -np 2 cairn run -t 1 on the block doubled along x (128 000 particles)
  weak    1x1   cairn run -t 1 on the doubled block

For each: the median of the run loop's particle-steps/s (the summary line; it leaves out start-up)
and the median wall time of the whole command (mpirun's start included). Speed-ups are per round
against the round's 1x1 run of the same problem, then the median.

  /usr/bin/python3 bench/mpi_scaling.py [--cairn build/release/cairn] [--rounds 5] [--steps 60]
"""
import argparse
import os
import re
import statistics
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SUMMARY = re.compile(r"cairn: (\d+) steps to t = \S+ in ([\d.]+) s \(([\d.e+-]+) particle-steps/s")
MPIRUN = ["mpirun", "--oversubscribe", "--bind-to", "none"] + (["--allow-run-as-root"] if os.geteuid() == 0 else [])


def doubled_input(scratch):
    """Problem (c) with the grid and the block twice as long along x (same cells, same spacing)."""
    with open(os.path.join(ROOT, "bench", "problems", "c_block3d_linear.toml")) as f:
        text = f.read()
    for old, new in (("extent = [1.0, 1.0, 1.0]", "extent = [2.0, 1.0, 1.0]"),
                     ("max = [0.8125, 0.8125, 0.8125]", "max = [1.8125, 0.8125, 0.8125]")):
        if old not in text:
            sys.exit(f"bench/problems/c_block3d_linear.toml no longer contains {old!r}")
        text = text.replace(old, new)
    path = os.path.join(scratch, "c_doubled.toml")
    with open(path, "w") as f:
        f.write(text)
    return path


def run(cmd):
    t0 = time.perf_counter()
    res = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if res.returncode != 0:
        sys.exit(f"failed ({res.returncode}): {' '.join(cmd)}\n{res.stdout}\n{res.stderr}")
    m = SUMMARY.search(res.stdout + res.stderr)
    if not m:
        sys.exit(f"no summary line from {' '.join(cmd)}:\n{res.stdout}\n{res.stderr}")
    return float(m.group(3)), wall


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cairn", default=os.path.join(ROOT, "build", "release", "cairn"))
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--steps", type=int, default=60)
    args = ap.parse_args()
    scratch = f"/tmp/cairn-mpi-scaling-{os.getpid()}"
    os.makedirs(scratch, exist_ok=True)
    single = os.path.join(ROOT, "bench", "problems", "c_block3d_linear.toml")
    double = doubled_input(scratch)
    common = ["--set", f"simulation.max_steps={args.steps}", "--set", "simulation.adapt_threads=false",
              "--set", f"output.directory={scratch}/out"]
    configs = {
        ("strong", "1x1"): [args.cairn, "run", single, "-t", "1"] + common,
        ("strong", "2x1"): MPIRUN + ["-np", "2", args.cairn, "run", single, "-t", "1"] + common,
        ("strong", "1x2"): [args.cairn, "run", single, "-t", "2"] + common,
        ("weak", "2x1"): MPIRUN + ["-np", "2", args.cairn, "run", double, "-t", "1"] + common,
        ("weak", "1x1"): [args.cairn, "run", double, "-t", "1"] + common,
    }
    keys = list(configs)
    rate = {k: [] for k in keys}
    wall = {k: [] for k in keys}
    print(f"load average {os.getloadavg()[0]:.1f} at start; {args.rounds} rounds, {args.steps} steps", flush=True)
    for r in range(args.rounds):
        order = keys[r % len(keys):] + keys[:r % len(keys)]
        for k in order:
            pr, w = run(configs[k])
            rate[k].append(pr)
            wall[k].append(w)
        print(f"  round {r + 1}: " + ", ".join(f"{k[0]} {k[1]} {rate[k][-1] / 1e6:.2f} M" for k in keys), flush=True)

    def speedup(k, ref):
        return statistics.median(a / b for a, b in zip(rate[k], rate[ref]))

    print(f"\nload average {os.getloadavg()[0]:.1f} at end; medians of {args.rounds} rounds")
    print("| run | particles | particle-steps/s (loop) | wall time (command) | speed-up over 1 rank x 1 thread |")
    print("|---|---:|---:|---:|---:|")
    ref_strong, ref_weak = ("strong", "1x1"), ("weak", "1x1")
    rows = [(("strong", "1x1"), "64 000", "1.00"),
            (("strong", "2x1"), "64 000", f"{speedup(('strong', '2x1'), ref_strong):.2f}"),
            (("strong", "1x2"), "64 000", f"{speedup(('strong', '1x2'), ref_strong):.2f}"),
            (("weak", "1x1"), "128 000", "1.00"),
            (("weak", "2x1"), "128 000", f"{speedup(('weak', '2x1'), ref_weak):.2f}")]
    for k, n, s in rows:
        label = {"1x1": "1 rank x 1 thread", "2x1": "2 ranks x 1 thread", "1x2": "1 rank x 2 threads"}[k[1]]
        print(f"| {k[0]}: {label} | {n} | {statistics.median(rate[k]) / 1e6:.2f} M | "
              f"{statistics.median(wall[k]):.2f} s | {s} |")
    eff = statistics.median(rate[("weak", "2x1")]) / 2 / statistics.median(rate[("strong", "1x1")])
    print(f"\nweak-scaling efficiency (2 ranks on twice the particles, per rank, against 1 rank on the block): {eff:.2f}")


if __name__ == "__main__":
    main()
