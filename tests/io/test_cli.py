"""The cairn command as a user meets it: usage and exit codes, the progress bar on a terminal,
Ctrl-C and SIGTERM, wall-clock checkpoints, restarts into other folders or from earlier
checkpoints, output folders relative to the input file, leftovers of killed runs.

Usage: /usr/bin/python3 test_cli.py <cairn binary> <source dir>
"""
import csv
import math
import os
import pty
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ET

import h5py

CASE = """\
[simulation]
dimension = 2
end_time = {end_time}

[grid]
origin = [0.0, 0.0]
extent = [0.04, 0.02]
cell_size = 5.0e-4

[[material]]
name = "steel"
model = "linear_elastic"
density = 7800.0
youngs_modulus = 200.0e9
poissons_ratio = 0.3

[[body]]
name = "plate"
material = "steel"
shape = {{ box = {{ min = [0.005, 0.005], max = [0.035, 0.015] }} }}
velocity = [10.0, 0.0]

[output]
directory = "{directory}"
every = {every}
"""


class CheckFailed(Exception):
    pass


def check(cond, message):
    if not cond:
        raise CheckFailed(message)
    print("  ok:", message)


def write_case(path, end_time=2.0e-6, every=5.0e-7, directory=""):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as f:
        f.write(CASE.format(end_time=end_time, every=every, directory=directory))
    return path


def cairn_run(cairn, args, expect=0, cwd=None):
    proc = subprocess.run([cairn] + args, capture_output=True, text=True, timeout=600, cwd=cwd)
    if proc.returncode != expect:
        raise CheckFailed(f"'cairn {' '.join(args)}' exited with {proc.returncode}, expected {expect}\n"
                          f"--- stdout ---\n{proc.stdout}\n--- stderr ---\n{proc.stderr}")
    return proc


def history_rows(out):
    with open(os.path.join(out, "history.csv")) as f:
        return list(csv.reader(f))[1:]


def xdmf_times(path):
    return [float(t.get("Value")) for t in ET.parse(path).getroot().iter("Time")]


def snapshot_files(out):
    return sorted(f for f in os.listdir(os.path.join(out, "snapshots")) if f.startswith("particles-"))


def usage_and_exit_codes(cairn, tmp):
    for args in ([], ["--bogus"], ["frobnicate"], ["run"], ["run", "a.toml", "--bogus"]):
        proc = cairn_run(cairn, args, expect=2)
        check("usage: cairn run INPUT.toml" in proc.stderr,
              f"'cairn {' '.join(args)}' exits with 2 and prints the usage line")
    for args in (["--help"], ["--version"]):
        cairn_run(cairn, args, expect=0)
    check(True, "--help and --version exit with 0")
    proc = cairn_run(cairn, ["run", os.path.join(tmp, "missing.toml")], expect=2)
    check("missing.toml" in proc.stderr, "a missing input file is bad input: exit code 2")


def gmsh_loaded_on_demand(cairn, tmp):
    # Gmsh and its 91 libraries live in the module beside the binary (src/cairn/fem/gmsh_module.hpp),
    # not among the libraries every command loads at start (docs/performance.md, "Start-up").
    libs = subprocess.run(["ldd", cairn], capture_output=True, text=True, check=True).stdout
    check("libgmsh" not in libs, "cairn does not load Gmsh at start (ldd)")
    module = os.path.join(os.path.dirname(cairn), "libcairn_gmsh.so")
    check(os.path.isfile(module), "the Gmsh mesher module is built beside cairn")
    check("libgmsh" in subprocess.run(["ldd", module], capture_output=True, text=True, check=True).stdout,
          "the module links Gmsh")


