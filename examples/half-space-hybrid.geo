// The far field of the hybrid half-space (examples/half-space-hybrid.json): the half-space of
// examples/half-space-fem.geo, [x0, x1] x [y0, 0.1] m in squares of h, without the MPM window
// [a, b] x [c, 0.1] around the line load. Three transfinite blocks: left of the window, under
// it, right of it. The window's three sides are the interface with the particles.
DefineConstant[ h = {0.002, Name "Parameters/h"} ];
DefineConstant[ x0 = {0, Name "Parameters/x0"}, x1 = {0.2, Name "Parameters/x1"},
                y0 = {0, Name "Parameters/y0"} ];
DefineConstant[ a = {0.07, Name "Parameters/a"}, b = {0.13, Name "Parameters/b"},
                c = {0.07, Name "Parameters/c"} ];
Point(1) = {x0, y0, 0}; Point(2) = {a, y0, 0}; Point(3) = {b, y0, 0}; Point(4) = {x1, y0, 0};
Point(5) = {x1, 0.1, 0}; Point(6) = {b, 0.1, 0}; Point(7) = {b, c, 0}; Point(8) = {a, c, 0};
Point(9) = {a, 0.1, 0}; Point(10) = {x0, 0.1, 0};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 5}; Line(5) = {5, 6};
Line(6) = {6, 7}; Line(7) = {7, 3}; Line(8) = {7, 8}; Line(9) = {8, 2}; Line(10) = {8, 9};
Line(11) = {9, 10}; Line(12) = {10, 1};
Curve Loop(1) = {1, -9, 10, 11, 12}; Plane Surface(1) = {1};
Curve Loop(2) = {2, -7, 8, 9}; Plane Surface(2) = {2};
Curve Loop(3) = {3, 4, 5, 6, 7}; Plane Surface(3) = {3};
Transfinite Curve{1, 11} = Round((a - x0) / h) + 1;
Transfinite Curve{2, 8} = Round((b - a) / h) + 1;
Transfinite Curve{3, 5} = Round((x1 - b) / h) + 1;
Transfinite Curve{4, 12} = Round((0.1 - y0) / h) + 1;
Transfinite Curve{6, 10} = Round((0.1 - c) / h) + 1;
Transfinite Curve{7, 9} = Round((c - y0) / h) + 1;
Transfinite Surface{1} = {1, 2, 9, 10}; Transfinite Surface{2} = {2, 3, 7, 8};
Transfinite Surface{3} = {3, 4, 5, 6};
Recombine Surface{1, 2, 3};
Physical Surface("ground", 1) = {1, 2, 3};
Physical Curve("bottom", 11) = {1, 2, 3}; Physical Curve("right", 12) = {4};
Physical Curve("top", 13) = {5, 11}; Physical Curve("left", 15) = {12};
Physical Curve("interface", 16) = {6, 8, 10};
