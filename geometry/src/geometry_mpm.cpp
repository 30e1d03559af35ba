// MPM bodies and boundary sets from gmsh groups: lattice seeding of physical surfaces, particle
// layers and grid nodes along physical curves. No gmsh here: only the arrays of Geometry.
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <sstream>
#include <unordered_map>

#include "silentmpm/geometry.hpp"
#include "silentmpm/solver.hpp"

namespace smpm {
namespace {


std::string grid_text(const Grid& G) {
  return "[" + Geometry::num(G.x0) + ", " + Geometry::num(G.x1()) + "] x [" + Geometry::num(G.y0) + ", " + Geometry::num(G.y1()) + "]";
}

inline double cross(double ax, double ay, double bx, double by) { return ax * by - ay * bx; }

// Point in triangle (inclusive of its edges, to a relative tolerance).
inline bool in_triangle(const Geometry& g, int a, int b, int c, double px, double py) {
  const double ax = g.x[a], ay = g.y[a], bx = g.x[b], by = g.y[b], cx = g.x[c], cy = g.y[c];
  const double o = cross(bx - ax, by - ay, cx - ax, cy - ay);
  if (o == 0) return false;
  const double eps = -1e-12 * std::fabs(o);
  const double s = o > 0 ? 1.0 : -1.0;
  return s * cross(bx - ax, by - ay, px - ax, py - ay) >= eps &&
         s * cross(cx - bx, cy - by, px - bx, py - by) >= eps &&
         s * cross(ax - cx, ay - cy, px - cx, py - cy) >= eps;
}

inline bool in_element(const Geometry& g, const std::array<int, 4>& e, double px, double py) {
  if (in_triangle(g, e[0], e[1], e[2], px, py)) return true;
  return e[3] >= 0 && in_triangle(g, e[0], e[2], e[3], px, py);
}

// A physical curve as a set of straight segments with outward normals and a bucket grid for
// closest-segment queries.
struct Polyline {
  struct Seg {
    double ax, ay, bx, by;   // end points
    double tx, ty, len;      // unit tangent a -> b, length
    double nx, ny;           // unit normal (outward once oriented)
    double nax, nay, nbx, nby;  // normals at the two ends (blended at smooth vertices)
    bool open_a = false, open_b = false;  // end of the curve (no other segment there)
    int na, nb;              // node indices
  };
  std::vector<Seg> segs;
  double length = 0;
  // Buckets.
  double bx0 = 0, by0 = 0, cell = 1;
  int bnx = 1, bny = 1;
  std::vector<std::vector<int>> bucket;

  Polyline(const Geometry& g, const Geometry::Curve& c) {
    for (const auto& s : c.segs) {
      Seg q;
      q.na = s[0];
      q.nb = s[1];
      q.ax = g.x[s[0]]; q.ay = g.y[s[0]];
      q.bx = g.x[s[1]]; q.by = g.y[s[1]];
      q.len = std::hypot(q.bx - q.ax, q.by - q.ay);
      if (!(q.len > 0)) continue;
      q.tx = (q.bx - q.ax) / q.len;
      q.ty = (q.by - q.ay) / q.len;
      q.nx = q.ty;
      q.ny = -q.tx;
      length += q.len;
      segs.push_back(q);
    }
  }

  // Ends and blended vertex normals (after orientation).
  void vertex_normals() {
    std::unordered_map<int, std::vector<std::pair<int, int>>> at;  // node -> (segment, end)
    for (std::size_t i = 0; i < segs.size(); ++i) {
      at[segs[i].na].push_back({static_cast<int>(i), 0});
      at[segs[i].nb].push_back({static_cast<int>(i), 1});
    }
    for (auto& s : segs) {
      s.nax = s.nbx = s.nx;
      s.nay = s.nby = s.ny;
    }
    const double smooth = std::cos(30.0 * M_PI / 180.0);
    for (const auto& [node, ends] : at) {
      if (ends.size() == 1) {
        Seg& s = segs[ends[0].first];
        (ends[0].second == 0 ? s.open_a : s.open_b) = true;
        continue;
      }
      if (ends.size() != 2) continue;  // a branch point: keep each side's normal
      Seg& s0 = segs[ends[0].first];
      Seg& s1 = segs[ends[1].first];
      if (s0.nx * s1.nx + s0.ny * s1.ny < smooth) continue;  // a corner
      double mx = s0.nx + s1.nx, my = s0.ny + s1.ny;
      const double m = std::hypot(mx, my);
      mx /= m;
      my /= m;
      for (const auto& [si, end] : ends) {
        Seg& s = segs[si];
        if (end == 0) s.nax = mx, s.nay = my;
        else s.nbx = mx, s.nby = my;
      }
    }
  }

