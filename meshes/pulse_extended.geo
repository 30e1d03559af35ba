// Extended plate for the pulse problem (Shen & Chen 2005, Figs. 3-7): Lx = 150 mm (the 50 mm
// plate plus 100 mm to the right), Ly = 200 mm, origin at the
// bottom-left corner. Structured square quads of size h (transfinite + recombine).
//
// Physical groups (project convention: surfaces 1, 2, ...; curves 11 left, 12 right, 13 bottom,
// 14 top, 15+ others; no Physical Points):
//   surface 1  plate    the tungsten plate
//   curve  11  left     x = 0     (loaded side)
//   curve  12  right    x = Lx    (free end of the extension)
//   curve  13  bottom   y = 0
//   curve  14  top      y = Ly
//
// Mesh size: h (m), overridden by the case ("fem.size") through the ONELAB parameter
// "Parameters/h"; Lx / h and Ly / h are rounded to whole numbers of cells.
DefineConstant[ h = {0.001, Name "Parameters/h"} ];
Lx = 0.15;
Ly = 0.2;

Point(1) = {0, 0, 0};
Point(2) = {Lx, 0, 0};
Point(3) = {Lx, Ly, 0};
Point(4) = {0, Ly, 0};
Line(1) = {1, 2};  // bottom
Line(2) = {2, 3};  // right
Line(3) = {3, 4};  // top
Line(4) = {4, 1};  // left
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};

nx = Round(Lx / h);
ny = Round(Ly / h);
Transfinite Curve{1, 3} = nx + 1;
Transfinite Curve{2, 4} = ny + 1;
Transfinite Surface{1};
Recombine Surface{1};

Physical Surface("plate", 1) = {1};
Physical Curve("left", 11) = {4};
Physical Curve("right", 12) = {2};
Physical Curve("bottom", 13) = {1};
Physical Curve("top", 14) = {3};
