"""Cairn from Python: set up, run, inspect and script material point method simulations.

The module drives the same engine as the ``cairn`` command (no second code path): a run from
Python writes the same files, bit for bit, as ``cairn run``. Start with::

    import cairn
    sim = cairn.Simulation.from_toml("examples/two_blocks.toml", set={"simulation.end_time": 1e-3})
    sim.run()
    sim.history()["kinetic_energy"]

See docs/python.md for the full reference; ``help(cairn.Simulation)`` for the class.
"""
import os as _os

# As `cairn run` (app/main.cpp): OpenMP threads waiting at a barrier spin briefly and then
# sleep, unless the user chose a policy. libgomp reads this when it loads, which is when the
# compiled part below is imported.
if "OMP_WAIT_POLICY" not in _os.environ and "GOMP_SPINCOUNT" not in _os.environ:
    _os.environ["GOMP_SPINCOUNT"] = "1000"


def _refuse_mpi():
    """The module runs on one MPI rank: refuse `mpirun -np N python3 script.py` with N > 1."""
    for name in ("OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE"):
        size = _os.environ.get(name)
        if size is not None and size.isdigit() and int(size) > 1:
            raise ImportError(
                f"cairn's Python module runs on one MPI rank (this process is one of {size}); "
                "for distributed runs use the command line, mpirun -np N cairn run case.toml "
                "(docs/parallel.md), or drive one-rank runs from Python")


_refuse_mpi()

from . import _cairn  # noqa: E402
from ._errors import InputError  # noqa: E402
from ._output import Output, read_history, read_output  # noqa: E402
from ._simulation import Particles, Simulation  # noqa: E402

__version__ = _cairn.__version__
#: Build options: ``mpi`` (compiled with MPI), ``openmp`` (always), ``openmp_max_threads``.
build = dict(_cairn.build)
RunFailure = _cairn.RunFailure
RunFailure.__doc__ = ("A simulation failed (which particle, step, time and quantity); the last good output "
                      "and a failure.xdmf snapshot of the failed state are on disk (CLI exit code 3).")
keys = _cairn.keys
keys_text = _cairn.keys_text
to_toml = _cairn.to_toml
threads = _cairn.threads
set_threads = _cairn.set_threads

__all__ = ["Simulation", "Particles", "Output", "InputError", "RunFailure", "read_output", "read_history",
           "keys", "keys_text", "to_toml", "threads", "set_threads", "build", "__version__"]
