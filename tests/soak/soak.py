#!/usr/bin/python3
"""Soak test (issue 36, docs/robustness.md "Long runs"): a 3D run with periodic checkpoints is
killed with SIGKILL at random times and restarted from its newest checkpoint, again and again; it
must end bit-identical (history.csv and the last snapshot, every dataset) to the same run left
alone. With --ranks N --restart-ranks M the run is distributed and each restart uses the other
rank count.

    /usr/bin/python3 tests/soak/soak.py --cairn build/release/cairn --minutes 60 --kills 10
    /usr/bin/python3 tests/soak/soak.py --cairn build/release/cairn --minutes 60 --kills 10 --ranks 2 --restart-ranks 3

ctest registers both under the label `soak` (not in the default suite): `ctest --test-dir
build/release -L soak`. --minutes sets the length of the uninterrupted run (the step count is
calibrated from a short run first); the interrupted one takes longer by its restarts.
"""
import argparse
import csv
import os
import random
import signal
import subprocess
import sys
import time
from pathlib import Path

import h5py

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "mpi"))
from compare_runs import compare_history, compare_snapshots  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
CASE = ROOT / "tests" / "mpi" / "cases" / "apic_3d.toml"


def command(args, ranks, verb, target, out, steps, extra=()):
    launcher = [args.mpirun, "--oversubscribe", "--allow-run-as-root", "-np", str(ranks)] if ranks > 1 else []
    # Bit-identical across rank counts (2 -> 3) asks for the ghost-particle halo: the node halo's
    # sums depend on the partition at round-off (docs/parallel.md).
    halo = ["--set", 'parallel.halo="particles"'] if ranks > 1 else []
    return launcher + [args.cairn, verb, str(target), "-q", "-t", "1",
                       "--set", f"simulation.max_steps={steps}", "--set", f'output.directory="{out}"', *halo, *extra]


def settings(every, end, history=None):
    """The run: the spinning 3D block of tests/mpi/cases, run long (`end`: twice the simulated time
    of the calibrated step count, so that the step count ends it), a checkpoint every `every`
    simulated seconds, a snapshot every ten, a history row every `history` (default `every`)."""
    return ["--set", f"simulation.end_time={end!r}", "--set", f"output.checkpoint_every={every!r}",
            "--set", f"output.every={every * 10!r}", "--set", f"output.history_every={history or every!r}"]


