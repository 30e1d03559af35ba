#pragma once
// gmsh source of an axis-aligned rectangle [x0, x1] x [y0, y1] with the project's group convention
// (physical surface 1 "body"; curves 11 left, 12 right, 13 bottom, 14 top) meshed by square
// transfinite quads of size h, the size a case's `size` overrides through
// DefineConstant "Parameters/h". Tests and studies write it to a file and load it like any .geo.
#include <cstdio>
#include <string>

namespace smpm::fem {

inline std::string box_geo_text(double x0, double y0, double x1, double y1, double h) {
  char buf[2048];
  std::snprintf(buf, sizeof buf,
                "DefineConstant[ h = {%.17g, Name \"Parameters/h\"} ];\n"
                "Point(1) = {%.17g, %.17g, 0}; Point(2) = {%.17g, %.17g, 0};\n"
                "Point(3) = {%.17g, %.17g, 0}; Point(4) = {%.17g, %.17g, 0};\n"
                "Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};\n"
                "Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};\n"
                "Transfinite Curve{1, 3} = Round(%.17g / h) + 1;\n"
                "Transfinite Curve{2, 4} = Round(%.17g / h) + 1;\n"
                "Transfinite Surface{1}; Recombine Surface{1};\n"
                "Physical Surface(\"body\", 1) = {1};\n"
                "Physical Curve(\"left\", 11) = {4}; Physical Curve(\"right\", 12) = {2};\n"
                "Physical Curve(\"bottom\", 13) = {1}; Physical Curve(\"top\", 14) = {3};\n",
                h, x0, y0, x1, y0, x1, y1, x0, y1, x1 - x0, y1 - y0);
  return buf;
}

}  // namespace smpm::fem
