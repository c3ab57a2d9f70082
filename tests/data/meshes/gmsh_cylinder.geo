// All-hex cylinder (radius 0.5, height 0.5): tetrahedra split into hexahedra by Gmsh's
// subdivision algorithm, so node and element layout is that of a genuinely unstructured mesh.
SetFactory("OpenCASCADE");
Cylinder(1) = {0, 0, 0, 0, 0, 0.5, 0.5};
Mesh.MeshSizeMin = 0.45;
Mesh.MeshSizeMax = 0.45;
Mesh.SubdivisionAlgorithm = 2;
Mesh.Algorithm = 6;
Physical Surface("wall") = {1};
Physical Surface("top") = {2};
Physical Surface("bottom") = {3};
Physical Volume("fluid") = {1};
