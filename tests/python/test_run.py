"""A run from Python is the run of `cairn run`: same history and particle arrays, bit for bit;
the particle views alias the engine's memory; a written velocity changes the next step."""
import subprocess

import h5py
import numpy as np
import pytest

import cairn
from conftest import BINARY


def run_cli(input_path, folder):
    subprocess.run([str(BINARY), "run", str(input_path), "--quiet", "--set", f"output.directory={folder}"],
                   check=True)


def last_snapshot(folder):
    return cairn.read_output(folder).snapshot(-1)


def assert_same_outputs(a, b):
    assert (a / "history.csv").read_bytes() == (b / "history.csv").read_bytes()
    sa, sb = last_snapshot(a), last_snapshot(b)
    assert sa["step"] == sb["step"] and sa["time"] == sb["time"]
    for name in ("position", "velocity", "stress", "deformation_gradient", "volume"):
        assert np.array_equal(sa[name], sb[name]), name
    # The checkpoints hold the same particle state.
    with h5py.File(a / "checkpoint-0000.h5") as fa, h5py.File(b / "checkpoint-0000.h5") as fb:
        for name in fa["particles"]:
            assert np.array_equal(fa["particles"][name][()], fb["particles"][name][()]), name


def test_run_is_bit_identical_to_the_cli(two_blocks, tmp_path):
    run_cli(two_blocks, tmp_path / "cli")
    sim = cairn.Simulation.from_toml(two_blocks, output=tmp_path / "py")
    summary = sim.run(progress=False)
    assert summary["steps"] == sim.steps > 10 and sim.finished
    assert_same_outputs(tmp_path / "cli", tmp_path / "py")
    # The in-memory arrays are those of the last snapshot (rows in id order in this small run).
    snap = last_snapshot(tmp_path / "py")
    p = sim.particles
    assert np.array_equal(p.id, np.arange(len(p)))
    assert np.array_equal(p.position, snap["position"][:, :2])
    assert np.array_equal(p.velocity, snap["velocity"][:, :2])
    assert np.array_equal(p.mass, snap["mass"])


def test_step_loop_is_bit_identical_to_the_cli(two_blocks, tmp_path):
    run_cli(two_blocks, tmp_path / "cli")
    sim = cairn.Simulation.from_toml(two_blocks, output=tmp_path / "py")
    while not sim.finished:
        assert sim.step() == 1
    sim.finish()
    assert_same_outputs(tmp_path / "cli", tmp_path / "py")


def test_run_until_and_callbacks(two_blocks):
    sim = cairn.Simulation.from_toml(two_blocks, output=False)
    seen = []
    sim.run(until=1e-4, progress=False, callback=lambda s: seen.append(s.steps), every=5)
    assert 1e-4 <= sim.time < 2e-4 and not sim.finished and sim.summary is None
    assert seen == list(range(5, sim.steps + 1, 5))
    sim.run(progress=True)
    assert sim.finished and sim.summary["end_time"] == sim.time
    with pytest.raises(RuntimeError, match="finished"):
        sim.step()
    sim.close()


def test_views_alias_engine_memory(two_blocks):
    with cairn.Simulation.from_toml(two_blocks, output=False) as sim:
        x = sim.particles.position
        before = x.copy()
        assert not x.flags.writeable and not x.flags.owndata
        with pytest.raises(ValueError):
            x[0, 0] = 1.0
        sim.step(3)
        assert not np.array_equal(x, before)  # the same array, changed by the steps
        assert np.shares_memory(x, sim.particles.position)
        assert sim.particles.deformation_gradient.shape == (len(sim.particles), 3, 3)
        assert sim.particles.kirchhoff_stress.shape == (len(sim.particles), 6)
        with pytest.raises(ValueError, match="read-only"):
            sim.particles.writable("mass")


def test_written_velocity_changes_the_next_step(two_blocks):
    """Both blocks stopped before the first step: FLIP carries no momentum to the grid and the
    blocks (unstressed) stay where they are; untouched, they move."""
    moving = cairn.Simulation.from_toml(two_blocks, output=False)
    stopped = cairn.Simulation.from_toml(two_blocks, output=False)
    x0 = stopped.particles.position.copy()
    v = stopped.particles.writable("velocity")
    assert v.flags.writeable
    v[:] = 0.0
    moving.step()
    stopped.step()
    assert np.array_equal(stopped.particles.position, x0)
    assert np.all(stopped.particles.velocity == 0.0)
    assert not np.array_equal(moving.particles.position, x0)
    moving.close()
    stopped.close()


