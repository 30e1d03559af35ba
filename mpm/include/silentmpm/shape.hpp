#pragma once
// Bilinear shape functions on a uniform square grid (paper Eq. 7).
//
// A point (x, y) lies in cell (ci, cj); its natural coordinates are (xi, eta) in [0, 1).
// The four nodes of the cell are numbered as in the paper:
//   1: (ci, cj)  2: (ci+1, cj)  3: (ci+1, cj+1)  4: (ci, cj+1)
// N1 = (1-xi)(1-eta), N2 = xi(1-eta), N3 = xi eta, N4 = (1-xi) eta.
#include <cmath>

namespace smpm {

struct Bilinear {
  static constexpr int kNodes = 4;
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
