// Probes along a physical curve: points evenly spaced by arc length (geometry.hpp, curve_points).
// The curve's line segments are chained into one path; each segment is taken as the circular arc
// through its two end nodes and the CAD point over its middle (Geometry::Curve::mid), so that
// points on straight lines and on circles are exact, and arc lengths on a circle are the true
// ones rather than those of the inscribed polygon.
#include <algorithm>
#include <cmath>
#include <sstream>
#include <unordered_map>

#include "silentmpm/geometry.hpp"

namespace smpm {
namespace {


// One segment of the chain, oriented along it.
struct Piece {
  double ax, ay, bx, by;  // end points
  double mx, my;          // point over the middle
  bool arc = false;
  double cx = 0, cy = 0;  // arc centre
  double sweep = 0;       // signed angle from a to b about the centre
  double len = 0;         // arc (or chord) length

  void shape() {
    const double ex = bx - ax, ey = by - ay, c = std::hypot(ex, ey);
    // Sagitta: offset of the middle point from the chord, along the chord's left normal.
    const double nx = -ey / c, ny = ex / c;
    const double delta = (mx - 0.5 * (ax + bx)) * nx + (my - 0.5 * (ay + by)) * ny;
    if (!(std::fabs(delta) > 1e-9 * c)) {  // straight (to round-off of the CAD projection)
      len = c;
      return;
    }
    const double r = (0.25 * c * c + delta * delta) / (2 * std::fabs(delta));
    // The centre lies on the chord's bisector, r from the middle point, away from it.
    const double ux = (delta > 0 ? nx : -nx), uy = (delta > 0 ? ny : -ny);
    cx = mx - r * ux;
    cy = my - r * uy;
    const double half = 2 * std::atan2(std::fabs(delta), 0.5 * c);  // half the arc's angle
    // Turning from a towards the middle point: counter-clockwise if cross(a - C, m - C) > 0.
    const double turn = (ax - cx) * (my - cy) - (ay - cy) * (mx - cx);
    sweep = (turn > 0 ? 2 : -2) * half;
    len = r * std::fabs(sweep);
    arc = true;
  }

