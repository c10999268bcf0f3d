"""Run every example of examples/ that has no verification case of its own, shortened, and check
that it shows what its header promises; check that docs/tutorial.md builds disk_wall.toml.

Usage: /usr/bin/python3 test_examples.py <cairn binary> <source dir>
(two_blocks.toml and nickel_shock.toml are the verification cases two_blocks and nickel_shock.)
"""
import csv
import math
import glob
import os
import re
import subprocess
import sys
import tempfile

import h5py
import numpy as np

G = 9.81


class CheckFailed(Exception):
    pass


def check(cond, message):
    if not cond:
        raise CheckFailed(message)
    print("  ok:", message)


def run(cairn, source, example, out, overrides):
    cmd = [cairn, "run", os.path.join(source, "examples", example), "-q", "--set", f"output.directory={out}"]
    for o in overrides:
        cmd += ["--set", o]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=900)
    if proc.returncode != 0:
        raise CheckFailed(f"'{' '.join(cmd)}' exited with {proc.returncode}\n{proc.stdout}\n{proc.stderr}")


def history(out):
    with open(os.path.join(out, "history.csv")) as f:
        rows = list(csv.DictReader(f))
    return {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}


def snapshots(out):
    """Per snapshot: time and, per body name, its particles' positions, velocities, masses, von
    Mises stresses."""
    result = []
    for path in sorted(glob.glob(os.path.join(out, "snapshots", "particles-*.h5"))):
        with h5py.File(path, "r") as f:
            names = [n.decode() for n in f["body_names"][:]]
            p = f["particles"]
            body = p["body"][:]
            bodies = {}
            for i, name in enumerate(names):
                s = body == i
                bodies[name] = {"x": p["position"][:][s], "v": p["velocity"][:][s], "m": p["mass"][:][s],
                                "von_mises": p["von_mises"][:][s]}
            result.append((float(f.attrs["time"]), bodies))
    return result


def mean_velocity(b, axis):
    return float(np.average(b["v"][:, axis], weights=b["m"]))


def disk_wall(cairn, source, out):
    # 4 mm cells (2 mm in the example) and half the time: the disk has hit the wall and left it.
    run(cairn, source, "disk_wall.toml", out, ["grid.cell_size=4.0e-3", "simulation.end_time=4.0e-3"])
    h = history(out)
    p0, p1 = h["momentum_x"][0], h["momentum_x"][-1]
    check(p0 > 0 and p1 < -0.5 * p0, f"disk_wall: momentum_x {p0:.4g} -> {p1:.4g} (rebound above half the speed)")
    check(h["contact_wall_disk_x"].max() > 0, f"disk_wall: the disk pushed the wall (+x), up to {h['contact_wall_disk_x'].max():.4g} N")
    # docs/output.md describes every column and array this run wrote.
    with open(os.path.join(source, "docs", "output.md")) as f:
        doc = f.read()
    generic = {"contact_wall_disk_x": "contact_<a>_<b>_<axis>", "contact_wall_disk_y": "contact_<a>_<b>_<axis>"}
    missing = [c for c in h if f"`{generic.get(c, c)}`" not in doc]
    check(not missing, f"disk_wall: docs/output.md lists every history.csv column (missing: {missing})")
    with h5py.File(sorted(glob.glob(os.path.join(out, "snapshots", "particles-*.h5")))[-1], "r") as f:
        names = list(f.attrs) + [k for k in f if k != "particles"] + list(f["particles"])
    missing = [n for n in names if f"`{n}`" not in doc and f"`/{n}`" not in doc and not n.startswith("deformation_gradient_")]
    check(not missing, f"disk_wall: docs/output.md lists every snapshot attribute and dataset (missing: {missing})")


def falling_cube(cairn, source, out):
    # One particle per cell and through the first bounce only (0.14 s of 0.25 s).
    run(cairn, source, "falling_cube_3d.toml", out,
        ["body.0.particles_per_cell=1", "body.1.particles_per_cell=1", "simulation.end_time=0.14",
         "output.every=0.02"])
    snaps = snapshots(out)
    t, bodies = next((t, b) for t, b in snaps if abs(t - 0.08) < 1e-3)
    vz = mean_velocity(bodies["cube"], 2)
    check(abs(vz + G * t) <= 0.01 * G * t, f"falling_cube: free fall, v_z(t = {t:.3f}) = {vz:.4f} m/s vs -g t = {-G * t:.4f}")
    lowest = min(b["cube"]["x"][:, 2].min() for _, b in snaps)
    check(lowest >= 0.02, f"falling_cube: the cube's particles stay above the floor (lowest z {lowest:.4f} >= 0.02)")
    t, bodies = snaps[-1]
    vz = mean_velocity(bodies["cube"], 2)
    check(vz > 0.3, f"falling_cube: bounced, v_z(t = {t:.3f}) = {vz:.3f} m/s upwards")


