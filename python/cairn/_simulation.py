"""cairn.Simulation: one run, set up from a file or a dict, stepped from Python (docs/python.md)."""
import math
import os
import shutil
import tempfile
import warnings

import numpy as np

from . import _cairn
from ._output import read_history
from ._progress import Progress

#: The particle arrays that may be written between steps (docs/python.md, "Writable fields").
WRITABLE = ("velocity", "temperature")


class Particles:
    """The particle arrays of a run as NumPy arrays over the engine's own memory (no copies).

    ``sim.particles.position`` (or ``sim.particles["position"]``) is a view: it changes when the
    simulation steps. Views are read-only; ``sim.particles.writable("velocity")`` gives a writable
    view of one of the fields in ``cairn.Simulation.WRITABLE`` (velocity, temperature). Rows are
    particles in storage order, which is creation order except in serial runs of 32768 or more
    particles (``simulation.sort_particles``): ``id`` gives each row's particle number.

    Arrays (``fields`` lists those stored in this run): position, reference_position, velocity
    (n, D); mass, volume0 (initial volume) (n,); size0 (n, D); deformation_gradient (n, 3, 3);
    kirchhoff_stress (n, 6) in Voigt order xx, yy, zz, yz, xz, xy; affine_velocity (n, 3, 3)
    (APIC); temperature (n,); material, body (int32 indices into ``material_names`` and the
    config's bodies); id (int64); state (n, k): the material state variables. Derived copies:
    ``volume`` (det F V0), ``cauchy_stress`` (n, 3, 3), ``pressure``.
    """

    def __init__(self, engine):
        self._engine = engine

    @property
    def fields(self):
        """Names of the arrays stored in this run."""
        return list(self._engine.particle_fields())

    @property
    def material_names(self):
        """[[material]] names, indexed by the ``material`` array."""
        return list(self._engine.material_names())

    def __getitem__(self, name):
        return self._engine.particle_array(name, False)

    def __getattr__(self, name):
        if name.startswith("_"):
            raise AttributeError(name)
        try:
            return self._engine.particle_array(name, False)
        except ValueError as error:
            if "no particle array" not in str(error):
                raise  # (an FEM run has no particles at all)
            raise AttributeError(str(error)) from None

    def __dir__(self):
        return sorted(set(super().__dir__()) | set(self.fields))

    def __len__(self):
        return len(self._engine.particle_array("mass", False))

    def writable(self, name):
        """A writable view of ``name`` (velocity or temperature); what the engine assumes of a
        value written between steps is in docs/python.md."""
        return self._engine.particle_array(name, True)

    @property
    def volume(self):
        """Current volume det(F) V0 (a copy)."""
        return np.linalg.det(self.deformation_gradient) * self.volume0

    @property
    def cauchy_stress(self):
        """Cauchy stress sigma = tau / det(F), (n, 3, 3) (a copy)."""
        tau = self.kirchhoff_stress
        full = tau[:, [[0, 5, 4], [5, 1, 3], [4, 3, 2]]]
        return full / np.linalg.det(self.deformation_gradient)[:, None, None]

    @property
    def pressure(self):
        """-trace(sigma) / 3 (a copy)."""
        return -np.trace(self.cauchy_stress, axis1=1, axis2=2) / 3.0


