// Light nodes extended from the heavy nodes behind them (light_nodes.hpp).
#include "silentmpm/light_nodes.hpp"

#include "silentmpm/grid.hpp"

namespace smpm {

// Node (a, b) is light when, for some direction (sx, sy) toward the body (each -1, 0 or 1, not
// both 0), every node of the extension's stencil lies on the grid and is at least 1 / ratio
// times as heavy as (a, b), and along each extended axis the node on the far side of (a, b) is
// no heavier than it (the body ends there). Along an extended axis the stencil is the next two
// nodes toward the body, weights 2 and -1 (the linear extension of the cell beyond); along the
// other axis the node's own line. A node with a constraint, or one a boundary layer weighs (its
// dashpot block), keeps its own velocity. Fewer extended axes first, then the heaviest nearest node.
void LightNodes::classify_and_fold(Grid& g, double floor, const std::vector<char>& layer) {
  links_.clear();
  const long nnx = g.nnx, nny = g.nny;
  const double* m = g.m.data();
  auto at = [nnx](long a, long b) { return b * nnx + a; };
  auto inside = [&](long a, long b) { return a >= 0 && a < nnx && b >= 0 && b < nny; };
  for (long b = 0; b < nny; ++b)
    for (long a = 0; a < nnx; ++a) {
      const long i = at(a, b);
      const double mi = m[i];
      if (!(mi > floor) || (g.fix[i] & 3) != 0 || layer[i]) continue;
      Link best;
      int best_axes = 3;
      double best_near = 0;
      for (int sy = -1; sy <= 1; ++sy)
        for (int sx = -1; sx <= 1; ++sx) {
          const int axes = (sx != 0) + (sy != 0);
          if (axes == 0 || axes > best_axes) continue;
          if (sx != 0 && inside(a - sx, b) && m[at(a - sx, b)] > mi) continue;
          if (sy != 0 && inside(a, b - sy) && m[at(a, b - sy)] > mi) continue;
          const long xs[2] = {a + sx, a + 2 * sx}, ys[2] = {b + sy, b + 2 * sy};
          const double wx[2] = {sx ? 2.0 : 1.0, -1.0}, wy[2] = {sy ? 2.0 : 1.0, -1.0};
          const int nx = sx ? 2 : 1, ny = sy ? 2 : 1;
          Link L;
          L.node = i;
          bool ok = true;
          for (int q = 0; q < ny && ok; ++q)
            for (int r = 0; r < nx && ok; ++r) {
              const long j = at(xs[r], ys[q]);
              ok = inside(xs[r], ys[q]) && m[j] * ratio >= mi;
              if (!ok) break;
              L.master[L.n] = j;
              L.w[L.n] = wx[r] * wy[q];
              ++L.n;
            }
          if (!ok) continue;
          const double near = m[at(a + sx, b + sy)];
          if (axes < best_axes || near > best_near) {
            best = L;
            best_axes = axes;
            best_near = near;
          }
        }
      if (best_axes < 3) links_.push_back(best);
    }
  // A master that is light itself would chain: such a node keeps its own velocity.
  light_.assign(g.nodes(), 0);
  for (const Link& L : links_) light_[L.node] = 1;
  std::size_t k = 0;
  for (const Link& L : links_) {
    bool chained = false;
    for (int q = 0; q < L.n; ++q) chained = chained || light_[L.master[q]];
    if (!chained) links_[k++] = L;
  }
  links_.resize(k);
  // The masses last (the momenta's weights are the same; no master is light).
  fold(g.px.data());
  fold(g.py.data());
  fold(g.m.data());
}

void LightNodes::fold(double* a) const {
  for (const Link& L : links_)
    for (int q = 0; q < L.n; ++q) a[L.master[q]] += L.w[q] * a[L.node];
}

void LightNodes::extend(double* a) const {
  for (const Link& L : links_) {
    double v = 0;
    for (int q = 0; q < L.n; ++q) v += L.w[q] * a[L.master[q]];
    a[L.node] = v;
  }
}

void LightNodes::fold_forces(Grid& g, double gx, double gy) const {
  for (const Link& L : links_) {
    g.fx[L.node] -= g.m[L.node] * gx;
    g.fy[L.node] -= g.m[L.node] * gy;
  }
  fold(g.fx.data());
  fold(g.fy.data());
}

void LightNodes::fold_product(const double* m, const unsigned char* fix, double floor,
                              const double* tx, const double* ty, double* ax,
                              double* ay) const {
  fold(ax);
  fold(ay);
  // The masters' next terms as the series will make them, extended to the light node.
  auto next = [&](long j, const double* t, const double* a, int bit) {
    return m[j] > floor && !(fix[j] & bit) ? t[j] - a[j] / m[j] : 0.0;
  };
  for (const Link& L : links_) {
    double nx = 0, ny = 0;
    for (int q = 0; q < L.n; ++q) {
      nx += L.w[q] * next(L.master[q], tx, ax, 1);
      ny += L.w[q] * next(L.master[q], ty, ay, 2);
    }
    const long i = L.node;
    ax[i] = m[i] * (tx[i] - nx);
    ay[i] = m[i] * (ty[i] - ny);
  }
}

}  // namespace smpm
