"""Write examples/meshes/projectile.stl, the meshed projectile of examples/meshed_projectile_3d.toml.

A cylinder of radius 3 mm and length 8 mm on a cone (nose) 4 mm long, axis along z, the nose's
tip at the origin pointing down (-z), as a closed ASCII STL in millimetres: n = 24 segments around
the axis, 4 n = 96 triangles, counter-clockwise seen from outside. Its polyhedral volume is
(n / 2) R^2 sin(2 pi / n) (8 + 4 / 3) mm^3 = 260.9 mm^3 (the regular 24-gon, not the circle).

Usage: python3 examples/meshes/make_projectile.py [OUTPUT.stl]
"""
import math
import os
import sys

N, R, NOSE, BODY = 24, 3.0, 4.0, 8.0


def triangles():
    ring = lambda z: [(R * math.cos(2 * math.pi * k / N), R * math.sin(2 * math.pi * k / N), z) for k in range(N)]
    tip, low, high, top = (0.0, 0.0, 0.0), ring(NOSE), ring(NOSE + BODY), (0.0, 0.0, NOSE + BODY)
    for k in range(N):
        j = (k + 1) % N
        yield tip, low[j], low[k]          # nose, facing down and out
        yield low[k], low[j], high[j]      # side
        yield low[k], high[j], high[k]
        yield top, high[k], high[j]        # top cap, facing up


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(os.path.abspath(__file__)), "projectile.stl")
    with open(out, "w") as f:
        f.write("solid projectile\n")
        for t in triangles():
            f.write(" facet normal 0 0 0\n  outer loop\n")
            for p in t:
                f.write("   vertex {:.9g} {:.9g} {:.9g}\n".format(*p))
            f.write("  endloop\n endfacet\n")
        f.write("endsolid projectile\n")


if __name__ == "__main__":
    main()
