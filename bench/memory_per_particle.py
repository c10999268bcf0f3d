#!/usr/bin/python3
"""Peak memory per particle: the slope of peak RSS between runs of N1 and N2 particles.

Runs `cairn run` on a block of quadratic B-spline (bspline2), FLIP/USL, neo-Hookean particles
(2 per cell and axis) in 2D and 3D, a few steps plus the final checkpoint, under
/usr/bin/time -v, and prints peak RSS and (RSS(N2) - RSS(N1)) / (N2 - N1) in bytes per particle.
The block is doubled along x, so the grid (and its node arrays) grows with the particle count as
it would in a real refinement at fixed particles per cell.

  /usr/bin/python3 bench/memory_per_particle.py [--cairn build/release/cairn] [--dims 2 3]
      [--particles 1000000 2000000] [--steps 3] [--no-checkpoint] [--set KEY=VALUE ...]
"""
import argparse
import math
import os
import re
import subprocess
import sys
import tempfile

TEMPLATE = """
[simulation]
title = "memory per particle"
dimension = {D}
mode = "{mode}"
end_time = 1.0
max_steps = {steps}
cfl = 0.4

[grid]
origin = [{origin}]
extent = [{extent}]
cell_size = {h}

[method]
shape = "bspline2"
update = "flip"
stress_update = "usl"

[[material]]
name = "m"
model = "neo_hookean"
density = 1000.0
youngs_modulus = 1.0e7
poissons_ratio = 0.3

[[body]]
name = "block"
material = "m"
shape = {{ box = {{ min = [{bmin}], max = [{bmax}] }} }}
particles_per_cell = 2
velocity = [{velocity}]

[output]
snapshots = false
checkpoints = {checkpoints}
history_every = 1.0
"""


def block_cells(dim, n_particles):
    """Cells per axis of a block holding about n_particles at 2 per cell and axis, the extra
    factor along x only (so N2 = 2 N1 doubles x and keeps the cross-section)."""
    base = round((1.0e6 / 2 ** dim) ** (1.0 / dim))  # 500 (2D) or 50 (3D) cells for 1M
    cells = [base] * dim
    cells[0] = round(base * n_particles / 1.0e6)
    return cells


def write_input(path, dim, n_particles, steps, checkpoints):
    h = 1.0e-2
    margin = 3
    cells = block_cells(dim, n_particles)
    vel = ['"0.5*(Y-0.5)"', '"-0.5*(X-0.5)"', '"0.0"'][:dim]
    text = TEMPLATE.format(
        D=dim, mode="plane_strain" if dim == 2 else "3d", steps=steps, h=h,
        origin=", ".join(["0.0"] * dim),
        extent=", ".join(f"{(c + 2 * margin) * h:.6f}" for c in cells),
        bmin=", ".join(f"{margin * h:.6f}" for _ in cells),
        bmax=", ".join(f"{(c + margin) * h:.6f}" for c in cells),
        velocity=", ".join(vel), checkpoints="true" if checkpoints else "false")
    with open(path, "w") as f:
        f.write(text)
    return math.prod(2 * c for c in cells)


def peak_rss_bytes(cairn, path, outdir, sets=()):
    cmd = ["/usr/bin/time", "-v", cairn, "run", path, "-t", "1", "-q",
           "--set", f"output.directory={outdir}"]
    for s in sets:
        cmd += ["--set", s]
    res = subprocess.run(cmd, capture_output=True, text=True)
    if res.returncode != 0:
        sys.exit(f"failed: {' '.join(cmd)}\n{res.stderr}")
    m = re.search(r"Maximum resident set size \(kbytes\): (\d+)", res.stderr)
    return int(m.group(1)) * 1024


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cairn", default="build/release/cairn")
    ap.add_argument("--dims", type=int, nargs="+", default=[2, 3])
    ap.add_argument("--particles", type=int, nargs=2, default=[1_000_000, 2_000_000])
    ap.add_argument("--steps", type=int, default=3)
    ap.add_argument("--no-checkpoint", action="store_true", help="skip the final checkpoint")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="an input override for every run (e.g. simulation.sort_particles=false)")
    args = ap.parse_args()
    cairn = os.path.abspath(args.cairn)
    with tempfile.TemporaryDirectory(prefix="cairn-memory-") as tmp:
        print(f"{'D':>2} {'particles':>10} {'peak RSS MiB':>13}")
        for dim in args.dims:
            rss = []
            counts = []
            for n in args.particles:
                path = os.path.join(tmp, f"memory_{dim}d_{n}.toml")
                counts.append(write_input(path, dim, n, args.steps, not args.no_checkpoint))
                rss.append(peak_rss_bytes(cairn, path, os.path.join(tmp, f"out_{dim}d_{n}"), args.set))
                print(f"{dim:>2} {counts[-1]:>10} {rss[-1] / 2**20:>13.1f}", flush=True)
            slope = (rss[1] - rss[0]) / (counts[1] - counts[0])
            print(f"{dim}D: {slope:.0f} bytes per particle (peak RSS slope)", flush=True)


if __name__ == "__main__":
    main()