  void build_buckets(double reach) {
    double x0 = HUGE_VAL, y0 = HUGE_VAL, x1 = -HUGE_VAL, y1 = -HUGE_VAL;
    for (const auto& s : segs) {
      x0 = std::min({x0, s.ax, s.bx}); y0 = std::min({y0, s.ay, s.by});
      x1 = std::max({x1, s.ax, s.bx}); y1 = std::max({y1, s.ay, s.by});
    }
    cell = std::max(reach, 1e-300);
    // At most about 2000 x 2000 buckets.
    cell = std::max(cell, (std::max(x1 - x0, y1 - y0) + 2 * reach) / 2000);
    bx0 = x0 - reach;
    by0 = y0 - reach;
    bnx = std::max(1, static_cast<int>(std::ceil((x1 - x0 + 2 * reach) / cell)) + 1);
    bny = std::max(1, static_cast<int>(std::ceil((y1 - y0 + 2 * reach) / cell)) + 1);
    bucket.assign(static_cast<std::size_t>(bnx) * bny, {});
    for (std::size_t i = 0; i < segs.size(); ++i) {
      const auto& s = segs[i];
      const int i0 = cx(std::min(s.ax, s.bx) - reach), i1 = cx(std::max(s.ax, s.bx) + reach);
      const int j0 = cy(std::min(s.ay, s.by) - reach), j1 = cy(std::max(s.ay, s.by) + reach);
      for (int j = j0; j <= j1; ++j)
        for (int k = i0; k <= i1; ++k) bucket[static_cast<std::size_t>(j) * bnx + k].push_back(static_cast<int>(i));
    }
  }
  int cx(double x) const { return std::clamp(static_cast<int>(std::floor((x - bx0) / cell)), 0, bnx - 1); }
  int cy(double y) const { return std::clamp(static_cast<int>(std::floor((y - by0) / cell)), 0, bny - 1); }

  // Closest segment to (px, py) among those bucketed near it: its index (or -1), distance and the
  // unclamped parameter along it (in length units from a).
  int closest(double px, double py, double& dist, double& along) const {
    const double fx = (px - bx0) / cell, fy = (py - by0) / cell;
    dist = HUGE_VAL;
    if (fx < 0 || fy < 0 || fx >= bnx || fy >= bny) return -1;
    int best = -1;
    for (int i : bucket[static_cast<std::size_t>(fy) * bnx + static_cast<std::size_t>(fx)]) {
      const Seg& s = segs[i];
      const double u = (px - s.ax) * s.tx + (py - s.ay) * s.ty;
      const double uc = std::clamp(u, 0.0, s.len);
      const double d = std::hypot(px - (s.ax + uc * s.tx), py - (s.ay + uc * s.ty));
      if (d < dist) dist = d, best = i, along = u;
    }
    return best;
  }