def crashing_reader_says_one_line(cairn, tmp):
    # A damaged .msh 4.1 (found by cairn_fuzz_geometry, seed 44) on which Gmsh 4.8 corrupts its
    # heap: glibc ends the reading child with "double free or corruption (out)" on its standard
    # error. That line comes back inside Cairn's message instead of reaching the terminal first
    # (util/child_process.hpp). Gmsh's own ending may differ elsewhere; one line it must be.
    folder = os.path.join(tmp, "crashing_reader")
    os.makedirs(folder)
    with open(os.path.join(sys.argv[2], "tests", "robustness", "corpus", "geometry", "regressions",
                           "msh41-heap-corruption-in-gmsh.bin"), "rb") as f:
        mesh = f.read().split(b"\n", 1)[1]  # the fuzz corpus's format line ("msh2") left out
    with open(os.path.join(folder, "m.msh"), "wb") as f:
        f.write(mesh)
    with open(os.path.join(folder, "in.toml"), "w") as f:
        f.write(CASE.format(end_time=1.0e-6, every=1.0e-6, directory="")
                .replace("shape = { box = { min = [0.005, 0.005], max = [0.035, 0.015] } }",
                         'shape = { volume_mesh = { file = "m.msh" } }'))
    proc = cairn_run(cairn, ["run", "in.toml"], expect=2, cwd=folder)
    lines = proc.stderr.strip().splitlines()
    check(len(lines) == 1 and lines[0].startswith("cairn: input error: ") and "m.msh" in lines[0]
          and "Gmsh" in lines[0], f"a mesh that crashes Gmsh: one input error line naming it: {proc.stderr.strip()!r}")


def progress_bar(cairn, tmp):
    case = write_case(os.path.join(tmp, "bar", "case.toml"), end_time=4.0e-6)
    pid, fd = pty.fork()
    if pid == 0:  # child: stdout and stderr on the terminal
        os.execv(cairn, [cairn, "run", case, "-t", "1"])
    text = b""
    while True:
        try:
            chunk = os.read(fd, 4096)
        except OSError:
            break
        if not chunk:
            break
        text += chunk
    _, status = os.waitpid(pid, 0)
    text = text.decode(errors="replace")
    check(os.waitstatus_to_exitcode(status) == 0, "a run on a terminal succeeds")
    frames = [f for f in re.split(r"\r", text) if "%" in f and "step" in f]
    check(len(frames) >= 1, f"{len(frames)} progress frames drawn on the terminal")
    last = frames[-1]
    check(re.search(r"\[#{10,}\]", last) is not None and "100.0%" in last and "done in" in last,
          f"the last frame is a full bar at 100 %: {last.strip()[:90]!r}")
    check(all(re.search(r"\[[#-]+\] +\d+\.\d%", f) for f in frames), "every frame has a bar and a percentage")


def interrupts(cairn, tmp):
    for sig, name in ((signal.SIGINT, "SIGINT"), (signal.SIGTERM, "SIGTERM")):
        out = os.path.join(tmp, "int_" + name)
        case = write_case(os.path.join(out, "case.toml"), end_time=4.0e-4, every=1.0e-6)
        proc = subprocess.Popen([cairn, "run", case, "-q", "-t", "1"], stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True)
        deadline = time.time() + 300
        while not os.path.exists(os.path.join(out, "out", "case", "snapshots", "particles-000002.h5")):
            if time.time() > deadline or proc.poll() is not None:
                proc.kill()
                raise CheckFailed(f"the run to interrupt ended or stalled early: {proc.communicate()}")
            time.sleep(0.05)
        proc.send_signal(sig)
        stdout, stderr = proc.communicate(timeout=300)
        autosave = os.path.join(out, "out", "case", "checkpoint-autosave.h5")
        check(proc.returncode == 1, f"{name}: exit code 1")
        check(f"interrupted by {name}" in stderr and autosave in stderr and "cairn restart" in stderr,
              f"{name}: says where the checkpoint is: {stderr.strip()[:160]!r}")
        check(os.path.isfile(autosave), f"{name}: {os.path.basename(autosave)} exists")
        with h5py.File(autosave, "r") as f:
            t_stop = float(f.attrs["time"])
        check(0 < t_stop < 4.0e-4, f"{name}: the checkpoint is at t = {t_stop:.3g}, before the end")
    # The interrupted run continues from its autosave to the end, as if never stopped.
    restarted = cairn_run(cairn, ["restart", autosave, "-q", "--set", "simulation.end_time=2.0e-5"])
    full = os.path.join(tmp, "int_full")
    cairn_run(cairn, ["run", write_case(os.path.join(full, "case.toml"), end_time=2.0e-5, every=1.0e-6), "-q"])
    a, b = history_rows(os.path.join(out, "out", "case")), history_rows(os.path.join(full, "out", "case"))
    check(a[-1] == b[-1], "the restarted run ends bit-identical to an uninterrupted one")
    del restarted


