#pragma once
// Shape functions on a uniform square grid. A shape is a small struct the kernels (kernels.hpp)
// take as a template argument:
//   kNodes                 nodes in a particle's support
//   kRowsBelow, kRowsAbove node rows a particle in cell row r touches: [r - below, r + above]
//   eval(x, y, x0, y0, inv_h)     values N[a] and gradients dNx[a], dNy[a] at the point
//   node_indices(nnx, nodes)      grid node index of each a
//   grow_box(box)                 widen a node box {i0, i1, j0, j1} to the support
//
// Bilinear (paper Eq. 7).
//
// A point (x, y) lies in cell (ci, cj); its natural coordinates are (xi, eta) in [0, 1).
// The four nodes of the cell are numbered as in the paper:
//   1: (ci, cj)  2: (ci+1, cj)  3: (ci+1, cj+1)  4: (ci, cj+1)
// N1 = (1-xi)(1-eta), N2 = xi(1-eta), N3 = xi eta, N4 = (1-xi) eta.
#include <array>
#include <cmath>

namespace smpm {

struct Bilinear {
  static constexpr int kNodes = 4;
  static constexpr int kRowsBelow = 0, kRowsAbove = 1;
  int ci = 0, cj = 0;   // cell index
  double N[4];          // shape function values
  double dNx[4];        // dN/dx
  double dNy[4];        // dN/dy
  int di[4] = {0, 1, 1, 0};  // node offsets from (ci, cj)
  int dj[4] = {0, 0, 1, 1};

  // Evaluate at (x, y) for a grid with origin (x0, y0) and inverse spacing inv_h.
  inline void eval(double x, double y, double x0, double y0, double inv_h) {
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
  inline void eval_clamped(double x, double y, double x0, double y0, double inv_h, int nx,
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

}  // namespace smpm
