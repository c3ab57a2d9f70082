// Schaefer-Turek 2D-1 channel (2.2 x 0.41 m) around the cylinder (centre (0.2, 0.2), radius 0.05):
// an unstructured quad mesh graded from h_min at the cylinder to h_max 0.6 m away, extruded one
// cell thick (0.01 m) into hexahedra. Patches as the block meshes of scripts/make_cylinder_mesh.py:
// inlet, outlet, walls, cylinder, frontAndBack.
//
//   gmsh cylinder_graded.geo -3 -format msh41 -o cylinder_graded.msh                # ~1,700 cells
//   gmsh cylinder_graded.geo -3 -format msh41 -setnumber h_min 0.0045 -setnumber h_max 0.02 \
//        -o cylinder_graded_medium.msh                                              # ~6,700 cells
//
// The committed cylinder_graded.msh is the first (Gmsh 4.11, Debian bookworm): max non-orthogonality
// ~30 deg, skewness ~0.35.
SetFactory("OpenCASCADE");
DefineConstant[ h_min = 0.009, h_max = 0.04 ];
Rectangle(1) = {0, 0, 0, 2.2, 0.41};
Disk(2) = {0.2, 0.2, 0, 0.05, 0.05};
BooleanDifference(3) = { Surface{1}; Delete; }{ Surface{2}; Delete; };
Field[1] = Distance;
Field[1].CurvesList = {5};  // the circle
Field[1].NumPointsPerCurve = 200;
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = h_min;
Field[2].SizeMax = h_max;
Field[2].DistMin = 0.0;
Field[2].DistMax = 0.6;
Background Field = 2;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
Mesh.Algorithm = 6;              // Frontal-Delaunay
Mesh.RecombinationAlgorithm = 1;  // Blossom
Mesh.RecombineAll = 1;
out[] = Extrude {0, 0, 0.01} { Surface{3}; Layers{1}; Recombine; };
e = 1e-6;
Physical Surface("frontAndBack") = {3, out[0]};
Physical Surface("inlet") = Surface In BoundingBox{-e, -e, -e, e, 0.41 + e, 0.01 + e};
Physical Surface("outlet") = Surface In BoundingBox{2.2 - e, -e, -e, 2.2 + e, 0.41 + e, 0.01 + e};
Physical Surface("walls") = {Surface In BoundingBox{-e, -e, -e, 2.2 + e, e, 0.01 + e},
                             Surface In BoundingBox{-e, 0.41 - e, -e, 2.2 + e, 0.41 + e, 0.01 + e}};
Physical Surface("cylinder") = Surface In BoundingBox{0.15 - e, 0.15 - e, -e, 0.25 + e, 0.25 + e, 0.01 + e};
Physical Volume("fluid") = {out[1]};