def taylor_bar(cairn, source, out):
    # 1.5 mm cells (0.75 mm in the example) and the first 20 us of 80 us.
    run(cairn, source, "taylor_bar.toml", out,
        ["grid.cell_size=1.5e-3", "simulation.end_time=2.0e-5", "output.every=1.0e-5"])
    (t0, first), (t1, last) = snapshots(out)[0], snapshots(out)[-1]

    def shape(b):
        x = b["x"]
        r, z = np.hypot(x[:, 0], x[:, 1]), x[:, 2]
        return z.max() - z.min(), r[z < z.min() + 1.5e-3].max(), r[z > z.max() - 1.5e-3].max()

    (l0, rb0, rt0), (l1, rb1, rt1) = shape(first["bar"]), shape(last["bar"])
    check(rb1 > 1.2 * rb0, f"taylor_bar: the impact end spreads, radius {rb0 * 1e3:.3f} -> {rb1 * 1e3:.3f} mm")
    check(abs(rt1 - rt0) < 0.02 * rt0, f"taylor_bar: the far end keeps its radius, {rt0 * 1e3:.3f} -> {rt1 * 1e3:.3f} mm")
    check(l1 < 0.95 * l0, f"taylor_bar: the bar shortens, {l0 * 1e3:.2f} -> {l1 * 1e3:.2f} mm")
    # J2 plasticity caps the deviatoric stress at the yield stress (400 MPa, + 100 MPa per unit
    # plastic strain): an elastic bar would reach rho c v = 6.7 GPa.
    vm = last["bar"]["von_mises"].max()
    check(vm < 1.1 * 500e6, f"taylor_bar: von Mises stress {vm / 1e6:.0f} MPa, capped by plasticity")


def friction_block(cairn, source, out):
    # The first 0.1 s of 0.4 s.
    run(cairn, source, "friction_block.toml", out, ["simulation.end_time=0.1", "output.every=0.05"])
    t, bodies = snapshots(out)[-1]
    dv = 1.0 - mean_velocity(bodies["block"], 0)
    expected = 0.3 * G * t
    check(abs(dv - expected) <= 0.1 * expected,
          f"friction_block: the block lost {dv:.4f} m/s in {t:.3f} s, mu g t = {expected:.4f} (within 10 %)")
    lowest = bodies["block"]["x"][:, 1].min()
    check(lowest >= 0.02, f"friction_block: the block stays on the floor (lowest y {lowest:.4f} >= 0.02)")


def meshed_projectile(cairn, source, out):
    # The first 15 us of 30 us: through the first contact (at 7.5 us).
    run(cairn, source, "meshed_projectile_3d.toml", out, ["simulation.end_time=1.5e-5", "output.every=5.0e-6"])
    snaps = snapshots(out)
    (t0, first), (t1, last) = snaps[0], snaps[-1]
    # The mesh (examples/meshes/make_projectile.py): a 24-gon prism of circumradius 3 mm from
    # z = 4 to 12 mm above the tip, on a 24-gon pyramid; translated to the tip at (12, 12, 8.5) mm.
    # An inside test of our own (half-planes of the 24-gon, scaled in the nose) over the lattice of
    # l = 0.5 mm must pick exactly the lattice points the mesh body holds.
    n, r, nose, body, l = 24, 3e-3, 4e-3, 8e-3, 0.5e-3
    k = np.arange(48)
    X, Y, Z = np.meshgrid((k + 0.5) * l, (k + 0.5) * l, (np.arange(60) + 0.5) * l, indexing="ij")
    h = Z - 0.0085
    scale = np.clip(h / nose, 0.0, 1.0)
    phi = (2 * np.arange(n) + 1) * math.pi / n
    reach = np.max([(X - 0.012) * math.cos(a) + (Y - 0.012) * math.sin(a) for a in phi], axis=0)
    inside = (h > 0) & (h < nose + body) & (reach < r * math.cos(math.pi / n) * scale)
    count = int(inside.sum())
    m = first["projectile"]["m"]
    check(len(m) == count and abs(m.sum() - 7850.0 * count * l ** 3) <= 1e-12 * m.sum(),
          f"meshed_projectile: {len(m)} particles of mass 7850 l^3, the lattice points inside the projectile "
          f"by an independent test: {count}")
    v_mesh = n / 2 * r * r * math.sin(2 * math.pi / n) * (body + nose / 3)
    print(f"  (particle volume {count * l ** 3 * 1e9:.2f} mm^3, mesh volume {v_mesh * 1e9:.2f} mm^3)")
    x = first["projectile"]["x"]
    check(x[:, 2].min() > 0.0085 and x[:, 2].max() < 0.0205 and abs(x[:, 0].mean() - 0.012) < 1e-5
          and abs(x[:, 1].mean() - 0.012) < 1e-5,
          f"meshed_projectile: the projectile lies where units = mm and translate put it "
          f"(z {x[:, 2].min():.4f}..{x[:, 2].max():.4f}, centre {x[:, 0].mean():.4f}, {x[:, 1].mean():.4f})")

    def momentum(bodies):
        return sum((b["m"] * b["v"][:, 2]).sum() for b in bodies.values())

    p0, p1 = momentum(first), momentum(last)
    check(abs(p1 - p0) <= 1e-3 * abs(p0), f"meshed_projectile: z momentum {p0:.6g} -> {p1:.6g} (no external force)")
    vp, vq = mean_velocity(last["projectile"], 2), mean_velocity(last["plate"], 2)
    check(vp > -190.0 and vq < -5.0,
          f"meshed_projectile: at t = {t1 * 1e6:.0f} us the projectile slowed to {vp:.1f} m/s and pushed the plate to {vq:.1f} m/s")