  // True if the closest point lies beyond an open end of the curve by more than tol.
  bool beyond_end(int i, double along, double tol) const {
    const Seg& s = segs[i];
    return (s.open_a && along < -tol) || (s.open_b && along > s.len + tol);
  }
};

// Interior test for a body given by a box.
inline bool in_box(const BodyRegion& r, double x, double y) {
  return x >= r.x0 && x <= r.x1 && y >= r.y0 && y <= r.y1;
}

}  // namespace

// ---------------------------------------------------------------------------------------------

std::size_t seed_surface(Solver& sol, const Geometry& g, const Geometry::Surface& s, int n,
                         int group, int body, double vx0, double vy0, Seeding seeding) {
  const Grid& G = sol.grid;
  const auto b = g.bounds(s);
  const double tol = 1e-6 * G.h;
  const std::string label = Geometry::label("physical surface", s.tag, s.name);
  if (b[0] < G.x0 - tol || b[1] < G.y0 - tol || b[2] > G.x1() + tol || b[3] > G.y1() + tol)
    throw GeometryError(g.file + ": " + label + " reaches outside the grid " + grid_text(G) +
                        ": its extent is [" + Geometry::num(b[0]) + ", " + Geometry::num(b[2]) + "] x [" + Geometry::num(b[1]) +
                        ", " + Geometry::num(b[3]) + "]");
  const double sp = G.h / n;
  const long NX = static_cast<long>(G.nx) * n, NY = static_cast<long>(G.ny) * n;
  auto lo = [&](double v, double o, long N) {
    return std::clamp(static_cast<long>(std::floor((v - o) / sp - 0.5)), 0L, N - 1);
  };
  auto hi = [&](double v, double o, long N) {
    return std::clamp(static_cast<long>(std::ceil((v - o) / sp - 0.5)), 0L, N - 1);
  };
  const long i0 = lo(b[0], G.x0, NX), i1 = hi(b[2], G.x0, NX);
  const long j0 = lo(b[1], G.y0, NY), j1 = hi(b[3], G.y0, NY);
  const long W = i1 - i0 + 1, H = j1 - j0 + 1;
  std::vector<uint8_t> mark(static_cast<std::size_t>(W) * H, 0);
  // Sub-lattice point i's position: the sub-cell's centre, or Gauss point i % n of cell i / n
  // (within 0.06 h of the centre: the elements' ranges below widen by one).
  const bool gauss = seeding == Seeding::Gauss;
  std::vector<double> gat(static_cast<std::size_t>(n)), gw(static_cast<std::size_t>(n));
  if (gauss)
    for (int q = 0; q < n; ++q) Solver::gauss_point(n, q, gat[q], gw[q]);
  auto pos = [&](long i, double o) {
    return gauss ? o + (static_cast<double>(i / n) + gat[i % n]) * G.h : o + (i + 0.5) * sp;
  };
  const long widen = gauss ? 1 : 0;
  for (const auto& e : s.elems) {
    double ex0 = HUGE_VAL, ey0 = HUGE_VAL, ex1 = -HUGE_VAL, ey1 = -HUGE_VAL;
    for (int k = 0; k < 4; ++k) {
      if (e[k] < 0) continue;
      ex0 = std::min(ex0, g.x[e[k]]); ey0 = std::min(ey0, g.y[e[k]]);
      ex1 = std::max(ex1, g.x[e[k]]); ey1 = std::max(ey1, g.y[e[k]]);
    }
    const long a0 = std::max(i0, lo(ex0, G.x0, NX) - widen);
    const long a1 = std::min(i1, hi(ex1, G.x0, NX) + widen);
    const long c0 = std::max(j0, lo(ey0, G.y0, NY) - widen);
    const long c1 = std::min(j1, hi(ey1, G.y0, NY) + widen);
    for (long j = c0; j <= c1; ++j) {
      const double py = pos(j, G.y0);
      for (long i = a0; i <= a1; ++i) {
        uint8_t& m = mark[static_cast<std::size_t>(j - j0) * W + (i - i0)];
        if (m) continue;
        if (in_element(g, e, pos(i, G.x0), py)) m = 1;
      }
    }
  }
  std::size_t count = 0;
  for (uint8_t m : mark) count += m;
  if (sol.seed_nothing) return count;
  const double rho = sol.materials.at(group).rho;
  Particles& p = sol.p;
  const std::size_t first = p.size();
  p.resize(first + count);
  std::size_t k = first;
  for (long j = j0; j <= j1; ++j)
    for (long i = i0; i <= i1; ++i) {
      if (!mark[static_cast<std::size_t>(j - j0) * W + (i - i0)]) continue;
      const double vol = gauss ? gw[i % n] * gw[j % n] * G.h * G.h : sp * sp;
      p.place(k, pos(i, G.x0), pos(j, G.y0), vol, rho, vx0, vy0, body, group);
      ++k;
    }
  return count;
}

BoundaryLayer select_curve_layer(const Solver& sol, const Geometry& g, const Geometry::Curve& c,
                                 const BodyRegion& region, int body, double depth,
                                 const std::string& name, LayerWeights weights) {
  const std::string label = Geometry::label("physical curve", c.tag, c.name);
  const std::string body_label =
      region.surface ? Geometry::label("physical surface", region.surface->tag, region.surface->name)
                     : "the body's box";
  Polyline P(g, c);
  if (P.segs.empty()) throw GeometryError(g.file + ": " + label + " has no segment of positive length");

  // Orientation: the outward normal points away from the body. For a surface body, from the
  // element of the surface that has the segment as an edge; for a box body, by testing points
  // just either side of the segment's midpoint.
  std::unordered_map<uint64_t, std::pair<int, int>> edge_elems;  // edge -> (element, count)
  auto key = [](int a, int b) {
    if (a > b) std::swap(a, b);
    return (static_cast<uint64_t>(static_cast<uint32_t>(a)) << 32) | static_cast<uint32_t>(b);
  };
  if (region.surface) {
    const auto& E = region.surface->elems;
    edge_elems.reserve(E.size() * 4);
    for (std::size_t e = 0; e < E.size(); ++e) {
      const int nn = E[e][3] < 0 ? 3 : 4;
      for (int k = 0; k < nn; ++k) {
        auto& v = edge_elems[key(E[e][k], E[e][(k + 1) % nn])];
        v.first = static_cast<int>(e);
        ++v.second;
      }
    }
  }
  for (auto& s : P.segs) {
    const double mx = 0.5 * (s.ax + s.bx), my = 0.5 * (s.ay + s.by);
    int side = 0;  // +1: body on the +n side, -1: on the -n side
    std::string problem;
    if (region.surface) {
      auto it = edge_elems.find(key(s.na, s.nb));
      if (it == edge_elems.end()) {
        problem = "is not on the boundary of " + body_label + " (no element of the surface has "
                  "the segment (" + Geometry::num(s.ax) + ", " + Geometry::num(s.ay) + ")-(" + Geometry::num(s.bx) + ", " +
                  Geometry::num(s.by) + ") as an edge)";
      } else if (it->second.second > 1) {
        problem = "runs through the inside of " + body_label + " at (" + Geometry::num(mx) + ", " + Geometry::num(my) + ")";
      } else {
        const auto& e = region.surface->elems[it->second.first];
        const int nn = e[3] < 0 ? 3 : 4;
        double cxm = 0, cym = 0;
        for (int k = 0; k < nn; ++k) cxm += g.x[e[k]] / nn, cym += g.y[e[k]] / nn;
        side = (cxm - mx) * s.nx + (cym - my) * s.ny > 0 ? 1 : -1;
      }
    } else {
      const double d = 1e-6 * std::max(s.len, sol.grid.h);
      const bool plus = in_box(region, mx + d * s.nx, my + d * s.ny);
      const bool minus = in_box(region, mx - d * s.nx, my - d * s.ny);
      if (plus == minus)
        problem = std::string(plus ? "runs through the inside of " : "does not touch ") +
                  body_label + " at (" + Geometry::num(mx) + ", " + Geometry::num(my) + ")";
      else side = plus ? 1 : -1;
    }
    if (!problem.empty()) throw GeometryError(g.file + ": " + label + " " + problem);
    if (side > 0) s.nx = -s.nx, s.ny = -s.ny;
  }
  P.vertex_normals();
  P.build_buckets(depth);

  BoundaryLayer L;
  L.name = name;
  L.depth = depth;
  L.length = P.length;
  const double tol = 1e-9 * sol.grid.h;
  const Particles& p = sol.p;
  double vsum = 0;
  std::vector<int> seg_of;
  std::vector<double> along_of;
  for (std::size_t k = 0; k < p.size(); ++k) {
    if (p.body[k] != body) continue;
    double dist, along;
    const int i = P.closest(p.x[k], p.y[k], dist, along);
    if (i < 0 || dist >= depth - tol) continue;
    if (P.beyond_end(i, along, tol)) continue;
    const auto& s = P.segs[i];
    const double u = std::clamp(along / s.len, 0.0, 1.0);
    double nx = (1 - u) * s.nax + u * s.nbx, ny = (1 - u) * s.nay + u * s.nby;
    const double m = std::hypot(nx, ny);
    nx /= m;
    ny /= m;
    L.ids.push_back(p.id[k]);
    L.idx.push_back(static_cast<uint32_t>(k));
    L.nx.push_back(nx);
    L.ny.push_back(ny);
    L.d.push_back(dist);
    L.w.push_back(p.vol[k]);
    seg_of.push_back(i);
    along_of.push_back(std::clamp(along, 0.0, s.len));
    vsum += p.vol[k];
  }
  if (vsum > 0) {
    L.width = vsum / L.length;
    for (double& w : L.w) w /= L.width;
  }
  if (weights == LayerWeights::Length && !L.w.empty()) {
    // Each particle carries the piece of its segment nearest to its projection (1D Voronoi cells
    // along the segment); particles projecting to the same point share their cell.
    std::vector<std::vector<std::size_t>> on(P.segs.size());
    for (std::size_t q = 0; q < seg_of.size(); ++q) on[seg_of[q]].push_back(q);
    double total = 0;
    for (std::size_t si = 0; si < on.size(); ++si) {
      auto& v = on[si];
      if (v.empty()) continue;
      std::sort(v.begin(), v.end(), [&](std::size_t a, std::size_t b) { return along_of[a] < along_of[b]; });
      const double len = P.segs[si].len, eps = 1e-9 * len;
      std::size_t g0 = 0;
      while (g0 < v.size()) {  // a group of equal projections
        std::size_t g1 = g0 + 1;
        while (g1 < v.size() && along_of[v[g1]] - along_of[v[g0]] <= eps) ++g1;
        const double lo = g0 == 0 ? 0.0 : 0.5 * (along_of[v[g0 - 1]] + along_of[v[g0]]);
        const double hi = g1 == v.size() ? len : 0.5 * (along_of[v[g1 - 1]] + along_of[v[g1]]);
        for (std::size_t q = g0; q < g1; ++q) L.w[v[q]] = (hi - lo) / (g1 - g0);
        total += hi - lo;
        g0 = g1;
      }
    }
    // Segments without a particle: spread their length so that the weights still sum to L.
    for (double& w : L.w) w *= L.length / total;
  }
  return L;
}

std::vector<uint32_t> nodes_near_curve(const Solver& sol, const Geometry& g,
                                       const Geometry::Curve& c, double tol) {
  Polyline P(g, c);
  std::vector<uint32_t> out;
  if (P.segs.empty()) return out;
  P.vertex_normals();  // marks the open ends
  const double reach = tol + 1e-6 * sol.grid.h;
  P.build_buckets(reach);
  const Grid& G = sol.grid;
  double x0 = HUGE_VAL, y0 = HUGE_VAL, x1 = -HUGE_VAL, y1 = -HUGE_VAL;
  for (const auto& s : P.segs) {
    x0 = std::min({x0, s.ax, s.bx}); y0 = std::min({y0, s.ay, s.by});
    x1 = std::max({x1, s.ax, s.bx}); y1 = std::max({y1, s.ay, s.by});
  }
  const int i0 = std::max(0, static_cast<int>(std::floor((x0 - reach - G.x0) / G.h)));
  const int i1 = std::min(G.nnx - 1, static_cast<int>(std::ceil((x1 + reach - G.x0) / G.h)));
  const int j0 = std::max(0, static_cast<int>(std::floor((y0 - reach - G.y0) / G.h)));
  const int j1 = std::min(G.nny - 1, static_cast<int>(std::ceil((y1 + reach - G.y0) / G.h)));
  for (int j = j0; j <= j1; ++j)
    for (int i = i0; i <= i1; ++i) {
      double dist, along;
      const int s = P.closest(G.node_x(i), G.node_y(j), dist, along);
      if (s < 0 || dist > reach) continue;
      if (P.beyond_end(s, along, 1e-6 * G.h)) continue;
      out.push_back(static_cast<uint32_t>(j * G.nnx + i));
    }
  return out;
}

}  // namespace smpm
