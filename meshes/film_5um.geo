// Tungsten film on a 5 um silicon substrate (fixed or silent bottom): film.geo with hs = 5 um.
//
// Physical groups: as film.geo
//   surfaces  1 "tungsten", 2 "silicon"
//   curves   11 "left", 12 "right", 13 "bottom" (y = 0), 14 "top", 15 "si_left",
//            16 "si_right", 17 "interface"
// Parameters: h mesh size (m).
DefineConstant[ h = 1e-7 ];
hs = 5e-6;
Include "film.geo";
