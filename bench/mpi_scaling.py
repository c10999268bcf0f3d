#!/usr/bin/python3
"""Strong and weak scaling of MPI ranks against OpenMP threads on this machine (docs/performance.md, "MPI").

Problem (c) of bench/problems/ (3D linear-elastic block, linear shapes, FLIP, 64 000 particles;
with --million its cells halved, 2.5^3 particles per cell: 1 000 000 particles), cut to --steps
steps. Configurations, run in rounds whose order rotates from round to round:

  strong  1x1             cairn run -t 1                                   64 000 particles
  strong  2x1 nodes       mpirun -np 2 cairn run -t 1 (parallel.halo = "nodes", the default)
  strong  2x1 particles   mpirun -np 2 cairn run -t 1 --set parallel.halo="particles"
  strong  1x2             cairn run -t 2 (adaptive thread count off)
  weak    2x1 nodes       mpirun -np 2 cairn run -t 1 on the block doubled along x (twice the particles)
  weak    1x1             cairn run -t 1 on the doubled block

--ranks 4 8 16 adds strong runs on those rank counts (node halo) and on as many threads of one
rank, for a machine with that many cores. Each MPI run's summary gives the bytes a rank sent per
step in halo exchanges, printed beside its rate.

For each: the median of the run loop's particle-steps/s (the summary line; it leaves out start-up)
and the median wall time of the whole command (mpirun's start included). Speed-ups are per round
against the round's 1x1 run of the same problem, then the median.

  /usr/bin/python3 bench/mpi_scaling.py [--cairn build/release/cairn] [--rounds 5] [--steps 60]
                                        [--million] [--ranks 4 8 16] [--mpirun mpirun]
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
HALO = re.compile(r"halo of (\w+) \(parallel.halo\), (\d+) bytes sent per rank and step")
MPIRUN = ["--oversubscribe", "--bind-to", "none"] + (["--allow-run-as-root"] if os.geteuid() == 0 else [])


def edited_input(scratch, name, edits):
    """Problem (c) with `edits` (old, new) applied."""
    with open(os.path.join(ROOT, "bench", "problems", "c_block3d_linear.toml")) as f:
        text = f.read()
    for old, new in edits:
        if old not in text:
            sys.exit(f"bench/problems/c_block3d_linear.toml no longer contains {old!r}")
        text = text.replace(old, new)
    path = os.path.join(scratch, name)
    with open(path, "w") as f:
        f.write(text)
    return path


def inputs(scratch, million):
    """The strong and the weak (doubled along x) problems."""
    refine = [("cell_size = 0.03125", "cell_size = 0.0125")]
    base = refine if million else []
    # 0.625^3 of the unit cube at h = 0.0125: 50 cells per axis, 2 particles each: 100^3 = 1 000 000
    strong = edited_input(scratch, "strong.toml", base)
    weak = edited_input(scratch, "weak.toml", base + [("extent = [1.0, 1.0, 1.0]", "extent = [2.0, 1.0, 1.0]"),
                                                      ("max = [0.8125, 0.8125, 0.8125]", "max = [1.8125, 0.8125, 0.8125]")])
    return strong, weak


def run(cmd):
    t0 = time.perf_counter()
    res = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if res.returncode != 0:
        sys.exit(f"failed ({res.returncode}): {' '.join(cmd)}\n{res.stdout}\n{res.stderr}")
    m = SUMMARY.search(res.stdout + res.stderr)
    if not m:
        sys.exit(f"no summary line from {' '.join(cmd)}:\n{res.stdout}\n{res.stderr}")
    h = HALO.search(res.stdout + res.stderr)
    return float(m.group(3)), wall, (int(h.group(2)) if h else 0)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cairn", default=os.path.join(ROOT, "build", "release", "cairn"))
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--steps", type=int, default=60)
    ap.add_argument("--million", action="store_true", help="the block refined to 1 000 000 particles")
    ap.add_argument("--ranks", type=int, nargs="*", default=[], help="more strong-scaling rank counts")
    ap.add_argument("--mpirun", default="mpirun")
    args = ap.parse_args()
    scratch = f"/tmp/cairn-mpi-scaling-{os.getpid()}"
    os.makedirs(scratch, exist_ok=True)
    single, double = inputs(scratch, args.million)
    n_strong = "1 000 000" if args.million else "64 000"
    n_weak = "2 000 000" if args.million else "128 000"
    common = ["--set", f"simulation.max_steps={args.steps}", "--set", "simulation.adapt_threads=false",
              "--set", f"output.directory={scratch}/out"]
    mpi = [args.mpirun] + MPIRUN
    particles = ["--set", 'parallel.halo="particles"']
    configs = {
        ("strong", "1x1"): [args.cairn, "run", single, "-t", "1"] + common,
        ("strong", "2x1 nodes"): mpi + ["-np", "2", args.cairn, "run", single, "-t", "1"] + common,
        ("strong", "2x1 particles"): mpi + ["-np", "2", args.cairn, "run", single, "-t", "1"] + common + particles,
        ("strong", "1x2"): [args.cairn, "run", single, "-t", "2"] + common,
        ("weak", "2x1 nodes"): mpi + ["-np", "2", args.cairn, "run", double, "-t", "1"] + common,
        ("weak", "1x1"): [args.cairn, "run", double, "-t", "1"] + common,
    }
    for n in args.ranks:
        configs[("strong", f"{n}x1 nodes")] = mpi + ["-np", str(n), args.cairn, "run", single, "-t", "1"] + common
        configs[("strong", f"1x{n}")] = [args.cairn, "run", single, "-t", str(n)] + common
    keys = list(configs)
    rate = {k: [] for k in keys}
    wall = {k: [] for k in keys}
    sent = {k: [] for k in keys}
    print(f"load average {os.getloadavg()[0]:.1f} at start; {args.rounds} rounds, {args.steps} steps", flush=True)
    for r in range(args.rounds):
        order = keys[r % len(keys):] + keys[:r % len(keys)]
        for k in order:
            pr, w, b = run(configs[k])
            rate[k].append(pr)
            wall[k].append(w)
            sent[k].append(b)
        print(f"  round {r + 1}: " + ", ".join(f"{k[0]} {k[1]} {rate[k][-1] / 1e6:.2f} M" for k in keys), flush=True)

    def speedup(k, ref):
        return statistics.median(a / b for a, b in zip(rate[k], rate[ref]))

    def label(k):
        ranks, threads = k[1].split()[0].split("x")
        halo = f", {k[1].split()[1]} halo" if " " in k[1] else ""
        return (f"{ranks} rank{'s' if ranks != '1' else ''} x {threads} thread{'s' if threads != '1' else ''}"
                f"{halo}")

    print(f"\nload average {os.getloadavg()[0]:.1f} at end; medians of {args.rounds} rounds")
    print("| run | particles | particle-steps/s (loop) | wall time (command) | halo bytes per rank and step | "
          "speed-up over 1 rank x 1 thread |")
    print("|---|---:|---:|---:|---:|---:|")
    for k in keys:
        ref = ("strong", "1x1") if k[0] == "strong" else ("weak", "1x1")
        b = statistics.median(sent[k])
        print(f"| {k[0]}: {label(k)} | {n_strong if k[0] == 'strong' else n_weak} | "
              f"{statistics.median(rate[k]) / 1e6:.2f} M | {statistics.median(wall[k]):.2f} s | "
              f"{b if b else '-'} | {speedup(k, ref):.2f} |")
    eff = statistics.median(rate[("weak", "2x1 nodes")]) / 2 / statistics.median(rate[("strong", "1x1")])
    print(f"\nweak-scaling efficiency (2 ranks on twice the particles, per rank, against 1 rank on the block): {eff:.2f}")
    print(f"2 ranks x 1 thread (node halo) over 1 rank x 2 threads: "
          f"{speedup(('strong', '2x1 nodes'), ('strong', '1x2')):.2f}")


if __name__ == "__main__":
    main()