def wall_clock_checkpoints(cairn, tmp):
    out = os.path.join(tmp, "wall")
    case = write_case(os.path.join(out, "case.toml"))
    cairn_run(cairn, ["run", case, "-q", "--set", "output.checkpoint_wall_interval=1e-9"])
    autosave = os.path.join(out, "out", "case", "checkpoint-autosave.h5")
    check(os.path.isfile(autosave), "output.checkpoint_wall_interval writes checkpoint-autosave.h5")
    proc = cairn_run(cairn, ["keys"])
    check("checkpoint_wall_interval" in proc.stdout and "1800.0" in proc.stdout,
          "the wall-clock interval is a key, 1800 s by default")


def relative_folders_and_restarts(cairn, tmp):
    # A relative output folder lies next to the input file, whatever the working directory.
    case = write_case(os.path.join(tmp, "rel", "inputs", "case.toml"), directory="results/a")
    cairn_run(cairn, ["run", "inputs/case.toml", "-q", "--set", "output.checkpoint_every=1.0e-6"],
              cwd=os.path.join(tmp, "rel"))
    first = os.path.join(tmp, "rel", "inputs", "results", "a")
    check(os.path.isfile(os.path.join(first, "history.csv")), "relative output.directory resolves against the input's folder")
    cairn_run(cairn, ["run", case, "-q", "--set", "output.directory=cli_out"], cwd=os.path.join(tmp, "rel"))
    check(os.path.isfile(os.path.join(tmp, "rel", "cli_out", "history.csv")),
          "--set output.directory is relative to the working directory")

    # A copied checkpoint restarts next to itself; the original folder is left alone.
    before = {f: os.path.getmtime(os.path.join(first, f)) for f in os.listdir(first) if f != "snapshots"}
    elsewhere = os.path.join(tmp, "rel", "copy")
    os.makedirs(elsewhere)
    shutil.copy(os.path.join(first, "checkpoint-0000.h5"), elsewhere)
    cairn_run(cairn, ["restart", os.path.join(elsewhere, "checkpoint-0000.h5"), "-q"])
    check(os.path.isfile(os.path.join(elsewhere, "history.csv")) and os.path.isfile(os.path.join(elsewhere, "particles.xdmf")),
          "cairn restart writes next to the checkpoint it was given")
    after = {f: os.path.getmtime(os.path.join(first, f)) for f in before}
    check(before == after, "the folder stored in the checkpoint is not touched")
    third = os.path.join(tmp, "rel", "third")
    cairn_run(cairn, ["restart", os.path.join(elsewhere, "checkpoint-0000.h5"), "-q", "--set", f"output.directory={third}"])
    check(os.path.isfile(os.path.join(third, "history.csv")), "--set output.directory chooses the restart's folder")

    # Restarting from an earlier checkpoint, every output agrees on where the run stands.
    with h5py.File(os.path.join(first, "checkpoint-0000.h5"), "r") as f:
        t_ckpt, step = float(f.attrs["time"]), int(f.attrs["step"])
    files_before = snapshot_files(first)
    cairn_run(cairn, ["restart", os.path.join(first, "checkpoint-0000.h5"), "-q", "--set",
                      f"simulation.max_steps={step}"])
    rows = history_rows(first)
    times = xdmf_times(os.path.join(first, "particles.xdmf"))
    files = snapshot_files(first)
    check(float(rows[-1][0]) <= t_ckpt and max(times) <= t_ckpt and len(files) == len(times) < len(files_before),
          f"after a restart from t = {t_ckpt:.3g}: history ends at {float(rows[-1][0]):.3g}, particles.xdmf at "
          f"{max(times):.3g}, {len(files)} snapshot files (were {len(files_before)})")


