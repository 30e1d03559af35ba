#pragma once
// Shape functions on a uniform square grid (docs/physics.md section 8). A shape is a small struct
// the kernels (kernels.hpp) take as a template argument:
//   kNodes                 nodes in a particle's support
//   kRowsBelow, kRowsAbove node rows a particle in cell row r touches: [r - below, r + above]
//   kSized                 the shape needs the particle's size: size(mass, inv_rho, inv_h) first
//   eval(grid, x, y)       values N[a] and gradients dNx[a], dNy[a] at a point of the grid
//   eval_clamped(grid, x, y)   the same for a boundary point that may sit on the grid's edge
//   node_indices(nnx, nodes)   grid node index of each a
//   grow_box(box)          widen a node box {i0, i1, j0, j1} to the support
// Three shapes: Bilinear (the paper's), UGimp (uniform GIMP) and BSpline2 (quadratic B-spline).
// Each is a partition of unity and reproduces linear fields, up to the grid's edges included.
//
// Bilinear (paper Eq. 7).
//
// A point (x, y) lies in cell (ci, cj); its natural coordinates are (xi, eta) in [0, 1).
// The four nodes of the cell are numbered as in the paper:
//   1: (ci, cj)  2: (ci+1, cj)  3: (ci+1, cj+1)  4: (ci, cj+1)
// N1 = (1-xi)(1-eta), N2 = xi(1-eta), N3 = xi eta, N4 = (1-xi) eta.
#include <array>
#include <cmath>

#include "silentmpm/grid.hpp"

// The kernels evaluate a shape once or twice per particle and pass: its evaluation must be
// inlined there. GCC stops inlining Bilinear::eval once the translation unit grows (measured: an
// out-of-line call per particle and pass cost 6-9 % of the bench), so it is forced.
#define SMPM_SHAPE_INLINE __attribute__((always_inline)) inline

namespace smpm {

struct Bilinear {
  static constexpr int kNodes = 4;
  static constexpr int kRowsBelow = 0, kRowsAbove = 1;
  static constexpr bool kSized = false;
  int ci = 0, cj = 0;   // cell index
  double N[4];          // shape function values
  double dNx[4];        // dN/dx
  double dNy[4];        // dN/dy
  int di[4] = {0, 1, 1, 0};  // node offsets from (ci, cj)
  int dj[4] = {0, 0, 1, 1};

  // Evaluate at (x, y) for a grid with origin (x0, y0) and inverse spacing inv_h.
  SMPM_SHAPE_INLINE void eval(double x, double y, double x0, double y0, double inv_h) {
    const double gx = (x - x0) * inv_h;
    const double gy = (y - y0) * inv_h;
    ci = static_cast<int>(std::floor(gx));
    cj = static_cast<int>(std::floor(gy));
    const double xi = gx - ci, eta = gy - cj;
    const double a = 1.0 - xi, b = 1.0 - eta;
    N[0] = a * b;  N[1] = xi * b;  N[2] = xi * eta;  N[3] = a * eta;
    dNx[0] = -b * inv_h;  dNx[1] = b * inv_h;  dNx[2] = eta * inv_h;  dNx[3] = -eta * inv_h;
    dNy[0] = -a * inv_h;  dNy[1] = -xi * inv_h; dNy[2] = xi * inv_h;  dNy[3] = a * inv_h;
  }

  inline void size(double, double, double) {}
  SMPM_SHAPE_INLINE void eval(const Grid& g, double x, double y) { eval(x, y, g.x0, g.y0, g.inv_h); }
  SMPM_SHAPE_INLINE void eval_clamped(const Grid& g, double x, double y) {
    eval_clamped(x, y, g.x0, g.y0, g.inv_h, g.nx, g.ny);
  }

  // Node indices in the order of N: 1 (ci, cj), 2 (ci+1, cj), 3 (ci+1, cj+1), 4 (ci, cj+1).
  inline void node_indices(long nnx, long nodes[4]) const {
    const long n0 = static_cast<long>(cj) * nnx + ci;
    nodes[0] = n0; nodes[1] = n0 + 1; nodes[2] = n0 + nnx + 1; nodes[3] = n0 + nnx;
  }

  inline void grow_box(std::array<int, 4>& b) const {
    b[0] = ci < b[0] ? ci : b[0];
    b[1] = ci + 1 > b[1] ? ci + 1 : b[1];
    b[2] = cj < b[2] ? cj : b[2];
    b[3] = cj + 1 > b[3] ? cj + 1 : b[3];
  }

