#!/usr/bin/env python3
"""Write the seeds of cairn_fuzz_geometry (tests/robustness/fuzz_geometry.cpp): small valid files
of every format the geometry readers take, each as a tag line naming the format and the file's
bytes. The shapes are those of tests/geometry (a square in two triangles, the Kuhn cube in six
tetrahedra, a closed cube surface, point sets, an outline with a hole) and the projectile of
examples/meshes. Run with Debian's interpreter (h5py): /usr/bin/python3 make_seeds.py"""
import itertools
import pathlib
import struct

here = pathlib.Path(__file__).resolve().parent
root = here.parents[3]


def seed(name, tag, data):
    if isinstance(data, str):
        data = data.encode()
    (here / f"seed-{name}").write_bytes(tag.encode() + b"\n" + data)


# --- Gmsh ------------------------------------------------------------------------------------
square_nodes = [(0.2, 0.2, 0.0), (0.8, 0.2, 0.0), (0.8, 0.5, 0.0), (0.2, 0.5, 0.0)]
square_triangles = [(1, 2, 3), (1, 3, 4)]
cube_nodes = [(0.2 + 0.4 * i, 0.2 + 0.4 * j, 0.2 + 0.4 * k) for k in (0, 1) for j in (0, 1) for i in (0, 1)]


def node(i, j, k):
    return 1 + i + 2 * j + 4 * k


cube_tets = []
for p in itertools.permutations(range(3)):
    c = [0, 0, 0]
    t = [node(0, 0, 0)]
    for s in p:
        c[s] = 1
        t.append(node(*c))
    cube_tets.append(tuple(t))


def msh22(nodes, elements, kind):
    s = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n%d\n" % len(nodes)
    s += "".join("%d %r %r %r\n" % (i + 1, *x) for i, x in enumerate(nodes))
    s += "$EndNodes\n$Elements\n%d\n" % len(elements)
    s += "".join("%d %d 2 1 1 %s\n" % (e + 1, kind, " ".join(map(str, el))) for e, el in enumerate(elements))
    return s + "$EndElements\n"


def msh22_binary(nodes, elements, kind):
    b = b"$MeshFormat\n2.2 1 8\n" + struct.pack("<i", 1) + b"\n$EndMeshFormat\n"
    b += b"$Nodes\n%d\n" % len(nodes)
    b += b"".join(struct.pack("<i3d", i + 1, *x) for i, x in enumerate(nodes))
    b += b"\n$EndNodes\n$Elements\n%d\n" % len(elements)
    b += struct.pack("<3i", kind, len(elements), 2)  # type, count, tags
    b += b"".join(struct.pack("<%di" % (3 + len(el)), e + 1, 1, 1, *el) for e, el in enumerate(elements))
    return b + b"\n$EndElements\n"


def msh41(nodes, elements, kind, dim):
    n, m = len(nodes), len(elements)
    s = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n"
    s += "$Nodes\n1 %d 1 %d\n%d 1 0 %d\n" % (n, n, dim, n)
    s += "".join("%d\n" % (i + 1) for i in range(n))
    s += "".join("%r %r %r\n" % x for x in nodes)
    s += "$EndNodes\n$Elements\n1 %d 1 %d\n%d 1 %d %d\n" % (m, m, dim, kind, m)
    s += "".join("%d %s\n" % (e + 1, " ".join(map(str, el))) for e, el in enumerate(elements))
    return s + "$EndElements\n"


seed("msh2-square-v22.txt", "msh2", msh22(square_nodes, square_triangles, 2))
seed("msh2-square-v22-binary.bin", "msh2", msh22_binary(square_nodes, square_triangles, 2))
seed("msh2-square-v41.txt", "msh2", msh41(square_nodes, square_triangles, 2, 2))
seed("msh3-cube-v22.txt", "msh3", msh22(cube_nodes, cube_tets, 4))
seed("msh3-cube-v22-binary.bin", "msh3", msh22_binary(cube_nodes, cube_tets, 4))
seed("msh3-cube-v41.txt", "msh3", msh41(cube_nodes, cube_tets, 4, 3))

