// A 40 x 40 mm square of 1 mm quadrilaterals (the command-line tests of the FE far field over
// MPI ranks).
DefineConstant[ h = {0.001, Name "Parameters/h"} ];
Point(1) = {0, 0, 0}; Point(2) = {0.04, 0, 0}; Point(3) = {0.04, 0.04, 0}; Point(4) = {0, 0.04, 0};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};
Transfinite Curve{1, 2, 3, 4} = Round(0.04 / h) + 1;
Transfinite Surface{1}; Recombine Surface{1};
Physical Surface("body", 1) = {1};
Physical Curve("bottom", 11) = {1}; Physical Curve("right", 12) = {2};
Physical Curve("top", 13) = {3}; Physical Curve("left", 14) = {4};