def orphan_temporaries(cairn, tmp):
    out = os.path.join(tmp, "orphans", "out")
    os.makedirs(os.path.join(out, "snapshots"))
    dead = subprocess.Popen(["true"])
    dead.wait()
    leftovers = [os.path.join(out, f"history.csv.tmp.{dead.pid}"),
                 os.path.join(out, "snapshots", f"particles-000003.h5.tmp.{dead.pid}.12345")]
    alive = os.path.join(out, f"particles.xdmf.tmp.{os.getpid()}")
    for p in leftovers + [alive]:
        open(p, "w").close()
    case = write_case(os.path.join(tmp, "orphans", "case.toml"), directory="out")
    cairn_run(cairn, ["run", case, "-q"])
    check(not any(os.path.exists(p) for p in leftovers), "temporaries of a dead run are removed")
    check(os.path.exists(alive), "a temporary of a live process is kept")


def thread_binding(cairn, tmp):
    # cairn restarts itself once to set its OpenMP spin (app/main.cpp). With OMP_PROC_BIND set,
    # libgomp has bound the first process's thread to one place by then; the restarted process
    # must still see every place, so that its threads run on different processors.
    cpus = sorted(os.sched_getaffinity(0))
    if len(cpus) < 2:
        print("  (one processor here: thread binding not checked)")
        return
    case = write_case(os.path.join(tmp, "bind", "case.toml"), end_time=1.0e-6, every=1.0e-6)
    env = {k: v for k, v in os.environ.items() if k not in ("OMP_WAIT_POLICY", "GOMP_SPINCOUNT", "OMP_NUM_THREADS")}
    for bind, places in (("spread", "threads"), ("close", "cores"), ("true", None)):
        env_b = dict(env, OMP_PROC_BIND=bind, OMP_DISPLAY_AFFINITY="TRUE",
                     OMP_AFFINITY_FORMAT="cairn-affinity %n %A")
        if places:
            env_b["OMP_PLACES"] = places
        proc = subprocess.run([cairn, "run", case, "-q", "-t", "2", "--set", "simulation.adapt_threads=false"],
                              capture_output=True, text=True, timeout=600, env=env_b)
        check(proc.returncode == 0, f"OMP_PROC_BIND={bind} OMP_PLACES={places}: the run succeeds")
        bound = {}
        for line in (proc.stdout + proc.stderr).splitlines():
            fields = line.split()
            if len(fields) == 3 and fields[0] == "cairn-affinity":
                bound[fields[1]] = fields[2]
        check(len(bound) == 2 and len(set(bound.values())) == 2,
              f"OMP_PROC_BIND={bind} OMP_PLACES={places}: the 2 threads are bound to different processors "
              f"({bound})")


def input_errors_at_once(cairn, tmp):
    # Every independent error of a file in one run, each on its own line with file:line and key.
    case = write_case(os.path.join(tmp, "errors", "case.toml"))
    with open(case) as f:
        text = f.read()
    text = text.replace("cell_size = 5.0e-4", "cell_size = 5.0e-4\ncfl = 0.3")
    text = text.replace("every = 5e-07", "every = 5e-07\nend_time = 1.0").replace("end_time = 2e-06\n", "")
    with open(case, "w") as f:
        f.write(text)
    proc = cairn_run(cairn, ["check", case], expect=2)
    lines = [l for l in proc.stderr.splitlines() if l.startswith("cairn: input error: ")]
    check(len(lines) == 3 and "3 input errors" in proc.stderr,
          f"three errors of one file reported in one run: {proc.stderr.strip()!r}")
    check("key 'simulation.end_time'" in lines[0] and "required key" in lines[0],
          "the missing simulation.end_time is reported")
    check("case.toml:8: key 'grid.cfl'" in lines[1] and "did you mean simulation.cfl?" in lines[1],
          "cfl under [grid] says where it belongs")
    check("key 'output.end_time'" in lines[2] and "did you mean simulation.end_time?" in lines[2],
          "end_time under [output] is reported too, with where it belongs")


