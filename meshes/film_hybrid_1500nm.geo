// The particle region of the hybrid film cases (studies/hybrid): the tungsten film on the top
// 1.5 um of its silicon substrate (film.geo with hs = 1.5 um); the rest of the substrate is the
// FE far field hybrid_film_substrate_unstructured.geo, whose top (y = 3.5 um) is this bottom.
//
// Physical groups: as film.geo
//   surfaces  1 "tungsten", 2 "silicon"
//   curves   11 "left", 12 "right", 13 "bottom" (y = 3.5 um: the MPM-FEM interface), 14 "top",
//            15 "si_left", 16 "si_right", 17 "interface" (W-Si, y = 5 um)
// Parameters: h mesh size (m).
DefineConstant[ h = 1e-7 ];
hs = 1.5e-6;
Include "film.geo";