  // Point at fraction f of the arc length.
  void at(double f, double& x, double& y) const {
    if (f <= 0) { x = ax; y = ay; return; }
    if (f >= 1) { x = bx; y = by; return; }
    if (!arc) {
      x = ax + f * (bx - ax);
      y = ay + f * (by - ay);
      return;
    }
    const double t = f * sweep, c = std::cos(t), s = std::sin(t);
    const double rx = ax - cx, ry = ay - cy;
    x = cx + c * rx - s * ry;
    y = cy + s * rx + c * ry;
  }
};

}  // namespace

CurvePoints curve_points(const Geometry& g, const Geometry::Curve& c, int count, double spacing,
                         bool reverse) {
  const std::string where = g.file + ": " + Geometry::label("physical curve", c.tag, c.name);
  // Segments of positive length, and their ends by node.
  std::vector<std::size_t> segs;
  for (std::size_t k = 0; k < c.segs.size(); ++k)
    if (c.segs[k][0] != c.segs[k][1] &&
        (g.x[c.segs[k][0]] != g.x[c.segs[k][1]] || g.y[c.segs[k][0]] != g.y[c.segs[k][1]]))
      segs.push_back(k);
  if (segs.empty()) throw GeometryError(where + " has no segment of positive length");
  // Ends of pieces that lie on each other (two gmsh curves with distinct but coincident end
  // points, e.g. the bottoms of two plates side by side) are joined: they count as one node.
  std::unordered_map<int, int> uses, alias;
  for (std::size_t q : segs) ++uses[c.segs[q][0]], ++uses[c.segs[q][1]];
  {
    std::vector<int> ends;
    double lo = HUGE_VAL, hi = -HUGE_VAL;
    for (const auto& [node, n] : uses) {
      if (n == 1) ends.push_back(node);
      lo = std::min({lo, g.x[node], g.y[node]});
      hi = std::max({hi, g.x[node], g.y[node]});
    }
    std::sort(ends.begin(), ends.end());
    const double tol = 1e-9 * std::max(hi - lo, 1e-300);
    for (std::size_t i = 0; i < ends.size(); ++i)
      for (std::size_t j = i + 1; j < ends.size(); ++j)
        if (!alias.count(ends[i]) && !alias.count(ends[j]) &&
            std::hypot(g.x[ends[i]] - g.x[ends[j]], g.y[ends[i]] - g.y[ends[j]]) <= tol)
          alias[ends[j]] = ends[i];
  }
  auto rep = [&](int node) {
    const auto it = alias.find(node);
    return it == alias.end() ? node : it->second;
  };
  std::unordered_map<int, std::vector<std::size_t>> at;  // node -> positions in segs
  for (std::size_t q = 0; q < segs.size(); ++q)
    for (int e = 0; e < 2; ++e) at[rep(c.segs[segs[q]][e])].push_back(q);
  for (const auto& [node, v] : at)
    if (v.size() > 2)
      throw GeometryError(where + " branches at (" + Geometry::num(g.x[node]) + ", " + Geometry::num(g.y[node]) +
                          "): " + std::to_string(v.size()) +
                          " segments meet there; a probe needs one unbranched curve");

  // Walk the chain from the first segment forwards (a -> b), then backwards from its start.
  std::vector<char> used(segs.size(), 0);
  auto walk = [&](int node, std::size_t from, std::vector<std::pair<std::size_t, bool>>& out) {
    // Follows the chain from `node`, leaving segment `from`; appends (segment, forward).
    std::size_t cur = from;
    while (true) {
      std::size_t next = segs.size();
      for (std::size_t q : at[node])
        if (q != cur && !used[q]) next = q;
      if (next == segs.size()) return node;
      used[next] = 1;
      const auto& sg = c.segs[segs[next]];
      const bool fwd = rep(sg[0]) == node;
      out.push_back({next, fwd});
      node = rep(fwd ? sg[1] : sg[0]);
      cur = next;
    }
  };
  used[0] = 1;
  std::vector<std::pair<std::size_t, bool>> ahead{{0, true}}, behind;
  const int first = rep(c.segs[segs[0]][0]);
  const int end = walk(rep(c.segs[segs[0]][1]), 0, ahead);
  const bool closed = end == first;
  if (!closed) walk(first, 0, behind);
  const std::size_t n_used = ahead.size() + behind.size();
  if (n_used != segs.size())
    throw GeometryError(where + " is not one connected curve (" + std::to_string(segs.size() - n_used) +
                        " of its " + std::to_string(segs.size()) +
                        " segments are not connected to the first one); a probe needs one chain");
  // The chain: behind (reversed, each segment flipped) then ahead.
  std::vector<Piece> chain;
  auto add = [&](std::size_t q, bool fwd) {
    const auto& sg = c.segs[segs[q]];
    const int a = fwd ? sg[0] : sg[1], b = fwd ? sg[1] : sg[0];
    Piece p;
    p.ax = g.x[a]; p.ay = g.y[a];
    p.bx = g.x[b]; p.by = g.y[b];
    const bool has_mid = c.mid.size() == c.segs.size();
    p.mx = has_mid ? c.mid[segs[q]][0] : 0.5 * (p.ax + p.bx);
    p.my = has_mid ? c.mid[segs[q]][1] : 0.5 * (p.ay + p.by);
    chain.push_back(p);
  };
  for (std::size_t k = behind.size(); k-- > 0;) add(behind[k].first, !behind[k].second);
  for (const auto& [q, fwd] : ahead) add(q, fwd);
  if (reverse) {
    std::reverse(chain.begin(), chain.end());
    for (auto& p : chain) std::swap(p.ax, p.bx), std::swap(p.ay, p.by);
  }
  std::vector<double> S(chain.size() + 1, 0.0);  // arc length at the start of each piece
  for (std::size_t k = 0; k < chain.size(); ++k) {
    chain[k].shape();
    S[k + 1] = S[k] + chain[k].len;
  }
  CurvePoints out;
  out.length = S.back();
  out.closed = closed;
  const double L = out.length;

  // Arc lengths of the points.
  std::vector<double> s;
  if (count > 0) {
    if (count < 2) throw GeometryError(where + ": a probe needs at least 2 points, got " + std::to_string(count));
    for (int k = 0; k < count; ++k)
      s.push_back(closed ? L * k / count : (k == count - 1 ? L : L * k / (count - 1)));
  } else {
    if (!(spacing > 0)) throw GeometryError(where + ": the spacing must be > 0");
    const double n = std::floor(L / spacing * (1 + 1e-9));  // whole spacings in L
    // Open: the points 0, spacing, ..., n spacing (<= L). Closed: the same, less the last one
    // when it falls on the first point (n spacing = L).
    const bool wraps = closed && std::fabs(n * spacing - L) <= 1e-9 * L;
    const double m = wraps ? n : n + 1;
    if (m < 2)
      throw GeometryError(where + ": spacing " + Geometry::num(spacing) + " gives fewer than 2 points on its length " + Geometry::num(L));
    if (m > 100000)
      throw GeometryError(where + ": spacing " + Geometry::num(spacing) + " gives " + Geometry::num(m) + " points (at most 100000)");
    for (long k = 0; k < static_cast<long>(m); ++k) s.push_back(std::min(k * spacing, L));
  }
  std::size_t piece = 0;
  for (double sk : s) {
    while (piece + 1 < chain.size() && sk > S[piece + 1]) ++piece;
    const Piece& p = chain[piece];
    const double f = p.len > 0 ? (sk - S[piece]) / p.len : 0.0;
    CurvePoint cp;
    cp.s = sk;
    p.at(f, cp.x, cp.y);
    // The same point on the chord (the meshed segment).
    const double ex = p.bx - p.ax, ey = p.by - p.ay, c2 = ex * ex + ey * ey;
    const double t = std::clamp(((cp.x - p.ax) * ex + (cp.y - p.ay) * ey) / c2, 0.0, 1.0);
    cp.cx = p.ax + t * ex;
    cp.cy = p.ay + t * ey;
    out.points.push_back(cp);
  }
  return out;
}

}  // namespace smpm
