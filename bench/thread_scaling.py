#!/usr/bin/python3
"""2 threads against 1 thread, on an idle machine and beside a CPU-bound neighbour.

For each problem of bench/problems/ (compare_baseline.py's a-d), runs `cairn run -t 1` and, for
each setting, `-t 2` in rounds (the order rotates from round to round) and prints the median
particle-steps/s and the median per-round speed-up over the round's 1-thread run, first alone,
then while one busy-looping process (/usr/bin/python3 spinning) competes for the cores. Each
round also prints the steal time of /proc/stat over the round: CPU time the hypervisor gave to
other guests, which marks the slow periods of a virtual machine.

  /usr/bin/python3 bench/thread_scaling.py [--cairn build/release/cairn] [--problems a d]
      [--pairs 3] [--settings default PASSIVE spin=1000 fixed:spin=1000] [--steps-scale 1]
      [--only alone|busy] [--quiet-check] [--quiet-rounds] [--ceiling]

A setting is the OpenMP wait policy of the 2-thread run: "default" leaves OMP_WAIT_POLICY and
GOMP_SPINCOUNT unset (what a user gets: cairn picks its own default, app/main.cpp), PASSIVE or
ACTIVE set OMP_WAIT_POLICY, spin=N sets GOMP_SPINCOUNT=N. The prefix "fixed:" turns the adaptive
thread count off (simulation.adapt_threads = false), so the run keeps 2 threads throughout.
The 1-thread reference runs with the "default" environment.

--quiet-rounds runs the side-by-side check (two 1-thread copies of (a) at once, one per core)
before every round alone and prints a second table over the quiet rounds only: those whose
slower copy ran at 0.92 or more of the fastest copy of the block. On a virtual machine a core
slows for minutes at a time (docs/performance.md, "Threads"); a round in those minutes does not
measure an idle machine. Both tables are printed, all rounds first.

--ceiling runs the machine's 2-thread ceiling (cairn_ceiling, bench/ceiling.cpp: a perfectly
parallel compute loop on private in-cache data, barriers at a step's cadence) once on 1 thread
before every round alone and on 2 threads right before and right after the round's runs. Its
gain, the block's median 1-thread time over the 2-thread time, is what this machine gives any
program from a second thread at that moment (2.0 on an idle 2-core machine). A third table
keeps the rounds whose ceiling gain was 1.9 or more both before and after ("machine at its
ceiling"), and gives every round's gain over the mean of its two ceiling gains.

The main table gives, beside the median of the rounds' 2 / 1 ratios, a 95 % interval for that
median (bootstrap: the median of as many rounds drawn with replacement, 2000 times): on a shared
machine one round's ratio moves by tens of percent, and the interval says how many rounds a
figure such as "never below 1.0" needs (an A/A block, 1 thread against 1 thread, 16 rounds:
median 1.02).
"""
import argparse
import os
import random
import re
import statistics
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import compare_baseline as cb  # noqa: E402

VARS = ("OMP_WAIT_POLICY", "GOMP_SPINCOUNT")


def run(binary, problem, threads, setting, scratch, scale):
    saved = {k: os.environ.get(k) for k in VARS}
    fixed = setting.startswith("fixed:")
    policy = setting.split(":", 1)[1] if fixed else setting
    for k in VARS:
        os.environ.pop(k, None)
    if policy.startswith("spin="):
        os.environ["GOMP_SPINCOUNT"] = policy[5:]
    elif policy != "default":
        os.environ["OMP_WAIT_POLICY"] = policy
    more = ["--set", "simulation.adapt_threads=false"] if fixed else []
    try:
        rate, output = cb.run_once(binary, problem, threads, scratch, scale, more, with_output=True)
        m = re.search(r"adaptive threads: (\d+) of (\d+) steps on 1 thread", output)
        return rate, (int(m.group(1)) if m else None)
    finally:
        for k, v in saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v


def median_interval(values, draws=2000, seed=1):
    """95 % bootstrap interval of the median of values: the 2.5th and 97.5th percentiles of the
    medians of `draws` resamples (with replacement, as many as values; a fixed seed, so a table
    is reproducible from its rounds)."""
    rng = random.Random(seed)
    meds = sorted(statistics.median(rng.choices(values, k=len(values))) for _ in range(draws))
    return meds[int(0.025 * draws)], meds[int(0.975 * draws) - 1]


