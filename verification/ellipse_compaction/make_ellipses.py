#!/usr/bin/python3
"""Draw the initial picture of the ellipse-compaction problem (seed 004 Sec. 4.2, Fig. 6A).

Twenty non-overlapping ellipses of random size and orientation are packed into a box of
aspect 1 x 2 (width x height) and drawn as an 8-bit greyscale PNG: background 255 (white, no
material), ellipse k (k = 1..20) in grey level 10 k, so that each ellipse becomes its own
[[body]] and material through Cairn's `image` body shape. The seed paper drew the picture at
280 x 560 pixels for a 1 x 2 mm box; --width sets the resolution (height = 2 width).

The packing is done in continuous box units (width 1, height 2), independent of --width, so
pictures at several resolutions show the same ellipses ("by rescaling the image, the problem was
discretized ... at various resolutions"):
  1. random sequential addition, largest first, of ellipses with random areas, aspect ratios
     and orientations (each shrunk by 10 % after 2000 failed placements);
  2. passes of inflation and jiggling: every ellipse tries random small moves and rotations,
     each followed by the largest uniform scaling (bisection) that keeps it valid, and keeps the
     largest; so neighbours end up nearly touching, as in Fig. 6A.
Valid means: at least --gap from every other ellipse and at least --wall-gap from the box walls
(so that no particle starts inside or against a wall). Pixels of different ellipses are then
never adjacent, not even diagonally, at any resolution whose pixel is smaller than the gap
(--gap 0.005 is 1.4 pixels at 280 x 560).

Outputs: the PNG (--png), the TOML fragment of the twenty [[body]] tables (printed, or written
to --toml), and optionally a CSV of the ellipse parameters (--csv). The bodies name materials
ellipse1 ... ellipse20, which the input must define. Deterministic for a given --seed.

The packing takes about 30 s; --ellipses CSV skips it and rasterizes the ellipses of a CSV written
earlier by --csv (ellipses.csv next to this script is the packing of --seed 4 with the default
--gap, --wall-gap, --passes and --tries; `--check-csv ellipses.csv` re-packs and verifies that it
reproduces that file).

Usage: make_ellipses.py [--width 280] [--seed 4] [--png ellipses.png] [--toml bodies.toml]
                        [--csv ellipses.csv] [--ellipses ellipses.csv] [--check-csv ellipses.csv]
                        [--box-width 1e-3] [--origin 0 0]
"""
from __future__ import annotations

import argparse
import math
import os
import struct
import sys
import zlib

import numpy as np

N_ELLIPSES = 20
BOX_W, BOX_H = 1.0, 2.0  # box units: the picture's width is 1


# ---- PNG writing (8-bit greyscale, no dependencies beyond zlib) -----------------------------

def write_png_grey(path: str, levels: np.ndarray) -> None:
    """levels: (height, width) uint8, row 0 = top of the picture."""
    height, width = levels.shape

    def chunk(kind: bytes, data: bytes) -> bytes:
        return (struct.pack(">I", len(data)) + kind + data +
                struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))

    rows = b"".join(b"\x00" + levels[r].astype(np.uint8).tobytes() for r in range(height))
    ihdr = struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0)  # 8-bit grey, no interlace
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n")
        f.write(chunk(b"IHDR", ihdr))
        f.write(chunk(b"IDAT", zlib.compress(rows, 9)))
        f.write(chunk(b"IEND", b""))


# ---- ellipse geometry (box units) ----------------------------------------------------------