def plate_with_holes(cairn, source, out):
    # The first 12 ms of 30 ms: the plate has hit the wall (at 5 ms) and been stopped.
    run(cairn, source, "plate_with_holes_2d.toml", out, ["simulation.end_time=1.2e-2", "output.every=6.0e-3"])
    snaps = snapshots(out)
    (t0, first), (t1, last) = snaps[0], snaps[-1]
    # The outline (examples/meshes/plate_with_holes.geo): 60 x 40 mm minus two holes of 8 mm, each
    # hole a polygon of chords h <= 1 mm inside its circle (2 pi h^2 / 12 more area per hole).
    h, r = 1e-3, 8e-3
    area = 0.06 * 0.04 - 2 * math.pi * r * r
    m = first["plate"]["m"].sum()
    check(area * 1000.0 <= m <= (area + 2 * 2 * math.pi * h * h / 12) * 1000.0,
          f"plate_with_holes: mass {m:.6g} kg = density x the meshed area ({area * 1000.0:.6g} kg for the exact outline)")
    x = first["plate"]["x"]
    in_holes = sum(int(np.hypot(x[:, 0] - cx, x[:, 1] - 0.03).min() < r * math.cos(math.pi / 8)) for cx in (0.025, 0.055))
    check(in_holes == 0 and x[:, 0].min() > 0.01 and x[:, 0].max() < 0.07,
          "plate_with_holes: the particles fill the outline and leave both holes empty")
    vy = mean_velocity(last["plate"], 1)
    lowest = min(b["plate"]["x"][:, 1].min() for _, b in snaps)
    check(vy > -1.0 and lowest > -1e-3,
          f"plate_with_holes: the wall stopped the plate (v_y {vy:.3f} m/s at t = {t1 * 1e3:.1f} ms, lowest y {lowest * 1e3:.2f} mm)")


def wls_plate_hole(cairn, source, out):
    # 2.5 mm cells (1.25 mm in the example): 4 cells across the hole's radius. The particles with
    # volume next to the hole against Kirsch's infinite-plate field at their reference positions.
    run(cairn, source, "wls_plate_hole_2d.toml", out, ["grid.cell_size=2.5e-3"])
    T, a, h = 1.0e5, 0.01, 2.5e-3
    path = sorted(glob.glob(os.path.join(out, "snapshots", "particles-*.h5")))[-1]
    with h5py.File(path, "r") as f:
        p = f["particles"]
        X = p["position"][:] - p["displacement"][:]
        s, volume = p["stress"][:] / T, p["volume"][:]  # stress: xx yy zz xy yz xz
    r, th = np.hypot(X[:, 0], X[:, 1]), np.arctan2(X[:, 1], X[:, 0])
    q, c2 = a * a / (r * r), np.cos(2 * th)
    srr = 0.5 * (1 - q) + 0.5 * (1 - 4 * q + 3 * q * q) * c2
    stt = 0.5 * (1 + q) - 0.5 * (1 + 3 * q * q) * c2
    srt = -0.5 * (1 + 2 * q - 3 * q * q) * np.sin(2 * th)
    c, sn = np.cos(th), np.sin(th)
    kirsch_xx = srr * c * c + stt * sn * sn - 2 * srt * sn * c
    far = X[:, 0] > 0.06
    check(abs(s[far, 0].mean() - 1.0) < 0.02, f"wls_plate_hole: far field sigma_xx {s[far, 0].mean():.3f} T (the traction T)")
    near = (r < a + 0.35 * h) & (volume > 0)
    top, side = near & (th > math.radians(80)), near & (th < math.radians(10))
    check(top.any() and abs(s[top, 0].mean() / kirsch_xx[top].mean() - 1) < 0.15,
          f"wls_plate_hole: at the hole's top sigma_xx {s[top, 0].mean():.3f} T, Kirsch {kirsch_xx[top].mean():.3f} T")
    check(side.any() and s[side, 1].mean() < -0.3,
          f"wls_plate_hole: at the hole's side sigma_yy {s[side, 1].mean():.3f} T (compressed; Kirsch -1 T at the hole)")