def restart_keys(cairn, tmp):
    out = os.path.join(tmp, "restart_keys")
    case = write_case(os.path.join(out, "case.toml"), directory="out")
    cairn_run(cairn, ["run", case, "-q", "--set", "output.checkpoint_every=1.0e-6"])
    folder = os.path.join(out, "out")
    first = os.path.join(folder, "checkpoint-0000.h5")
    for key, value in (("material[0].density", "2000"), ("material.0.youngs_modulus", "1e9"),
                       ("grid.cell_size", "1e-3"), ("method.shape", "linear"), ("simulation.cfl", "0.2")):
        proc = cairn_run(cairn, ["restart", first, "-q", "--set", f"{key}={value}"], expect=2)
        check(f"key '{key}'" in proc.stderr and "a restart honours" in proc.stderr and "simulation.end_time" in proc.stderr
              and "cairn run" in proc.stderr, f"restart refuses --set {key} (exit 2), naming the honoured keys")
    help_text = cairn_run(cairn, ["restart", "--help"]).stdout
    check("output.every" in help_text and "simulation.end_time" in help_text,
          "cairn restart --help lists the keys a restart honours")

    # A changed snapshot interval applies from the checkpoint on, on multiples of the new one.
    with h5py.File(first, "r") as f:
        t_ckpt = float(f.attrs["time"])
    cairn_run(cairn, ["restart", first, "-q", "--set", "output.every=2.5e-7"])
    later = [t for t in xdmf_times(os.path.join(folder, "particles.xdmf")) if t > t_ckpt * (1 + 1e-9)]
    check(len(later) == 4 and later[0] >= 1.25e-6 * (1 - 1e-9),
          f"--set output.every=2.5e-7 on restart: snapshots after t = {t_ckpt:.3g} at {later}")

    # A finished run: restarting it says so and how to go on.
    with h5py.File(os.path.join(folder, "checkpoint-0001.h5"), "r") as f:
        t_last = float(f.attrs["time"])
    check(abs(t_last - 2.0e-6) < 1e-12, f"checkpoint-0001.h5 is at the end (t = {t_last:.3g})")
    last = os.path.join(folder, "checkpoint-0001.h5")
    proc = cairn_run(cairn, ["restart", last, "-q"], expect=2)
    check("simulation.end_time" in proc.stderr and "where this run finished" in proc.stderr
          and "--set simulation.end_time=" in proc.stderr,
          f"restarting a finished run says so and how to continue: {proc.stderr.strip()[:200]!r}")
    cairn_run(cairn, ["restart", last, "-q", "--set", "simulation.end_time=3.0e-6"])
    rows = history_rows(folder)
    check(abs(float(rows[-1][0]) - 3.0e-6) < 1e-12, "raising simulation.end_time continues the finished run")


def earlier_outputs(cairn, tmp):
    out = os.path.join(tmp, "earlier")
    case = write_case(os.path.join(out, "case.toml"), every=2.5e-7, directory="out")
    folder = os.path.join(out, "out")
    cairn_run(cairn, ["run", case, "-q"])
    many = snapshot_files(folder)
    check(len(many) == 9, f"a first run writes 9 snapshots ({len(many)})")
    proc = cairn_run(cairn, ["run", case, "-q", "--set", "output.every=1.0e-6", "--set", "output.existing=keep"])
    check(len(snapshot_files(folder)) == 9 and "removing" not in proc.stderr,
          "output.existing = keep leaves the earlier run's snapshots")
    cairn_run(cairn, ["run", case, "-q", "--set", "output.every=1.0e-6", "--set", "output.existing=error"], expect=2)
    proc = cairn_run(cairn, ["run", case, "-q", "--set", "output.every=1.0e-6"])
    files = snapshot_files(folder)
    times = xdmf_times(os.path.join(folder, "particles.xdmf"))
    check(len(files) == len(times) == 3, f"a second run with fewer outputs leaves only its own: {files}")
    check("cairn: removing 9 snapshot files and 1 checkpoint of an earlier run in" in proc.stderr,
          f"and says what it removed first: {proc.stderr.strip()!r}")