# --- surface meshes: the cube [0.2, 0.6]^3, outward ---------------------------------------------
v = [(0.2 + 0.4 * i, 0.2 + 0.4 * j, 0.2 + 0.4 * k) for k in (0, 1) for j in (0, 1) for i in (0, 1)]
quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
tris = [t for q in quads for t in ((q[0], q[1], q[2]), (q[0], q[2], q[3]))]


def normal(t):
    a, b, c = (v[i] for i in t)
    u = [b[k] - a[k] for k in range(3)]
    w = [c[k] - a[k] for k in range(3)]
    return (u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0])


stl = "solid cube\n"
for t in tris:
    stl += " facet normal %r %r %r\n  outer loop\n" % normal(t)
    stl += "".join("   vertex %r %r %r\n" % v[i] for i in t)
    stl += "  endloop\n endfacet\n"
seed("stl-cube-ascii.stl", "stl", stl + "endsolid cube\n")
binary = b"cube".ljust(80, b" ") + struct.pack("<I", len(tris))
for t in tris:
    binary += struct.pack("<12fH", *normal(t), *v[t[0]], *v[t[1]], *v[t[2]], 0)
seed("stl-cube-binary.stl", "stl", binary)
seed("stl-projectile.stl", "stl", (root / "examples/meshes/projectile.stl").read_bytes())
seed("obj-cube-quads.obj", "obj",
     "".join("v %r %r %r\n" % x for x in v) + "".join("f %d %d %d %d\n" % tuple(i + 1 for i in q) for q in quads))
seed("off-cube.off", "off",
     "OFF\n%d %d 0\n" % (len(v), len(tris)) + "".join("%r %r %r\n" % x for x in v)
     + "".join("3 %d %d %d\n" % t for t in tris))
head = "ply\nformat %s 1.0\nelement vertex %d\nproperty float x\nproperty float y\nproperty float z\n" \
       "element face %d\nproperty list uchar int vertex_indices\nend_header\n"
seed("ply-cube-ascii.ply", "ply",
     head % ("ascii", len(v), len(tris)) + "".join("%r %r %r\n" % x for x in v)
     + "".join("3 %d %d %d\n" % t for t in tris))
seed("ply-cube-binary.ply", "ply",
     (head % ("binary_little_endian", len(v), len(tris))).encode()
     + b"".join(struct.pack("<3f", *x) for x in v) + b"".join(struct.pack("<B3i", 3, *t) for t in tris))

# --- point files and outlines -------------------------------------------------------------------
seed("points2.csv", "points2", "# x, y, volume\nx, y, volume, vx, vy\n0.2, 0.3, 1e-4, 1.0, 0.0\n"
     "0.25, 0.3, 1e-4, 1.0, 0.0\n0.3, 0.35, 2e-4, 0.0, -1.5\n")
seed("points3.csv", "points3", "x, y, z, volume, temperature, sxx, syy, szz, syz, sxz, sxy\n"
     "0.2, 0.3, 0.4, 1e-6, 300, -1e5, 0, 0, 0, 0, 1e3\n0.3, 0.3, 0.4, 1e-6, 310, 0, 0, 0, 0, 0, 0\n")
seed("outline-hole.csv", "outline", "x, y\n0.1, 0.1\n0.9, 0.1\n0.9, 0.6\n0.1, 0.6\n0.1, 0.1\n\n"
     "# a hole\n0.3, 0.3\n0.4, 0.3\n0.35, 0.4\n")

# --- an HDF5 point file (with h5py, as Debian's /usr/bin/python3 has it) ------------------------
try:
    import io

    import h5py
    import numpy as np

    buffer = io.BytesIO()
    with h5py.File(buffer, "w") as f:
        f["position"] = np.array([[0.2, 0.3, 0.4], [0.3, 0.3, 0.4]])
        f["volume"] = np.array([1e-6, 2e-6])
        f["velocity"] = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0]])
        f["stress"] = np.zeros((2, 6))
    seed("points3.h5", "points3h5", buffer.getvalue())
except ImportError:
    print("no h5py: seed-points3.h5 not written")
