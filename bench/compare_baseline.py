#!/usr/bin/python3
"""Whole-step throughput of the current tree against a baseline commit, run side by side.

Builds the baseline commit (default 9d0b960, the reference of issue 13) in a git worktree under
/tmp (never inside the repository) and the current tree (build/release), then runs the problems
of bench/problems/ with both binaries in pairs, alternating which goes first, and prints for each
problem the median particle-steps/s of each binary, the ratio of the medians and the median of
the per-pair ratios. Wall-clock figures on a shared machine are noisy; the per-pair ratio is the
robust one. Each run's own figure is the run loop's rate from `cairn run`'s summary line.

  /usr/bin/python3 bench/compare_baseline.py [--baseline 9d0b960] [--pairs 5] [--threads 1]
      [--problems a b c d] [--no-build] [--steps-scale 1.0] [--quiet-check]

Problems (bench/problems/*.toml):
  a  two blocks, CPDI, FLIP/USL, neo-Hookean, 8000 particles (seed 000 Sec. 3.1)
  b  the same with FMPM(4)
  c  3D linear-elastic block, linear shape functions, FLIP, 64 000 particles
  d  3D neo-Hookean block, quadratic B-splines, FLIP, 1 000 000 particles
"""
import argparse
import os
import re
import statistics
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PROBLEMS = {
    "a": ("a_two_blocks_cpdi.toml", ["--set", "simulation.max_steps=400"]),
    "b": ("a_two_blocks_cpdi.toml", ["--set", "simulation.max_steps=400", "--set", "method.update=fmpm",
                                     "--set", "method.order=4"]),
    "c": ("c_block3d_linear.toml", ["--set", "simulation.max_steps=60"]),
    "d": ("d_block3d_bspline2_nh.toml", ["--set", "simulation.max_steps=8"]),
}
SUMMARY = re.compile(r"cairn: (\d+) steps to t = \S+ in ([\d.]+) s \(([\d.e+-]+) particle-steps/s")


def sh(cmd, cwd=None):
    print("+", " ".join(cmd), flush=True)
    subprocess.run(cmd, cwd=cwd, check=True)


def build_baseline(commit, tree):
    if not os.path.isdir(tree):
        sh(["git", "-C", ROOT, "worktree", "add", "--detach", tree, commit])
    sh(["cmake", "--preset", "release", "-DCAIRN_BUILD_BENCH=OFF", "-DCAIRN_BUILD_TESTS=OFF"], cwd=tree)
    sh(["cmake", "--build", "--preset", "release", "--target", "cairn"], cwd=tree)
    return os.path.join(tree, "build", "release", "cairn")


def build_current():
    sh(["cmake", "--preset", "release"], cwd=ROOT)
    sh(["cmake", "--build", "--preset", "release", "--target", "cairn"], cwd=ROOT)
    return os.path.join(ROOT, "build", "release", "cairn")


def run_once(binary, problem, threads, scratch, scale, more=(), with_output=False):
    """Particle-steps/s of one run (and the run's printed output with with_output)."""
    toml, extra = PROBLEMS[problem]
    extra = list(extra) + list(more)
    if scale != 1.0:
        extra = [re.sub(r"max_steps=(\d+)", lambda m: f"max_steps={max(1, round(int(m.group(1)) * scale))}", e)
                 for e in extra]
    cmd = [binary, "run", os.path.join(ROOT, "bench", "problems", toml), "-t", str(threads),
           "--set", f"output.directory={scratch}"] + extra
    env = dict(os.environ)
    res = subprocess.run(cmd, capture_output=True, text=True, env=env)
    if res.returncode != 0:
        sys.exit(f"failed ({res.returncode}): {' '.join(cmd)}\n{res.stdout}\n{res.stderr}")
    m = SUMMARY.search(res.stdout + res.stderr)
    if not m:
        sys.exit(f"no summary line from {' '.join(cmd)}:\n{res.stdout}\n{res.stderr}")
    return (float(m.group(3)), res.stdout + res.stderr) if with_output else float(m.group(3))


