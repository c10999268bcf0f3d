"""Shared plumbing for the verification cases under verification/<case>/run.

Each case script imports this module (it adds tools/verification_common to sys.path), then:
  args = cairn_case.parse_args("bar_1d_mms", __doc__)   # --quick, --cairn, --out, --threads
  cairn_case.run_cairn(args, toml_path, out_dir)         # writes the input, runs `cairn run ... -q`
  cairn_case.stage_times(log)                            # seconds per stage of a run without -q
  cairn_case.read_history(dir), cairn_case.snapshots(dir), cairn_case.read_snapshot(file)
  cairn_case.print_table(...), cairn_case.save_plot(fig, args), cairn_case.finish(checks)

Only numpy, h5py and matplotlib are needed (Debian's /usr/bin/python3 has all three).
"""
from __future__ import annotations

import argparse
import math
import os
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

# Exit codes of a case's run script: 0 every assertion holds, 1 the assertions were evaluated and
# at least one failed (finish()), EXIT_ERROR for anything else: a run that did not complete, a
# missing binary, an uncaught exception (the hook below). known_failure.py relies on this.
EXIT_ERROR = 2


def _uncaught(kind, value, tb):
    """An uncaught exception is a crash, not a failed assertion: print it and exit EXIT_ERROR."""
    import traceback
    traceback.print_exception(kind, value, tb)
    print(f"RESULT: ERROR (uncaught {kind.__name__})", flush=True)
    sys.stderr.flush()
    os._exit(EXIT_ERROR)


sys.excepthook = _uncaught

REPO = Path(__file__).resolve().parents[2]
VERIFICATION = REPO / "verification"


def parse_args(case: str, description: str | None = None, default_threads: int = 1, extra=None):
    """Common options; extra(parser) may add case-specific ones."""
    p = argparse.ArgumentParser(description=description,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--quick", action="store_true",
                   help="the reduced variant run by the default test suite")
    p.add_argument("--cairn", default=str(REPO / "build" / "release" / "cairn"),
                   help="path to the cairn binary (default: %(default)s)")
    p.add_argument("--out", default=str(VERIFICATION / case / "results"),
                   help="output folder for inputs, runs, tables and plots (default: %(default)s)")
    p.add_argument("--threads", type=int, default=default_threads,
                   help="OpenMP threads per cairn run, 0 = OpenMP default (default: %(default)s)")
    p.add_argument("--no-copy", action="store_true",
                   help="do not copy the plot next to the README (full runs copy it by default)")
    if extra:
        extra(p)
    args = p.parse_args()
    args.case = case
    args.cairn = str(Path(args.cairn).resolve())
    args.out = Path(args.out).resolve()
    args.out.mkdir(parents=True, exist_ok=True)
    if not os.access(args.cairn, os.X_OK):
        print(f"cairn binary not found or not executable: {args.cairn}\nRESULT: ERROR (no binary)")
        sys.exit(EXIT_ERROR)
    return args


def toml_value(v) -> str:
    """Format a Python value as TOML (numbers with full precision, lists, strings, bools)."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return repr(v)
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{k} = {toml_value(x)}" for k, x in v.items()) + " }"
    raise TypeError(f"cannot write {type(v)} to TOML")


def toml_text(doc: dict, header: str = "") -> str:
    """doc: {section: {key: value}} or {section: [ {key: value}, ... ]} for arrays of tables."""
    lines = [f"# {line}" if line else "#" for line in header.strip().splitlines()] if header else []
    for section, body in doc.items():
        entries = body if isinstance(body, list) else [body]
        for entry in entries:
            lines.append("")
            lines.append(f"[[{section}]]" if isinstance(body, list) else f"[{section}]")
            for k, v in entry.items():
                lines.append(f"{k} = {toml_value(v)}")
    return "\n".join(lines) + "\n"


def run_cairn(args, toml_path: Path, run_dir: Path, quiet: bool = True) -> float:
    """Run `cairn run toml_path -q` writing into run_dir; returns the wall time in seconds.

    The input file itself must name run_dir as output.directory (so that it reproduces the run);
    the thread count comes from --threads. Raises RuntimeError with cairn's output on failure.
    quiet=False drops -q, so that the log (<toml stem>.log next to run_dir) ends with cairn's run
    summary, including the time per stage (see stage_times).
    """
    if run_dir.exists():
        shutil.rmtree(run_dir)
    cmd = [args.cairn, "run", str(toml_path)] + (["-q"] if quiet else [])
    if args.threads > 0:
        cmd += ["--set", f"simulation.threads={args.threads}"]
    t0 = time.monotonic()
    proc = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.monotonic() - t0
    (run_dir.parent / (toml_path.stem + ".log")).write_text(
        " ".join(cmd) + "\n" + proc.stdout + proc.stderr)
    if proc.returncode != 0:
        raise RuntimeError(f"cairn failed (exit {proc.returncode}) on {toml_path}:\n"
                           + proc.stdout[-2000:] + proc.stderr[-2000:])
    return wall


def stage_times(log_path: Path) -> dict[str, float]:
    """Seconds per step stage from the `cairn: time per stage:` line of a non-quiet run's log."""
    out = {}
    for line in Path(log_path).read_text().splitlines():
        if line.startswith("cairn: time per stage:"):
            for name, sec in re.findall(r"(\w+) ([0-9.eE+-]+) s \(", line):
                out[name] = float(sec)
    return out