def check_estimates(cairn, tmp):
    case = write_case(os.path.join(tmp, "estimates", "case.toml"))
    proc = cairn_run(cairn, ["check", case])
    check("warning" not in proc.stderr, f"steel with SI values draws no warning: {proc.stderr.strip()!r}")
    m = re.search(r"# material 'steel': wave speed ([0-9.e+-]+) m/s, step limit .* = ([0-9.e+-]+) s "
                  r"\(fastest: sets the time step\)", proc.stdout)
    check(m is not None, "cairn check prints the material's wave speed and step limit")
    E, nu, rho = 200.0e9, 0.3, 7800.0
    lam, mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))
    c = ((lam + 2 * mu) / rho) ** 0.5
    check(abs(float(m.group(1)) / c - 1) < 1e-3, f"the wave speed {m.group(1)} is sqrt((lambda + 2 mu) / rho) = {c:.6g}")
    dt = float(re.search(r"# first time step: ([0-9.e+-]+)", proc.stdout).group(1))
    check(abs(dt / (0.5 * 5.0e-4 / (c + 10.0)) - 1) < 1e-3, f"the first step {dt:.4g} is cfl h / (c + |v|)")
    steps = float(re.search(r"# estimated steps: ([0-9.e+]+)", proc.stdout).group(1))
    check(steps == math.ceil(2.0e-6 / dt - 1e-9), f"estimated steps {steps:g} = end_time / first step")
    check(re.search(r"# wall time estimate: [0-9.e+-]+ s \([0-9.e+-]+ s per step over [0-9]+ timed step", proc.stdout),
          "and a wall-time estimate from timed steps")
    proc = cairn_run(cairn, ["check", case, "--set", "material[0].density=1.0"])
    warnings = [l for l in proc.stderr.splitlines() if l.startswith("cairn: warning: ")]
    check(any("key 'material[0].density'" in w and "below that of any real solid" in w and "cgs" in w for w in warnings),
          f"steel with density 1.0 is flagged as a likely slip (g/cm^3): {warnings}")
    check(any("wave speed" in w and "faster than any real solid" in w for w in warnings),
          "and its wave speed as faster than any solid's")


def keys_explain_seeds(cairn, tmp):
    text = " ".join(cairn_run(cairn, ["keys"]).stdout.split())
    header = text.split("[simulation]")[0]
    check("seed 001 = Wallstedt and Guilkey" in header and "seed 001 Eq. 34" in text,
          "cairn keys says what the \"seed 001\" its keys cite is")


def main():
    if len(sys.argv) < 3:
        print("usage: test_cli.py <cairn binary> <source dir>", file=sys.stderr)
        return 2
    cairn = os.path.abspath(sys.argv[1])
    with tempfile.TemporaryDirectory(prefix="cairn_cli_") as tmp:
        try:
            for case in (usage_and_exit_codes, gmsh_loaded_on_demand, crashing_reader_says_one_line, progress_bar, interrupts, wall_clock_checkpoints,
                         relative_folders_and_restarts, orphan_temporaries, thread_binding, input_errors_at_once,
                         restart_keys, earlier_outputs, check_estimates, keys_explain_seeds):
                print(case.__name__)
                case(cairn, tmp)
        except (CheckFailed, subprocess.TimeoutExpired) as e:
            print(f"FAIL: {e}", file=sys.stderr)
            return 1
    print("ok: the command line behaves")
    return 0


if __name__ == "__main__":
    sys.exit(main())
