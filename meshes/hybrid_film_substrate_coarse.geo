// Coarser graded variant of hybrid_film_substrate.geo (studies/hybrid): the substrate x in
// [0, 10] um, y in [-10, 3] um, square cells of size h in the band y in [2, 3] um next to the
// particles, and 24 rows growing geometrically (ratio 1.1, about 0.14 um to 1.2 um) below it
// (hybrid_film_substrate_graded.geo: 40 rows, ratio 1.05). Same columns everywhere (conforming,
// no hanging nodes): 3535 nodes against 13 231 for uniform squares. The interface y = 3 um has
// square cells of size h on the MPM grid nodes, as the hybrid requires. A ratio of 1.15 moved
// the film probes by 2 % (studies/hybrid/README.md); 1.1 keeps them within the uniform mesh's.
//
// Physical groups (project convention; no Physical Points):
//   surface 1  substrate  (band + graded block)
//   curve  11  left    x = 0
//   curve  12  right   x = 10 um
//   curve  13  bottom  y = -10 um
//   curve  14  top     y = 3 um    (the interface with the particles)
// Default h is coarse (a quick look / the mesh test); the study cases set fem.size = 1e-7.
DefineConstant[ h = {5e-7, Name "Parameters/h"} ];
L = 10e-6;
y0 = -10e-6;
yb = 2e-6;
y1 = 3e-6;
nrows = 24;    // graded rows in [y0, yb]
ratio = 1.1;   // size ratio of consecutive graded rows (the top one is about 1.4 h)
Point(1) = {0, y0, 0};
Point(2) = {L, y0, 0};
Point(3) = {L, yb, 0};
Point(4) = {0, yb, 0};
Point(5) = {L, y1, 0};
Point(6) = {0, y1, 0};
Line(1) = {1, 2};   // bottom
Line(2) = {2, 3};   // right, graded block (upwards)
Line(3) = {3, 4};   // band / block boundary
Line(4) = {4, 1};   // left, graded block (downwards)
Line(5) = {3, 5};   // right, band
Line(6) = {5, 6};   // top (interface)
Line(7) = {6, 4};   // left, band
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Curve Loop(2) = {-3, 5, 6, 7};
Plane Surface(2) = {2};
Transfinite Curve{1, 3, 6} = Round(L / h) + 1;
Transfinite Curve{5, 7} = Round((y1 - yb) / h) + 1;
Transfinite Curve{2} = nrows + 1 Using Progression 1 / ratio;
Transfinite Curve{4} = nrows + 1 Using Progression ratio;
Transfinite Surface{1, 2};
Recombine Surface{1, 2};
Physical Surface("substrate", 1) = {1, 2};
Physical Curve("left", 11) = {4, 7};
Physical Curve("right", 12) = {2, 5};
Physical Curve("bottom", 13) = {1};
Physical Curve("top", 14) = {6};
