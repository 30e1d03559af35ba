// The half-space of examples/half-space.json as Q1 elements: [x0, x1] x [y0, 0.1] m in squares
// of h, its top free but for the line load on [0.098, 0.102]. x0, x1 and y0 are parameters, so
// that one file gives the window and a wider, deeper domain (fem.parameters).
DefineConstant[ h = {0.002, Name "Parameters/h"} ];
DefineConstant[ x0 = {0, Name "Parameters/x0"}, x1 = {0.2, Name "Parameters/x1"},
                y0 = {0, Name "Parameters/y0"} ];
Point(1) = {x0, y0, 0}; Point(2) = {x1, y0, 0}; Point(3) = {x1, 0.1, 0};
Point(4) = {0.102, 0.1, 0}; Point(5) = {0.098, 0.1, 0}; Point(6) = {x0, 0.1, 0};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 5}; Line(5) = {5, 6};
Line(6) = {6, 1};
Curve Loop(1) = {1, 2, 3, 4, 5, 6}; Plane Surface(1) = {1};
Transfinite Curve{1} = Round((x1 - x0) / h) + 1;
Transfinite Curve{2, 6} = Round((0.1 - y0) / h) + 1;
Transfinite Curve{3} = Round((x1 - 0.102) / h) + 1;
Transfinite Curve{4} = Round(0.004 / h) + 1;
Transfinite Curve{5} = Round((0.098 - x0) / h) + 1;
Transfinite Surface{1} = {1, 2, 3, 6}; Recombine Surface{1};
Physical Surface("ground", 1) = {1};
Physical Curve("bottom", 11) = {1}; Physical Curve("right", 12) = {2};
Physical Curve("top", 13) = {3, 5}; Physical Curve("load", 14) = {4};
Physical Curve("left", 15) = {6};
