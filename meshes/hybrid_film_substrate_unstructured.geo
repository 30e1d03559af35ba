// Far field of the hybrid film cases (studies/hybrid) as an unstructured all-quad mesh whose size
// grows with depth: the silicon substrate x in [0, 10] um, y in [-10, top] um (the particles
// take the silicon above y = top, up to the film at 5 um). Below the interface y = top a band
// 1 um thick of square cells of size h sits on the MPM grid nodes (the hybrid's interface needs
// cells of one grid cell there); below it the cells grow linearly with depth, size
// h + grow (yb - y): about 0.1 um at the band, 1.35 um at the bottom for h = 0.1 um, grow = 0.1.
// 2 312 nodes against 3 535 for the structured grading of hybrid_film_substrate_coarse.geo
// (whose deep rows keep all 100 columns) and 13 231 for uniform squares. A growth of 0.2 moved
// the film probes by 0.5-1 % (studies/hybrid/README.md); 0.1 keeps them where the uniform
// mesh has them.
//
// Parameters: h (the case's fem.size), top (interface height, default 3.5 um: 1.5 um of
// particles under the film; hybrid_film_substrate_unstructured_1um.geo sets 4 um), grow, y0
// (bottom, default -10 um: the 15 um substrate; hybrid_film_substrate_unstructured_30um.geo
// sets -25 um).
//
// Physical groups (project convention; no Physical Points):
//   surface 1  substrate  (band + graded block)
//   curve  11  left    x = 0
//   curve  12  right   x = 10 um
//   curve  13  bottom  y = y0 (-10 um)
//   curve  14  top     y = top    (the interface with the particles)
DefineConstant[ h = {5e-7, Name "Parameters/h"} ];
DefineConstant[ top = {3.5e-6, Name "Parameters/top"} ];
DefineConstant[ grow = {0.1, Name "Parameters/grow"} ];
DefineConstant[ y0 = {-10e-6, Name "Parameters/bottom"} ];
L = 10e-6;
yb = top - 1e-6;
Point(1) = {0, y0, 0};
Point(2) = {L, y0, 0};
Point(3) = {L, yb, 0};
Point(4) = {0, yb, 0};
Point(5) = {L, top, 0};
Point(6) = {0, top, 0};
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
// Band: transfinite squares on the grid lattice.
Transfinite Curve{3, 6} = Round(L / h) + 1;
Transfinite Curve{5, 7} = Round((top - yb) / h) + 1;
Transfinite Surface{2};
// Block: size grows linearly below the band; Delaunay triangles recombined into quads (Blossom).
// (Meshing 0.08 s; MeshAdapt gives the same probes in 0.35 s, Frontal-Delaunay a 0.4 % larger
// difference at E, and Frontal-Delaunay for quads crashes gmsh 4.8 at micrometre lengths.)
Field[1] = MathEval;
Field[1].F = Sprintf("%g + %g * (%g - y)", h, grow, yb);
Background Field = 1;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.Algorithm = 5;
Mesh.RecombinationAlgorithm = 1;
Recombine Surface{1, 2};
Physical Surface("substrate", 1) = {1, 2};
Physical Curve("left", 11) = {4, 7};
Physical Curve("right", 12) = {2, 5};
Physical Curve("bottom", 13) = {1};
Physical Curve("top", 14) = {6};