  // As eval(), for a point that may lie on the last grid line (a boundary point): the cell is
  // clamped to [0, nx) x [0, ny) so the point is at natural coordinate 1 of the last cell.
  SMPM_SHAPE_INLINE void eval_clamped(double x, double y, double x0, double y0, double inv_h, int nx,
                           int ny) {
    eval(x, y, x0, y0, inv_h);
    if (ci >= nx || cj >= ny || ci < 0 || cj < 0) {
      const double gx = (x - x0) * inv_h, gy = (y - y0) * inv_h;
      ci = ci < 0 ? 0 : (ci >= nx ? nx - 1 : ci);
      cj = cj < 0 ? 0 : (cj >= ny ? ny - 1 : cj);
      const double xi = gx - ci, eta = gy - cj;
      const double a = 1.0 - xi, b = 1.0 - eta;
      N[0] = a * b;  N[1] = xi * b;  N[2] = xi * eta;  N[3] = a * eta;
      dNx[0] = -b * inv_h;  dNx[1] = b * inv_h;  dNx[2] = eta * inv_h;  dNx[3] = -eta * inv_h;
      dNy[0] = -a * inv_h;  dNy[1] = -xi * inv_h; dNy[2] = xi * inv_h;  dNy[3] = a * inv_h;
    }
  }
};

// ---- shapes with a 3 x 3 node support ----------------------------------------------------------
//
// In 1D a point at grid coordinate g = (x - x0) / h takes the nodes base, base + 1, base + 2
// with base = floor(g - 1/2) (the node nearest to the point is the middle one). At the grid's
// edges the support would reach a node outside the grid (index -1 or nn); its weight is folded
// onto the two nearest nodes inside by linear extrapolation, v_out = 2 v_edge - v_next, which
// keeps the partition of unity and the linear reproduction, makes the edge node interpolate at
// the edge (N = 1 there), and leaves every weight non-negative. For the quadratic B-spline this
// is the usual boundary modification of the basis; a grid needs at least 2 cells each way.
namespace shape_detail {

// Fold the weight of an outside node (index base = -1, or base + 2 = nn) onto the inside ones;
// afterwards base..base+2 are all grid nodes.
SMPM_SHAPE_INLINE void fold_edges(int& base, int nn, double w[3], double d[3]) {
  if (base < 0) {
    w[1] += 2 * w[0]; w[2] -= w[0];
    d[1] += 2 * d[0]; d[2] -= d[0];
    w[0] = w[1]; w[1] = w[2]; w[2] = 0;
    d[0] = d[1]; d[1] = d[2]; d[2] = 0;
    base = 0;
  } else if (base + 2 >= nn) {
    w[1] += 2 * w[2]; w[0] -= w[2];
    d[1] += 2 * d[2]; d[0] -= d[2];
    w[2] = w[1]; w[1] = w[0]; w[0] = 0;
    d[2] = d[1]; d[1] = d[0]; d[0] = 0;
    base = nn - 3;
  }
}

// The first node floor(g - 1/2) of a 3 x 3 support and the offset g - base, g = d / h the grid
// coordinate of a point at d from the grid's origin. Written out as multiply-adds where the
// host has them (GCC would otherwise fuse the product into its uses or not depending on the
// code around it), so that the kernels' four-particle form (kernels.hpp, simd::Shape3x3_4)
// computes the same bits.
SMPM_SHAPE_INLINE void first_node(double d, double ih, int& base, double& f) {
#if defined(__FMA__) && !defined(__clang__)
  base = static_cast<int>(std::floor(std::fma(d, ih, -0.5)));
  f = std::fma(d, ih, -static_cast<double>(base));
#else
  const double g = d * ih;
  base = static_cast<int>(std::floor(g - 0.5));
  f = g - base;
#endif
}

// Quadratic B-spline weights (and d/dg) of the nodes base..base+2 for fx = g - base in [1/2, 3/2).
// T: double, or a SIMD register of four (the kernels' four-particle form): the same operations.
template <class T>
SMPM_SHAPE_INLINE void bspline2_1d(T fx, T w[3], T d[3]) {
  const T a = 1.5 - fx, b = fx - 1.0, c = fx - 0.5;
  w[0] = 0.5 * a * a;  d[0] = -a;
  w[1] = 0.75 - b * b; d[1] = -2 * b;
  w[2] = 0.5 * c * c;  d[2] = c;
}

// Uniform GIMP weight (and d/dxi) of one node at distance xi (cell units) from a particle of
// half-width lp (cell units, 0 < lp <= 1/2): the hat function convolved with the particle's
// characteristic function (Bardenhagen & Kober 2004).
// xi^2 + lp^2 (a multiply-add written out: see first_node).
SMPM_SHAPE_INLINE double ugimp_squares(double xi, double lp) {
#if defined(__FMA__) && !defined(__clang__)
  return std::fma(xi, xi, lp * lp);
#else
  return xi * xi + lp * lp;
#endif
}

SMPM_SHAPE_INLINE void ugimp_1d(double xi, double lp, double& w, double& d) {
  const double r = std::abs(xi), sg = xi < 0 ? -1.0 : 1.0;
  if (r < lp) {
    w = 1 - ugimp_squares(xi, lp) / (2 * lp);
    d = -xi / lp;
  } else if (r <= 1 - lp) {
    w = 1 - r;
    d = -sg;
  } else if (r < 1 + lp) {
    const double q = 1 + lp - r;
    w = q * q / (4 * lp);
    d = -sg * q / (2 * lp);
  } else {
    w = 0;
    d = 0;
  }
}

}  // namespace shape_detail

// Tensor-product shape of 3 x 3 nodes from a 1D rule W (a functor filling w[3], d[3] for the
// nodes base..base+2 at grid coordinate g). Node a = 3 jj + ii is (bi + ii, bj + jj).
template <class Derived>
struct Shape3x3 {
  static constexpr int kNodes = 9;
  static constexpr int kRowsBelow = 1, kRowsAbove = 2;
  int bi = 0, bj = 0;  // lower-left node of the support
  double N[9], dNx[9], dNy[9];

