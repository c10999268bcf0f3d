#!/usr/bin/python3
"""A contact run on 2 MPI ranks under both halos (docs/performance.md, "MPI"; docs/parallel.md,
"Contact under the node halo").

tests/mpi/cases/contact_disks.toml (two disks colliding across the 2-rank boundary, LR normals
and separations, XPIC(3)) refined by --refine (cell size divided by it; 4: 8 000 particles),
run in pairs that alternate their order from round to round:

  nodes      mpirun -np 2 cairn run -t 1 --set parallel.halo="nodes"      (the default)
  particles  mpirun -np 2 cairn run -t 1 --set parallel.halo="particles"

For each: the median of the run loop's particle-steps/s (the summary line, start-up left out),
the median ratio nodes / particles over the pairs, and the bytes a rank sent per step in halo
exchanges (for the node halo, with the part that carried the particles of contact nodes).

  /usr/bin/python3 bench/mpi_contact.py [--cairn build/release/cairn] [--rounds 5] [--refine 4]
"""
import argparse
import os
import re
import statistics
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from mpi_scaling import MPIRUN, ROOT, SUMMARY  # noqa: E402

HALO = re.compile(r"halo of (\w+) \(parallel.halo\), (\d+) bytes sent per rank and step"
                  r"(?: \((\d+) of them particles of contact nodes\))?")


def run(cmd):
    res = subprocess.run(cmd, capture_output=True, text=True)
    out = res.stdout + res.stderr
    if res.returncode != 0:
        sys.exit(f"failed ({res.returncode}): {' '.join(cmd)}\n{out}")
    m, h = SUMMARY.search(out), HALO.search(out)
    if not m or not h:
        sys.exit(f"no summary lines from {' '.join(cmd)}:\n{out}")
    return float(m.group(3)), int(h.group(2)), int(h.group(3) or 0), int(m.group(1))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cairn", default=os.path.join(ROOT, "build", "release", "cairn"))
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--refine", type=float, default=4.0)
    ap.add_argument("--mpirun", default="mpirun")
    args = ap.parse_args()
    scratch = f"/tmp/cairn-mpi-contact-{os.getpid()}"
    case = os.path.join(ROOT, "tests", "mpi", "cases", "contact_disks.toml")
    common = [args.mpirun] + MPIRUN + ["-np", "2", args.cairn, "run", case, "-t", "1",
                                       "--set", f"grid.cell_size={2.0e-3 / args.refine!r}",
                                       "--set", "simulation.adapt_threads=false",
                                       "--set", "output.every=1.0", "--set", "output.checkpoint_every=0.0",
                                       "--set", f"output.directory=\"{scratch}\""]
    modes = ["nodes", "particles"]
    rate = {m: [] for m in modes}
    sent = {m: [] for m in modes}
    cloud, steps = [], 0
    print(f"load average {os.getloadavg()[0]:.1f} at start; {args.rounds} rounds", flush=True)
    for r in range(args.rounds):
        for m in (modes if r % 2 == 0 else modes[::-1]):
            pr, b, c, steps = run(common + ["--set", f'parallel.halo="{m}"'])
            rate[m].append(pr)
            sent[m].append(b)
            if m == "nodes":
                cloud.append(c)
        print(f"  round {r + 1}: " + ", ".join(f"{m} {rate[m][-1] / 1e6:.3f} M" for m in modes), flush=True)
    ratio = statistics.median(a / b for a, b in zip(rate["nodes"], rate["particles"]))
    print(f"\nload average {os.getloadavg()[0]:.1f} at end; medians of {args.rounds} pairs, {steps} steps")
    for m in modes:
        extra = f" ({statistics.median(cloud):.0f} of them particles of contact nodes)" if m == "nodes" else ""
        print(f"{m}: {statistics.median(rate[m]) / 1e6:.3f} M particle-steps/s, "
              f"{statistics.median(sent[m]):.0f} bytes per rank and step{extra}")
    print(f"nodes / particles: {ratio:.2f} (median of the pairs' ratios; range "
          f"{min(a / b for a, b in zip(rate['nodes'], rate['particles'])):.2f}-"
          f"{max(a / b for a, b in zip(rate['nodes'], rate['particles'])):.2f})")


if __name__ == "__main__":
    main()
