#pragma once
// The MPM kernels as free functions over one range of particles and one set of nodal arrays,
// templated on the shape function (shape.hpp) and, for the stress update, on the material model.
//
// The solver's step (solver.cpp) calls them for every range of the strip colouring and for every
// velocity field: the grid's own arrays in the ordinary single-field step, one set of arrays per
// body in the multi-field contact (contact.hpp). A kernel never owns or swaps arrays; what it
// reads and writes is the NodalField it is handed.
//
// Each kernel keeps the arithmetic of the formulas it implements in a fixed order (node a = 0 ..
// Shape::kNodes - 1, particle by particle), so that a run is reproducible bit for bit for a given
// thread count.
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <type_traits>
#include <limits>

#include "silentmpm/film.hpp"
#include "silentmpm/grid.hpp"
#include "silentmpm/material.hpp"
#include "silentmpm/particles.hpp"
#include "silentmpm/shape.hpp"

namespace smpm {

// One velocity field on the grid: nodal arrays (all nodes, n = j * nnx + i). Pointers a kernel
// does not use may be null.
struct NodalField {
  double* m = nullptr;              // lumped mass
  double* px = nullptr;             // momentum at the start of the step
  double* py = nullptr;
  double* fx = nullptr;             // internal (+ external) force
  double* fy = nullptr;
  double* vx = nullptr;             // velocity at the start of the step
  double* vy = nullptr;
  double* vnx = nullptr;            // updated velocity
  double* vny = nullptr;
  double* qx = nullptr;             // MUSL: re-mapped momentum, then velocity
  double* qy = nullptr;
  // Multi-field contact only: mass gradient sum m_p grad N, and sum m_p N x_p, m_p N y_p,
  // m_p N sqrt(V_p) (nodal centroid and size of the body's particles).
  double* gx = nullptr;
  double* gy = nullptr;
  double* xm = nullptr;
  double* ym = nullptr;
  double* sm = nullptr;
};

// A range of node indices i0..i1, j0..j1 (inclusive); empty when i0 > i1 or j0 > j1.
using NodeBox = std::array<int, 4>;
inline bool box_empty(const NodeBox& b) { return b[0] > b[1] || b[2] > b[3]; }

// What a p2g pass maps.
enum Transfer : unsigned {
  kMomentum = 1,  // mass and momentum
  kForce = 2,     // internal force -V sigma grad N
  kContact = 4    // with kMomentum: the contact fields (mass gradient, centroid, size)
};

// Cell rows a moving pass found its particles in, and how many left the grid's columns.
struct RowSpan {
  int lo = std::numeric_limits<int>::max();
  int hi = std::numeric_limits<int>::min();
  int out = 0;
  double kinetic = 0; // g2p: kinetic energy of the particles' new velocities
  double speed2 = 0;  // g2p: largest squared particle speed
  void add(int r, bool outside) {
    lo = r < lo ? r : lo;
    hi = r > hi ? r : hi;
    out += outside;
  }
};

namespace kernels {

// Four particles at a time (GCC vector extensions): one register per quantity, each lane the
// scalar code's operations in its order.
namespace simd {
using V4 = double __attribute__((vector_size(32)));
inline V4 load(const double* a) {
  V4 v;
  std::memcpy(&v, a, sizeof v);
  return v;
}
inline void store(double* a, V4 v) { std::memcpy(a, &v, sizeof v); }
// The particle passes ask for their arrays' lines kAhead particles ahead: the hardware's stream
// prefetchers alone fall behind the ten or so arrays a pass reads (AMD EPYC host, one thread,
// 1e6 particles: 7-9 % of the MUSL step at 1 ppc, 14-18 % at 4 ppc; 5-7 % in cache at 1e5).
// W: the pass writes them too. A prefetch has no effect on the values and never faults.
constexpr uint32_t kAhead = 64;
template <int W = 0, class... A>
inline void prefetch_ahead(uint32_t k, const A*... a) {
  (__builtin_prefetch(a + k + kAhead, W), ...);
}
// The grid's node rows ahead of the pass: a pass over particles ordered by cell meets new lines
// of the nodal arrays first at the top node row of its cells (the rows below it met a cell row
// earlier). at: the last of four particles' top row's node; kGridAhead nodes beyond it.
constexpr long kGridAhead = 64;
template <int W = 0, class... A>
inline void prefetch_grid(long at, const A*... a) {
  (__builtin_prefetch(a + at + kGridAhead, W), ...);
}
// Bilinear::eval of four points: each one's first node n0 (its cell's lower left) and the values
// N (and gradients dNx, dNy) in Bilinear's node order.
inline void bilinear_values(V4 x, V4 y, double x0, double y0, double ih, long nnx, long n0[4],
                            V4 N[4], V4* dNx = nullptr, V4* dNy = nullptr) {
  const V4 gx = (x - x0) * ih, gy = (y - y0) * ih;
  V4 cif, cjf;
  for (int l = 0; l < 4; ++l) {
    const int ci = static_cast<int>(std::floor(gx[l])), cj = static_cast<int>(std::floor(gy[l]));
    cif[l] = ci;
    cjf[l] = cj;
    n0[l] = static_cast<long>(cj) * nnx + ci;
  }
  const V4 xi = gx - cif, eta = gy - cjf;
  const V4 a = 1.0 - xi, b = 1.0 - eta;
  N[0] = a * b; N[1] = xi * b; N[2] = xi * eta; N[3] = a * eta;
  if (dNx) {
    dNx[0] = -b * ih; dNx[1] = b * ih; dNx[2] = eta * ih; dNx[3] = -eta * ih;
    dNy[0] = -a * ih; dNy[1] = -xi * ih; dNy[2] = xi * ih; dNy[3] = a * ih;
  }
}
// The essential conditions of four nodes as lane masks: x held (fix bit 0) and y held (bit 1).
using M4 = long __attribute__((vector_size(32)));
inline void held(const uint8_t* fix, M4& hx, M4& hy) {
  for (int l = 0; l < 4; ++l) {
    hx[l] = (fix[l] & 1) ? -1 : 0;
    hy[l] = (fix[l] & 2) ? -1 : 0;
  }
}
// The four points' values of a nodal array at their node `off` from their first node n0.
inline V4 gather(const double* a, const long n0[4], long off) {
  return V4{a[n0[0] + off], a[n0[1] + off], a[n0[2] + off], a[n0[3] + off]};
}
// Whether four points' first nodes are consecutive (four particles in consecutive cells of a row,
// as at one particle per cell): their values of a nodal array at each node are then one load.
inline bool in_a_row(const long n0[4]) {
  return n0[1] == n0[0] + 1 && n0[2] == n0[0] + 2 && n0[3] == n0[0] + 3;
}
// Whether the four points lie two by two in two neighbouring cells of a row (n0 = c, c, c + 1,
// c + 1: a row of particles seeded at four per cell): their values at each node are then two.
inline bool in_pairs(const long n0[4]) {
  return n0[1] == n0[0] && n0[2] == n0[0] + 1 && n0[3] == n0[2];
}
// How four points' first nodes lie, for the passes' reads: kInRow (in_a_row); kInPairs
// (in_pairs); kInCell, all the same; kInTwo, each the first one's or the next (a row of particles
// seeded at 9 per cell spans two cells unevenly), `upper` marking the lanes of the next; else
// kScattered.
constexpr int kScattered = 0, kInRow = 1, kInPairs = 2, kInCell = 3, kInTwo = 4;
struct Layout {
  int kind;
  M4 upper;
};
inline Layout layout(const long n0[4]) {
  if (in_a_row(n0)) return {kInRow, M4{}};
  if (in_pairs(n0)) return {kInPairs, M4{}};
  M4 up;
  bool two = true, any = false;
  for (int l = 0; l < 4; ++l) {
    const long d = n0[l] - n0[0];
    two = two && (d == 0 || d == 1);
    any = any || d == 1;
    up[l] = d == 1 ? -1 : 0;
  }
  return {!two ? kScattered : any ? kInTwo : kInCell, up};
}
using V2 = double __attribute__((vector_size(16)));
// gather(a, n0, off), read as one load or two values where the layout allows: the same values.
inline V4 gather(const double* a, const long n0[4], long off, const Layout& lay) {
  if (lay.kind == kInRow) return load(a + n0[0] + off);
  if (lay.kind == kInPairs) {
    V2 two;
    std::memcpy(&two, a + n0[0] + off, sizeof two);
    return __builtin_shufflevector(two, two, 0, 0, 1, 1);
  }
  if (lay.kind == kInCell || lay.kind == kInTwo) {
    const double lo = a[n0[0] + off];
    if (lay.kind == kInCell) return V4{lo, lo, lo, lo};
    const double hi = a[n0[0] + 1 + off];
    return lay.upper ? V4{hi, hi, hi, hi} : V4{lo, lo, lo, lo};
  }
  return gather(a, n0, off);
}
// Four particles in consecutive cells of a grid row (in_a_row: particle l's cell starts at node
// n + l) summed into one row of nodes n .. n + 4 of `a`: right(s) adds to s each particle's term
// at its right node (lane l into node n + l + 1), left(s) each one's term at its left node (lane
// l into node n). At each node the right term of particle l - 1 comes before the left term of
// particle l: the particle order of the scalar loop, the same additions.
template <class Right, class Left>
inline void add_row(double* a, long n, const Right& right, const Left& left) {
  const V4 t = right(load(a + n + 1));  // nodes n + 1 .. n + 4
  const double a0 = a[n];
  const V4 s = __builtin_shufflevector(V4{a0, a0, a0, a0}, t, 3, 4, 5, 6);  // nodes n .. n + 3
  store(a + n, left(s));
  a[n + 4] = t[3];
}
// The same for supports three nodes wide (the 3 x 3 shapes: particle l's nodes n + l .. n + l + 2
// in the row, terms third(s), second(s), first(s) in that order at each node: those of particle
// l - 2, l - 1 and l, as the scalar loop adds them), into nodes n .. n + 5.
template <class Third, class Second, class First>
inline void add_row3(double* a, long n, const Third& third, const Second& second, const First& first) {
  const V4 t = third(load(a + n + 2));  // nodes n + 2 .. n + 5
  const double a1 = a[n + 1], a0 = a[n];
  const V4 u = second(__builtin_shufflevector(V4{a1, a1, a1, a1}, t, 3, 4, 5, 6));  // n + 1 .. n + 4
  const V4 s = __builtin_shufflevector(V4{a0, a0, a0, a0}, u, 3, 4, 5, 6);           // n .. n + 3
  store(a + n, first(s));
  a[n + 4] = u[3];
  a[n + 5] = t[3];
}
// The three node rows of four particles' 3 x 3 supports (in_a_row, first node n), add_row3 each:
// term(a) the terms at node a = 3 jj + ii of the support.
template <class Term>
inline void add_rows3(double* a, long n, long nnx, const Term& term) {
  for (int jj = 0; jj < 3; ++jj)
    add_row3(a, n + jj * nnx, term(3 * jj + 2), term(3 * jj + 1), term(3 * jj));
}
// t + w s for the row forms' adders.
inline auto plus(V4 w, V4 s) {
  return [w, s](V4 t) { return t + w * s; };
}
// Four particles two by two in cells n and n + 1 of a row (in_pairs) summed into nodes n .. n + 2
// of `a`, as two pairs of lanes, one particle of each cell: pair 0 the particles 0 and 2, pair 1
// the particles 1 and 3. right(s, j) adds pair j's terms at their right nodes (n + 1, n + 2),
// left(s, j) at their left nodes (n, n + 1). At node n + 1 the right terms of particles 0 and 1
// come before the left terms of 2 and 3: particle order at every node, the scalar loop's sums.
inline V2 pair_of(V4 w, int j) {
  return j == 0 ? __builtin_shufflevector(w, w, 0, 2) : __builtin_shufflevector(w, w, 1, 3);
}
template <class Right, class Left>
inline void add_pairs(double* a, long n, const Right& right, const Left& left) {
  V2 x;
  std::memcpy(&x, a + n + 1, sizeof x);  // nodes n + 1, n + 2
  x = right(right(x, 0), 1);
  V2 y = {a[n], x[0]};  // nodes n, n + 1
  y = left(left(y, 0), 1);
  std::memcpy(a + n, &y, sizeof y);
  a[n + 2] = x[1];
}
// p2g's health flags for four particles (volumes v, masses m), as the scalar loop sets them.
inline void check_volumes(V4 v, V4 m, double stretch_limit, bool& negative, bool& stretched) {
  for (int l = 0; l < 4; ++l) {
    negative |= std::signbit(v[l]);
    stretched |= v[l] > stretch_limit * m[l];
  }
}
// Four particles advance by dt (wx, wy) and their rows are tracked, as the scalar passes do.
inline void move(double* X, double* Y, V4 wx, V4 wy, double dt, const Grid& g, RowSpan& rows) {
  const double x0 = g.x0, y0 = g.y0, ih = g.inv_h, x1 = g.x1();
  const V4 xn = load(X) + dt * wx, yn = load(Y) + dt * wy;
  store(X, xn);
  store(Y, yn);
  for (int l = 0; l < 4; ++l)
    rows.add(static_cast<int>(std::floor((yn[l] - y0) * ih)), !(xn[l] >= x0 && xn[l] < x1));
}
// Four points' shape functions in registers, for the passes that take four particles at a time:
// each lane's first node n0 (the scalar shape's node a is n0 + off[a]), the values N[a] and
// gradients dNx[a], dNy[a], each the scalar shape's arithmetic. eval() returns false when a lane
// needs what the vector form leaves to the scalar shape (the 3 x 3 supports folded at the
// grid's edge): those four particles take the scalar loop.
struct Bilinear4 {
  static constexpr int kNodes = 4;
  long off[4];
  Bilinear4(long nnx, double) : off{0, 1, nnx + 1, nnx} {}
  bool eval(V4 x, V4 y, const double*, const Grid& g, long n0[4], V4 N[4], V4* dNx,
            V4* dNy) const {
    bilinear_values(x, y, g.x0, g.y0, g.inv_h, g.nnx, n0, N, dNx, dNy);
    return true;
  }
};
// The 3 x 3 shapes (Shape3x3): per axis the support's first node floor(g - 1/2), the offset
// from it and the weights of the shape's 1D rule (W::weights: four lanes' w[3], d[3]; given the
// particles' masses for the sized ones).
template <class W>
struct Shape3x3_4 {
  static constexpr int kNodes = 9;
  long off[9];
  W rule;
  Shape3x3_4(long nnx, double inv_rho) : rule{inv_rho} {
    for (int jj = 0; jj < 3; ++jj)
      for (int ii = 0; ii < 3; ++ii) off[3 * jj + ii] = jj * nnx + ii;
  }
  // One axis (coordinates x, the grid's origin x0): false if a lane's support leaves the nodes
  // 0 .. nn - 1. Each lane's first node and offset as Shape3x3::eval takes them.
  static bool axis(V4 x, double x0, double ih, int nn, int base[4], V4& f) {
    bool inside = true;
    for (int l = 0; l < 4; ++l) {
      double fl;
      shape_detail::first_node(x[l] - x0, ih, base[l], fl);
      f[l] = fl;
      inside = inside && base[l] >= 0 && base[l] + 2 < nn;
    }
    return inside;
  }
  bool eval(V4 x, V4 y, const double* mass, const Grid& g, long n0[4], V4 N[9], V4* dNx,
            V4* dNy) const {
    const double ih = g.inv_h;
    int bi[4], bj[4];
    V4 fx, fy;
    const bool in_x = axis(x, g.x0, ih, g.nnx, bi, fx);
    const bool in_y = axis(y, g.y0, ih, g.nny, bj, fy);
    if (!(in_x && in_y)) return false;
    V4 wx[3], dx[3], wy[3], dy[3];
    rule.weights(fx, fy, mass, ih, wx, dx, wy, dy);
    for (int l = 0; l < 4; ++l) n0[l] = static_cast<long>(bj[l]) * g.nnx + bi[l];
    for (int jj = 0; jj < 3; ++jj)
      for (int ii = 0; ii < 3; ++ii) {
        const int a = 3 * jj + ii;
        N[a] = wx[ii] * wy[jj];
        if (dNx) {
          dNx[a] = dx[ii] * ih * wy[jj];
          dNy[a] = wx[ii] * dy[jj] * ih;
        }
      }
    return true;
  }
};
// The quadratic B-spline's rule (shape_detail::bspline2_1d), in registers.
struct BSplineRule4 {
  double inv_rho;
  void weights(V4 fx, V4 fy, const double*, double, V4 wx[3], V4 dx[3], V4 wy[3],
               V4 dy[3]) const {
    shape_detail::bspline2_1d(fx, wx, dx);
    shape_detail::bspline2_1d(fy, wy, dy);
  }
};
// Uniform GIMP's rule (UGimp::size, shape_detail::ugimp_1d) in registers: each of its four
// formulas for every lane, then the one the lane's distance picks (the scalar rule's branches).
struct UGimpRule4 {
  double inv_rho;
  static void one(V4 xi, V4 lp, V4& w, V4& d) {
    V4 r, ss;
    for (int l = 0; l < 4; ++l) {
      r[l] = std::abs(xi[l]);
      ss[l] = shape_detail::ugimp_squares(xi[l], lp[l]);
    }
    const V4 one = {1, 1, 1, 1}, zero = {0, 0, 0, 0};
    const V4 sg = xi < 0 ? -one : one;
    const V4 q = 1 + lp - r;
    const V4 w1 = 1 - ss / (2 * lp), d1 = -xi / lp;
    const V4 w2 = 1 - r, d2 = -sg;
    const V4 w3 = q * q / (4 * lp), d3 = -sg * q / (2 * lp);
    w = r < lp ? w1 : r <= 1 - lp ? w2 : r < 1 + lp ? w3 : zero;
    d = r < lp ? d1 : r <= 1 - lp ? d2 : r < 1 + lp ? d3 : zero;
  }
  void weights(V4 fx, V4 fy, const double* mass, double ih, V4 wx[3], V4 dx[3], V4 wy[3],
               V4 dy[3]) const {
    V4 lp = {0, 0, 0, 0};  // (every lane set below)
    for (int l = 0; l < 4; ++l) {
      UGimp sf;
      sf.size(mass[l], inv_rho, ih);
      lp[l] = sf.lp;
    }
    for (int a = 0; a < 3; ++a) {
      one(fx - static_cast<double>(a), lp, wx[a], dx[a]);
      one(fy - static_cast<double>(a), lp, wy[a], dy[a]);
    }
  }
};
using BSpline4 = Shape3x3_4<BSplineRule4>;
using UGimp4 = Shape3x3_4<UGimpRule4>;
// The four-particle form of a scalar shape (void: none).
template <class Shape> struct Vector4 { using type = void; };
template <> struct Vector4<Bilinear> { using type = Bilinear4; };
template <> struct Vector4<BSpline2> { using type = BSpline4; };
template <> struct Vector4<UGimp> { using type = UGimp4; };
}  // namespace simd

// p2g with bilinear shapes (no contact fields), four particles at a time: the shape values in
// SIMD registers, the sums into the nodes lane by lane in particle order, each term as the
// scalar loop writes it (the same bits). Returns the first particle left for the scalar loop.
template <unsigned WHAT>
inline uint32_t p2g_bilinear4(const Grid& g, const Particles& p, uint32_t b, uint32_t e,
                              const NodalField& f, double stretch_limit, bool& negative,
                              bool& stretched) {
  using simd::V4;
  const double ih = g.inv_h;
  const long nnx = g.nnx;
  const double* X = p.x.data(); const double* Y = p.y.data();
  const double* VX = p.vx.data(); const double* VY = p.vy.data();
  const double* M = p.mass.data(); const double* V = p.vol.data();
  const double* SXX = p.sxx.data(); const double* SYY = p.syy.data(); const double* SXY = p.sxy.data();
  // The nodal arrays this pass sums into: m, px, py with the momenta, fx, fy with the force.
  constexpr bool kM = (WHAT & kMomentum) != 0, kFo = (WHAT & kForce) != 0;
  constexpr int kF = (kM ? 3 : 0) + (kFo ? 2 : 0), kFx = kM ? 3 : 0;
  double* fld[kF];
  if constexpr (kM) { fld[0] = f.m; fld[1] = f.px; fld[2] = f.py; }
  if constexpr (kFo) { fld[kFx] = f.fx; fld[kFx + 1] = f.fy; }
  // The last particle's four node sums, kept in registers (node order 0 at cl, 1 at cl + 1, 2 at
  // cl + nnx + 1, 3 at cl + nnx): a particle of the same cell goes on from all four, one in the
  // next cell of the row from the right column (the left one written back), any other has them
  // written back first: the same additions in the same order as through memory.
  long cl = -1;
  double L0[kF] = {}, R1[kF] = {}, R2[kF] = {}, L3[kF] = {};  // (read only once cl is set)
  auto flush = [&] {
    if (cl < 0) return;
    for (int c = 0; c < kF; ++c) {
      fld[c][cl] = L0[c]; fld[c][cl + 1] = R1[c];
      fld[c][cl + nnx + 1] = R2[c]; fld[c][cl + nnx] = L3[c];
    }
    cl = -1;
  };
  uint32_t k = b;
  for (; k + 4 <= e; k += 4) {
    long n0[4];
    V4 N[4], dNx[4], dNy[4];
    simd::prefetch_ahead(k, X, Y);
    if constexpr (kM) simd::prefetch_ahead(k, M, VX, VY);
    if constexpr (kFo) simd::prefetch_ahead(k, V, SXX, SYY, SXY);
    simd::bilinear_values(simd::load(X + k), simd::load(Y + k), g.x0, g.y0, ih, nnx, n0, N, dNx,
                          dNy);
    for (int c = 0; c < kF; ++c) simd::prefetch_grid<1>(n0[3] + nnx, fld[c]);
    if (const bool row = simd::in_a_row(n0); row || simd::in_pairs(n0)) {
      // A node row's sums at once (four consecutive cells: add_row), or two cells' (two by two:
      // add_pairs); each node's terms in particle order.
      flush();
      const long n = n0[0], nu = n + nnx;
      // F S added (SUB: subtracted) at each particle's right (Sr) and left (Sl) node of a row.
      auto into = [&](double* a, long at, V4 F, V4 Sr, V4 Sl, auto sub) {
        auto term = [](auto t, auto f, auto s) {
          if constexpr (decltype(sub)::value) return t - f * s;
          else return t + f * s;
        };
        using simd::pair_of;
        if (row)
          simd::add_row(a, at, [&](V4 t) { return term(t, F, Sr); }, [&](V4 t) { return term(t, F, Sl); });
        else
          simd::add_pairs(
              a, at, [&](simd::V2 t, int j) { return term(t, pair_of(F, j), pair_of(Sr, j)); },
              [&](simd::V2 t, int j) { return term(t, pair_of(F, j), pair_of(Sl, j)); });
      };
      const std::false_type add;
      const std::true_type sub;
      if constexpr (kM) {
        const V4 mk = simd::load(M + k), mvx = mk * simd::load(VX + k), mvy = mk * simd::load(VY + k);
        for (int c = 0; c < 3; ++c) {
          const V4 w = c == 0 ? mk : c == 1 ? mvx : mvy;
          into(fld[c], n, w, N[1], N[0], add);
          into(fld[c], nu, w, N[2], N[3], add);
        }
      }
      if constexpr (kFo) {
        const V4 v = simd::load(V + k), sxx = simd::load(SXX + k), syy = simd::load(SYY + k),
                 sxy = simd::load(SXY + k);
        simd::check_volumes(v, simd::load(M + k), stretch_limit, negative, stretched);
        V4 Tx[4], Ty[4];
        for (int a = 0; a < 4; ++a) {
          Tx[a] = sxx * dNx[a] + sxy * dNy[a];
          Ty[a] = sxy * dNx[a] + syy * dNy[a];
        }
        into(fld[kFx], n, v, Tx[1], Tx[0], sub);
        into(fld[kFx], nu, v, Tx[2], Tx[3], sub);
        into(fld[kFx + 1], n, v, Ty[1], Ty[0], sub);
        into(fld[kFx + 1], nu, v, Ty[2], Ty[3], sub);
      }
      continue;
    }
    for (int l = 0; l < 4; ++l) {
      const uint32_t q = k + l;
      const long i0 = n0[l];
      if (i0 == cl + 1 && cl >= 0) {
        for (int c = 0; c < kF; ++c) {
          fld[c][cl] = L0[c]; fld[c][cl + nnx] = L3[c];
          L0[c] = R1[c]; L3[c] = R2[c];
          R1[c] = fld[c][i0 + 1]; R2[c] = fld[c][i0 + nnx + 1];
        }
      } else if (i0 != cl) {
        flush();
        for (int c = 0; c < kF; ++c) {
          L0[c] = fld[c][i0]; R1[c] = fld[c][i0 + 1];
          R2[c] = fld[c][i0 + nnx + 1]; L3[c] = fld[c][i0 + nnx];
        }
      }
      cl = i0;
      double* node[4] = {L0, R1, R2, L3};
      if constexpr (kM) {
        const double mk = M[q], mvx = mk * VX[q], mvy = mk * VY[q];
        for (int a = 0; a < 4; ++a) {
          node[a][0] += mk * N[a][l];
          node[a][1] += mvx * N[a][l];
          node[a][2] += mvy * N[a][l];
        }
      }
      if constexpr (kFo) {
        const double v = V[q], sxx = SXX[q], syy = SYY[q], sxy = SXY[q];
        negative |= std::signbit(v);
        stretched |= v > stretch_limit * M[q];
        for (int a = 0; a < 4; ++a) {
          node[a][kFx] -= v * (sxx * dNx[a][l] + sxy * dNy[a][l]);
          node[a][kFx + 1] -= v * (sxy * dNx[a][l] + syy * dNy[a][l]);
        }
      }
    }
  }
  flush();
  return k;
}

// p2g four particles at a time with the 3 x 3 shapes of S4 (simd::BSpline4, UGimp4; no contact
// fields): the shape values in SIMD registers, the sums into the nodes lane by lane in particle
// order, each term as the scalar loop writes it (the same bits). Returns the first particle left
// for the scalar loop: the range's last one to three, or the first of four that S4 leaves to the
// scalar shape.
template <class S4, unsigned WHAT>
inline uint32_t p2g4(const Grid& g, const Particles& p, uint32_t b, uint32_t e, const NodalField& f,
                     double inv_rho, double stretch_limit, bool& negative, bool& stretched) {
  using simd::V4;
  constexpr int K = S4::kNodes;
  const S4 shape(g.nnx, inv_rho);
  const long* off = shape.off;
  const double* X = p.x.data(); const double* Y = p.y.data();
  const double* VX = p.vx.data(); const double* VY = p.vy.data();
  const double* M = p.mass.data(); const double* V = p.vol.data();
  const double* SXX = p.sxx.data(); const double* SYY = p.syy.data(); const double* SXY = p.sxy.data();
  uint32_t k = b;
  for (; k + 4 <= e; k += 4) {
    long n0[4];
    V4 N[K], dNx[K], dNy[K];
    simd::prefetch_ahead(k, X, Y, M);
    if constexpr ((WHAT & kMomentum) != 0) simd::prefetch_ahead(k, VX, VY);
    if constexpr ((WHAT & kForce) != 0) simd::prefetch_ahead(k, V, SXX, SYY, SXY);
    if (!shape.eval(simd::load(X + k), simd::load(Y + k), M + k, g, n0, N, dNx, dNy)) return k;
    if constexpr ((WHAT & kMomentum) != 0) simd::prefetch_grid<1>(n0[3] + off[K - 1], f.m, f.px, f.py);
    if constexpr ((WHAT & kForce) != 0) simd::prefetch_grid<1>(n0[3] + off[K - 1], f.fx, f.fy);
    if (K == 9 && simd::in_a_row(n0)) {  // each node row's sums at once, in particle order
      const long nnx = g.nnx;
      if constexpr ((WHAT & kMomentum) != 0) {
        const V4 mk = simd::load(M + k), mvx = mk * simd::load(VX + k), mvy = mk * simd::load(VY + k);
        double* fm[3] = {f.m, f.px, f.py};
        for (int c = 0; c < 3; ++c) {
          const V4 w = c == 0 ? mk : c == 1 ? mvx : mvy;
          simd::add_rows3(fm[c], n0[0], nnx, [&](int a) { return simd::plus(w, N[a]); });
        }
      }
      if constexpr ((WHAT & kForce) != 0) {
        const V4 v = simd::load(V + k), sxx = simd::load(SXX + k), syy = simd::load(SYY + k),
                 sxy = simd::load(SXY + k);
        simd::check_volumes(v, simd::load(M + k), stretch_limit, negative, stretched);
        auto tx = [&](int a) { return [&, a](V4 t) { return t - v * (sxx * dNx[a] + sxy * dNy[a]); }; };
        auto ty = [&](int a) { return [&, a](V4 t) { return t - v * (sxy * dNx[a] + syy * dNy[a]); }; };
        simd::add_rows3(f.fx, n0[0], nnx, tx);
        simd::add_rows3(f.fy, n0[0], nnx, ty);
      }
      continue;
    }
    for (int l = 0; l < 4; ++l) {
      const uint32_t q = k + l;
      if constexpr ((WHAT & kMomentum) != 0) {
        const double mk = M[q], mvx = mk * VX[q], mvy = mk * VY[q];
        for (int a = 0; a < K; ++a) {
          const long i = n0[l] + off[a];
          f.m[i] += mk * N[a][l];
          f.px[i] += mvx * N[a][l];
          f.py[i] += mvy * N[a][l];
        }
      }
      if constexpr ((WHAT & kForce) != 0) {
        const double v = V[q], sxx = SXX[q], syy = SYY[q], sxy = SXY[q];
        negative |= std::signbit(v);
        stretched |= v > stretch_limit * M[q];
        for (int a = 0; a < K; ++a) {
          const long i = n0[l] + off[a];
          f.fx[i] -= v * (sxx * dNx[a][l] + sxy * dNy[a][l]);
          f.fy[i] -= v * (sxy * dNx[a][l] + syy * dNy[a][l]);
        }
      }
    }
  }
  return k;
}

// Particle to grid over [b, e) (paper Eq. 15, 18): mass and momentum, and/or the internal force.
// With kContact the node box the particles touch is grown in `box`.
// inv_rho: 1 / density of the range's material (shapes that need the particle size).
// Returns, for the health check, from the pass that loads the volumes anyway (kForce passes
// only): kInverted when a particle of the range has a negative volume (J < 0), kStretched when
// one has V > stretch_limit * m (its wave speed c_d sqrt(J) puts dt above the stability limit).
constexpr unsigned kInverted = 1, kStretched = 2;
template <class Shape, unsigned WHAT>
inline unsigned p2g(const Grid& g, const Particles& p, uint32_t b, uint32_t e, const NodalField& f,
                    double inv_rho, NodeBox* box = nullptr,
                    double stretch_limit = std::numeric_limits<double>::infinity()) {
  const double ih = g.inv_h;
  const long nnx = g.nnx;
  const double* X = p.x.data(); const double* Y = p.y.data();
  const double* VX = p.vx.data(); const double* VY = p.vy.data();
  const double* M = p.mass.data(); const double* V = p.vol.data();
  const double* SXX = p.sxx.data(); const double* SYY = p.syy.data(); const double* SXY = p.sxy.data();
  Shape sf;
  long nodes[Shape::kNodes];
  bool negative = false, stretched = false;
  using S4 = typename simd::Vector4<Shape>::type;
  // Four at a time where the vector shape takes them (see update_stress).
  uint32_t k = b, retry = b;
  for (; k < e; ++k) {
    if constexpr (!std::is_void_v<S4> && (WHAT & kContact) == 0) {
      if (k == retry) {
        if constexpr (std::is_same_v<Shape, Bilinear>)
          k = p2g_bilinear4<WHAT>(g, p, k, e, f, stretch_limit, negative, stretched);
        else
          k = p2g4<S4, WHAT>(g, p, k, e, f, inv_rho, stretch_limit, negative, stretched);
        retry = k + 1;
        if (k == e) break;
      }
    }
    if constexpr (Shape::kSized) sf.size(M[k], inv_rho, ih);
    sf.eval(g, X[k], Y[k]);
    sf.node_indices(nnx, nodes);
    if constexpr ((WHAT & kMomentum) != 0) {
      const double mk = M[k], mvx = mk * VX[k], mvy = mk * VY[k];
      if constexpr ((WHAT & kContact) != 0) {
        sf.grow_box(*box);
        // sqrt(V_p) per node, not hoisted: hoisted, the compiler fuses the gradient sums into
        // FMAs differently and multi-field histories move at 1e-16 from earlier versions'.
        for (int a = 0; a < Shape::kNodes; ++a) {
          f.m[nodes[a]] += mk * sf.N[a];
          f.px[nodes[a]] += mvx * sf.N[a];
          f.py[nodes[a]] += mvy * sf.N[a];
          f.gx[nodes[a]] += mk * sf.dNx[a];
          f.gy[nodes[a]] += mk * sf.dNy[a];
          f.xm[nodes[a]] += mk * sf.N[a] * X[k];
          f.ym[nodes[a]] += mk * sf.N[a] * Y[k];
          f.sm[nodes[a]] += mk * sf.N[a] * std::sqrt(V[k]);
        }
      } else {
        for (int a = 0; a < Shape::kNodes; ++a) {
          f.m[nodes[a]] += mk * sf.N[a];
          f.px[nodes[a]] += mvx * sf.N[a];
          f.py[nodes[a]] += mvy * sf.N[a];
        }
      }
    }
    if constexpr ((WHAT & kForce) != 0) {
      const double v = V[k], sxx = SXX[k], syy = SYY[k], sxy = SXY[k];
      negative |= std::signbit(v);
      stretched |= v > stretch_limit * M[k];
      for (int a = 0; a < Shape::kNodes; ++a) {
        f.fx[nodes[a]] -= v * (sxx * sf.dNx[a] + sxy * sf.dNy[a]);
        f.fy[nodes[a]] -= v * (sxy * sf.dNx[a] + syy * sf.dNy[a]);
      }
    }
  }
  return (negative ? kInverted : 0u) | (stretched ? kStretched : 0u);
}

// g2p four particles at a time, with the shape functions of S4 (simd::Bilinear4, BSpline4,
// UGimp4): one SIMD register per quantity, each lane the scalar loop's operations in its order;
// the sums over particles, the kinetic energy and the re-mapped momenta, taken lane by lane in
// particle order: the same bits. Returns the first particle left for the scalar loop: the
// range's last one to three, or the first of four that S4 leaves to the scalar shape.
template <class S4, bool REMAP, bool MOVE>
inline uint32_t g2p4(const Grid& g, Particles& p, uint32_t b, uint32_t e, const NodalField& f,
                     double inv_rho, double flip, double dt, RowSpan& rows, double& kinetic,
                     double& speed2) {
  using simd::V4;
  constexpr int K = S4::kNodes;
  const S4 shape(g.nnx, inv_rho);
  const long* off = shape.off;
  const double pic = 1.0 - flip;
  const double* vx = f.vx; const double* vy = f.vy;
  const double* ux = f.vnx; const double* uy = f.vny;
  double* X = p.x.data(); double* Y = p.y.data();
  double* VX = p.vx.data(); double* VY = p.vy.data();
  const double* M = p.mass.data();
  uint32_t k = b;
  for (; k + 4 <= e; k += 4) {
    long n0[4];
    V4 N[K];
    simd::prefetch_ahead(k, X, Y, M);
    simd::prefetch_ahead<1>(k, VX, VY);
    if (!shape.eval(simd::load(X + k), simd::load(Y + k), M + k, g, n0, N, nullptr, nullptr)) return k;
    simd::prefetch_grid(n0[3] + off[K - 1], ux, uy, vx, vy);
    const simd::Layout lay = simd::layout(n0);
    const bool row = lay.kind == simd::kInRow;
    V4 dvx = {0, 0, 0, 0}, dvy = dvx, wx = dvx, wy = dvx;
#pragma GCC unroll 9
    for (int c = 0; c < K; ++c) {
      const V4 Ux = simd::gather(ux, n0, off[c], lay), Uy = simd::gather(uy, n0, off[c], lay);
      const V4 Vx = simd::gather(vx, n0, off[c], lay), Vy = simd::gather(vy, n0, off[c], lay);
      wx += N[c] * Ux;
      wy += N[c] * Uy;
      dvx += N[c] * (Ux - Vx);
      dvy += N[c] * (Uy - Vy);
    }
    const V4 nvx = flip * (simd::load(VX + k) + dvx) + pic * wx;
    const V4 nvy = flip * (simd::load(VY + k) + dvy) + pic * wy;
    simd::store(VX + k, nvx);
    simd::store(VY + k, nvy);
    const V4 v2 = nvx * nvx + nvy * nvy;
    const V4 mk = simd::load(M + k);
    // The sums lane by lane, each product taken into its sum as the scalar loop does.
    for (int l = 0; l < 4; ++l) {
      kinetic += 0.5 * mk[l] * v2[l];
      speed2 = v2[l] > speed2 ? v2[l] : speed2;
    }
    if constexpr (REMAP) {
      const V4 mvx = mk * nvx, mvy = mk * nvy;
      auto term = [&](V4 w, int a) { return simd::plus(w, N[a]); };
      if (K == 4 && row) {  // bilinear: node a is 0 lower left, 1 lower right, 2 upper right, 3 upper left
        const long n = n0[0], nu = n + g.nnx;
        simd::add_row(f.qx, n, term(mvx, 1), term(mvx, 0));
        simd::add_row(f.qx, nu, term(mvx, 2), term(mvx, 3));
        simd::add_row(f.qy, n, term(mvy, 1), term(mvy, 0));
        simd::add_row(f.qy, nu, term(mvy, 2), term(mvy, 3));
      } else if (K == 9 && row) {  // the 3 x 3 shapes: node a = 3 jj + ii at n0 + jj nnx + ii
        simd::add_rows3(f.qx, n0[0], g.nnx, [&](int a) { return term(mvx, a); });
        simd::add_rows3(f.qy, n0[0], g.nnx, [&](int a) { return term(mvy, a); });
      } else
      for (int l = 0; l < 4; ++l)
        for (int c = 0; c < K; ++c) {
          f.qx[n0[l] + off[c]] += mvx[l] * N[c][l];
          f.qy[n0[l] + off[c]] += mvy[l] * N[c][l];
        }
    }
    if constexpr (MOVE) simd::move(X + k, Y + k, wx, wy, dt, g, rows);
  }
  return k;
}

// Grid to particle over [b, e): velocities from the field's start (vx, vy) and updated (vnx, vny)
// nodal velocities with the FLIP/PIC blend (flip = 1: FLIP). REMAP: MUSL's re-map of the new
// particle momenta into (qx, qy). MOVE: USF's position update with the updated nodal velocity.
template <class Shape, bool REMAP, bool MOVE>
inline void g2p(const Grid& g, Particles& p, uint32_t b, uint32_t e, const NodalField& f,
                double inv_rho, double flip, double dt, RowSpan& rows) {
  const double x0 = g.x0, y0 = g.y0, ih = g.inv_h, x1 = g.x1();
  const long nnx = g.nnx;
  const double pic = 1.0 - flip;
  const double* vx = f.vx; const double* vy = f.vy;
  const double* ux = f.vnx; const double* uy = f.vny;
  double* X = p.x.data(); double* Y = p.y.data();
  double* VX = p.vx.data(); double* VY = p.vy.data();
  const double* M = p.mass.data();
  double kinetic = 0, speed2 = 0;  // kept local: a reference could alias the particle arrays
  Shape sf;
  long nodes[Shape::kNodes];
  using S4 = typename simd::Vector4<Shape>::type;
  // Four at a time where the vector shape takes them (see update_stress).
  uint32_t k = b, retry = b;
  for (; k < e; ++k) {
    if constexpr (!std::is_void_v<S4>) {
      if (k == retry) {
        k = g2p4<S4, REMAP, MOVE>(g, p, k, e, f, inv_rho, flip, dt, rows, kinetic, speed2);
        retry = k + 1;
        if (k == e) break;
      }
    }
    if constexpr (Shape::kSized) sf.size(M[k], inv_rho, ih);
    sf.eval(g, X[k], Y[k]);
    sf.node_indices(nnx, nodes);
    double dvx = 0, dvy = 0, wx = 0, wy = 0;
    for (int a = 0; a < Shape::kNodes; ++a) {
      const long i = nodes[a];
      wx += sf.N[a] * ux[i];
      wy += sf.N[a] * uy[i];
      dvx += sf.N[a] * (ux[i] - vx[i]);
      dvy += sf.N[a] * (uy[i] - vy[i]);
    }
    const double nvx = flip * (VX[k] + dvx) + pic * wx;
    const double nvy = flip * (VY[k] + dvy) + pic * wy;
    VX[k] = nvx; VY[k] = nvy;
    const double v2 = nvx * nvx + nvy * nvy;  // health checks (Solver::check_health)
    kinetic += 0.5 * M[k] * v2;
    speed2 = v2 > speed2 ? v2 : speed2;
    if constexpr (REMAP) {
      const double mvx = M[k] * nvx, mvy = M[k] * nvy;
      for (int a = 0; a < Shape::kNodes; ++a) {
        f.qx[nodes[a]] += mvx * sf.N[a];
        f.qy[nodes[a]] += mvy * sf.N[a];
      }
    }
    if constexpr (MOVE) {
      X[k] += dt * wx;
      Y[k] += dt * wy;
      rows.add(static_cast<int>(std::floor((Y[k] - y0) * ih)), !(X[k] >= x0 && X[k] < x1));
    }
  }
  rows.kinetic += kinetic;
  rows.speed2 = speed2 > rows.speed2 ? speed2 : rows.speed2;
}

// update_stress for the elastic and von Mises models, four particles at a time, with the shape
// functions of S4 (simd::Bilinear4, BSpline4, UGimp4): one SIMD register per quantity, each lane
// the scalar loop's operations in its order; the dissipation summed lane by lane in particle
// order: the same bits. Returns the first particle left for the scalar loop: the range's last
// one to three, or the first of four that S4 leaves to the scalar shape.
template <class S4, Model MODEL, bool MOVE>
inline uint32_t update_stress4(const Grid& g, Particles& p, uint32_t b, uint32_t e,
                               const Material& mat, const double* gx, const double* gy,
                               const double* ux, const double* uy, double dt, RowSpan& rows,
                               double& diss) {
  using simd::V4;
  constexpr int K = S4::kNodes;
  const S4 shape(g.nnx, 1.0 / mat.rho);
  const long* off = shape.off;
  double* X = p.x.data(); double* Y = p.y.data();
  const double* M = p.mass.data();
  double* V = p.vol.data();
  double* SXX = p.sxx.data(); double* SYY = p.syy.data();
  double* SZZ = p.szz.data(); double* SXY = p.sxy.data();
  const double mu = mat.mu;
  uint32_t k = b;
  for (; k + 4 <= e; k += 4) {
    long n0[4];
    V4 N[K], dNx[K], dNy[K];
    simd::prefetch_ahead<1>(k, X, Y, V, SXX, SYY, SZZ, SXY);
    if (!shape.eval(simd::load(X + k), simd::load(Y + k), M + k, g, n0, N, dNx, dNy)) return k;
    simd::prefetch_grid(n0[3] + off[K - 1], gx, gy);
    if constexpr (MOVE) simd::prefetch_grid(n0[3] + off[K - 1], ux, uy);
    const simd::Layout lay = simd::layout(n0);
    V4 lxx = {0, 0, 0, 0}, lxy = lxx, lyx = lxx, lyy = lxx, wx = lxx, wy = lxx;
#pragma GCC unroll 9
    for (int c = 0; c < K; ++c) {
      const V4 Gx = simd::gather(gx, n0, off[c], lay), Gy = simd::gather(gy, n0, off[c], lay);
      lxx += Gx * dNx[c];
      lxy += Gx * dNy[c];
      lyx += Gy * dNx[c];
      lyy += Gy * dNy[c];
      if constexpr (MOVE) {
        wx += N[c] * simd::gather(ux, n0, off[c], lay);
        wy += N[c] * simd::gather(uy, n0, off[c], lay);
      }
    }
    V4 sxx = simd::load(SXX + k), syy = simd::load(SYY + k), szz = simd::load(SZZ + k),
       sxy = simd::load(SXY + k);
    const V4 w = 0.5 * (lxy - lyx) * dt;
    const V4 rxx = 2 * w * sxy, rxy = w * (syy - sxx);
    sxx += rxx; syy -= rxx; sxy += rxy;
    elastic_increment(mat, lxx * dt, lyy * dt, (lxy + lyx) * dt, sxx, syy, szz, sxy);
    [[maybe_unused]] V4 wp = {0, 0, 0, 0};
    if constexpr (MODEL == Model::VonMises) {  // stress_update<VonMises>, the return where q > sigma_y
      using M4 = long __attribute__((vector_size(32)));
      const V4 pm = (sxx + syy + szz) / 3.0;
      const V4 a = sxx - pm, bd = syy - pm, c = szz - pm;
      const V4 ss = a * a + bd * bd + c * c + 2 * sxy * sxy;
      V4 q = {0, 0, 0, 0};
      for (int l = 0; l < 4; ++l) q[l] = std::sqrt(1.5 * ss[l]);
      const M4 plastic = !(q <= mat.sigma_y);
      if (plastic[0] | plastic[1] | plastic[2] | plastic[3]) {
        const V4 scale = mat.sigma_y / q;
        const V4 dgamma = (q - mat.sigma_y) / (3 * mu);
        wp = plastic ? scale * (1 - scale) * ss / (2 * mu) : wp;
        sxx = plastic ? pm + a * scale : sxx;
        syy = plastic ? pm + bd * scale : syy;
        szz = plastic ? pm + c * scale : szz;
        sxy = plastic ? sxy * scale : sxy;
        double* EP = p.eps_p.data() + k;
        for (int l = 0; l < 4; ++l)
          if (plastic[l]) EP[l] += dgamma[l];
      }
    }
    simd::store(SXX + k, sxx); simd::store(SYY + k, syy);
    simd::store(SZZ + k, szz); simd::store(SXY + k, sxy);
    const V4 vn = simd::load(V + k) * ((1 + lxx * dt) * (1 + lyy * dt) - lxy * lyx * dt * dt);
    simd::store(V + k, vn);
    if constexpr (MODEL == Model::VonMises)
      for (int l = 0; l < 4; ++l) diss += wp[l] * vn[l];  // in particle order, as the scalar loop
    if constexpr (MOVE) simd::move(X + k, Y + k, wx, wy, dt, g, rows);
  }
  return k;
}

// Stress update over [b, e) for one material group with model MODEL: velocity gradient from the
// nodal velocity (gx, gy), Jaumann rotation, strain increment, material update, volume. MOVE:
// the particle advances with the updated nodal velocity (ux, uy). Returns the energy dissipated.
template <class Shape, Model MODEL, bool MOVE>
inline double update_stress(const Grid& g, Particles& p, uint32_t b, uint32_t e,
                            const Material& mat, const double* gx, const double* gy,
                            const double* ux, const double* uy, double dt, RowSpan& rows) {
  const double x0 = g.x0, y0 = g.y0, ih = g.inv_h, x1 = g.x1();
  const long nnx = g.nnx;
  double* X = p.x.data(); double* Y = p.y.data();
  double* V = p.vol.data();
  double* SXX = p.sxx.data(); double* SYY = p.syy.data();
  double* SZZ = p.szz.data(); double* SXY = p.sxy.data();
  double* EP = p.eps_p.data();
  [[maybe_unused]] const double* M = p.mass.data();
  [[maybe_unused]] const double inv_rho = 1.0 / mat.rho;
  double diss = 0;
  Shape sf;
  long nodes[Shape::kNodes];
  using S4 = typename simd::Vector4<Shape>::type;
  constexpr bool kFour = !std::is_void_v<S4> && (MODEL == Model::Elastic || MODEL == Model::VonMises);
  // Four at a time where the vector shape takes them; four it leaves (a 3 x 3 support folded at
  // the grid's edge) go one by one until it takes four again.
  uint32_t k = b, retry = b;
  for (; k < e; ++k) {
    if constexpr (kFour) {
      if (k == retry) {
        k = update_stress4<S4, MODEL, MOVE>(g, p, k, e, mat, gx, gy, ux, uy, dt, rows, diss);
        retry = k + 1;
        if (k == e) break;
      }
    }
    if constexpr (Shape::kSized) sf.size(M[k], inv_rho, ih);
    sf.eval(g, X[k], Y[k]);
    sf.node_indices(nnx, nodes);
    double lxx = 0, lxy = 0, lyx = 0, lyy = 0, wx = 0, wy = 0;
    for (int a = 0; a < Shape::kNodes; ++a) {
      const long i = nodes[a];
      lxx += gx[i] * sf.dNx[a];
      lxy += gx[i] * sf.dNy[a];
      lyx += gy[i] * sf.dNx[a];
      lyy += gy[i] * sf.dNy[a];
      if constexpr (MOVE) {
        wx += sf.N[a] * ux[i];
        wy += sf.N[a] * uy[i];
      }
    }
    double sxx = SXX[k], syy = SYY[k], szz = SZZ[k], sxy = SXY[k];
    // Jaumann rotation with spin w = (dvx/dy - dvy/dx) / 2.
    const double w = 0.5 * (lxy - lyx) * dt;
    const double rxx = 2 * w * sxy, rxy = w * (syy - sxx);
    sxx += rxx; syy -= rxx; sxy += rxy;
    double wp;
    if constexpr (MODEL == Model::J2Film)  // history in the film arrays of the particles
      wp = film_update(mat, p, k, lxx * dt, lyy * dt, (lxy + lyx) * dt, sxx, syy, szz, sxy);
    else
      wp = stress_update<MODEL>(mat, lxx * dt, lyy * dt, (lxy + lyx) * dt, sxx, syy, szz, sxy,
                                EP[k]);
    SXX[k] = sxx; SYY[k] = syy; SZZ[k] = szz; SXY[k] = sxy;
    V[k] *= (1 + lxx * dt) * (1 + lyy * dt) - lxy * lyx * dt * dt;
    diss += wp * V[k];
    if constexpr (MOVE) {
      X[k] += dt * wx;
      Y[k] += dt * wy;
      rows.add(static_cast<int>(std::floor((Y[k] - y0) * ih)), !(X[k] >= x0 && X[k] < x1));
    }
  }
  return diss;
}

// The consistent mass matrix of particles [b, e) times a nodal vector field t: a_i += sum_p m_p
// N_i(x_p) sum_j N_j(x_p) t_j (one gather and one scatter per particle; Solver::correct_increments).
template <class Shape>
inline void consistent_mass_product(const Grid& g, const Particles& p, uint32_t b, uint32_t e,
                                    double inv_rho, const double* tx, const double* ty, double* ax,
                                    double* ay) {
  const double ih = g.inv_h;
  const long nnx = g.nnx;
  const double* X = p.x.data(); const double* Y = p.y.data();
  const double* M = p.mass.data();
  Shape sf;
  long nodes[Shape::kNodes];
  for (uint32_t k = b; k < e; ++k) {
    if constexpr (Shape::kSized) sf.size(M[k], inv_rho, ih);
    sf.eval(g, X[k], Y[k]);
    sf.node_indices(nnx, nodes);
    double ux = 0, uy = 0;
    for (int a = 0; a < Shape::kNodes; ++a) {
      ux += sf.N[a] * tx[nodes[a]];
      uy += sf.N[a] * ty[nodes[a]];
    }
    const double mx = M[k] * ux, my = M[k] * uy;
    for (int a = 0; a < Shape::kNodes; ++a) {
      ax[nodes[a]] += mx * sf.N[a];
      ay[nodes[a]] += my * sf.N[a];
    }
  }
}

// fn(node index) over the nodes of a box, rows in parallel.
template <class Fn>
inline void for_box(const NodeBox& bx, long nnx, int threads, Fn&& fn) {
  if (box_empty(bx)) return;
#pragma omp parallel for schedule(static) num_threads(threads)
  for (int j = bx[2]; j <= bx[3]; ++j) {
    const long r = static_cast<long>(j) * nnx;
    for (int i = bx[0]; i <= bx[1]; ++i) fn(r + i);
  }
}

// Nodal velocity v = p / m over the nodes of `box` (nodes lighter than `floor` get zero), with
// the essential conditions `fix` (bit 0: x held, bit 1: y held). v and p may alias.
inline void nodal_velocity_range(long i0, long i1, const double* m, const uint8_t* fix,
                                 const double* qx, const double* qy, double* vx, double* vy,
                                 double floor) {
  // Four nodes at a time (each lane the scalar loop's operations), then the rest one by one.
  using simd::V4;
  using simd::M4;
  const V4 zero = {0, 0, 0, 0};
  long i = i0;
  for (; i + 4 <= i1; i += 4) {
    const V4 mi = simd::load(m + i);
    M4 hx, hy;
    simd::held(fix + i, hx, hy);
    const M4 heavy = mi > floor;
    const V4 ax = (heavy & ~hx) ? simd::load(qx + i) / mi : zero;
    const V4 ay = (heavy & ~hy) ? simd::load(qy + i) / mi : zero;
    simd::store(vx + i, ax);
    simd::store(vy + i, ay);
  }
  for (; i < i1; ++i) {
    if (m[i] > floor) {
      vx[i] = (fix[i] & 1) ? 0.0 : qx[i] / m[i];
      vy[i] = (fix[i] & 2) ? 0.0 : qy[i] / m[i];
    } else {
      vx[i] = 0; vy[i] = 0;
    }
  }
}

inline void nodal_velocity(const Grid& g, const NodeBox& box, const double* m, const uint8_t* fix,
                           const double* qx, const double* qy, double* vx, double* vy,
                           double floor, int threads) {
  if (box_empty(box)) return;
  const long nnx = g.nnx;
#pragma omp parallel for schedule(static) num_threads(threads)
  for (int j = box[2]; j <= box[3]; ++j)
    nodal_velocity_range(j * nnx + box[0], j * nnx + box[1] + 1, m, fix, qx, qy, vx, vy, floor);
}

}  // namespace kernels
}  // namespace smpm
