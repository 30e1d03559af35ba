// Oblique impact, extended target (the reference run of studies/impact): as impact.geo with the
// steel plate 0.3 m long, so that nothing returns from its right side in the study's window.
//
// Physical groups: the same as impact.geo
//   surfaces  1 "aluminium", 2 "steel"
//   curves   11 "left", 12 "right" (x = 0.3), 13 "bottom", 14 "top", 15 "flyer_left",
//            16 "flyer_right", 17 "flyer_bottom", 18 "flyer_top"
// Parameters: h mesh size (m).
DefineConstant[ h = 0.0005 ];
Lt = 0.3;
Include "impact.geo";
