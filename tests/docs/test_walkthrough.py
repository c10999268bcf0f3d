"""A newcomer's walk through docs/tutorial.md and docs/output.md, each in a fresh folder of its own,
exactly as the pages say: the "set once" lines at the top of the tutorial, then every sh and
python block in order. Then every number the tutorial and the examples' headers state about a run
is measured and compared with the page, within the tolerance stated beside each comparison below.

A page that drifts from the program (a number, a path, a command that no longer works from a
fresh folder) fails here. Needs ParaView's pvbatch and xvfb-run (./tools/install-deps), as the
pages do.

Usage: /usr/bin/python3 test_walkthrough.py <cairn binary> <source dir>
"""
import csv
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile


class CheckFailed(Exception):
    pass


def check(cond, message):
    if not cond:
        raise CheckFailed(message)
    print("  ok:", message)


def close(measured, stated, rel):
    return abs(measured - stated) <= rel * abs(stated)


def blocks(page):
    """(language, text) of every fenced code block of a page, in order."""
    return re.findall(r"```(\w*)\n(.*?)```", page, re.S)


def number(pattern, text, what):
    m = re.search(pattern, text, re.S)
    if m is None:
        raise CheckFailed(f"{what}: pattern {pattern!r} not found")
    return m.groups() if len(m.groups()) > 1 else m.group(1)


class Folder:
    """A fresh folder with the tutorial's "set once" lines run before every command."""

    def __init__(self, path, set_once, cairn):
        self.path = path
        os.makedirs(path)
        # The pages' first line names the clone; here it is the source tree under test. The
        # binary under test goes first on PATH too (a build folder other than build/release).
        self.prefix = set_once + f'\nexport PATH="{os.path.dirname(os.path.abspath(cairn))}:$PATH"\n'

    def sh(self, script, timeout=600):
        proc = subprocess.run(["bash", "-e", "-c", self.prefix + script], cwd=self.path, capture_output=True,
                              text=True, timeout=timeout)
        if proc.returncode != 0:
            raise CheckFailed(f"in a fresh folder, {script.strip()!r} exited with {proc.returncode}\n"
                              f"--- stdout ---\n{proc.stdout[-3000:]}\n--- stderr ---\n{proc.stderr[-3000:]}")
        print(f"  ran: {script.strip().splitlines()[0][:100]}")
        return proc

    def python(self, code):
        proc = subprocess.run(["/usr/bin/python3", "-c", code], cwd=self.path, capture_output=True, text=True,
                              timeout=300)
        if proc.returncode != 0:
            raise CheckFailed(f"the python block failed in a fresh folder:\n{code}\n{proc.stderr[-3000:]}")
        print("  ran: a python block")
        return proc


def set_once_lines(source):
    with open(os.path.join(source, "docs", "tutorial.md")) as f:
        first_sh = next(text for lang, text in blocks(f.read()) if lang == "sh")
    check("export CAIRN=" in first_sh and "export PATH=" in first_sh,
          "the tutorial's first command block sets CAIRN and PATH once")
    return re.sub(r"export CAIRN=\S+", f'export CAIRN="{source}"', first_sh)