def side_by_side(binary, scratch):
    """Two 1-thread runs of problem (a) started together, one per core, and their particle-steps/s.

    On a virtual machine the host's load comes and goes for minutes; in its slow periods one or
    both cores run slower (docs/performance.md, "The slow periods"), and ratios measured then are
    lower than on a quiet machine. Both copies near a lone 1-thread run's rate mark a quiet core
    pair; one or both well below it mark a block to repeat.
    """
    toml, extra = PROBLEMS["a"]
    procs = []
    for k in range(2):
        cmd = [binary, "run", os.path.join(ROOT, "bench", "problems", toml), "-t", "1",
               "--set", f"output.directory={scratch}-side{k}"] + list(extra)
        procs.append(subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True))
    rates = []
    for proc in procs:
        out, _ = proc.communicate()
        m = SUMMARY.search(out)
        rates.append(float(m.group(3)) if m else float("nan"))
    return rates


def quiet_line(binary, scratch):
    a, b = side_by_side(binary, scratch)
    return f"two 1-thread copies of (a) side by side: {a / 1e6:.2f} M and {b / 1e6:.2f} M"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--baseline", default="9d0b960")
    ap.add_argument("--tree", default=None, help="baseline worktree (default /tmp/cairn-baseline-COMMIT)")
    ap.add_argument("--pairs", type=int, default=5)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--problems", nargs="+", default=["a", "b", "c", "d"], choices=sorted(PROBLEMS))
    ap.add_argument("--no-build", action="store_true", help="use the binaries already built")
    ap.add_argument("--current", default=None, help="current binary (default build/release/cairn)")
    ap.add_argument("--steps-scale", type=float, default=1.0, help="scale every problem's step count")
    ap.add_argument("--quiet-check", action="store_true",
                    help="before and after the block, run two 1-thread copies of (a) side by side with the "
                         "current binary and print their rates (both near a lone run's: quiet cores)")
    args = ap.parse_args()
    tree = args.tree or f"/tmp/cairn-baseline-{args.baseline}"
    if args.no_build:
        base_bin = os.path.join(tree, "build", "release", "cairn")
        cur_bin = args.current or os.path.join(ROOT, "build", "release", "cairn")
    else:
        base_bin = build_baseline(args.baseline, tree)
        cur_bin = args.current or build_current()
    scratch = f"/tmp/cairn-compare-{os.getpid()}"
    print(f"baseline {args.baseline}: {base_bin}\ncurrent: {cur_bin}\nthreads {args.threads}, "
          f"{args.pairs} pairs per problem, load average {os.getloadavg()[0]:.1f} at start", flush=True)
    if args.quiet_check:
        print("before: " + quiet_line(cur_bin, scratch), flush=True)
    rows = []
    for prob in args.problems:
        base, cur, ratios = [], [], []
        for r in range(args.pairs):
            order = [("base", base_bin), ("cur", cur_bin)]
            if r % 2:
                order.reverse()
            got = {}
            for name, binary in order:
                got[name] = run_once(binary, prob, args.threads, scratch, args.steps_scale)
            base.append(got["base"])
            cur.append(got["cur"])
            ratios.append(got["cur"] / got["base"])
            print(f"  ({prob}) pair {r + 1}: baseline {got['base']:.3g}, current {got['cur']:.3g}, "
                  f"ratio {ratios[-1]:.2f}", flush=True)
        rows.append((prob, statistics.median(base), statistics.median(cur),
                     statistics.median(cur) / statistics.median(base), statistics.median(ratios),
                     min(ratios), max(ratios)))
    if args.quiet_check:
        print("after: " + quiet_line(cur_bin, scratch), flush=True)
    print(f"\nload average {os.getloadavg()[0]:.1f} at end; particle-steps/s, {args.threads} thread(s), "
          f"medians of {args.pairs} alternating pairs")
    print("| problem | baseline | current | ratio of medians | median pair ratio (min-max) |")
    print("|---|---:|---:|---:|---:|")
    for prob, b, c, rm, rp, lo, hi in rows:
        print(f"| ({prob}) | {b / 1e6:.3f} M | {c / 1e6:.3f} M | {rm:.2f} | {rp:.2f} ({lo:.2f}-{hi:.2f}) |")


if __name__ == "__main__":
    main()
