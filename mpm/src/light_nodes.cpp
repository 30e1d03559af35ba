// Light nodes extended from the heavy nodes behind them (light_nodes.hpp).
#include "silentmpm/light_nodes.hpp"

#include "silentmpm/grid.hpp"

#include <algorithm>

namespace smpm {

// Node (a, b) is light when, for some direction (sx, sy) toward the body (each -1, 0 or 1, not
// both 0), every node of the extension's stencil lies on the grid and is at least 1 / ratio
// times as heavy as (a, b) and at least half as heavy as the heaviest node within two of it, and
// along each extended axis the three nodes of the line beyond (a, b) are no heavier than it (the
// body ends there). Along an extended axis the stencil is the next two nodes toward the body,
// weights 2 and -1 (the linear extension of the cell beyond); along the other axis the node's
// own line; a corner (both axes) takes the diagonal node's velocity (weight 1). A node with a
// constraint, or one a boundary layer weighs (its dashpot block), keeps its own velocity. Fewer
// extended axes first, then the heaviest nearest node.
bool LightNodes::candidates(const Grid& g, double floor) {
  cand_.clear();
  const long n = static_cast<long>(g.nodes());
  const double* m = g.m.data();
  double top = 0;
  for (long i = 0; i < n; ++i) top = std::max(top, m[i]);
  // A light node is at most `ratio` times as heavy as some node, the heaviest included.
  const double cut = ratio * top;
  for (long i = 0; i < n; ++i)
    if (m[i] > floor && m[i] <= cut && (g.fix[i] & 3) == 0) cand_.push_back(i);
  if (cand_.empty()) links_.clear();
  return !cand_.empty();
}

void LightNodes::classify_and_fold(Grid& g, const std::vector<char>& layer) {
  constexpr double kHeavy = 0.5;
  links_.clear();
  const long nnx = g.nnx, nny = g.nny;
  const double* m = g.m.data();
  auto at = [nnx](long a, long b) { return b * nnx + a; };
  auto inside = [&](long a, long b) { return a >= 0 && a < nnx && b >= 0 && b < nny; };
  for (const long i : cand_) {
    const long a = i % nnx, b = i / nnx;
    const double mi = m[i];
    if (layer[i]) continue;
    // The heaviest node within two of it: a master must be at least half as heavy (a node at
    // the edge of the body, partly filled itself, would take the extension's -1 weight on a
    // small mass: its highest frequency rises past the step's).
    double near_top = 0;
    for (long q = std::max(0L, b - 2); q <= std::min(nny - 1, b + 2); ++q)
      for (long r = std::max(0L, a - 2); r <= std::min(nnx - 1, a + 2); ++r)
        near_top = std::max(near_top, m[at(r, q)]);
    Link best;
    int best_axes = 3;
    double best_near = 0;
    for (int sy = -1; sy <= 1; ++sy)
      for (int sx = -1; sx <= 1; ++sx) {
        const int axes = (sx != 0) + (sy != 0);
        if (axes == 0 || axes > best_axes) continue;
        // Beyond the node, along each extended axis, the three nodes of the next line are no
        // heavier than it: the body ends there (not a gap to another body).
        bool beyond = false;
        for (int t = -1; t <= 1; ++t) {
          if (sx != 0 && inside(a - sx, b + t) && m[at(a - sx, b + t)] > mi) beyond = true;
          if (sy != 0 && inside(a + t, b - sy) && m[at(a + t, b - sy)] > mi) beyond = true;
        }
        if (beyond) continue;
        // A corner (both axes) takes the diagonal node's velocity: the bilinear extension's
        // weights 4, -2, -2, 1 took enough mass off the -2 nodes of a corner to make two bodies
        // meeting at CFL 0.6 unstable.
        const long xs[2] = {a + sx, a + 2 * sx}, ys[2] = {b + sy, b + 2 * sy};
        const bool corner = axes == 2;
        const double wx[2] = {sx && !corner ? 2.0 : 1.0, -1.0};
        const double wy[2] = {sy && !corner ? 2.0 : 1.0, -1.0};
        const int nx = sx && !corner ? 2 : 1, ny = sy && !corner ? 2 : 1;
        Link L;
        L.node = i;
        bool ok = true;
        for (int q = 0; q < ny && ok; ++q)
          for (int r = 0; r < nx && ok; ++r) {
            const long j = at(xs[r], ys[q]);
            ok = inside(xs[r], ys[q]) && m[j] * ratio >= mi && m[j] >= kHeavy * near_top;
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
  if (light_.size() != g.nodes()) light_.assign(g.nodes(), 0);
  for (const Link& L : links_) light_[L.node] = 1;
  keep_.assign(links_.size(), 0);
  for (std::size_t j = 0; j < links_.size(); ++j) {
    bool chained = false;
    for (int q = 0; q < links_[j].n; ++q) chained = chained || light_[links_[j].master[q]];
    keep_[j] = !chained;
  }
  for (const Link& L : links_) light_[L.node] = 0;
  std::size_t k = 0;
  for (std::size_t j = 0; j < links_.size(); ++j)
    if (keep_[j]) links_[k++] = links_[j];
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
