"""Ctrl-C stops a Python run cleanly between steps: KeyboardInterrupt, the state intact, the
simulation still usable (a checkpoint written afterwards restarts with `cairn restart`)."""
import os
import signal
import subprocess
import sys

from conftest import BINARY, SOURCE, two_blocks_text

CHILD = r"""
import sys
import numpy as np
import cairn

sim = cairn.Simulation.from_toml(sys.argv[1], output=sys.argv[2])
sim.step(2)
try:
    print("running", flush=True)
    # One call into the engine to the end: only its signal check between steps can stop it.
    sim.run(progress=False)
    print("not interrupted")
    sys.exit(1)
except KeyboardInterrupt:
    pass
steps, time = sim.steps, sim.time
assert 2 <= steps and 0 < time < sim.end_time and not sim.finished
assert np.all(np.isfinite(sim.particles.position))
rows = sim.history(as_pandas=False)
assert rows["step"][-1] <= steps
path = sim.write_checkpoint()
assert sim.step() == 1 and sim.steps == steps + 1
print("stopped", steps, repr(time), path, flush=True)
"""


def test_sigint_stops_between_steps(tmp_path):
    case = tmp_path / "two_blocks.toml"
    case.write_text(two_blocks_text(end_time=1.8e-2))  # far longer than the test waits
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    child = subprocess.Popen([sys.executable, "-c", CHILD, str(case), str(tmp_path / "out")], env=env,
                             stdout=subprocess.PIPE, text=True, cwd=SOURCE)
    assert child.stdout.readline().strip() == "running"
    child.send_signal(signal.SIGINT)
    out, _ = child.communicate(timeout=120)
    assert child.returncode == 0, out
    words = out.split()
    assert words[0] == "stopped", out
    checkpoint = words[3]
    restarted = subprocess.run([str(BINARY), "restart", checkpoint, "--quiet", "--set",
                                f"simulation.end_time={float(words[2]) + 2e-5!r}"], capture_output=True, text=True)
    assert restarted.returncode == 0, restarted.stderr
