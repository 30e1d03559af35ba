#pragma once
// Dense uniform background grid of square cells. Nodal fields are plain arrays indexed
// n = j * nnx + i. The grid is reset every step (paper §3: the mesh may be discarded).
#include <cstddef>
#include <cstdint>
#include <new>
#include <vector>

namespace smpm {

// Storage on A-byte boundaries (a record of A bytes then lies on one cache line).
template <class T, std::size_t A>
struct AlignedAllocator {
  using value_type = T;
  template <class U>
  struct rebind { using other = AlignedAllocator<U, A>; };
  AlignedAllocator() = default;
  template <class U>
  AlignedAllocator(const AlignedAllocator<U, A>&) {}
  T* allocate(std::size_t n) {
    return static_cast<T*>(::operator new(n * sizeof(T), std::align_val_t(A)));
  }
  void deallocate(T* p, std::size_t) { ::operator delete(p, std::align_val_t(A)); }
  template <class U>
  bool operator==(const AlignedAllocator<U, A>&) const { return true; }
  template <class U>
  bool operator!=(const AlignedAllocator<U, A>&) const { return false; }
};

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
  // Semi-implicit nodal dashpot block C (symmetric 2x2), assembled from the boundary layers,
  // and the silent layers' weight w N rho c_d at the node (the dashpot solve's): kDash values
  // per node together, on one cache line (along an edge each node lies on its own lines of the
  // other fields).
  static constexpr int kDash = 4;
  std::vector<double, AlignedAllocator<double, 32>> dash;
  double& cxx(std::size_t n) { return dash[kDash * n]; }
  double& cxy(std::size_t n) { return dash[kDash * n + 1]; }
  double& cyy(std::size_t n) { return dash[kDash * n + 2]; }
  double& dash_weight(std::size_t n) { return dash[kDash * n + 3]; }
  double cxx(std::size_t n) const { return dash[kDash * n]; }
  double cxy(std::size_t n) const { return dash[kDash * n + 1]; }
  double cyy(std::size_t n) const { return dash[kDash * n + 2]; }
  double dash_weight(std::size_t n) const { return dash[kDash * n + 3]; }
  // Essential conditions: bit 0 fixes the x velocity, bit 1 fixes y. Bit 2 (kDashpotNode) is
  // the solver's: the node carries a dashpot block this step.
  std::vector<uint8_t> fix;
  static constexpr uint8_t kDashpotNode = 4;

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
