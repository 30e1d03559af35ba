// Convergence plates (Shen & Chen 2005, §4, Figs. 11-13; docs/physics.md §3.3): geometrically
// identical aluminium and steel plates side by side; the aluminium plate impacts at 10 m/s, the
// steel plate's right edge is silent, point D at the steel plate's centre. Plate size (not in the
// paper): 0.1 m x 0.1 m each, as in studies/convergence.
//
//   +-----------+-----------+ y = 0.1
//   | aluminium |   steel   |
//   |  [-0.1,0] |  [0, 0.1] |
//   +-----------+-----------+ y = 0
//
// Physical groups (project convention; no Physical Points):
//   surfaces  1 "aluminium"
//             2 "steel"
//   curves   11 "left"         aluminium, x = -0.1
//            12 "right"        steel, x = 0.1 (silent)
//            13 "bottom"       both plates, y = 0
//            14 "top"          both plates, y = 0.1
//            15 "al_contact"   aluminium, x = 0
//            16 "st_contact"   steel, x = 0
// Parameters: h mesh size (m); L plate size (m).
// The plates are separate surfaces (no shared points): two bodies in contact.
DefineConstant[ h = 0.005, L = 0.1 ];
Point(1) = {-L, 0, 0, h}; Point(2) = {0, 0, 0, h}; Point(3) = {0, L, 0, h}; Point(4) = {-L, L, 0, h};
Line(1) = {4, 1}; Line(2) = {2, 3}; Line(3) = {1, 2}; Line(4) = {3, 4};
Curve Loop(1) = {3, 2, 4, 1};
Plane Surface(1) = {1};
Point(11) = {0, 0, 0, h}; Point(12) = {L, 0, 0, h}; Point(13) = {L, L, 0, h}; Point(14) = {0, L, 0, h};
Line(11) = {14, 11}; Line(12) = {12, 13}; Line(13) = {11, 12}; Line(14) = {13, 14};
Curve Loop(2) = {13, 12, 14, 11};
Plane Surface(2) = {2};
Physical Surface("aluminium", 1) = {1};
Physical Surface("steel", 2) = {2};
Physical Curve("left", 11) = {1};
Physical Curve("right", 12) = {12};
Physical Curve("bottom", 13) = {3, 13};
Physical Curve("top", 14) = {4, 14};
Physical Curve("al_contact", 15) = {2};
Physical Curve("st_contact", 16) = {11};
