"""The progress display of Simulation.run (docs/python.md)."""
import sys


def _in_jupyter():
    return "ipykernel" in sys.modules


class Progress:
    """A tqdm bar over simulated time when tqdm is installed (Debian python3-tqdm): in a
    terminal a text bar on stderr, in Jupyter a widget when ipywidgets is installed, else a text
    bar on stdout. Without tqdm: a line per 10 %, as ``cairn run`` writes when not on a terminal."""

    def __init__(self, sim, until):
        self._sim = sim
        self._end = min(until, sim.end_time)
        self._start = sim.time
        self._bar = None
        self._decile = int(10 * self._fraction())
        try:
            if _in_jupyter():
                try:
                    import ipywidgets  # noqa: F401
                    from tqdm.notebook import tqdm
                    file = None
                except ImportError:
                    from tqdm.std import tqdm
                    file = sys.stdout
            else:
                from tqdm.std import tqdm
                file = sys.stderr
        except ImportError:
            return
        kwargs = {"file": file} if file is not None else {}
        self._bar = tqdm(total=1000, unit="‰", bar_format="{l_bar}{bar}| t = {postfix} [{elapsed}<{remaining}]",
                         **kwargs)
        self.update()

    def _fraction(self):
        span = self._end - self._start
        return 1.0 if span <= 0 else min(max((self._sim.time - self._start) / span, 0.0), 1.0)

    def update(self):
        fraction = self._fraction()
        if self._bar is not None:
            self._bar.n = int(1000 * fraction)
            self._bar.postfix = f"{self._sim.time:.4g}, step {self._sim.steps}"
            self._bar.refresh()
            return
        decile = int(10 * fraction)
        if decile > self._decile:
            self._decile = decile
            print(f"  step {self._sim.steps}  t = {self._sim.time:.6g}  ({10 * decile}%)", file=sys.stderr)

    def close(self):
        if self._bar is not None:
            self._bar.close()
