#pragma once
// Dense uniform background grid of square cells. Nodal fields are plain arrays indexed
// n = j * nnx + i. The grid is reset every step (paper §3: the mesh may be discarded).
#include <cstdint>
#include <vector>

namespace smpm {

struct Grid {
  double x0 = 0, y0 = 0;  // origin (lower-left node)
  double h = 1, inv_h = 1;
  int nx = 0, ny = 0;     // cells
  int nnx = 0, nny = 0;   // nodes per row / column

  // Per step nodal fields.
  std::vector<double> m;        // lumped mass (Eq. 15)
  std::vector<double> px, py;   // momentum at the start of the step
  std::vector<double> fx, fy;   // internal + external force (Eq. 17-19)
  std::vector<double> vx, vy;   // velocity at the start of the step (p / m)
  std::vector<double> vnx, vny; // updated velocity
  std::vector<double> qx, qy;   // MUSL: momentum re-mapped from the updated particle velocities
  // Semi-implicit nodal dashpot block C (symmetric 2x2), assembled from the silent layer.
  std::vector<double> cxx, cxy, cyy;
  // Essential conditions: bit 0 fixes the x velocity, bit 1 fixes y.
  std::vector<uint8_t> fix;

  // The geometry and the constraint flags; the nodal fields too unless `fields` is false (a grid
  // that only describes the whole one to a split over ranks, whose windows hold the fields).
  void init(double x0_, double y0_, double h_, int nx_, int ny_, bool fields = true);
  std::size_t nodes() const { return static_cast<std::size_t>(nnx) * nny; }
  double node_x(int i) const { return x0 + i * h; }
  double node_y(int j) const { return y0 + j * h; }
  double x1() const { return x0 + nx * h; }
  double y1() const { return y0 + ny * h; }
  bool inside(double x, double y) const {
    return x >= x0 && y >= y0 && x < x1() && y < y1();
  }
};

}  // namespace smpm
