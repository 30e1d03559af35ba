// Oblique impact (Shen & Chen 2005, §4, Figs. 8-10; docs/physics.md §3.2): a smaller aluminium
// plate (the flyer) strikes the left edge of a steel plate (the target) off-centre, so that the
// waves reach the target's right side obliquely. The geometry of studies/impact/cases:
//
//                  y = 0.1  +------------------------------+
//   flyer  [-0.02, 0] x     |                              |
//          [0.06, 0.09] +---+                              |
//                       |   |          target              | <- right side x = Lt
//                       +---+          [0, Lt] x [0, 0.1]  |    (free / silent)
//                           |                              |
//                  y = 0    +------------------------------+
//
// Physical groups (project convention; no Physical Points):
//   surfaces  1 "aluminium"     the flyer
//             2 "steel"         the target
//   curves   11 "left"          target, x = 0 (struck edge)
//            12 "right"         target, x = Lt (free / silent side)
//            13 "bottom"        target, y = 0
//            14 "top"           target, y = 0.1
//            15 "flyer_left"    flyer, x = -0.02
//            16 "flyer_right"   flyer, x = 0 (contact face)
//            17 "flyer_bottom"  flyer, y = 0.06
//            18 "flyer_top"     flyer, y = 0.09
// Parameters: h mesh size (m); Lt target length (m): 0.1 here, 0.3 in impact_extended.geo.
// The two plates are separate surfaces (no shared points): two bodies in contact.
DefineConstant[ h = 0.0005, Lt = 0.1 ];
// target
Point(1) = {0, 0, 0, h}; Point(2) = {Lt, 0, 0, h}; Point(3) = {Lt, 0.1, 0, h}; Point(4) = {0, 0.1, 0, h};
Line(1) = {4, 1}; Line(2) = {2, 3}; Line(3) = {1, 2}; Line(4) = {3, 4};
Curve Loop(1) = {3, 2, 4, 1};
Plane Surface(2) = {1};
// flyer
Point(11) = {-0.02, 0.06, 0, h}; Point(12) = {0, 0.06, 0, h};
Point(13) = {0, 0.09, 0, h}; Point(14) = {-0.02, 0.09, 0, h};
Line(11) = {14, 11}; Line(12) = {12, 13}; Line(13) = {11, 12}; Line(14) = {13, 14};
Curve Loop(2) = {13, 12, 14, 11};
Plane Surface(1) = {2};
Physical Surface("aluminium", 1) = {1};
Physical Surface("steel", 2) = {2};
Physical Curve("left", 11) = {1};
Physical Curve("right", 12) = {2};
Physical Curve("bottom", 13) = {3};
Physical Curve("top", 14) = {4};
Physical Curve("flyer_left", 15) = {11};
Physical Curve("flyer_right", 16) = {12};
Physical Curve("flyer_bottom", 17) = {13};
Physical Curve("flyer_top", 18) = {14};