  SMPM_SHAPE_INLINE void eval(const Grid& g, double x, double y) {
    double fx, fy;
    shape_detail::first_node(x - g.x0, g.inv_h, bi, fx);
    shape_detail::first_node(y - g.y0, g.inv_h, bj, fy);
    eval_f(g, fx, fy);
  }
  // A boundary point: its grid coordinates are clamped to the grid.
  SMPM_SHAPE_INLINE void eval_clamped(const Grid& g, double x, double y) {
    double gx = (x - g.x0) * g.inv_h, gy = (y - g.y0) * g.inv_h;
    gx = gx < 0 ? 0 : (gx > g.nx ? g.nx : gx);
    gy = gy < 0 ? 0 : (gy > g.ny ? g.ny : gy);
    bi = static_cast<int>(std::floor(gx - 0.5));
    bj = static_cast<int>(std::floor(gy - 0.5));
    eval_f(g, gx - bi, gy - bj);
  }
  inline void node_indices(long nnx, long nodes[9]) const {
    for (int jj = 0; jj < 3; ++jj)
      for (int ii = 0; ii < 3; ++ii) nodes[3 * jj + ii] = (static_cast<long>(bj) + jj) * nnx + bi + ii;
  }
  inline void grow_box(std::array<int, 4>& b) const {
    b[0] = bi < b[0] ? bi : b[0];
    b[1] = bi + 2 > b[1] ? bi + 2 : b[1];
    b[2] = bj < b[2] ? bj : b[2];
    b[3] = bj + 2 > b[3] ? bj + 2 : b[3];
  }

 private:
  // The values and gradients from the first nodes (bi, bj) and the offsets from them.
  SMPM_SHAPE_INLINE void eval_f(const Grid& g, double fx, double fy) {
    double wx[3], dx[3], wy[3], dy[3];
    static_cast<Derived*>(this)->weights(fx, wx, dx);
    static_cast<Derived*>(this)->weights(fy, wy, dy);
    shape_detail::fold_edges(bi, g.nnx, wx, dx);
    shape_detail::fold_edges(bj, g.nny, wy, dy);
    const double ih = g.inv_h;
    for (int jj = 0; jj < 3; ++jj)
      for (int ii = 0; ii < 3; ++ii) {
        const int a = 3 * jj + ii;
        N[a] = wx[ii] * wy[jj];
        dNx[a] = dx[ii] * ih * wy[jj];
        dNy[a] = wx[ii] * dy[jj] * ih;
      }
  }
};

// Quadratic B-spline (Steffen, Kirby & Berzins 2008): C1, support 3 cells, no cell-crossing jump
// of the gradient.
struct BSpline2 : Shape3x3<BSpline2> {
  static constexpr bool kSized = false;
  inline void size(double, double, double) {}
  inline void weights(double f, double w[3], double d[3]) const { shape_detail::bspline2_1d(f, w, d); }
};

// Uniform GIMP: each particle a square of side 2 lp, lp from its initial volume M_p / rho (the
// material's density), fixed through the run (the "u" of uGIMP); lp <= h/2.
struct UGimp : Shape3x3<UGimp> {
  static constexpr bool kSized = true;
  double lp = 0.5;  // half-width in cells
  // mass and 1 / density of the particle's material, 1 / h.
  inline void size(double mass, double inv_rho, double inv_h) {
    lp = 0.5 * std::sqrt(mass * inv_rho) * inv_h;
    lp = lp > 0.5 ? 0.5 : lp;
  }
  inline void weights(double f, double w[3], double d[3]) const {
    for (int a = 0; a < 3; ++a) shape_detail::ugimp_1d(f - a, lp, w[a], d[a]);
  }
};

// The shapes a case can choose (scheme.shape).
enum class ShapeKind { Bilinear, UGimp, BSpline2 };
const char* shape_name(ShapeKind s);

}  // namespace smpm