class Simulation:
    """One run of one of Cairn's engines (MPM, WLS, FEM), set up from an input file or a dict.

    Make one with ``Simulation.from_toml(path, set={...})``, ``Simulation.from_dict({...})`` or
    ``Simulation.from_text(toml_text)``; each validates the input exactly as ``cairn run`` does
    and raises ``cairn.InputError`` (file, line, key, expected, found) for a bad one.

    Then ``run()`` to the end (or ``run(until=t)``), or ``step(n)``; ``time``, ``steps``,
    ``particles`` (NumPy views of the engine's arrays, read-only; ``particles.writable(name)``
    for velocity and temperature), ``grid()``, ``history()``, ``write_checkpoint()``. The outputs
    (history.csv, snapshots, checkpoints) go to ``output_directory``, as the CLI writes them.
    Ctrl-C during ``run`` or ``step`` raises KeyboardInterrupt after the current step; the
    simulation stays usable.
    """

    WRITABLE = WRITABLE

    def __init__(self, engine, _temporary=None):
        """Use the from_* constructors and restart; ``engine`` is a ``cairn._cairn.Engine``."""
        self._temporary = _temporary
        self._summary = None
        self._engine = engine
        self.particles = Particles(self._engine)
        for warning in engine.config.warnings:  # as `cairn run` prints them
            warnings.warn(warning, stacklevel=3)

    @classmethod
    def _make(cls, load, set, output):
        """A simulation of the engine `load(overrides)` makes; a temporary output folder made
        for it is removed again when the input or the set-up is refused."""
        overrides, temporary = _output_overrides(set, output)
        try:
            return cls(load(overrides), temporary)
        except BaseException:
            if temporary is not None:
                shutil.rmtree(temporary, ignore_errors=True)
            raise

    # ---- construction --------------------------------------------------------------------------
    @classmethod
    def from_toml(cls, path, set=None, output=None):
        """Read, override and validate an input file, as ``cairn run path --set key=value``.

        ``set``: a dict of overrides, ``{"method.order": 4, "material.0.density": 1100}``.
        ``output``: None (the input's output.directory, by default out/<input stem> beside the
        input), a folder, or False for a temporary folder removed by ``close()``.
        """
        return cls._make(lambda overrides: _cairn.Engine(_cairn.load_config(os.fspath(path), overrides)), set,
                         output)

    @classmethod
    def from_text(cls, text, name="input.toml", set=None, output=None):
        """As from_toml for TOML text; ``name`` stands for the file name in error messages."""
        return cls._make(lambda overrides: _cairn.Engine(_cairn.load_config_string(text, name, overrides)), set,
                         output)

    @classmethod
    def from_dict(cls, config, name="dict", set=None, output=None):
        """An input given as a dict: one dict per section, lists of dicts for [[material]] and
        [[body]] (and the other array sections), inline tables as dicts::

            cairn.Simulation.from_dict({
                "simulation": {"dimension": 2, "end_time": 1e-3},
                "grid": {"origin": [0, 0], "size": [1, 1], "cells": [20, 20]},
                "material": [{"name": "rubber", "model": "neo_hookean", "density": 1000, ...}],
                "body": [{"material": "rubber", "shape": {"box": {"min": [...], "max": [...]}}}],
            })

        It is written as TOML (``cairn.to_toml(config)`` shows the text) and validated as an
        input file called ``name``; line numbers in errors refer to that text.
        """
        return cls.from_text(_cairn.to_toml(config), name=name, set=set, output=output)

    @classmethod
    def restart(cls, checkpoint, set=None, output=None):
        """Continue the run a checkpoint holds, as ``cairn restart checkpoint --set ...``: ``set``
        may change only what steers the continuation (end time, step limit, threads, output
        intervals and folder); the outputs go beside the checkpoint unless ``output`` says where.
        Without changes the continuation ends bit-identical to the run that never stopped."""
        return cls._make(lambda overrides: _cairn.Engine.restore(os.fspath(checkpoint), _cairn.overrides(overrides)),
                         set, output)

    # ---- state ---------------------------------------------------------------------------------
    @property
    def time(self):
        """Simulated time reached."""
        return self._engine.time

    @property
    def steps(self):
        """Steps taken (from the start of the run, a restart included)."""
        return self._engine.steps

    @property
    def end_time(self):
        return self._engine.end_time

    @property
    def finished(self):
        """True once simulation.end_time or simulation.max_steps is reached."""
        return self._engine.finished

    @property
    def dimension(self):
        return self._engine.dimension

    @property
    def engine(self):
        """The engine's name: 'mpm', 'wls' or 'fem'."""
        return self._engine.name

    @property
    def output_directory(self):
        return self._engine.config.output_directory

    @property
    def toml(self):
        """The resolved input as TOML text (every key written out), as checkpoints store it."""
        return self._engine.config.toml

    @property
    def warnings(self):
        """The input's load-time warnings (``cairn run`` prints them)."""
        return list(self._engine.config.warnings)

    @property
    def summary(self):
        """The run's summary (steps, wall_seconds, ...) once it finished, else None."""
        return self._summary

    # ---- running -------------------------------------------------------------------------------
    def step(self, n=1):
        """Take n steps (fewer if the run ends first) and write the outputs their schedule asks
        for; returns the number taken. Reaching the end does not write the final outputs: call
        ``finish()`` (``run()`` does)."""
        return self._engine.advance(max_steps=int(n))

    def run(self, until=None, progress=True, callback=None, every=1):
        """Run to the end (then ``finish()``), or until ``time >= until`` (no final outputs).

        ``progress``: a bar (tqdm when installed: a terminal bar, or in Jupyter a widget when
        ipywidgets is installed, else a text bar; a line per 10 % without tqdm); False for none.
        ``callback(sim)`` is called every ``every`` steps (counted from step 0) with the GIL held;
        it may read and write the particle arrays. Returns the summary dict when the run finished,
        else None.
        """
        if every < 1:
            raise ValueError("every must be a positive number of steps")
        limit = math.inf if until is None else float(until)
        bar = Progress(self, limit) if progress else None
        try:
            while not self._engine.finished and self.time < limit:
                batch = every - self.steps % every if callback is not None else 1 << 62
                taken = self._engine.advance(max_steps=batch, until=limit,
                                             wall_seconds=0.25 if bar is not None else 0.0)
                if bar is not None:
                    bar.update()
                if callback is not None and taken and self.steps % every == 0:
                    callback(self)
                if taken == 0:
                    break
            if until is None and not self._engine.closed:
                self.finish()
        finally:
            if bar is not None:
                bar.close()
        return self._summary

    def finish(self):
        """Write the final history row, snapshot and checkpoint (as ``cairn run`` at its end) and
        return the summary; the run can take no more steps afterwards."""
        self._summary = self._engine.finish()
        return self._summary

    def write_checkpoint(self, autosave=False):
        """Write checkpoint-NNNN.h5 (or checkpoint-autosave.h5) now; returns its path.
        ``cairn restart`` continues from it, bit-identical to a run that never stopped."""
        return self._engine.write_checkpoint(autosave)

    # ---- data ----------------------------------------------------------------------------------
    def history(self, as_pandas=None):
        """history.csv so far (flushed first): a pandas DataFrame when pandas is installed
        (``as_pandas=False`` for a dict of NumPy arrays), one column per quantity."""
        self._engine.flush()
        return read_history(os.path.join(self.output_directory, "history.csv"), as_pandas)

    def grid(self):
        """The node fields of the last step (summed over material fields; copies): position,
        mass, momentum, velocity (v), velocity_new (v+), nodes_per_axis."""
        return dict(self._engine.grid_fields())

    def close(self):
        """Remove the temporary output folder of ``output=False`` (nothing else)."""
        if getattr(self, "_temporary", None) is not None:
            shutil.rmtree(self._temporary, ignore_errors=True)
            self._temporary = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __del__(self):
        self.close()

    def __repr__(self):
        items = "elements" if self.engine == "fem" else "particles"
        return (f"<cairn.Simulation {self.engine} {self.dimension}D, {self._engine.items} {items}, "
                f"step {self.steps}, t = {self.time:.6g} of {self.end_time:.6g}>")


def _output_overrides(set, output):
    """The overrides of ``set`` plus the output folder ``output`` asks for."""
    overrides = dict(set or {})
    temporary = None
    if output is False:
        temporary = tempfile.mkdtemp(prefix="cairn-")
        overrides["output.directory"] = temporary
    elif output is not None:
        overrides["output.directory"] = os.path.abspath(os.fspath(output))
    return overrides, temporary
