// 4x2x2 hex box [0,1]x[0,0.5]x[0,0.25] by extrusion, sides as physical surfaces.
Point(1) = {0, 0, 0, 1};
Point(2) = {1, 0, 0, 1};
Line(1) = {1, 2};
Transfinite Curve{1} = 5;
e1[] = Extrude {0, 0.5, 0} { Curve{1}; Layers{2}; Recombine; };
e2[] = Extrude {0, 0, 0.25} { Surface{e1[1]}; Layers{2}; Recombine; };
eps = 1e-6;
Physical Surface("left") = Surface In BoundingBox{-eps, -eps, -eps, eps, 0.5 + eps, 0.25 + eps};
Physical Surface("right") = Surface In BoundingBox{1 - eps, -eps, -eps, 1 + eps, 0.5 + eps, 0.25 + eps};
Physical Surface("bottom") = Surface In BoundingBox{-eps, -eps, -eps, 1 + eps, eps, 0.25 + eps};
Physical Surface("top") = Surface In BoundingBox{-eps, 0.5 - eps, -eps, 1 + eps, 0.5 + eps, 0.25 + eps};
Physical Surface("back") = Surface In BoundingBox{-eps, -eps, -eps, 1 + eps, 0.5 + eps, eps};
Physical Surface("front") = Surface In BoundingBox{-eps, -eps, 0.25 - eps, 1 + eps, 0.5 + eps, 0.25 + eps};
Physical Volume("fluid") = {e2[1]};
