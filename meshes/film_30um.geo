// Tungsten film on a 30 um silicon substrate (studies/hybrid: the all-MPM reference for runs to
// 6.4 ns; the Si P-wave round trip through 30 um is 6.5 ns): film.geo with hs = 30 um.
//
// Physical groups: as film.geo
//   surfaces  1 "tungsten", 2 "silicon"
//   curves   11 "left", 12 "right", 13 "bottom" (y = -25 um), 14 "top", 15 "si_left",
//            16 "si_right", 17 "interface"
// Parameters: h mesh size (m).
DefineConstant[ h = 1e-7 ];
hs = 30e-6;
Include "film.geo";
