// Silicon substrate under the MPM film region of the hybrid film study (studies/hybrid): the part
// of the 15 um substrate below the 2 um of silicon kept as particles. x in [0, 10] um,
// y in [-10, 3] um (the film sits on y = 5 um; particles fill y in [3, 5] um).
// Square transfinite quads of size h, so that the nodes on the interface y = 3 um coincide with
// the MPM grid nodes (grid origin on a multiple of h).
//
// Physical groups (project convention; no Physical Points):
//   surface 1  substrate
//   curve  11  left    x = 0
//   curve  12  right   x = 10 um
//   curve  13  bottom  y = -10 um  (fixed: "extended"; or LK dashpot)
//   curve  14  top     y = 3 um    (the interface with the particles; no load here)
// Default h is coarse (a quick look / the mesh test); the study cases set fem.size = 1e-7.
DefineConstant[ h = {5e-7, Name "Parameters/h"} ];
L = 10e-6;
y0 = -10e-6;
y1 = 3e-6;
Point(1) = {0, y0, 0};
Point(2) = {L, y0, 0};
Point(3) = {L, y1, 0};
Point(4) = {0, y1, 0};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Transfinite Curve{1, 3} = Round(L / h) + 1;
Transfinite Curve{2, 4} = Round((y1 - y0) / h) + 1;
Transfinite Surface{1};
Recombine Surface{1};
Physical Surface("substrate", 1) = {1};
Physical Curve("left", 11) = {4};
Physical Curve("right", 12) = {2};
Physical Curve("bottom", 13) = {1};
Physical Curve("top", 14) = {3};
