#!/usr/bin/python3
"""MPI faults (issue 36, docs/robustness.md "MPI faults"): on a 2-rank run, rank 1 is killed
(SIGKILL), throws (CAIRN_FAULT=throw), runs out of memory under `ulimit -v` (CAIRN_FAULT=alloc)
or is stopped (SIGSTOP) past simulation.mpi_timeout. Each time the job must end within a bound,
with a non-zero exit code and a message naming rank 1 and the cause, and the last checkpoint
written before the fault must still restart (serially).

    tests/mpi/faults.py --cairn build/release/cairn --mpirun mpirun --case tests/mpi/cases/contact_disks.toml --out DIR
"""
import argparse
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import h5py

TIMEOUT = 4.0      # simulation.mpi_timeout of the stall case (s)
BOUND = 60.0       # every faulty job must have ended this long after the fault (s)


def job_tag(name):
    """The CAIRN_FAULT_JOB of this script's job `name`: with the script's PID, so that the faults
    of another worktree's run of this test at the same time never hit these ranks."""
    return f"{name}-{os.getpid()}"


def rank_pids(job, rank):
    """The PIDs of the cairn processes of `job` (an mpirun) with OMPI_COMM_WORLD_RANK = rank."""
    found = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            env = (entry / "environ").read_bytes().split(b"\0")
            cmd = (entry / "cmdline").read_bytes().split(b"\0")
        except OSError:
            continue
        if cmd and cmd[0].endswith(b"cairn") and f"OMPI_COMM_WORLD_RANK={rank}".encode() in env \
                and f"CAIRN_FAULT_JOB={job}".encode() in env:
            found.append(int(entry.name))
    return found


def start(args, name, extra_env=None, wrap=None, timeout=None):
    out = args.out / name
    # A fresh folder: an earlier run's checkpoints would look like this run's progress.
    shutil.rmtree(out, ignore_errors=True)
    shutil.rmtree(out.parent / f"{name}-restarted", ignore_errors=True)
    # 250 steps: the disks leave the grid at step 306.
    cmd = [args.cairn, "run", str(args.case), "-q", "-t", "1", "--set", "simulation.max_steps=250",
           "--set", "simulation.end_time=1.0", "--set", "output.checkpoint_every=2e-5",
           "--set", "output.every=1.0", "--set", f'output.directory="{out}"']
    if timeout is not None:
        cmd += ["--set", f"simulation.mpi_timeout={timeout}"]
    if wrap:
        cmd = ["/bin/bash", "-c", wrap + ' exec "$@"', "wrap"] + cmd
    env = dict(os.environ, CAIRN_FAULT_JOB=job_tag(name), **(extra_env or {}))
    job = subprocess.Popen([args.mpirun, "--oversubscribe", "--allow-run-as-root", "-np", "2"] + cmd,
                           stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=env)
    return job, out


def wait_for_checkpoints(out, job, count=2, limit=120.0):
    t0 = time.monotonic()
    while time.monotonic() - t0 < limit:
        if len(list(out.glob("checkpoint-*.h5"))) >= count:
            return True
        if job.poll() is not None:
            return False
        time.sleep(0.2)
    return False


def finish(job, since, problems, name):
    try:
        text, _ = job.communicate(timeout=BOUND)
    except subprocess.TimeoutExpired:
        job.kill()
        text, _ = job.communicate()
        problems.append(f"{name}: the job did not end within {BOUND:.0f} s of the fault (it hangs)")
    return job.returncode, time.monotonic() - since, text


def check_restart(args, out, problems, name):
    """The newest complete checkpoint restarts on one rank and takes five more steps."""
    done = sorted(out.glob("checkpoint-*.h5"))
    if not done:
        problems.append(f"{name}: no checkpoint left")
        return
    with h5py.File(done[-1], "r") as f:
        step = int(f.attrs["step"])
    r = subprocess.run([args.cairn, "restart", str(done[-1]), "-q", "-t", "1",
                        "--set", f"simulation.max_steps={step + 5}",
                        "--set", f'output.directory="{out}-restarted"'],
                       capture_output=True, text=True, timeout=600)
    if r.returncode != 0:
        problems.append(f"{name}: restart from {done[-1].name} failed (exit {r.returncode}): {r.stderr.strip()[-300:]}")


def case(args, name, expect, problems, fault, extra_env=None, wrap=None, timeout=None):
    job, out = start(args, name, extra_env, wrap, timeout)
    if not wait_for_checkpoints(out, job):
        job.kill()
        problems.append(f"{name}: no checkpoint was written before the fault: {job.communicate()[0][-500:]}")
        return
    since = time.monotonic()
    if fault:
        pids = rank_pids(job_tag(name), 1)
        if not pids:
            problems.append(f"{name}: rank 1's process not found")
        for pid in pids:
            os.kill(pid, fault)
    code, took, text = finish(job, since, problems, name)
    missing = [e for e in expect if e not in text]
    status = "ok  " if code != 0 and not missing and took <= BOUND else "FAIL"
    said = [line for line in text.splitlines() if line.startswith("cairn:") or "signal" in line]
    print(f"{status} {name}: exit {code} after {took:.1f} s")
    for line in said:
        print("    " + line.strip())
    if code == 0:
        problems.append(f"{name}: exit code 0 after a fault")
    if missing:
        problems.append(f"{name}: the message lacks {missing}:\n{text[-1500:]}")
    for p in rank_pids(job_tag(name), 1):  # a stopped rank that the launcher left behind
        problems.append(f"{name}: rank 1 (pid {p}) is still there")
        os.kill(p, signal.SIGKILL)
    check_restart(args, out, problems, name)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cairn", required=True)
    ap.add_argument("--mpirun", default="mpirun")
    ap.add_argument("--case", type=Path, required=True)
    ap.add_argument("--out", type=Path, required=True)
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    problems = []
    case(args, "killed", ["rank 1", "signal 9"], problems, signal.SIGKILL)
    case(args, "throws", ["rank 1 of 2: fault injected by CAIRN_FAULT"], problems, None,
         extra_env={"CAIRN_FAULT": "throw:1:40"})
    case(args, "out_of_memory", ["rank 1 of 2: out of memory"], problems, None,
         extra_env={"CAIRN_FAULT": "alloc:1:40"},
         wrap='if [ "$OMPI_COMM_WORLD_RANK" = 1 ]; then ulimit -v 4000000; fi;')
    case(args, "stalled", ["rank 1 stopped answering", "simulation.mpi_timeout"], problems, signal.SIGSTOP,
         timeout=TIMEOUT)
    for p in problems:
        print("problem:", p)
    print("RESULT:", "every fault stopped the job with its rank and cause named" if not problems
          else f"{len(problems)} problem(s)")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
