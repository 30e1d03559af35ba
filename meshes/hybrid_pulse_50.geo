// Far field of the pulse plate in the hybrid study (studies/hybrid): x in [10, 50] mm,
// y in [0, 200] mm; the particles fill x in [0, 10] mm next to the loaded side. Square
// transfinite quads of size h, nodes on the MPM grid (origin -2 mm, cell h).
//
// Physical groups (project convention; no Physical Points):
//   surface 1  plate
//   curve  11  left    x = 10 mm  (the interface with the particles; no load here)
//   curve  12  right   x = 50 mm
//   curve  13  bottom  y = 0
//   curve  14  top     y = 200 mm
// Default h is coarse (a quick look / the mesh test); the study cases set fem.size = 0.001.
DefineConstant[ h = {0.005, Name "Parameters/h"} ];
x0 = 0.01;
x1 = 0.050;
Ly = 0.2;
Point(1) = {x0, 0, 0};
Point(2) = {x1, 0, 0};
Point(3) = {x1, Ly, 0};
Point(4) = {x0, Ly, 0};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Transfinite Curve{1, 3} = Round((x1 - x0) / h) + 1;
Transfinite Curve{2, 4} = Round(Ly / h) + 1;
Transfinite Surface{1};
Recombine Surface{1};
Physical Surface("plate", 1) = {1};
Physical Curve("left", 11) = {4};
Physical Curve("right", 12) = {2};
Physical Curve("bottom", 13) = {1};
Physical Curve("top", 14) = {3};