class Ellipse:
    __slots__ = ("cx", "cy", "a", "b", "theta")

    def __init__(self, cx, cy, a, b, theta):
        self.cx, self.cy, self.a, self.b, self.theta = cx, cy, a, b, theta

    def scaled(self, s):
        return Ellipse(self.cx, self.cy, self.a * s, self.b * s, self.theta)

    def area(self):
        return math.pi * self.a * self.b

    def half_extents(self):
        c, s = math.cos(self.theta), math.sin(self.theta)
        return (math.sqrt((self.a * c) ** 2 + (self.b * s) ** 2),
                math.sqrt((self.a * s) ** 2 + (self.b * c) ** 2))

    def to_local(self, x, y):
        """Coordinates of points (x, y) in the ellipse's frame (major axis along u)."""
        c, s = math.cos(self.theta), math.sin(self.theta)
        dx, dy = x - self.cx, y - self.cy
        return c * dx + s * dy, -s * dx + c * dy

    def inside(self, x, y):
        u, v = self.to_local(x, y)
        return (u / self.a) ** 2 + (v / self.b) ** 2 <= 1.0

    def boundary(self, spacing):
        """Points on the boundary, at most `spacing` apart."""
        n = max(16, int(math.ceil(2.0 * math.pi * self.a / spacing)))
        t = np.linspace(0.0, 2.0 * math.pi, n, endpoint=False)
        u, v = self.a * np.cos(t), self.b * np.sin(t)
        c, s = math.cos(self.theta), math.sin(self.theta)
        return self.cx + c * u - s * v, self.cy + s * u + c * v


def distance_outside(e: Ellipse, x, y):
    """Distance from points outside ellipse e to it (Eberly: bisection on the Lagrange root)."""
    u, v = e.to_local(x, y)
    u, v = np.abs(u), np.abs(v)
    a2, b2 = e.a * e.a, e.b * e.b
    lo = np.zeros_like(u)
    hi = np.sqrt(a2 * u * u + b2 * v * v)
    for _ in range(48):
        t = 0.5 * (lo + hi)
        f = (e.a * u / (t + a2)) ** 2 + (e.b * v / (t + b2)) ** 2 - 1.0
        lo = np.where(f > 0.0, t, lo)
        hi = np.where(f > 0.0, hi, t)
    t = 0.5 * (lo + hi)
    return np.hypot(u - a2 * u / (t + a2), v - b2 * v / (t + b2))


def valid(e: Ellipse, others, gap: float, wall_gap: float) -> bool:
    hx, hy = e.half_extents()
    if e.cx - hx < wall_gap or e.cx + hx > BOX_W - wall_gap:
        return False
    if e.cy - hy < wall_gap or e.cy + hy > BOX_H - wall_gap:
        return False
    bx = by = None
    for o in others:
        d = math.hypot(e.cx - o.cx, e.cy - o.cy)
        if d >= e.a + o.a + gap:
            continue  # circumscribed discs apart
        if d < e.b + o.b + gap:
            return False  # inscribed discs closer than the gap
        if e.inside(o.cx, o.cy) or o.inside(e.cx, e.cy):
            return False
        if bx is None:
            bx, by = e.boundary(gap)  # spacing <= gap: a crossing is never missed
        u, v = o.to_local(bx, by)
        if np.any((u / o.a) ** 2 + (v / o.b) ** 2 <= 1.0):
            return False
        if distance_outside(o, bx, by).min() < gap:
            return False
    return True


def max_scale(e: Ellipse, others, gap, wall_gap, cap) -> float:
    """Largest s in [1, cap] (to 1e-4) with e scaled by s valid; e itself must be valid."""
    if valid(e.scaled(cap), others, gap, wall_gap):
        return cap
    lo, hi = 1.0, cap
    while hi - lo > 1e-4:
        mid = 0.5 * (lo + hi)
        if valid(e.scaled(mid), others, gap, wall_gap):
            lo = mid
        else:
            hi = mid
    return lo


