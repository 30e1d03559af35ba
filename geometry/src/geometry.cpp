// Queries on gmsh geometries read into plain arrays (areas, bounds, inside tests, lengths). The
// reading itself calls gmsh and lives in the gmsh module (gmsh/src/geometry_load.cpp), so that a
// process loads gmsh only when a case has a geometry.
#include "silentmpm/geometry.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

namespace smpm {

// ---------------------------------------------------------------------------------------------
// Geometry queries.

namespace {
template <class V>
int find_tag(const V& v, int tag) {
  for (std::size_t i = 0; i < v.size(); ++i)
    if (v[i].tag == tag) return static_cast<int>(i);
  return -1;
}
template <class V>
int find_name(const V& v, const std::string& name) {
  for (std::size_t i = 0; i < v.size(); ++i)
    if (!name.empty() && v[i].name == name) return static_cast<int>(i);
  return -1;
}
template <class V>
std::string list_groups(const V& v) {
  if (v.empty()) return "none";
  std::string s;
  for (std::size_t i = 0; i < v.size(); ++i) {
    s += (i ? ", " : "") + std::to_string(v[i].tag);
    if (!v[i].name.empty()) s += " \"" + v[i].name + "\"";
  }
  return s;
}
}  // namespace

int Geometry::find_surface(int tag) const { return find_tag(surfaces, tag); }
int Geometry::find_surface(const std::string& name) const { return find_name(surfaces, name); }
int Geometry::find_curve(int tag) const { return find_tag(curves, tag); }
int Geometry::find_curve(const std::string& name) const { return find_name(curves, name); }
std::string Geometry::list_surfaces() const { return list_groups(surfaces); }
std::string Geometry::list_curves() const { return list_groups(curves); }

std::string Geometry::num(double v) {
  std::ostringstream o;
  o.precision(6);
  o << v;
  return o.str();
}

std::string Geometry::label(const char* kind, int tag, const std::string& name) {
  return std::string(kind) + " " + std::to_string(tag) + (name.empty() ? "" : " \"" + name + "\"");
}

double Geometry::area(const Surface& s) const {
  double a = 0;
  for (const auto& e : s.elems) {
    const int n = e[3] < 0 ? 3 : 4;
    double twice = 0;  // shoelace
    for (int k = 0; k < n; ++k) {
      const int i = e[k], j = e[(k + 1) % n];
      twice += x[i] * y[j] - x[j] * y[i];
    }
    a += 0.5 * std::fabs(twice);
  }
  return a;
}

std::array<double, 4> Geometry::bounds(const Surface& s) const {
  std::array<double, 4> b = {HUGE_VAL, HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  for (const auto& e : s.elems)
    for (int k = 0; k < 4; ++k) {
      if (e[k] < 0) continue;
      b[0] = std::min(b[0], x[e[k]]);
      b[1] = std::min(b[1], y[e[k]]);
      b[2] = std::max(b[2], x[e[k]]);
      b[3] = std::max(b[3], y[e[k]]);
    }
  return b;
}

bool Geometry::contains(const Surface& s, double px, double py, double tol) const {
  auto seg_dist = [&](int a, int b) {
    const double ex = x[b] - x[a], ey = y[b] - y[a], L2 = ex * ex + ey * ey;
    const double t = L2 > 0 ? std::clamp(((px - x[a]) * ex + (py - y[a]) * ey) / L2, 0.0, 1.0) : 0.0;
    return std::hypot(px - (x[a] + t * ex), py - (y[a] + t * ey));
  };
  for (const auto& e : s.elems) {
    const int n = e[3] < 0 ? 3 : 4;
    // Inside a convex element: on the same side of every edge (either orientation).
    int pos = 0, neg = 0;
    double dmin = HUGE_VAL;
    for (int k = 0; k < n; ++k) {
      const int a = e[k], b = e[(k + 1) % n];
      const double cr = (x[b] - x[a]) * (py - y[a]) - (y[b] - y[a]) * (px - x[a]);
      pos += cr > 0;
      neg += cr < 0;
      dmin = std::min(dmin, seg_dist(a, b));
    }
    if (pos == 0 || neg == 0 || dmin <= tol) return true;
  }
  return false;
}

double Geometry::length(const Curve& c) const {
  double L = 0;
  for (const auto& s : c.segs) L += std::hypot(x[s[1]] - x[s[0]], y[s[1]] - y[s[0]]);
  return L;
}

}  // namespace smpm
