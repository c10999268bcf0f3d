#!/usr/bin/python3
"""The cost of a particle of each material model, relative to linear_elastic (corotational): the
measured factors behind `[parallel] balance = "cost"` (docs/parallel.md, "Load balance").

    /usr/bin/python3 bench/material_cost.py [--rounds 5] [--steps 60] [--cairn build/release/cairn]

One block of particles (2D, plane strain, uGIMP, FLIP/USL, one thread, no output files) is run
with each material in turn, in rounds that rotate the order; the block is stretched by its
initial velocity so that the plastic model yields. The time compared is each run's own wall time
of its steps (printed by `cairn run`), divided by its particle-steps. Prints per model the median
time per particle-step and the median of the per-round ratios to linear_elastic. `--contact`
adds two runs of two touching blocks of two materials, with and without `[contact]`, and prints
their ratio.
"""
import argparse
import re
import statistics
import subprocess
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

MODELS = {
    "linear_elastic": 'model = "linear_elastic"\nyoungs_modulus = 2.0e9\npoissons_ratio = 0.3\n',
    "linear_elastic_small": 'model = "linear_elastic"\nform = "small_strain"\nyoungs_modulus = 2.0e9\n'
                            'poissons_ratio = 0.3\n',
    "neo_hookean": 'model = "neo_hookean"\nyoungs_modulus = 2.0e9\npoissons_ratio = 0.3\n',
    "mie_gruneisen": 'model = "mie_gruneisen"\nbulk_modulus = 1.6e9\nshear_modulus = 0.8e9\ngamma0 = 2.0\n'
                     's1 = 1.5\n',
    "mie_gruneisen_plastic": 'model = "mie_gruneisen"\nbulk_modulus = 1.6e9\nshear_modulus = 0.8e9\n'
                             'gamma0 = 2.0\ns1 = 1.5\nyield_stress = 1.0e5\nhardening_modulus = 1.0e7\n',
}

BASE = """
[simulation]
dimension = 2
mode = "plane_strain"
end_time = 1.0
max_steps = {steps}
cfl = 0.3
threads = 1
adapt_threads = false

[grid]
origin = [0.0, 0.0]
extent = [0.2, 0.1]
cell_size = 1.0e-3

[method]
shape = "ugimp"
update = "flip"
stress_update = "usl"

[output]
snapshots = false
checkpoints = false
"""


def one_block(model, steps):
    return BASE.format(steps=steps) + f"""
[[material]]
name = "m"
density = 2000.0
{MODELS[model]}
[[body]]
material = "m"
shape = {{ box = {{ min = [0.02, 0.02], max = [0.18, 0.08] }} }}
particles_per_cell = 3
velocity = ["40.0 * (X - 0.1)", "-40.0 * (Y - 0.05)"]
"""


def two_blocks(steps, contact):
    text = BASE.format(steps=steps)
    if contact:
        text += '\n[contact]\nmode = "material"\n'
    for name in ("a", "b"):
        text += f'\n[[material]]\nname = "{name}"\ndensity = 2000.0\n{MODELS["neo_hookean"]}'
    text += """
[[body]]
material = "a"
shape = { box = { min = [0.02, 0.02], max = [0.1, 0.08] } }
particles_per_cell = 3
velocity = [5.0, 0.0]

[[body]]
material = "b"
shape = { box = { min = [0.1, 0.02], max = [0.18, 0.08] } }
particles_per_cell = 3
velocity = [-5.0, 0.0]
"""
    return text


def run(cairn, text, tmp, name):
    path = Path(tmp) / f"{name}.toml"
    path.write_text(text)
    r = subprocess.run([cairn, "run", str(path), "--set", f"output.directory={tmp}/out-{name}"],
                       capture_output=True, text=True)
    if r.returncode != 0:
        raise SystemExit(f"{name}: exit {r.returncode}\n{r.stdout}\n{r.stderr}")
    m = re.search(r"(\d+) steps to t = \S+ in ([0-9.]+) s", r.stdout + r.stderr)
    p = re.search(r"([0-9]+) particles", r.stdout + r.stderr)
    if not m or not p:
        raise SystemExit(f"{name}: no timing in the output\n{r.stdout}\n{r.stderr}")
    return float(m.group(2)) / (int(m.group(1)) * int(p.group(1)))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--steps", type=int, default=60)
    ap.add_argument("--cairn", default=str(ROOT / "build" / "release" / "cairn"))
    ap.add_argument("--contact", action="store_true")
    args = ap.parse_args()
    names = list(MODELS)
    times = {n: [] for n in names}
    ratios = {n: [] for n in names}
    contact = []
    with tempfile.TemporaryDirectory() as tmp:
        for k in range(args.rounds):
            order = names[k % len(names):] + names[:k % len(names)]
            t = {n: run(args.cairn, one_block(n, args.steps), tmp, n) for n in order}
            for n in names:
                times[n].append(t[n])
                ratios[n].append(t[n] / t["linear_elastic"])
            print(f"round {k + 1}: " + ", ".join(f"{n} {t[n] * 1e9:.0f} ns" for n in names), flush=True)
            if args.contact:
                pair = [run(args.cairn, two_blocks(args.steps, c), tmp, f"contact{c}") for c in ((k % 2 == 0), (k % 2 == 1))]
                on, off = (pair[0], pair[1]) if k % 2 == 0 else (pair[1], pair[0])
                contact.append(on / off)
                print(f"  contact / no contact: {on / off:.3f}", flush=True)
    print("\nmodel                    ns per particle-step (median)   ratio to linear_elastic (median)")
    for n in names:
        print(f"{n:24s} {statistics.median(times[n]) * 1e9:12.0f} {statistics.median(ratios[n]):28.3f}")
    if contact:
        print(f"two blocks with [contact] / without: {statistics.median(contact):.3f} (median of {len(contact)})")


if __name__ == "__main__":
    main()