def steal_ms():
    """Milliseconds of CPU time the hypervisor gave to other guests (/proc/stat, all CPUs)."""
    with open("/proc/stat") as f:
        fields = f.readline().split()
    return int(fields[8]) * 1000.0 / os.sysconf("SC_CLK_TCK") if len(fields) > 8 else 0.0


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cairn", default=os.path.join(cb.ROOT, "build", "release", "cairn"))
    ap.add_argument("--problems", nargs="+", default=["a", "d"], choices=sorted(cb.PROBLEMS))
    ap.add_argument("--pairs", type=int, default=3)
    ap.add_argument("--settings", nargs="+", default=["default", "fixed:default", "fixed:PASSIVE"])
    ap.add_argument("--steps-scale", type=float, default=1.0)
    ap.add_argument("--only", choices=["alone", "busy"], default=None)
    ap.add_argument("--quiet-check", action="store_true",
                    help="before and after the runs alone, two 1-thread copies of (a) side by side "
                         "(compare_baseline.side_by_side): both near a lone run's rate mark quiet cores")
    ap.add_argument("--quiet-rounds", action="store_true",
                    help="the side-by-side check before every round alone, and a table of the quiet rounds")
    ap.add_argument("--ceiling", action="store_true",
                    help="the machine's 2-thread ceiling (cairn_ceiling) around every round alone, and a "
                         "table of the rounds at the ceiling")
    args = ap.parse_args()
    ceiling_bin = os.path.join(os.path.dirname(os.path.abspath(args.cairn)), "bench", "cairn_ceiling")
    if args.ceiling and not os.path.exists(ceiling_bin):
        sys.exit(f"--ceiling: {ceiling_bin} not found (cmake --build build/release --target cairn_ceiling)")
    scratch = f"/tmp/cairn-threads-{os.getpid()}"
    quiet = args.quiet_check and args.only != "busy"
    if quiet:
        print("before: " + cb.quiet_line(args.cairn, scratch), flush=True)
    rows, quiet_rows, ceiling_rows = [], [], []
    for busy in (False, True):
        if args.only and args.only != ("busy" if busy else "alone"):
            continue
        neighbour = subprocess.Popen(["/usr/bin/python3", "-c", "while True: pass"]) if busy else None
        load = os.getloadavg()[0]
        try:
            for prob in args.problems:
                configs = [(1, "default")] + [(2, s) for s in args.settings]
                got = {c: [] for c in configs}
                ratios = {s: [] for s in args.settings}
                checks = []  # the slower and the faster copy of each round's side-by-side check
                ceil = []  # each round's ceiling times: 1 thread, 2 threads before, 2 threads after
                for r in range(args.pairs):
                    if args.ceiling and not busy:
                        ceil.append([ceiling_seconds(ceiling_bin, 1), ceiling_seconds(ceiling_bin, 2)])
                    if args.quiet_rounds and not busy:
                        pair = sorted(cb.side_by_side(args.cairn, scratch))
                        checks.append(pair)
                        print(f"  check: {pair[0] / 1e6:.2f} / {pair[1] / 1e6:.2f} M", flush=True)
                    k = r % len(configs)
                    order = configs[k:] + configs[:k]
                    steal = steal_ms()
                    runs = {c: run(args.cairn, prob, c[0], c[1], scratch, args.steps_scale) for c in order}
                    res = {c: runs[c][0] for c in configs}
                    single = {c: runs[c][1] for c in configs}
                    steal = steal_ms() - steal
                    if args.ceiling and not busy:
                        ceil[-1].append(ceiling_seconds(ceiling_bin, 2))
                        print(f"  ceiling: 1 thread {ceil[-1][0]:.3f} s, 2 threads {ceil[-1][1]:.3f} s before, "
                              f"{ceil[-1][2]:.3f} s after", flush=True)
                    for c in configs:
                        got[c].append(res[c])
                    for s in args.settings:
                        ratios[s].append(res[(2, s)] / res[(1, "default")])
                    print(f"  ({prob}) {'busy' if busy else 'alone'} round {r + 1}: 1 thread {res[(1, 'default')]:.3g}; "
                          + ", ".join(f"{s} {res[(2, s)] / res[(1, 'default')]:.2f}"
                                      + (f" [{single[(2, s)]} steps on 1 thread]" if single[(2, s)] is not None else "")
                                      for s in args.settings)
                          + f"; steal {steal:.0f} ms", flush=True)
                for s in args.settings:
                    rows.append((prob, "busy" if busy else "alone", s, statistics.median(got[(1, "default")]),
                                 statistics.median(got[(2, s)]), statistics.median(ratios[s]), min(ratios[s]),
                                 max(ratios[s]), median_interval(ratios[s]), load))
                if checks:
                    full = max(c[1] for c in checks)
                    keep = [r for r, c in enumerate(checks) if c[0] >= 0.92 * full]
                    for s in args.settings:
                        if keep:
                            q = [ratios[s][r] for r in keep]
                            quiet_rows.append((prob, s, len(keep), len(checks), statistics.median(q), min(q), max(q)))
                        else:
                            quiet_rows.append((prob, s, 0, len(checks), float("nan"), float("nan"), float("nan")))
                if ceil:
                    one = statistics.median(c[0] for c in ceil)
                    gains = [(one / c[1], one / c[2]) for c in ceil]
                    keep = [r for r, g in enumerate(gains) if min(g) >= 1.9]
                    for s in args.settings:
                        at = [ratios[s][r] for r in keep]
                        rel = [ratios[s][r] / (0.5 * (g[0] + g[1])) for r, g in enumerate(gains)]
                        ceiling_rows.append((prob, s, len(keep), len(gains),
                                             statistics.median(at) if at else float("nan"),
                                             min(at) if at else float("nan"), max(at) if at else float("nan"),
                                             statistics.median(g for pair in gains for g in pair),
                                             statistics.median(rel), min(rel), max(rel)))
        finally:
            if neighbour:
                neighbour.kill()
                neighbour.wait()
        if quiet and not busy:
            print("after: " + cb.quiet_line(args.cairn, scratch), flush=True)
    print(f"\nload average {os.getloadavg()[0]:.1f} at end; particle-steps/s, medians of {args.pairs} rounds; "
          "'busy': one CPU-bound process beside the run; load: 1-minute load average at the start of the block")
    print("| problem | machine | load | 2-thread setting | 1 thread | 2 threads | 2 / 1 (min-max) "
          "| 95 % interval of the median |")
    print("|---|---|---:|---|---:|---:|---:|---:|")
    for prob, busy, s, a, b, r, lo, hi, (clo, chi), load in rows:
        print(f"| ({prob}) | {busy} | {load:.1f} | {s} | {a / 1e6:.2f} M | {b / 1e6:.2f} M | {r:.3f} ({lo:.2f}-{hi:.2f}) "
              f"| {clo:.3f}-{chi:.3f} |")
    if quiet_rows:
        print("\nquiet rounds alone only (the slower side-by-side copy at >= 0.92 of the block's fastest copy):")
        print("| problem | 2-thread setting | quiet rounds | 2 / 1 (min-max) |")
        print("|---|---|---:|---:|")
        for prob, s, k, n, r, lo, hi in quiet_rows:
            print(f"| ({prob}) | {s} | {k} of {n} | {r:.2f} ({lo:.2f}-{hi:.2f}) |")
    if ceiling_rows:
        print("\nthe machine's 2-thread ceiling (cairn_ceiling) around each round alone; 'at the ceiling': "
              "rounds whose ceiling gain was >= 1.9 before and after")
        print("| problem | 2-thread setting | rounds at the ceiling | 2 / 1 there (min-max) | ceiling gain, "
              "median | 2 / 1 over the round's ceiling gain (min-max) |")
        print("|---|---|---:|---:|---:|---:|")
        for prob, s, k, n, r, lo, hi, g, rel, rlo, rhi in ceiling_rows:
            print(f"| ({prob}) | {s} | {k} of {n} | {r:.2f} ({lo:.2f}-{hi:.2f}) | {g:.2f} | "
                  f"{rel:.2f} ({rlo:.2f}-{rhi:.2f}) |")


def ceiling_seconds(binary, threads):
    """Seconds of one cairn_ceiling run (bench/ceiling.cpp) with cairn's own spin setting."""
    env = dict(os.environ, GOMP_SPINCOUNT="1000")
    env.pop("OMP_WAIT_POLICY", None)
    out = subprocess.run([binary, str(threads)], capture_output=True, text=True, check=True, env=env).stdout
    return float(out.split()[0])


if __name__ == "__main__":
    main()