def history(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return {k: [float(r[k]) for r in rows] for k in rows[0]}


def particles_in(check_output):
    return {name: int(n) for name, n in re.findall(r"# body '(\w+)': (\d+) particles", check_output)}


def first_step(check_output):
    return float(re.search(r"# first time step: ([0-9.e+-]+)", check_output).group(1))


def tutorial(cairn, source, tmp, set_once):
    with open(os.path.join(source, "docs", "tutorial.md")) as f:
        page = f.read()
    folder = Folder(os.path.join(tmp, "tutorial"), set_once, cairn)
    with open(os.path.join(folder.path, "disk.toml"), "w") as f:
        f.write("\n".join(text for lang, text in blocks(page) if lang == "toml"))
    outputs = {}
    for lang, text in blocks(page):
        if lang == "sh" and "export CAIRN=" not in text:
            outputs[text] = folder.sh(text).stdout
        elif lang == "python":
            folder.python(text)
    check_out = next(out for cmd, out in outputs.items() if cmd.strip().startswith("cairn check"))
    out = os.path.join(folder.path, "out", "disk")
    for name in ("history.csv", "particles.xdmf", "energy.png"):
        check(os.path.isfile(os.path.join(out, name)), f"tutorial: out/disk/{name} written")
    check(os.path.getsize(os.path.join(folder.path, "disk.png")) > 10000, "tutorial: ParaView drew disk.png")

    # The numbers the page states, each from the run it describes (line breaks as spaces).
    page = " ".join(page.split())
    n_disk, n_wall = (int(v) for v in number(r"particles per body \((\d+) for the disk, (\d+) for the wall\)",
                                             page, "particle counts"))
    counts = particles_in(check_out)
    check(counts == {"wall": n_wall, "disk": n_disk}, f"tutorial: particles per body {counts} as stated (exact)")
    stated_dt = float(number(r"first time step \(about ([0-9.]+) µs\)", page, "first time step"))
    dt = first_step(check_out)
    check(close(dt * 1e6, stated_dt, 0.01), f"tutorial: first time step {dt * 1e6:.4g} µs, stated {stated_dt} (1 %)")
    h = history(os.path.join(out, "history.csv"))
    p0_stated, p1_stated, percent = number(
        r"`momentum_x` goes from \+([0-9.]+) kg·m/s.*?to about −([0-9.]+) after the bounce: the disk comes back "
        r"with (\d+) % of its speed", page, "momentum")
    p0, p1 = h["momentum_x"][0], h["momentum_x"][-1]
    check(close(p0, float(p0_stated), 0.005), f"tutorial: momentum_x starts at {p0:.4g}, stated +{p0_stated} (0.5 %)")
    check(close(-p1, float(p1_stated), 0.01), f"tutorial: momentum_x ends at {p1:.4g}, stated −{p1_stated} (1 %)")
    check(abs(100 * -p1 / p0 - int(percent)) <= 1.0,
          f"tutorial: the disk comes back with {100 * -p1 / p0:.1f} % of its momentum, stated {percent} % (1 point)")
    force_stated, at_stated = number(r"rises to about ([0-9.]+) kN at ([0-9.]+) ms", page, "contact force")
    force = max(h["contact_wall_disk_x"])
    at = h["time"][h["contact_wall_disk_x"].index(force)]
    check(close(force / 1e3, float(force_stated), 0.05),
          f"tutorial: contact force peaks at {force / 1e3:.3g} kN, stated {force_stated} kN (5 %)")
    check(abs(at * 1e3 - float(at_stated)) <= 0.25,
          f"tutorial: at {at * 1e3:.2f} ms, stated {at_stated} ms (0.25 ms: 2.5 history rows)")
    check(abs(h["contact_wall_disk_x"][-1]) < 1e-6 * force, "tutorial: the force is back to zero at the end")
    return {"percent": 100 * -p1 / p0, "particles": n_disk + n_wall, "steps": int(h["step"][-1]), "dt": dt}


def output_page(cairn, source, tmp, set_once):
    with open(os.path.join(source, "docs", "output.md")) as f:
        page = f.read()
    folder = Folder(os.path.join(tmp, "output"), set_once, cairn)
    script = number(r"saved as `([\w.]+)`", page, "the ParaView script's name")
    ran = 0
    for lang, text in blocks(page):
        if lang == "sh":
            folder.sh(text)
            ran += 1
        elif lang == "python" and "paraview.simple" in text:
            with open(os.path.join(folder.path, script), "w") as f:
                f.write(text)
        elif lang == "python":
            out = folder.python(text).stdout
            check("XX" in out or "xx" in out, f"output.md: the h5py snippet prints the stress components: {out.strip()!r}")
            ran += 1
    check(ran == 3, f"output.md: its 3 commands and snippets ran in a fresh folder ({ran})")
    png = number(r'SaveScreenshot\("([\w.]+)"', page, "the screenshot's name")
    check(os.path.getsize(os.path.join(folder.path, png)) > 10000, f"output.md: the ParaView script drew {png}")


def example_headers(cairn, source, tmp, measured):
    def header(name, whole=False):
        with open(os.path.join(source, "examples", name)) as f:
            text = f.read()
        return text if whole else text.split("[simulation]")[0]

    def cairn_check(name, *sets):
        args = [cairn, "check", os.path.join(source, "examples", name)]
        for s in sets:
            args += ["--set", s]
        proc = subprocess.run(args, capture_output=True, text=True, timeout=300)
        if proc.returncode != 0:
            raise CheckFailed(f"{' '.join(args)} exited with {proc.returncode}: {proc.stderr}")
        return proc.stdout

    # disk_wall.toml is the tutorial's input (tests/examples/test_examples.py checks that).
    text = header("disk_wall.toml")
    percent = int(number(r"about (\d+) %\s+# of its speed", text, "disk_wall's rebound"))
    check(abs(measured["percent"] - percent) <= 1.0,
          f"disk_wall.toml: rebound {measured['percent']:.1f} %, stated about {percent} % (1 point)")
    n, steps = (int(v) for v in number(r"# (\d+) particles, (\d+) steps", text, "disk_wall's size"))
    check(n == measured["particles"], f"disk_wall.toml: {measured['particles']} particles as stated (exact)")
    check(close(measured["steps"], steps, 0.02), f"disk_wall.toml: the run took {measured['steps']} steps, stated {steps} (2 %)")
    fold = float(number(r"would cut the time step about (\d+)-fold", header("disk_wall.toml", whole=True),
                        "the steel wall's cost"))
    steel = first_step(cairn_check("disk_wall.toml", "material[1].youngs_modulus=2.0e11", "material[1].density=7850.0"))
    check(close(measured["dt"] / steel, fold, 0.05),
          f"disk_wall.toml: a steel wall cuts the first step {measured['dt'] / steel:.3g}-fold, stated about {fold:g} (5 %)")
    # The others: what `cairn check` says of them, as their headers quote it.
    for name in ("falling_cube_3d.toml", "friction_block.toml", "taylor_bar.toml"):
        n, steps = (int(v) for v in number(r"cairn check: (\d+) particles, about (\d+) steps", header(name), name))
        out = cairn_check(name)
        total = sum(particles_in(out).values())
        estimate = float(re.search(r"# estimated steps: ([0-9.e+]+)", out).group(1))
        check(total == n, f"{name}: {total} particles as stated (exact)")
        check(close(estimate, steps, 0.02), f"{name}: cairn check estimates {estimate:g} steps, stated about {steps} (2 %)")


def main():
    if len(sys.argv) < 3:
        print("usage: test_walkthrough.py <cairn binary> <source dir>", file=sys.stderr)
        return 2
    cairn, source = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    if shutil.which("pvbatch") is None or shutil.which("xvfb-run") is None:
        print("FAIL: pvbatch or xvfb-run not found; install Debian's paraview, python3-paraview and xvfb "
              "(./tools/install-deps)", file=sys.stderr)
        return 1
    with tempfile.TemporaryDirectory(prefix="cairn_docs_") as tmp:
        try:
            set_once = set_once_lines(source)
            print("tutorial")
            measured = tutorial(cairn, source, tmp, set_once)
            print("output.md")
            output_page(cairn, source, tmp, set_once)
            print("example headers")
            example_headers(cairn, source, tmp, measured)
        except (CheckFailed, subprocess.TimeoutExpired) as e:
            print(f"FAIL: {e}", file=sys.stderr)
            return 1
    print("ok: the tutorial and docs/output.md work from a fresh folder, and their numbers are the program's")
    return 0


if __name__ == "__main__":
    sys.exit(main())