def test_checkpoint_and_history(two_blocks, tmp_path):
    sim = cairn.Simulation.from_toml(two_blocks, output=tmp_path / "out")
    sim.step(10)
    path = sim.write_checkpoint()
    assert path.name == "checkpoint-0000.h5" and path.exists()
    h = sim.history(as_pandas=False)
    assert h["step"][0] == 0 and h["time"][-1] <= sim.time
    frame = sim.history()
    assert list(frame.columns)[:3] == ["time", "step", "dt"]
    grid = sim.grid()
    assert grid["mass"].sum() == pytest.approx(sim.particles.mass.sum(), rel=1e-12)


def test_build_information():
    assert cairn.__version__
    assert set(cairn.build) >= {"mpi", "openmp"}
    assert cairn.threads() >= 1


def test_help_shows_the_docstrings():
    import pydoc
    text = pydoc.render_doc(cairn.Simulation)
    for phrase in ("from_dict", "KeyboardInterrupt", "writable", "every"):
        assert phrase in text, phrase


def test_several_mpi_ranks_are_refused_clearly():
    import os
    import sys
    env = dict(os.environ, OMPI_COMM_WORLD_SIZE="2")
    r = subprocess.run([sys.executable, "-c", "import cairn"], capture_output=True, text=True, env=env)
    assert r.returncode != 0 and "one MPI rank" in r.stderr and "mpirun -np N cairn run" in r.stderr


def test_the_gil_is_released_while_stepping(two_blocks):
    """A Python thread counts while the main thread is inside one long engine call."""
    import threading
    sim = cairn.Simulation.from_toml(two_blocks, output=False)
    counted, running = [0], [True]

    def count():
        while running[0]:
            counted[0] += 1

    thread = threading.Thread(target=count)
    thread.start()
    before = counted[0]
    sim.step(60)
    during = counted[0] - before
    running[0] = False
    thread.join()
    sim.close()
    # Holding the GIL for the whole call would let the thread run only at the switch interval's
    # few hand-overs (the call never yields); released, it counts throughout.
    assert during > 100000, during


def test_threads_as_the_cli():
    import os
    if "OMP_NUM_THREADS" in os.environ:
        assert cairn.threads() == int(os.environ["OMP_NUM_THREADS"])


def test_restart_from_python_ends_bit_identical(two_blocks, tmp_path):
    whole = cairn.Simulation.from_toml(two_blocks, output=tmp_path / "whole")
    whole.run(progress=False)
    first = cairn.Simulation.from_toml(two_blocks, output=tmp_path / "split")
    first.run(until=1e-4, progress=False)
    checkpoint = first.write_checkpoint()
    del first
    second = cairn.Simulation.restart(checkpoint)
    assert second.time == pytest.approx(1e-4, abs=5e-6) and second.output_directory == str(tmp_path / "split")
    second.run(progress=False)
    assert (tmp_path / "whole" / "history.csv").read_bytes() == (tmp_path / "split" / "history.csv").read_bytes()
    assert np.array_equal(second.particles.position, whole.particles.position)
    assert np.array_equal(last_snapshot(tmp_path / "whole")["stress"], last_snapshot(tmp_path / "split")["stress"])
    with pytest.raises(cairn.InputError, match="restart honours"):
        cairn.Simulation.restart(checkpoint, set={"method.order": 2})


def test_fem_runs_from_python(tmp_path):
    """The reference FEM (seed 001 Appendix A) is one more engine: the same run control."""
    from conftest import SOURCE
    sim = cairn.Simulation.from_toml(SOURCE / "tests" / "fem" / "ring_mms.toml",
                                     set={"simulation.max_steps": 5}, output=tmp_path)
    assert sim.engine == "fem" and "elements" in repr(sim)
    sim.run(progress=False)
    assert sim.steps == 5 and sim.history(as_pandas=False)["step"][-1] == 5
    with pytest.raises(ValueError, match="MPM and WLS"):
        sim.particles.position