def pack(rng: np.random.Generator, gap: float, wall_gap: float, passes: int, tries: int):
    # Random areas (mean such that the first placement fills 40 % of the box) and aspect ratios.
    mean_area = 0.40 * BOX_W * BOX_H / N_ELLIPSES
    areas = np.sort(mean_area * rng.uniform(0.5, 1.5, N_ELLIPSES))[::-1]
    aspects = rng.uniform(1.2, 2.2, N_ELLIPSES)
    max_area = 2.5 * mean_area  # inflation cap: keeps the sizes varied
    placed: list[Ellipse] = []
    for area, r in zip(areas, aspects):
        a, b = math.sqrt(area * r / math.pi), math.sqrt(area / (r * math.pi))
        while True:
            done = False
            for _ in range(2000):
                e = Ellipse(rng.uniform(0.0, BOX_W), rng.uniform(0.0, BOX_H), a, b,
                            rng.uniform(0.0, math.pi))
                if valid(e, placed, gap, wall_gap):
                    placed.append(e)
                    done = True
                    break
            if done:
                break
            a, b = 0.9 * a, 0.9 * b
    for p in range(passes):
        step = 0.05 * (1.0 - p / passes) + 0.005
        for i in rng.permutation(N_ELLIPSES):
            others = placed[:i] + placed[i + 1:]
            best = placed[i]
            cap = math.sqrt(max_area / best.area())
            best = best.scaled(max_scale(best, others, gap, wall_gap, max(cap, 1.0)))
            for _ in range(tries):
                # Moved and turned at its size shrunk by 10 %, then inflated as far as it goes.
                e = Ellipse(best.cx + rng.normal(0.0, step), best.cy + rng.normal(0.0, step),
                            0.9 * best.a, 0.9 * best.b, best.theta + rng.normal(0.0, 0.2))
                if not valid(e, others, gap, wall_gap):
                    continue
                cap = math.sqrt(max_area / e.area())
                if cap <= 1.0:
                    continue
                e = e.scaled(max_scale(e, others, gap, wall_gap, cap))
                if e.area() > best.area():
                    best = e
            placed[i] = best
    # Number them from the top left, row by row, for readable pictures.
    placed.sort(key=lambda e: (-round(e.cy / 0.25), e.cx))
    return placed


def read_csv(path: str):
    """The ellipses of a CSV written by --csv, in its order (k = 1..20)."""
    rows = np.genfromtxt(path, delimiter=",", names=True)
    if len(rows) != N_ELLIPSES:
        raise SystemExit(f"make_ellipses: {path}: {len(rows)} ellipses, expected {N_ELLIPSES}")
    return [Ellipse(float(r["center_x"]), float(r["center_y"]), float(r["semi_major"]),
                    float(r["semi_minor"]), float(r["angle_rad"])) for r in rows]


def rasterize(ellipses, width: int) -> np.ndarray:
    height = 2 * width
    s = BOX_W / width
    x = (np.arange(width) + 0.5) * s
    y = BOX_H - (np.arange(height) + 0.5) * s  # row 0 = top of the picture
    X, Y = np.meshgrid(x, y)
    levels = np.full((height, width), 255, dtype=np.uint8)
    for k, e in enumerate(ellipses, start=1):
        inside = e.inside(X, Y)
        if np.any(levels[inside] != 255):
            raise SystemExit("make_ellipses: internal error: ellipses overlap")
        levels[inside] = 10 * k
    return levels


def check_picture(levels: np.ndarray) -> None:
    """Every ellipse present; pixels of different ellipses never 8-adjacent; walls clear."""
    h, w = levels.shape
    for k in range(1, N_ELLIPSES + 1):
        if not np.any(levels == 10 * k):
            raise SystemExit(f"make_ellipses: ellipse {k} has no pixel at width {w}")
    if np.any(levels[0] != 255) or np.any(levels[-1] != 255) or \
            np.any(levels[:, 0] != 255) or np.any(levels[:, -1] != 255):
        raise SystemExit("make_ellipses: an ellipse touches the border of the picture")
    for dr, dc in ((0, 1), (1, 0), (1, 1), (1, -1)):  # each neighbour pair once
        a = levels[0:h - dr, max(0, -dc):w - max(0, dc)]
        b = levels[dr:h, max(0, dc):w - max(0, -dc)]
        touching = (a != 255) & (b != 255) & (a != b)
        if np.any(touching):
            raise SystemExit("make_ellipses: two ellipses share an edge or corner of a pixel")


