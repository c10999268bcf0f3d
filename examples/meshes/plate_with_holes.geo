// A 2D plate with two holes for examples/plate_with_holes_2d.toml: the outline is read and
// meshed by Gmsh when Cairn loads the input (shape = { volume_mesh = { file = ... } }), and
// every triangle becomes one particle (docs/geometry.md). Lengths in metres.
SetFactory("OpenCASCADE");
Rectangle(1) = {0.01, 0.01, 0, 0.06, 0.04};
Disk(2) = {0.025, 0.03, 0, 0.008};
Disk(3) = {0.055, 0.03, 0, 0.008};
BooleanDifference{ Surface{1}; Delete; }{ Surface{2, 3}; Delete; }
Mesh.MeshSizeMax = 1.0e-3;
