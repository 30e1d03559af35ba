// Plate with an inclined right edge (the silent edge of studies/geometry, 30 degrees case).
//
//   (0, H) +---------------+ (xb - H tan(theta), H)
//          |                \        the right edge has the outward normal
//          |                 \       (cos theta, sin theta): a plane P wave travelling in +x
//          |                  \      meets it at theta from its normal
//   (0, 0) +-------------------+ (xb, 0)
//
// Physical groups
//   surfaces  1 "plate"
//   curves   11 "left"      x = 0 (the loaded edge)
//            12 "right"     the inclined edge (silent)
//            13 "bottom"    y = 0
//            14 "top"       y = H
// Parameters (override with "geometry": {"size": ..., "parameters": {...}}):
//   h      mesh size (m)
//   theta  angle of the right edge's outward normal from +x (degrees), 0 <= theta < 90
//   H      height (m)
//   xb     x of the right edge at y = 0 (m), > H tan(theta)
DefineConstant[ h = 0.001, theta = 30, H = 0.16, xb = 0.16 ];
xt = xb - H * Tan(theta * Pi / 180);
If (xt <= 0)
  Error("inclined_edge.geo: xb = %g must exceed H tan(theta) = %g", xb, xb - xt);
EndIf
Point(1) = {0, 0, 0, h};
Point(2) = {xb, 0, 0, h};
Point(3) = {xt, H, 0, h};
Point(4) = {0, H, 0, h};
Line(1) = {4, 1};   // left
Line(2) = {2, 3};   // right (inclined)
Line(3) = {1, 2};   // bottom
Line(4) = {3, 4};   // top
Curve Loop(1) = {3, 2, 4, 1};
Plane Surface(1) = {1};
Physical Surface("plate", 1) = {1};
Physical Curve("left", 11) = {1};
Physical Curve("right", 12) = {2};
Physical Curve("bottom", 13) = {3};
Physical Curve("top", 14) = {4};