def toml_fragment(png_name: str, pixel_size: float, origin, width: int, args) -> str:
    lines = [
        f"# {N_ELLIPSES} ellipses of {png_name} ({width} x {2 * width} pixels), one body and one",
        f"# material each; generated by make_ellipses.py --seed {args.seed} --width {width}.",
        "# The input must define [[material]] tables named ellipse1 ... ellipse20.",
    ]
    for k in range(1, N_ELLIPSES + 1):
        lines += [
            "",
            "[[body]]",
            f'name = "ellipse{k}"',
            f'material = "ellipse{k}"',
            f'shape = {{ image = {{ file = "{png_name}", pixel_size = {pixel_size!r}, '
            f'origin = [{origin[0]!r}, {origin[1]!r}], levels = [{10 * k}, {10 * k}] }} }}',
        ]
    return "\n".join(lines) + "\n"


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--width", type=int, default=280, help="picture width in pixels; height = 2 width (default 280)")
    p.add_argument("--seed", type=int, default=4, help="random seed (default 4)")
    p.add_argument("--png", default="ellipses.png", help="output picture (default ellipses.png)")
    p.add_argument("--toml", default=None, help="write the [[body]] tables here (default: print them)")
    p.add_argument("--csv", default=None, help="also write k, level, centre, semi-axes, angle (box units)")
    p.add_argument("--box-width", type=float, default=1.0e-3,
                   help="physical width of the box in length units (default 1e-3: 1 mm in metres)")
    p.add_argument("--origin", type=float, nargs=2, default=[0.0, 0.0],
                   help="physical position of the box's lower-left corner (default 0 0)")
    p.add_argument("--gap", type=float, default=0.005,
                   help="least distance between ellipses, in box widths (default 0.005)")
    p.add_argument("--wall-gap", type=float, default=0.01,
                   help="least distance from an ellipse to a box wall, in box widths (default 0.01)")
    p.add_argument("--ellipses", default=None,
                   help="read the ellipses from this CSV (as written by --csv) instead of packing them")
    p.add_argument("--check-csv", default=None,
                   help="pack, then exit 1 unless the packing equals the ellipses of this CSV")
    p.add_argument("--passes", type=int, default=12, help="inflation passes (default 12)")
    p.add_argument("--tries", type=int, default=12, help="moves tried per ellipse and pass (default 12)")
    args = p.parse_args()
    if args.width < 20:
        p.error("--width must be at least 20")
    if args.gap * args.width < 1.0:
        print(f"make_ellipses: warning: --gap {args.gap} is under one pixel at width {args.width}; "
              "pixels of neighbouring ellipses may touch", file=sys.stderr)

    if args.ellipses:
        ellipses = read_csv(args.ellipses)
    else:
        rng = np.random.default_rng(args.seed)
        ellipses = pack(rng, args.gap, args.wall_gap, args.passes, args.tries)
    if args.check_csv:
        ref = read_csv(args.check_csv)
        same = len(ref) == len(ellipses) and all(
            max(abs(a.cx - b.cx), abs(a.cy - b.cy), abs(a.a - b.a), abs(a.b - b.b),
                abs((a.theta - b.theta + 0.5 * math.pi) % math.pi - 0.5 * math.pi)) < 1e-12
            for a, b in zip(ref, ellipses))
        print(f"make_ellipses: packing {'reproduces' if same else 'DIFFERS FROM'} {args.check_csv}",
              file=sys.stderr)
        if not same:
            return 1
    levels = rasterize(ellipses, args.width)
    if args.gap * args.width >= 1.0:
        check_picture(levels)
    write_png_grey(args.png, levels)

    pixel_size = args.box_width / args.width
    fill = sum(e.area() for e in ellipses) / (BOX_W * BOX_H)
    pixel_fill = float(np.mean(levels != 255))
    print(f"make_ellipses: {args.png}: {args.width} x {2 * args.width} pixels, pixel_size "
          f"{pixel_size!r}, {N_ELLIPSES} ellipses filling {fill:.3f} of the box "
          f"({pixel_fill:.3f} of the pixels)", file=sys.stderr)

    if args.csv:
        with open(args.csv, "w") as f:
            f.write("k,level,center_x,center_y,semi_major,semi_minor,angle_rad\n")
            for k, e in enumerate(ellipses, start=1):
                f.write(f"{k},{10 * k},{e.cx!r},{e.cy!r},{e.a!r},{e.b!r},{e.theta % math.pi!r}\n")

    if args.toml:
        png_name = os.path.relpath(os.path.abspath(args.png), os.path.dirname(os.path.abspath(args.toml)))
        with open(args.toml, "w") as f:
            f.write(toml_fragment(png_name, pixel_size, args.origin, args.width, args))
    else:
        sys.stdout.write(toml_fragment(os.path.basename(args.png), pixel_size, args.origin, args.width, args))
    return 0


if __name__ == "__main__":
    sys.exit(main())