def wls_two_blocks(cairn, source, out):
    # As it is (about a second): the blocks as elastic bars touch at 4 mm / (2 v), stay in contact
    # for 2 L / c and press with rho c v H (per metre of thickness).
    run(cairn, source, "wls_two_blocks.toml", out, [])
    h = history(out)
    c, v, L, H, h_cell = math.sqrt(1.0e7 / 1500.0), 0.8165, 0.05, 0.02, 2.0e-3
    active = np.nonzero(h["contact_active"] > 0)[0]
    check(len(active) > 0, "wls_two_blocks: the blocks came into contact")
    first = active[0]
    after = np.nonzero(h["contact_active"][first:] == 0)[0]
    check(len(after) > 0, "wls_two_blocks: and left it")
    last = first + after[0]
    touch, duration = h["time"][first], h["time"][last] - h["time"][first]
    check(abs(touch - 0.004 / (2 * v)) < 0.1 * h_cell / (2 * v),
          f"wls_two_blocks: contact from {touch * 1e3:.3f} ms (the surfaces meet at {0.004 / (2 * v) * 1e3:.3f} ms)")
    check(abs(duration - 2 * L / c) < 0.1 * 2 * L / c,
          f"wls_two_blocks: in contact for {duration * 1e3:.3f} ms (2 L / c = {2 * L / c * 1e3:.3f} ms)")
    force = -h["contact_left_right_x"][first:last].mean()
    check(abs(force - 1500.0 * c * v * H) < 0.15 * 1500.0 * c * v * H,
          f"wls_two_blocks: mean contact force {force:.0f} N/m (rho c v H = {1500.0 * c * v * H:.0f} N/m)")
    _, end = snapshots(out)[-1]
    left, right = mean_velocity(end["left"], 0), mean_velocity(end["right"], 0)
    check(left < -0.8 * v and right > 0.8 * v, f"wls_two_blocks: the blocks leave at {left:.3f} and {right:.3f} m/s")


def tutorial(cairn, source, out):
    """docs/tutorial.md builds examples/disk_wall.toml block by block: its TOML blocks put
    together must resolve to the same input (the output folder aside)."""
    with open(os.path.join(source, "docs", "tutorial.md")) as f:
        blocks = re.findall(r"```toml\n(.*?)```", f.read(), re.S)
    os.makedirs(out)
    case = os.path.join(out, "disk.toml")
    with open(case, "w") as f:
        f.write("\n".join(blocks))

    def resolved(path):
        proc = subprocess.run([cairn, "check", path], capture_output=True, text=True, timeout=300)
        if proc.returncode != 0:
            raise CheckFailed(f"cairn check {path} exited with {proc.returncode}: {proc.stderr}")
        return [line for line in proc.stdout.splitlines()
                if not line.startswith(("directory = ", "# wall time estimate: "))]  # (a timing)

    check(resolved(case) == resolved(os.path.join(source, "examples", "disk_wall.toml")),
          f"tutorial: its {len(blocks)} TOML blocks make examples/disk_wall.toml")


def main():
    if len(sys.argv) < 3:
        print("usage: test_examples.py <cairn binary> <source dir>", file=sys.stderr)
        return 2
    cairn, source = sys.argv[1], sys.argv[2]
    with tempfile.TemporaryDirectory(prefix="cairn_examples_") as tmp:
        try:
            for case in (tutorial, disk_wall, falling_cube, taylor_bar, friction_block, meshed_projectile, plate_with_holes,
                         wls_plate_hole, wls_two_blocks):
                print(case.__name__)
                case(cairn, source, os.path.join(tmp, case.__name__))
        except CheckFailed as e:
            print(f"FAIL: {e}", file=sys.stderr)
            return 1
    print("ok: every example ran and shows what it promises")
    return 0


if __name__ == "__main__":
    sys.exit(main())
