// Circular body radiating into a silent ring (studies/geometry): an aluminium annulus whose hole
// is loaded by a pressure pulse; its outer circle is free or silent.
//
//            outer circle r = R (16 "rim": free / silent)
//         .-''''-.
//       /   .--.   \      hole r = a (15 "hole": pressure pulse)
//      |   (  o  )  |     centre (0, 0)
//       \   '--'   /
//         '-....-'
//
// Physical groups (project convention; the ring has no left/right/bottom/top, so 11-14 are
// unused; no Physical Points):
//   surfaces  1 "aluminium"
//   curves   15 "hole"          r = a
//            16 "rim"           r = R
//            17 "probe_circle"  r = rp, only when rp > 0: a circle embedded in the surface (for a
//                               probe along it; it does not change the body)
// Parameters: h mesh size (m); a hole radius (m); R outer radius (m); rp radius of the probe
// circle (m), a < rp < R, or 0 for none. All circles run counter-clockwise from the +x axis.
DefineConstant[ h = 0.0005, a = 0.01, R = 0.05, rp = 0 ];
Point(1) = {0, 0, 0, h};
Point(2) = {R, 0, 0, h}; Point(3) = {0, R, 0, h}; Point(4) = {-R, 0, 0, h}; Point(5) = {0, -R, 0, h};
Point(6) = {a, 0, 0, h}; Point(7) = {0, a, 0, h}; Point(8) = {-a, 0, 0, h}; Point(9) = {0, -a, 0, h};
Circle(1) = {2, 1, 3}; Circle(2) = {3, 1, 4}; Circle(3) = {4, 1, 5}; Circle(4) = {5, 1, 2};
Circle(5) = {6, 1, 7}; Circle(6) = {7, 1, 8}; Circle(7) = {8, 1, 9}; Circle(8) = {9, 1, 6};
Curve Loop(1) = {1, 2, 3, 4};
Curve Loop(2) = {5, 6, 7, 8};
Plane Surface(1) = {1, 2};
Physical Surface("aluminium", 1) = {1};
Physical Curve("hole", 15) = {5, 6, 7, 8};
Physical Curve("rim", 16) = {1, 2, 3, 4};
If (rp > 0)
  Point(10) = {rp, 0, 0, h}; Point(11) = {0, rp, 0, h}; Point(12) = {-rp, 0, 0, h}; Point(13) = {0, -rp, 0, h};
  Circle(9) = {10, 1, 11}; Circle(10) = {11, 1, 12}; Circle(11) = {12, 1, 13}; Circle(12) = {13, 1, 10};
  Curve{9, 10, 11, 12} In Surface{1};
  Physical Curve("probe_circle", 17) = {9, 10, 11, 12};
EndIf