def newest_checkpoint(out):
    done = sorted(out.glob("checkpoint-[0-9]*.h5"))
    return done[-1] if done else None


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cairn", required=True)
    ap.add_argument("--mpirun", default="mpirun")
    ap.add_argument("--out", type=Path, default=Path("out/soak"))
    ap.add_argument("--minutes", type=float, default=60.0)
    ap.add_argument("--kills", type=int, default=10)
    ap.add_argument("--ranks", type=int, default=1)
    ap.add_argument("--restart-ranks", type=int, default=0, help="rank count of the restarts (default: --ranks)")
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()
    rng = random.Random(args.seed)
    restart_ranks = args.restart_ranks or args.ranks
    args.out.mkdir(parents=True, exist_ok=True)

    # Calibrate: steps per second of this machine for this run, from two probes of 200 and 800
    # steps without checkpoints, as the run has almost none (their difference leaves out the
    # start-up: timed from one probe of 200 steps with a checkpoint every 130, a soak asked for
    # 60 minutes on 2 ranks ran 41).
    took = []
    for n in (200, 800):
        probe = args.out / f"probe-{n}"
        t0 = time.monotonic()
        subprocess.run(command(args, args.ranks, "run", CASE, probe, n, settings(1.0, 1.0, history=1e-3)),
                       check=True, capture_output=True)
        took.append(time.monotonic() - t0)
    rate = 600 / max(took[1] - took[0], 1e-3)
    steps = max(400, int(rate * args.minutes * 60))
    with open(probe / "history.csv") as f:
        last = list(csv.DictReader(f))[-1]
    dt = float(last["time"]) / float(last["step"])
    every = dt * steps / (8 * (args.kills + 1))  # about 8 checkpoints between two kills
    end = 2.0 * dt * steps
    print(f"soak: {steps} steps (about {args.minutes:g} min at {rate:.0f} steps/s), a checkpoint every "
          f"{every:.3g} s of simulated time, {args.kills} kills, ranks {args.ranks} -> {restart_ranks}", flush=True)

    reference = args.out / "reference"
    t0 = time.monotonic()
    subprocess.run(command(args, args.ranks, "run", CASE, reference, steps, settings(every, end)), check=True,
                   capture_output=True)
    wall = time.monotonic() - t0
    print(f"soak: uninterrupted run took {wall / 60:.1f} min", flush=True)

    killed = args.out / "killed"
    # Kill moments by progress, not by the clock (a shared machine's speed varies): after a
    # randomly chosen checkpoint appears, within a random fraction of the interval since the one
    # before, so that a kill lands inside a step or inside a checkpoint's writing.
    total = int(steps * dt / every)  # about 8 (kills + 1); the kills land in its first 80 %, in case
    targets = sorted(rng.sample(range(1, max(int(0.8 * total), args.kills + 1)), args.kills))  # dt shrinks
    kills, restarts = 0, 0
    cmd = command(args, args.ranks, "run", CASE, killed, steps, settings(every, end))
    while True:
        job = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                               start_new_session=True)
        target = killed / f"checkpoint-{targets[kills]:04d}.h5" if kills < args.kills else None
        before = killed / f"checkpoint-{targets[kills] - 1:04d}.h5" if target is not None else None
        seen_before = None  # when the checkpoint before the target appeared: the live interval
        while job.poll() is None and target is not None and not target.exists():
            if seen_before is None and before.exists():
                seen_before = time.monotonic()
            time.sleep(0.01)
        if job.poll() is None and target is not None:
            interval = time.monotonic() - seen_before if seen_before is not None else 0.1
            time.sleep(rng.uniform(0.0, 0.8) * interval)
        if job.poll() is not None or target is None:
            _, err = job.communicate()
            if job.returncode != 0:
                print(f"RESULT: FAIL (restart {restarts} exited {job.returncode}: {err.strip()[-400:]})")
                return 1
            if target is not None:  # the machine sped up: the run ended before this kill
                print(f"soak: the run ended before kill {kills + 1} ({target.name})", flush=True)
            break
        os.killpg(job.pid, signal.SIGKILL)  # the launcher and every rank at once
        job.communicate()
        kills += 1
        checkpoint = newest_checkpoint(killed)
        with h5py.File(checkpoint, "r") as f:
            at = int(f.attrs["step"])
        print(f"soak: kill {kills} (SIGKILL); restart {restarts + 1} from {checkpoint.name} (step {at}) "
              f"on {restart_ranks} rank(s)", flush=True)
        cmd = command(args, restart_ranks, "restart", checkpoint, killed, steps)
        restarts += 1
        # A restart must not meet a target already behind it.
        while kills < args.kills and targets[kills] <= int(checkpoint.stem.split("-")[1]):
            targets[kills] = int(checkpoint.stem.split("-")[1]) + 1

    # `imbalance` describes how the particles are spread over the ranks, which a restart on
    # another rank count changes; every physical column must agree bit for bit.
    skip = ("imbalance",) if restart_ranks != args.ranks else ()
    problems = compare_history(reference, killed, "soak", skip) + compare_snapshots(reference, killed, "soak")
    for p in problems:
        print("problem:", p)
    if kills < args.kills:
        problems.append(f"{kills} of the {args.kills} kills landed before the run ended")
    print(f"RESULT: {'PASS' if not problems else 'FAIL'}: {kills} kills and {restarts} restarts, "
          f"{'bit-identical to' if not problems else 'different from'} the uninterrupted run of {steps} steps")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
