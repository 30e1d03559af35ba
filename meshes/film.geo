// Tungsten film on a silicon substrate (Shen & Chen 2005, §5, Figs. 14-24; docs/physics.md §3.4):
// film L = 10 um long, ht = 2.5 um thick, on a substrate as wide as the film (assumption) and
// hs thick; the W-Si interface at y = 5 um, as in studies/film. film_5um.geo and film_15um.geo
// set hs.
//
//   y = 7.5 um  +--------------------+
//               |  tungsten (film)   |  <- both sides loaded (11, 12)
//   y = 5 um    +--------------------+  interface (17)
//               |  silicon           |
//   y = 5 - hs  +--------------------+  bottom (13): fixed or silent
//              x = 0              x = 10 um
//
// Physical groups (project convention; no Physical Points):
//   surfaces  1 "tungsten"
//             2 "silicon"
//   curves   11 "left"         tungsten, x = 0 (loaded)
//            12 "right"        tungsten, x = L (loaded)
//            13 "bottom"       silicon, y = 5 um - hs
//            14 "top"          tungsten, y = 7.5 um (free)
//            15 "si_left"      silicon, x = 0
//            16 "si_right"     silicon, x = L
//            17 "interface"    y = 5 um (shared by both surfaces)
// Parameters: h mesh size (m); hs substrate thickness (m).
DefineConstant[ h = 1e-7, hs = 5e-6 ];
L = 10e-6; ht = 2.5e-6; yi = 5e-6;
Point(1) = {0, yi - hs, 0, h}; Point(2) = {L, yi - hs, 0, h};
Point(3) = {L, yi, 0, h}; Point(4) = {0, yi, 0, h};
Point(5) = {L, yi + ht, 0, h}; Point(6) = {0, yi + ht, 0, h};
Line(1) = {1, 2};   // bottom
Line(2) = {2, 3};   // silicon right
Line(3) = {3, 4};   // interface
Line(4) = {4, 1};   // silicon left
Line(5) = {3, 5};   // tungsten right
Line(6) = {5, 6};   // top
Line(7) = {6, 4};   // tungsten left
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(2) = {1};
Curve Loop(2) = {-3, 5, 6, 7};
Plane Surface(1) = {2};
Physical Surface("tungsten", 1) = {1};
Physical Surface("silicon", 2) = {2};
Physical Curve("left", 11) = {7};
Physical Curve("right", 12) = {5};
Physical Curve("bottom", 13) = {1};
Physical Curve("top", 14) = {6};
Physical Curve("si_left", 15) = {4};
Physical Curve("si_right", 16) = {2};
Physical Curve("interface", 17) = {3};
