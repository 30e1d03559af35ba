#include "silentmpm/grid.hpp"

namespace smpm {

void Grid::init(double x0_, double y0_, double h_, int nx_, int ny_, bool fields) {
  x0 = x0_; y0 = y0_; h = h_; inv_h = 1.0 / h_;
  nx = nx_; ny = ny_; nnx = nx + 1; nny = ny + 1;
  const std::size_t n = nodes();
  for (auto* v : {&m, &px, &py, &fx, &fy, &vx, &vy, &vnx, &vny, &qx, &qy}) {
    if (fields) v->assign(n, 0.0);
    else std::vector<double>().swap(*v);
  }
  if (fields) dash.assign(kDash * n, 0.0);
  else decltype(dash)().swap(dash);
  fix.assign(n, 0);
}

}  // namespace smpm
