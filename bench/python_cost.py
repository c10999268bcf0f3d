#!/usr/bin/python3
"""What driving a run from Python costs (issue 32): the two-block example (examples/two_blocks.toml)
run by `cairn run`, by `sim.run()` and by a loop of `sim.step()` calls, in alternating rounds.

    /usr/bin/python3 bench/python_cost.py [--rounds 7] [--threads 1] [--end-time 1.8e-3]
                                          [--cairn build/release/cairn]

Each round runs the three in a rotating order, each in a fresh process (the Python ones with the
module of build/release/python). The time compared is each run's own wall time from its first
step to its end (RunSummary::wall_seconds: `cairn run` prints it, the module returns it), so
process start, imports and set-up, the same in both, are left out and the Python loop's overhead
(a GIL release and a signal check per step, Python calls per step for the loop) is in. Prints per
round the three times and the ratios to the CLI of the same round, then the medians of the
per-round ratios.

The rounds are only as steady as the machine: a compile beside them scatters the ratios by
+-30 %. `--overhead` measures the Python loop's own cost without that noise: a tiny 1D run (6
particles, about 12 us a step) stepped 20000 times in one call and by a `sim.step()` loop, in one
process; the difference per step, set against the two-block example's step (about 2 ms), bounds
what the loop can add.
"""
import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

PYTHON = r"""
import sys, cairn
sim = cairn.Simulation.from_toml(sys.argv[1], set={"simulation.end_time": float(sys.argv[3])}, output=sys.argv[2])
if sys.argv[4] == "run":
    summary = sim.run(progress=False)
else:
    while not sim.finished:
        sim.step()
    summary = sim.finish()
print("wall", repr(summary["wall_seconds"]), "steps", summary["steps"])
"""


def cli(args, out):
    r = subprocess.run([args.cairn, "run", str(ROOT / "examples" / "two_blocks.toml"), "--set",
                        f"output.directory={out}", "--set", f"simulation.end_time={args.end_time!r}"],
                       capture_output=True, text=True, check=True)
    return float(re.search(r"steps to t = \S+ in ([0-9.]+) s", r.stdout).group(1))


def python(args, out, how):
    env = dict(os.environ, PYTHONPATH=str(Path(args.cairn).resolve().parent / "python"))
    r = subprocess.run([sys.executable, "-c", PYTHON, str(ROOT / "examples" / "two_blocks.toml"), str(out),
                        repr(args.end_time), how], capture_output=True, text=True, check=True, env=env)
    return float(r.stdout.split()[1])


OVERHEAD = r"""
import sys, time, cairn
d = {"simulation": {"dimension": 1, "end_time": 2000.0, "cfl": 0.5, "max_steps": 20000},
     "grid": {"origin": [0.0], "extent": [1.0], "cell_size": 0.1},
     "material": [{"name": "m", "model": "linear_elastic", "density": 1.0, "youngs_modulus": 1.0,
                   "poissons_ratio": 0.0}],
     "body": [{"name": "b", "material": "m", "shape": {"box": {"min": [0.2], "max": [0.8]}},
               "particles_per_cell": 1}],
     "output": {"every": 0.0, "history_every": 0.0, "checkpoints": False}}
for rep in range(int(sys.argv[1])):
    one = cairn.Simulation.from_dict(d, output=False)
    t = time.perf_counter(); n = one.step(20000); t_one = (time.perf_counter() - t) / n
    loop = cairn.Simulation.from_dict(d, output=False)
    t = time.perf_counter()
    while not loop.finished:
        loop.step()
    t_loop = (time.perf_counter() - t) / loop.steps
    print(f"{t_one * 1e6:.2f} {t_loop * 1e6:.2f}")
    one.close(); loop.close()
"""


def overhead(args):
    env = dict(os.environ, PYTHONPATH=str(Path(args.cairn).resolve().parent / "python"))
    r = subprocess.run([sys.executable, "-c", OVERHEAD, str(args.rounds)], capture_output=True, text=True,
                       check=True, env=env)
    rows = [tuple(map(float, line.split())) for line in r.stdout.split("\n") if line.strip()]
    print("one call (us/step)   step() loop (us/step)   difference")
    for one, loop in rows:
        print(f"{one:18.2f}   {loop:21.2f}   {loop - one:10.2f}")
    print(f"median difference: {statistics.median(loop - one for one, loop in rows):.2f} us per step")


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--rounds", type=int, default=7)
    p.add_argument("--threads", type=int, default=1, help="OMP_NUM_THREADS of every run")
    p.add_argument("--end-time", type=float, default=1.8e-3)
    p.add_argument("--cairn", default=str(ROOT / "build" / "release" / "cairn"))
    p.add_argument("--overhead", action="store_true", help="the step() loop's own cost per step (see above)")
    args = p.parse_args()
    os.environ["OMP_NUM_THREADS"] = str(args.threads)
    if args.overhead:
        overhead(args)
        return
    kinds = ["cli", "run", "step"]
    ratios = {"run": [], "step": []}
    with tempfile.TemporaryDirectory() as tmp:
        print("round   cairn run   sim.run()   step loop   run/cli   step/cli")
        for i in range(args.rounds):
            order = kinds[i % 3:] + kinds[:i % 3]
            t = {}
            for kind in order:
                out = Path(tmp) / kind
                t[kind] = cli(args, out) if kind == "cli" else python(args, out, kind)
            for kind in ("run", "step"):
                ratios[kind].append(t[kind] / t["cli"])
            print(f"{i:5d}   {t['cli']:8.3f}s   {t['run']:8.3f}s   {t['step']:8.3f}s   "
                  f"{ratios['run'][-1]:7.4f}   {ratios['step'][-1]:7.4f}")
    print(f"median ratio over {args.rounds} rounds ({args.threads} thread(s)): sim.run() "
          f"{statistics.median(ratios['run']):.4f}, step loop {statistics.median(ratios['step']):.4f}")


if __name__ == "__main__":
    main()