def read_history(run_dir: Path) -> dict[str, np.ndarray]:
    data = np.genfromtxt(run_dir / "history.csv", delimiter=",", names=True)
    return {name: np.atleast_1d(data[name]) for name in data.dtype.names}


def snapshots(run_dir: Path) -> list[Path]:
    return sorted((run_dir / "snapshots").glob("particles-*.h5"))


def read_snapshot(path: Path, fields=("position", "displacement", "velocity", "mass", "body")):
    import h5py
    with h5py.File(path, "r") as f:
        out = {"time": float(f.attrs["time"])}
        for k in fields:
            out[k] = f["particles"][k][()]
    return out


def prune_snapshots(run_dir: Path, keep) -> None:
    """Delete snapshot files whose index is not in keep (a set of ints) and drop them from the XDMF."""
    for s in snapshots(run_dir):
        if int(s.stem.split("-")[1]) not in keep:
            s.unlink()
    xdmf = run_dir / "particles.xdmf"
    if xdmf.exists():
        text = xdmf.read_text()
        pattern = re.compile(r'\n\s*<Grid Name="particles-(\d+)" GridType="Uniform">.*?</Grid>', re.S)
        text = pattern.sub(lambda m: m.group(0) if int(m.group(1)) in keep else "", text)
        xdmf.write_text(text)


def lsq_slope(x, y) -> float:
    """Least-squares slope of log(y) against log(x)."""
    lx, ly = np.log(np.asarray(x, float)), np.log(np.asarray(y, float))
    return float(np.polyfit(lx, ly, 1)[0])


def fmt(v, spec: str = ".4g") -> str:
    if isinstance(v, str):
        return v
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return "-"
    return format(v, spec)


def table(headers, rows, specs=None) -> str:
    """A Markdown table (also readable on a terminal)."""
    specs = specs or [".4g"] * len(headers)
    cells = [[fmt(v, s) for v, s in zip(r, specs)] for r in rows]
    w = [max(len(h), *(len(r[i]) for r in cells)) if cells else len(h) for i, h in enumerate(headers)]
    line = lambda r: "| " + " | ".join(c.rjust(w[i]) for i, c in enumerate(r)) + " |"
    out = [line(headers), "|" + "|".join("-" * (x + 1) + ":" for x in w) + "|"]
    out += [line(r) for r in cells]
    return "\n".join(out)


def save_plot(fig, args) -> Path:
    """Write <out>/<case>.png; full runs (not --quick) also copy it to verification/<case>/."""
    png = args.out / f"{args.case}.png"
    fig.savefig(png, dpi=110, bbox_inches="tight")
    if not args.quick and not args.no_copy:
        shutil.copyfile(png, VERIFICATION / args.case / f"{args.case}.png")
    return png


def finish(checks, summary: str = "") -> int:
    """checks: list of (description, measured text, passed). Prints them and the RESULT line."""
    print("\nAssertions:")
    for desc, measured, ok in checks:
        print(f"  [{'PASS' if ok else 'FAIL'}] {desc}: {measured}")
    ok = all(c[2] for c in checks)
    failed = [c[0] for c in checks if not c[2]]
    tail = summary if ok else "failed: " + "; ".join(failed)
    print(f"RESULT: {'PASS' if ok else 'FAIL'} {tail}".rstrip())
    return 0 if ok else 1
