#!/usr/bin/python3
"""2 threads against 1 thread, on an idle machine and beside a CPU-bound neighbour.

For each problem of bench/problems/ (compare_baseline.py's a-d) and each OpenMP wait policy
setting, runs `cairn run -t 1` and `-t 2` in alternating pairs and prints the median
particle-steps/s and the median per-pair speed-up, first alone, then while one busy-looping
process (a second /usr/bin/python3 spinning) competes for the 2 cores.

  /usr/bin/python3 bench/thread_scaling.py [--cairn build/release/cairn] [--problems a d]
      [--pairs 3] [--policies default PASSIVE ACTIVE]

"default" leaves OMP_WAIT_POLICY unset (what a user gets); the others set it for the run.
"""
import argparse
import os
import statistics
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import compare_baseline as cb  # noqa: E402


def run(binary, problem, threads, policy, scratch):
    saved = os.environ.get("OMP_WAIT_POLICY")
    if policy == "default":
        os.environ.pop("OMP_WAIT_POLICY", None)
    else:
        os.environ["OMP_WAIT_POLICY"] = policy
    try:
        return cb.run_once(binary, problem, threads, scratch, 1.0)
    finally:
        if saved is None:
            os.environ.pop("OMP_WAIT_POLICY", None)
        else:
            os.environ["OMP_WAIT_POLICY"] = saved


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cairn", default=os.path.join(cb.ROOT, "build", "release", "cairn"))
    ap.add_argument("--problems", nargs="+", default=["a", "d"], choices=sorted(cb.PROBLEMS))
    ap.add_argument("--pairs", type=int, default=3)
    ap.add_argument("--policies", nargs="+", default=["default", "PASSIVE"])
    args = ap.parse_args()
    scratch = f"/tmp/cairn-threads-{os.getpid()}"
    rows = []
    for busy in (False, True):
        neighbour = subprocess.Popen(["/usr/bin/python3", "-c", "while True: pass"]) if busy else None
        try:
            for prob in args.problems:
                for policy in args.policies:
                    one, two, ratios = [], [], []
                    for r in range(args.pairs):
                        order = [1, 2] if r % 2 == 0 else [2, 1]
                        got = {t: run(args.cairn, prob, t, policy, scratch) for t in order}
                        one.append(got[1])
                        two.append(got[2])
                        ratios.append(got[2] / got[1])
                    rows.append((prob, "busy" if busy else "alone", policy, statistics.median(one),
                                 statistics.median(two), statistics.median(ratios), min(ratios), max(ratios)))
                    print(f"  ({prob}) {rows[-1][1]}, {policy}: 2 threads / 1 thread = "
                          f"{rows[-1][5]:.2f} (pairs {', '.join(f'{x:.2f}' for x in ratios)})", flush=True)
        finally:
            if neighbour:
                neighbour.kill()
                neighbour.wait()
    print(f"\nload average {os.getloadavg()[0]:.1f} at end; particle-steps/s, medians of {args.pairs} "
          "alternating pairs; 'busy': one CPU-bound process beside the run")
    print("| problem | machine | OMP_WAIT_POLICY | 1 thread | 2 threads | 2 / 1 (min-max) |")
    print("|---|---|---|---:|---:|---:|")
    for prob, busy, policy, a, b, r, lo, hi in rows:
        print(f"| ({prob}) | {busy} | {policy} | {a / 1e6:.2f} M | {b / 1e6:.2f} M | {r:.2f} ({lo:.2f}-{hi:.2f}) |")


if __name__ == "__main__":
    main()
