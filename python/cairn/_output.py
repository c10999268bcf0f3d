"""Reading a finished run's folder (docs/output.md describes the files): cairn.read_output."""
import csv
import glob
import os
import xml.etree.ElementTree as ElementTree

import numpy as np


def read_history(path, as_pandas=None):
    """history.csv as a pandas DataFrame (when pandas is installed and ``as_pandas`` is not
    False) or a dict of NumPy arrays, one per column (time, step, dt, kinetic_energy, ...)."""
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    columns = rows[0]
    # The writer prints 17 significant digits (io/history.cpp), which float() reads back to the
    # engine's doubles bit for bit.
    data = np.array([[float(v) for v in row] for row in rows[1:]], dtype=float).reshape(-1, len(columns))
    table = {name: data[:, i] for i, name in enumerate(columns)}
    if "step" in table:
        table["step"] = table["step"].astype(np.int64)
    if as_pandas is False:
        return table
    try:
        import pandas
    except ImportError:
        if as_pandas:
            raise
        return table
    return pandas.DataFrame(table)


class Output:
    """A run folder written by ``cairn run`` or ``Simulation.run``: ``history`` (as
    read_history), ``times`` and ``files`` of the particle snapshots (particles.xdmf order),
    ``snapshot(i)`` (a dict of arrays with their units in ``units``), ``checkpoints``."""

    def __init__(self, folder):
        self.folder = os.fspath(folder)
        if not os.path.isdir(self.folder):
            raise FileNotFoundError(f"no run folder {self.folder}")
        self.times, self.files = _snapshot_series(self.folder)
        self.checkpoints = sorted(glob.glob(os.path.join(self.folder, "checkpoint-*.h5")))

    def history(self, as_pandas=None):
        return read_history(os.path.join(self.folder, "history.csv"), as_pandas)

    def __len__(self):
        return len(self.files)

    def snapshot(self, index=-1):
        """Snapshot ``index`` (-1: the last): every array under /particles (h5py), plus ``time``,
        ``step``, ``units`` (array -> unit), ``material_names`` and ``body_names``."""
        import h5py

        with h5py.File(self.files[index], "r") as f:
            out = {name: np.asarray(data) for name, data in f["particles"].items()}
            out["units"] = {name: _text(data.attrs.get("units", "")) for name, data in f["particles"].items()}
            for key in ("material_names", "body_names"):
                if key in f:
                    out[key] = [_text(v) for v in f[key][()]]
            out["time"] = float(f.attrs["time"])
            out["step"] = int(f.attrs["step"])
        return out


def read_output(folder):
    """The outputs of a finished (or running) run in ``folder``: an ``Output``."""
    return Output(folder)


def _text(value):
    return value.decode() if isinstance(value, bytes) else str(value)


def _snapshot_series(folder):
    """Times and files of particles.xdmf's temporal collection, in order."""
    index = os.path.join(folder, "particles.xdmf")
    if not os.path.exists(index):
        return [], []
    times, files = [], []
    for grid in ElementTree.parse(index).getroot().iter("Grid"):
        time = grid.find("Time")
        if time is None or grid.get("GridType") == "Collection":
            continue
        item = grid.find(".//DataItem")
        if item is None or item.text is None:
            continue
        times.append(float(time.get("Value")))
        files.append(os.path.join(folder, item.text.strip().split(":")[0]))
    return times, files
